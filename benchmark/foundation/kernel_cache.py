"""Keep numba's on-disk caches of the stepping kernel consistent with the kernels it calls.

numba's ``cache=True`` invalidates a cached function only when *its own* source file changes,
not when a function it calls in another module changes (numba issue #6845). The stepping
kernel calls the bearing, damper and controller kernels of other modules, which call further
ones; after an edit there (say, a new damper model registered in ``damper/models/registry.py``), a
stale cached ``run_steps`` would still dispatch to the old code (an unknown model id returns
NaN).

:func:`ensure_fresh` fingerprints the sources of every module the kernel can reach (size,
modification time and path of each file of :data:`KERNEL_SOURCES`) and, when the
fingerprint differs from the one stored beside the caches, deletes the numba cache files
(``*.nbi``, ``*.nbc``) of those packages, so that everything is recompiled once. It is called
explicitly, never as a side effect of an import: once per process by :func:`ensure_fresh_once`
at the entry points that run kernels (the ``sbib`` command, :func:`benchmark.simulator.simulation.simulate`,
:func:`damper.models.response.simulate`) and by the test suite's ``conftest.py``, before numba loads any
cache. With ``NUMBA_CACHE_DIR`` set, the caches live elsewhere
and are cleared there as well (the whole directory's ``.nbi``/``.nbc`` files).
"""

from __future__ import annotations

import contextlib
import hashlib
import os
from pathlib import Path

__all__ = ["ensure_fresh", "ensure_fresh_once", "kernel_source_fingerprint", "stepping_kernel_cached",
           "KERNEL_SOURCES", "KERNEL_SOURCE_DIRS"]

_ROOT = Path(__file__).resolve().parents[2]  # the repository root (benchmark/foundation/..)
#: Source files (globs relative to the repository root) the stepping kernel can reach.
KERNEL_SOURCES = ("benchmark/simulator/stepping.py", "benchmark/simulator/kernel_args.py",
                  "controllers/measurement_layout.py", "controllers/measurements.py",
                  "benchmark/simulator/isolation/*.py", "damper/models/*.py", "damper/diagnosis/effects.py",
                  "damper/diagnosis/augmented.py", "controllers/compiled.py")
#: Directories whose ``__pycache__`` holds numba caches of those modules.
KERNEL_SOURCE_DIRS = ("benchmark/simulator", "benchmark/simulator/isolation", "damper/models", "damper/diagnosis",
                      "controllers")
_STAMP_NAME = "sbib-kernel-sources.txt"


def kernel_source_fingerprint() -> str:
    """Hash of (path, size, mtime) of every ``.py`` file the kernel can reach."""
    h = hashlib.sha256()
    for pattern in KERNEL_SOURCES:
        for path in sorted(_ROOT.glob(pattern)):
            with contextlib.suppress(OSError):
                st = path.stat()
                h.update(f"{path.relative_to(_ROOT)}:{st.st_size}:{st.st_mtime_ns}\n".encode())
    return h.hexdigest()


def _cache_dirs() -> list[Path]:
    dirs = [_ROOT / rel / "__pycache__" for rel in KERNEL_SOURCE_DIRS]
    custom = os.environ.get("NUMBA_CACHE_DIR")
    if custom:
        dirs.append(Path(custom))
    return dirs


def ensure_fresh() -> bool:
    """Delete stale numba caches of the kernel's modules; return True if anything was cleared."""
    fingerprint = kernel_source_fingerprint()
    stamp_dir = _ROOT / "benchmark" / "__pycache__"
    stamp = stamp_dir / _STAMP_NAME
    try:
        if stamp.read_text() == fingerprint:
            return False
    except OSError:
        pass
    for folder in _cache_dirs():
        if not folder.is_dir():
            continue
        for pattern in ("*.nbi", "*.nbc"):
            for path in folder.rglob(pattern) if folder.name != "__pycache__" else folder.glob(pattern):
                with contextlib.suppress(OSError):
                    path.unlink()
    with contextlib.suppress(OSError):
        stamp_dir.mkdir(parents=True, exist_ok=True)
        tmp = stamp.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(fingerprint)
        os.replace(tmp, stamp)
    return True


_CHECKED = False


def ensure_fresh_once() -> None:
    """:func:`ensure_fresh`, the first time it is called in this process."""
    global _CHECKED
    if not _CHECKED:
        _CHECKED = True
        ensure_fresh()


def stepping_kernel_cached() -> bool:
    """Whether the building's stepping kernel has a compiled copy in numba's on-disk cache (False:
    the next run compiles it, a few minutes on 2 cores; the command line says so first)."""
    custom = os.environ.get("NUMBA_CACHE_DIR")
    folders = [Path(custom)] if custom else [_ROOT / "benchmark" / "simulator" / "__pycache__"]
    for folder in folders:
        with contextlib.suppress(OSError):
            if any(folder.rglob("stepping.run_steps-*.nbi")):
                return True
    return False
