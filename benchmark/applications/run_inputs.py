"""What a result names as its inputs: each file a run read, by absolute path and SHA-256.

``sbib run`` and ``sbib compare`` write the same entries (``inputs`` in their HDF5 files), so that
a result says which record, structure, damper model and user's controller it was computed
from, and an edited file is told from the one a result used (docs/results.md).
"""

from __future__ import annotations

from typing import Sequence

from benchmark.foundation.provenance import file_identity
from controllers.user import user_controller_file

__all__ = ["record_identity", "controller_identity", "damper_identities"]


def record_identity(source: str | Sequence[str]) -> dict:
    """A record's file by path and SHA-256; a pair of component files gives both under ``files``.

    Parameters
    ----------
    source : str or sequence of str
        The file the record was read from (a benchmark record's file, a user's file), or the two
        files of a pair; ``""``: a record with no file (a synthetic motion): ``{}``.
    """
    if isinstance(source, (list, tuple)):
        files = [file_identity(f) for f in source]
        if len(files) > 1:
            return {"path": " + ".join(f["path"] for f in files), "files": files}
        return files[0] if files else {}
    return file_identity(source) if source else {}


def controller_identity(spec: str) -> dict:
    """A controller by name, or a user's controller (``file.py:Class``, ``package.module:Class``)
    by its spec and its file's path and SHA-256 (:func:`controllers.user.user_controller_file`).

    Parameters
    ----------
    spec : str
        The ``--controller`` value.
    """
    source = user_controller_file(spec)
    return {"path": spec} if source is None else {**file_identity(source), "spec": spec}


def damper_identities(damper: dict | None) -> list[dict]:
    """The damper model files of a run's damper description (``{"dampers": [{"path": ...}]}``,
    :meth:`benchmark.applications.damper_choice.DamperChoice.describe`), by path and SHA-256.

    Parameters
    ----------
    damper : dict or None
        The description; ``None``: none.
    """
    return [file_identity(d["path"]) for d in (damper or {}).get("dampers", []) if d.get("path")]
