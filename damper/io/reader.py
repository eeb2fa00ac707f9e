"""The one entry for a damper-test file of any supported format: :func:`read_test`.

``sbib diagnose --data/--validate``, ``sbib identify --data`` and the Python API read tests through
it, so every command accepts the same formats and screens them the same way
(:mod:`damper.io.screening`):

* a UTFSM preprocessed ``.txt`` file, recognised by its name pattern
  (:func:`damper.io.data.read_utfsm`);
* a Dyke random-voltage record, recognised by its header (``t, D, Y, V, F``; :mod:`damper.io.dyke`);
* otherwise a damper CSV with units in its header (:func:`damper.io.data.read_csv`).
"""

from __future__ import annotations

from pathlib import Path

from benchmark.foundation.errors import InputError
from damper.io.data import DamperTest, parse_utfsm_name, read_csv, read_utfsm
from damper.io.dyke import is_dyke_file, read_dyke

__all__ = ["read_test"]


def read_test(path, keep_flagged: bool = False) -> DamperTest:
    """Read one damper test, screened; the format is recognised from the file (module docstring).

    Parameters
    ----------
    path : str or Path
        A UTFSM preprocessed ``.txt`` file, a Dyke CSV or a damper CSV.
    keep_flagged : bool
        Keep the samples the screening flags in fits and errors (the findings are still reported).

    Returns
    -------
    DamperTest
        The test in SI units, with the screening's findings and mask in its metadata.

    Raises
    ------
    InputError
        A file that cannot be read as any of the formats (the message names the file and line).
    """
    p = Path(path)
    if p.suffix.lower() == ".txt":
        try:
            parse_utfsm_name(p)
        except InputError:
            pass
        else:
            return read_utfsm(p, keep_flagged=keep_flagged)
    if p.is_file() and is_dyke_file(p):
        return read_dyke(p, keep_flagged=keep_flagged)
    return read_csv(p, keep_flagged=keep_flagged)
