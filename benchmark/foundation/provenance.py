"""Provenance attributes stored with every result file (package version, git commit, time, versions)."""

from __future__ import annotations

import datetime as _dt
import platform
import subprocess
import sys
from functools import lru_cache
from pathlib import Path
from benchmark import __version__

__all__ = ["provenance"]


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

    Keys: ``package``, ``package_version``, ``git_commit``, ``created_utc``, ``python``,
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
