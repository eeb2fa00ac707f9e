"""Provenance attributes stored with every result file (package version, git commit, time, versions)."""

from __future__ import annotations

import datetime as _dt
import platform
import subprocess
import sys
from functools import lru_cache
from pathlib import Path
from benchmark import __version__

__all__ = ["provenance", "file_identity", "record_command", "sha256_of"]


@lru_cache(maxsize=1)
def _git_commit() -> str:
    root = Path(__file__).resolve().parents[2]  # the repository root
    try:
        out = subprocess.run(["git", "-C", str(root), "rev-parse", "HEAD"], capture_output=True,
                             text=True, timeout=5, check=False)
        return out.stdout.strip() or "unknown"
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def provenance(**extra: object) -> dict[str, str]:
    """Return a flat dict of provenance attributes (strings), merged with ``extra``.

    Keys: ``command`` (the command line, ``sbib ...`` when run from the CLI), ``package``,
    ``package_version``, ``git_commit``, ``created_utc``, ``python``,
    ``numpy``, ``scipy``, ``numba``, ``platform``, plus ``extra`` converted to ``str``.

    Parameters
    ----------
    **extra
        Further attributes (converted to strings).
    """
    import numba
    import numpy
    import scipy


    attrs = {
        "command": _command_line(),
        "package": "sbib",
        "package_version": __version__,
        "git_commit": _git_commit(),
        "created_utc": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "python": sys.version.split()[0],
        "numpy": numpy.__version__,
        "scipy": scipy.__version__,
        "numba": numba.__version__,
        "platform": platform.platform(),
    }
    attrs.update({k: str(v) for k, v in extra.items()})
    return attrs


_COMMAND: list[str] = []


def record_command(argv: list[str]) -> None:
    """Set the command line the result files record (``sbib`` and its arguments, set by the
    CLI's entry point; a script's own ``sys.argv`` otherwise).

    Parameters
    ----------
    argv : list of str
        The program's name and its arguments.
    """
    _COMMAND[:] = [str(a) for a in argv]


def _command_line() -> str:
    """The command line, quoted as a shell would take it (the program by its name)."""
    import shlex
    argv = _COMMAND or list(sys.argv) or [""]
    return " ".join([Path(argv[0]).name] + [shlex.quote(a) for a in argv[1:]])


def file_identity(path: str | Path) -> dict[str, str]:
    """Where an input file was read and what it held: its absolute path and SHA-256.

    Parameters
    ----------
    path : str or Path
        The file; a name that is not a file (a benchmark record's name, a registered model)
        gives only ``{"path": name}``.
    """
    p = Path(path).expanduser()
    if not p.is_file():
        return {"path": str(path)}
    return {"path": str(p.resolve()), "sha256": sha256_of(p)}


def sha256_of(path: str | Path) -> str:
    """SHA-256 of a file's bytes (hex), read in blocks.

    Parameters
    ----------
    path : str or Path
        The file.
    """
    import hashlib
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()
