"""Where the shared benchmark data live.

The project never copies the benchmark's data into the repository. They are read
from a *shared* directory (the ``shared/`` folder beside the checkout), found in
this order: an explicit argument, the ``SBIB_SHARED`` environment variable, then
``../shared`` relative to the repository root. Records are looked up in
``--records-dir``, ``SBIB_RECORDS_DIR``, then ``<shared>/records/raw/FDZ``.
"""

from __future__ import annotations

import os
from pathlib import Path

from benchmark.foundation.errors import DataNotFoundError

__all__ = ["shared_dir", "records_dir", "structure_file"]

_REPO_ROOT = Path(__file__).resolve().parents[2]  # benchmark/foundation/paths.py -> repository root


def shared_dir(explicit: str | os.PathLike | None = None) -> Path:
    """Return the shared data directory.

    Parameters
    ----------
    explicit : path-like, optional
        A directory given by the caller (e.g. ``--shared``); wins over everything.

    Raises
    ------
    DataNotFoundError
        If no candidate directory exists; the message lists what was tried.
    """
    tried = []
    for candidate, origin in ((explicit, "argument"),
                              (os.environ.get("SBIB_SHARED"), "SBIB_SHARED"),
                              (_REPO_ROOT.parent / "shared", "default ../shared")):
        if candidate in (None, ""):
            continue
        path = Path(candidate).expanduser()
        tried.append(f"{path} ({origin})")
        if path.is_dir():
            return path.resolve()
    raise DataNotFoundError(
        "shared data directory not found; tried " + (", ".join(tried) or "nothing")
        + ". Set SBIB_SHARED to the folder holding benchmark/structure.json and records/.")


def records_dir(explicit: str | os.PathLike | None = None) -> Path:
    """Return the directory of the benchmark's two-column record files.

    Order: ``explicit`` (``--records-dir``), ``SBIB_RECORDS_DIR``, ``<shared>/records/raw/FDZ``.

    Raises
    ------
    DataNotFoundError
        If the chosen directory does not exist (the message names it).
    """
    for candidate, origin in ((explicit, "--records-dir"),
                              (os.environ.get("SBIB_RECORDS_DIR"), "SBIB_RECORDS_DIR")):
        if candidate not in (None, ""):
            path = Path(candidate).expanduser()
            if not path.is_dir():
                raise DataNotFoundError(f"records directory {path} (from {origin}) does not exist")
            return path.resolve()
    path = shared_dir() / "records" / "raw" / "FDZ"
    if not path.is_dir():
        raise DataNotFoundError(f"records directory {path} does not exist; pass --records-dir or set SBIB_RECORDS_DIR")
    return path


def structure_file(explicit: str | os.PathLike | None = None) -> Path:
    """Return the path of ``benchmark/structure.json`` (the benchmark's mode data).

    Raises
    ------
    DataNotFoundError
        If the file is absent.
    """
    path = Path(explicit) if explicit else shared_dir() / "benchmark" / "structure.json"
    if not path.is_file():
        raise DataNotFoundError(f"benchmark structure file {path} not found")
    return path
