"""Where the shared benchmark data live.

The project never copies the benchmark's data into the repository. They are read
from a *shared* directory (the ``shared/`` folder beside the checkout), found in
this order: an explicit argument, the ``SBIB_SHARED`` environment variable, then
``../shared`` relative to the repository root. A directory the user names (argument or
``SBIB_SHARED``) that does not exist is an error naming it, not a silent fallback. Records are looked up in
``--records-dir``, ``SBIB_RECORDS_DIR``, then ``<shared>/records/raw/FDZ``; the structure file
in an explicit path, ``SBIB_STRUCTURE``, then ``<shared>/benchmark/structure.json``.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

from benchmark.foundation.errors import DataNotFoundError

__all__ = ["shared_dir", "records_dir", "structure_file", "file_label"]

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
        If the directory named by ``explicit`` or ``SBIB_SHARED`` does not exist (the message
        names it; there is no fallback then), or if neither is given and ``../shared`` is absent.
    """
    # A directory the user named (argument or SBIB_SHARED) is used or refused, never skipped:
    # falling back to ../shared behind the user's back would run on data they did not choose.
    for candidate, origin in ((explicit, "argument"), (os.environ.get("SBIB_SHARED"), "SBIB_SHARED")):
        if candidate in (None, ""):
            continue
        path = Path(candidate).expanduser()
        if not path.is_dir():
            what = "does not exist" if not path.exists() else "is not a directory"
            setting = f"SBIB_SHARED={candidate}" if origin == "SBIB_SHARED" else f"{path} (given as argument)"
            raise DataNotFoundError(f"shared data directory {setting} {what}; set SBIB_SHARED to the folder "
                                    "holding benchmark/structure.json and records/, or unset it")
        return path.resolve()
    path = _REPO_ROOT.parent / "shared"
    if path.is_dir():
        return path.resolve()
    raise DataNotFoundError(
        f"shared data directory not found (SBIB_SHARED is not set and the default {path} does not exist); "
        "set SBIB_SHARED to the folder holding benchmark/structure.json and records/")


def records_dir(explicit: str | os.PathLike | None = None) -> Path:
    """Return the directory of the benchmark's two-column record files.

    Order: ``explicit`` (``--records-dir``), ``SBIB_RECORDS_DIR``, ``<shared>/records/raw/FDZ``.

    Parameters
    ----------
    explicit : str | os.PathLike | None, optional
        A path given by the user (option or argument); None: the environment variable, then the default
        location.

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
                setting = f"SBIB_RECORDS_DIR={candidate}" if origin == "SBIB_RECORDS_DIR" else f"{path} (from {origin})"
                raise DataNotFoundError(f"records directory {setting} does not exist; give an existing "
                                        "--records-dir or set SBIB_RECORDS_DIR to one")
            return path.resolve()
    path = shared_dir() / "records" / "raw" / "FDZ"
    if not path.is_dir():
        raise DataNotFoundError(f"records directory {path} does not exist; pass --records-dir or set SBIB_RECORDS_DIR")
    return path


def structure_file(explicit: str | os.PathLike | None = None) -> Path:
    """Return the path of ``benchmark/structure.json`` (the benchmark's mode data).

    Parameters
    ----------
    explicit : str | os.PathLike | None, optional
        A path given by the user (option or argument); None: the ``SBIB_STRUCTURE`` environment
        variable (a variant of the benchmark's structure file, also what ``--structure`` sets
        for a command and its worker processes), then ``<shared>/benchmark/structure.json``.

    Raises
    ------
    DataNotFoundError
        If the file is absent (naming ``SBIB_STRUCTURE`` when it came from there).
    """
    if explicit:
        path, origin = Path(explicit), ""
    elif os.environ.get("SBIB_STRUCTURE"):
        path, origin = Path(os.environ["SBIB_STRUCTURE"]), " (SBIB_STRUCTURE)"
    else:
        path, origin = shared_dir() / "benchmark" / "structure.json", ""
    if not path.is_file():
        raise DataNotFoundError(f"benchmark structure file {path}{origin} not found")
    return path


def file_label(text: str, limit: int = 100) -> str:
    """``text`` as one safe piece of a file name: letters, digits and ``_ . + -`` only.

    Names that end up in output file names come from users' files (a test's ``# name:`` line, a
    record's name); a separator or ``..`` in them must not place a file outside the output
    folder, nor make a subfolder. Every other run of characters becomes ``_``; leading dots are
    dropped (no hidden files, no ``..``); the result is cut to ``limit`` characters and is never
    empty.

    Parameters
    ----------
    text : str
        The label (a test's or a record's name).
    limit : int
        Longest result, in characters.
    """
    label = re.sub(r"[^A-Za-z0-9_.+-]+", "_", str(text)).lstrip(".")[:limit]
    return label or "_"

