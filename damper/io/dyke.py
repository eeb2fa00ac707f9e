"""Reader of the Dyke prototype MR-damper records (random motion, randomly switching voltage).

The files of Dyke's characterization tests of the ~1.5 kN prototype damper of Spencer et al.
(1997), as distributed in the converted CSV form (``ransim_u_converted.csv``, see the data
provenance notes of the shared data folder), have one quoted header line and columns

=====  ==========================================  =============
name   meaning                                     unit in file
=====  ==========================================  =============
``t``  time                                        s
``A``  acceleration channel (not used)             --
``D``  displacement                                cm
``Y``  command voltage                             V
``fs`` sampling rate (first row only)              Hz
``V``  velocity                                    cm/s
``F``  force                                       N
=====  ==========================================  =============

(rows may end with a trailing comma). :func:`read_dyke` converts cm and cm/s to m and m/s at
this edge and returns a :class:`~damper.io.data.DamperTest` with the command voltage as its input.

References
----------
Dyke S.J., *Prototype MR damper characterization tests using white noise*, NEES-2012-1158,
DesignSafe-CI, doi:10.4231/D3V11VM6X.
Spencer B.F. Jr., Dyke S.J., Sain M.K., Carlson J.D. (1997), *Phenomenological model for
magnetorheological dampers*, J. Eng. Mech. 123(3):230-238.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from benchmark.foundation.errors import DataNotFoundError, InputError
from benchmark.foundation.textfile import read_text
from damper.io.data import DamperTest, decimal_points, parse_rows, sniff_delimiter, split_rows
from damper.io.screening import repair_samples, screened

__all__ = ["read_dyke", "is_dyke_file", "looks_like_dyke_file", "DYKE_COLUMNS"]

#: Columns a Dyke record must have (``A`` and ``fs`` may be present and are ignored).
DYKE_COLUMNS = ("t", "D", "Y", "V", "F")
_CM = 1e-2


def _header(path: Path) -> list[str] | None:
    try:
        with open(path, newline="", encoding="utf-8-sig", errors="replace") as fh:  # -sig: a BOM is not a name
            text = fh.read(65536)
    except OSError:
        return None
    for _, row in split_rows(text, sniff_delimiter(text)):
        if row and any(c.strip() for c in row):
            return [c.strip().strip('"') for c in row]
    return None


def is_dyke_file(path) -> bool:
    """Whether ``path`` is a CSV whose header carries the Dyke columns (t, D, Y, V, F).

    Parameters
    ----------
    path
        File to look at.
    """
    header = _header(Path(path))
    return header is not None and all(c in header for c in DYKE_COLUMNS)


def looks_like_dyke_file(path) -> bool:
    """Whether ``path``'s header is Dyke's (``t``, at least three of D, Y, V, F, and ``A`` or
    ``fs``), complete or not: such a file is read as a Dyke record (D in cm, V in cm/s), so that a
    missing column is named as one. A ``t, D, V, F, Y`` file without Dyke's ``A`` and ``fs`` is a
    user's own, and is not read in Dyke's units.

    Parameters
    ----------
    path
        File to look at.
    """
    header = _header(Path(path))
    # D, V, F, Y alone are letters anyone may use (in SI); Dyke's files also carry A and fs
    return (header is not None and "t" in header and "time" not in header
            and sum(c in header for c in DYKE_COLUMNS[1:]) >= 3 and ("fs" in header or "A" in header))


def read_dyke(path, name: str | None = None, keep_flagged: bool = False) -> DamperTest:
    """Read one Dyke record into SI units (displacement [m], velocity [m/s], force [N], voltage [V]),
    screened (:mod:`damper.io.screening`: the shared record's last 217 samples sit at the load
    cell's clipping level, 4545.45 N, with the displacement frozen; they are flagged and left
    out of fits and errors unless ``keep_flagged``).

    Parameters
    ----------
    path : path-like
        The CSV file (format in the module docstring).
    name : str, optional
        Label (default: the file stem).
    keep_flagged : bool
        Keep the flagged samples in the mask (only missing values stay out).

    Raises
    ------
    DataNotFoundError
        The file does not exist.
    InputError
        Missing columns, a non-numeric or non-finite value (the message names the line and
        column), fewer than 2 rows or a time axis that does not increase.
    """
    path = Path(path)
    if not path.exists():
        raise DataNotFoundError(f"{path}: Dyke damper record not found")
    text = read_text(path, "Dyke damper record")  # a directory, binary or not UTF-8: one-line InputError
    header = _header(path)
    if header is None:
        raise InputError(f"{path}: empty file; expected a header with columns t, D, Y, V, F")
    missing = [c for c in DYKE_COLUMNS if c not in header]
    if missing:
        raise InputError(f"{path}:1: header: missing column(s) {', '.join(missing)}; expected "
                         "t [s], D [cm], Y [V], V [cm/s], F [N]")
    index = {c: header.index(c) for c in DYKE_COLUMNS}
    rows: list[list[str]] = []
    lines: list[int] = []
    started = False
    delimiter = sniff_delimiter(text)
    for line_no, row in split_rows(text, delimiter):
        if not row or all(not c.strip() for c in row):
            continue
        if not started:
            started = True  # the header
            continue
        if len(row) <= max(index.values()):
            raise InputError(f"{path}:{line_no}: expected {len(header)} values ({', '.join(header)}), "
                             f"got {len(row)}")
        cells = decimal_points([row[index[c]] for c in DYKE_COLUMNS], delimiter)
        rows.append(cells)
        lines.append(line_no)
    if len(rows) < 2:
        raise InputError(f"{path}: expected at least 2 data lines, got {len(rows)}")
    data = parse_rows(path, list(DYKE_COLUMNS), rows, lines)
    t, d, y, v, f = (data[:, i] for i in range(5))
    t, col, excluded, prior = repair_samples(
        t, {"displacement": d * _CM, "velocity": v * _CM, "force": f, "voltage": y},
        label=str(path), lines=lines, keep_flagged=keep_flagged)
    test = DamperTest(time=t, displacement=col["displacement"], velocity=col["velocity"],
                      force=col["force"], voltage=col["voltage"],
                      name=name or path.stem, source=str(path),
                      metadata={"units_in_file": "t [s], D [cm], Y [V], V [cm/s], F [N]",
                                "provider": "S. Dyke, NEES-2012-1158 (doi:10.4231/D3V11VM6X)"})
    return screened(test, prior, excluded, keep_flagged=keep_flagged)
