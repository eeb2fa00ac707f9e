"""Readers for the ground-motion file formats users bring; units are converted here, at the edge.

Every reader returns a :class:`records.Record` in m/s² and rejects a malformed file with
an :class:`~benchmark.foundation.errors.InputError` whose one-line message names the file, the line
and what was expected (empty file, text where a number belongs, NaN or infinity, ragged
rows, a missing, zero or negative time step, time that does not increase).

Formats
-------
``benchmark``
    The smart base-isolated benchmark's two-column files (Narasimhan et al. 2006): header
    lines start with ``%``, two whitespace-separated columns (tabs or spaces, CRLF allowed),
    acceleration in cm/s², dt = 0.005 s. A step (``dt=0.005 sec``, ``DT: 0.01 s``, ``time step =
    20 ms``) or a unit written in the header, in ``%`` or ``#`` lines, is read and must agree with
    an explicit argument: any spelling of the unit table (``cm/sec^2``, ``m/s**2``, ``m/s²``,
    ``CM/SEC/SEC``, ``mm/s2``); a bare ``g`` or ``gal`` where the header states it as the unit
    (``in g``, ``units: g``, ``[g]``), never a value's unit (``PGA 0.82 g``); two units stated as
    the file's are refused (:func:`_header_units`).
``at2``
    PEER NGA ``.AT2``: four header lines (the third names the units, e.g. ``UNITS OF G``;
    the fourth gives ``NPTS=..., DT=...``, ``DT=..., NPTS=...`` or the older ``3908  .0100  NPTS, DT``), then the
    values, several per line; the number of values must equal NPTS.
``single``
    One value per line, no time column (e.g. the USGS SLAMMER library, in g). The time step
    is not in the file and must be given (``dt=``, ``--dt``).
``csv``
    A time column then one or more acceleration columns (``time, ax[, ay]``), separated by
    commas, semicolons or whitespace. Lines starting with ``#`` are comments; the first line
    :func:`write_csv` writes, ``# SYNTHETIC ground motion: <name>; source: <source>; written by
    sbib``, marks a generated motion, which stays ``synthetic`` (with its name and source) when
    read back. An optional
    header row names the columns and may carry units in brackets (``ax [g]``), in
    parentheses (``Acc (g)``), as a suffix after ``_`` (``ax_cm_s2``, ``acc_gal``; a bare ``_g`` is "ground", not g) or in a row of
    units under the names (``s, g, g``); a comment ``# units: g`` works too. Names that give a
    direction order the components (``time, ay, ax`` is read as ax, ay; ``FP, FN`` as FN, FP) and
    a vertical column (``az``, ``UP``) is left out, with a note in ``metadata["columns"]``
    (:func:`_component_order`). A column in a
    velocity or displacement unit (``vel (cm/s)``) is refused. Cells may be quoted, every line
    may end with the separator, and between semicolons or whitespace a decimal comma
    (``0,25``) is read as a decimal point; a file of ``1,5`` lines (a decimal comma or integer
    columns?) is refused. Over whitespace-separated data, names with spaces are split at tabs or
    at runs of spaces (``Time (s)<tab>Acc X (g)``). Time must increase with a uniform step
    (relative tolerance ``1e-3``, or stamps within half their last printed digit of a uniform
    grid: 1/300 s written as ``%.4f``, noted in ``metadata["time_rounded"]``); the record's time
    origin is moved to zero and the first time kept in metadata. A step outside
    :data:`DT_RANGE` (1e-5 to 1 s) is refused in every format. Components past the first two are
    named in ``metadata["columns"]`` when the building takes its two (``records.resolve``); a
    ``V`` beside ``H1, H2`` is the vertical.

``knet``, ``esm``, ``cosmos``
    NIED K-NET/KiK-net and ESM ASCII files (one component each) and COSMOS V1/V2 files
    (:mod:`records.station_files`).

Values whose magnitude exceeds 1e8 m/s² after conversion (no unit mix-up gives that much) are
refused as corrupt. PEER velocity (``.VT2``) and displacement (``.DT2``) files are refused, and
Fortran fixed-width values written without a space between them (``1.2E-02-3.4E-02``) are split.

Units accepted (case-insensitive, :mod:`benchmark.foundation.file_units`): ``g``; ``m/s2``,
``m/s^2``, ``m/s²``, ``m/s/s``, ``m/s**2``, ``m/sec/sec``; the same in ``cm`` (and ``gal``) and
``mm``. One g is 9.80665 m/s².
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path
from typing import Sequence

import numpy as np

from benchmark.foundation.atomic import atomic_path
from benchmark.foundation.errors import DataNotFoundError, InputError
from benchmark.foundation.file_units import QUANTITY_UNITS, si_factor, unit_key
from benchmark.foundation.textfile import decode_text, parse_float
from records.record import STANDARD_GRAVITY, Record
from records.file_values import DT_RANGE, is_vertical_label, unit_factor
from records.file_values import AXIS_NAME as _AXIS_NAME
from records.file_values import AXIS_SLOT as _AXIS_SLOT
from records.file_values import build_record as _record
from records.file_values import canonical_units as _canonical
from records.file_values import check_dt as _check_dt
from records.file_values import parse_number as _number
from records.file_values import read_lines as _read_lines
from records.file_values import to_si as _to_si
from records.station_files import is_cosmos, is_esm, is_knet, read_cosmos, read_esm, read_knet

__all__ = [
    "FORMATS",
    "BENCHMARK_DT",
    "unit_factor",
    "read_benchmark",
    "read_at2",
    "read_single_column",
    "read_csv",
    "load_record",
    "detect_format",
    "write_csv",
    "is_vertical_label",
]

#: Format names accepted by :func:`load_record`.
FORMATS = ("auto", "benchmark", "at2", "single", "csv", "knet", "esm", "cosmos")

#: The benchmark's sampling step [s] (Narasimhan et al. 2006; every FDZ file).
BENCHMARK_DT = 0.005


def _parse_table(lines: Sequence[str], path: Path, first_lineno: int, n_columns: int | None,
                 comment: tuple[str, ...], what: str) -> tuple[np.ndarray, list[int]]:
    """Parse whitespace/delimiter-split numeric rows; return (values, line numbers of the rows)."""
    rows: list[list[float]] = []
    linenos: list[int] = []
    for offset, line in enumerate(lines):
        lineno = first_lineno + offset
        stripped = line.strip()
        if not stripped or stripped.startswith(comment):
            continue
        tokens = stripped.split()
        if n_columns is None:
            n_columns = len(tokens)
        if len(tokens) != n_columns:
            raise InputError(f"{path}:{lineno}: row has {len(tokens)} values, expected {n_columns} "
                             f"({what}); ragged rows are not accepted")
        rows.append([_number(t, path, lineno, what) for t in tokens])
        linenos.append(lineno)
    if not rows:
        raise InputError(f"{path}: no data rows; expected {what}")
    if len(rows) < 2:
        raise InputError(f"{path}:{linenos[0]}: one data row; expected at least two samples ({what})")
    return np.asarray(rows, dtype=float), linenos


# --------------------------------------------------------------------------- benchmark format
#: A step stated in a header: ``dt=0.005 sec``, ``DT: 0.01 s``, ``time step = 5 ms``.
_DT_IN_HEADER = re.compile(r"\b(?:dt|delta\s*t|time\s*step|sampling\s*(?:interval|step))\s*[:=]?\s*"
                           r"([0-9]*\.?[0-9]+(?:[eEdD][-+]?[0-9]+)?)\s*(ms|msec|s|sec|seconds)?\b", re.IGNORECASE)
#: A word that could be an acceleration unit (``cm/sec^2``, ``m/s**2``, ``m/s²``, ``CM/SEC/SEC``, ``g``).
_UNIT_WORD = re.compile(r"(?<![\w/.^*])([A-Za-z][A-Za-z/^*²0-9]*)")
#: What comes before a unit that a header states as the file's (``in``, ``of``, ``units:``, ``[``).
_UNIT_CONTEXT = re.compile(r"(?:\b(?:in|of|units?|acc\w*)\s*[:=]?|[\[(:=])\s*$", re.IGNORECASE)


def _header_dt(header: str, where: str) -> float | None:
    """The time step a header states [s], or None."""
    m = _DT_IN_HEADER.search(header)
    if not m:
        return None
    scale = 1e-3 if (m.group(2) or "").lower() in ("ms", "msec") else 1.0
    return _check_dt(parse_float(m.group(1)) * scale, f"{where}: header dt")


def _stated(header: str, where: str, dt: float | None, units: str | None, said: str,
            origin: str, free: bool = False) -> tuple[float | None, str, str | None, str]:
    """The step and the unit of a file from its arguments and its comment lines (``header``):
    ``(dt, dt_from, units, units_from)``, None where neither gives them (the caller's default).
    An argument must agree with what the file states (``said``: "the header", "the file").

    ``free``: the lines are a user's free comments, not a format's header: a unit counts only
    where they state it as the values' (``units: m/s2``, ``in cm/s2``, ``[g]``; not ``converted
    from cm/s2``), and a ``--units`` argument wins over it (``in cm/s2, scaled to g`` states a
    unit the values no longer have)."""
    header_dt = _header_dt(header, where)
    dt_from = "argument"
    if dt is not None:
        dt = _check_dt(dt, f"{where}: dt argument")
        if header_dt is not None and not math.isclose(dt, header_dt, rel_tol=1e-9):
            raise InputError(f"{where}: dt = {dt} s given but {said} says dt = {header_dt} s")
    elif header_dt is not None:
        dt, dt_from = header_dt, origin
    units_from = "argument"
    if units is not None and free:
        unit_factor(units, f"{where}: units argument")
        return dt, dt_from, units, units_from
    found_units = _header_units(header, f"{where}: {origin}", stated_only=free)
    if units is not None:
        factor = unit_factor(units, f"{where}: units argument")
        if found_units is not None and not math.isclose(factor, unit_factor(found_units)):
            raise InputError(f"{where}: units {units!r} given but {said} says {found_units!r}")
    elif found_units is not None:
        units, units_from = found_units, origin
    return dt, dt_from, units, units_from


def _header_units(header: str, where: str = "header", stated_only: bool = False) -> str | None:
    """The acceleration unit a header names, looked up in the project's unit table.

    Any spelling the table knows is found (``cm/sec^2``, ``m/s**2``, ``m/s²``, ``m/sec/sec``,
    ``mm/s2``, ``gal``); a bare ``g`` or ``gal`` only where the header states it as a unit
    (after ``in``, ``of``, ``units:``, ``acc``, ``=`` or inside brackets: ``PGA 0.8 g`` is a value, not the
    file's unit). A number's unit (``0.35 g``) is never the file's. Two different units stated
    as the file's are refused. ``stated_only``: every unit, not only a bare ``g``, must be stated
    so (a user's free comments: ``converted from cm/s2`` names no unit of the values).
    """
    table = QUANTITY_UNITS["acceleration"]
    stated: dict[float, str] = {}
    for m in _UNIT_WORD.finditer(header):
        word = m.group(1).rstrip("/.")
        key = unit_key(word)
        if key not in table:
            continue
        before = header[:m.start()]
        if re.search(r"[0-9.]\s*$", before):
            continue  # "0.35 g": a value's unit
        bare = "/" not in key
        after = header[m.end():m.end() + 2].lstrip()
        if (bare or stated_only) and not (_UNIT_CONTEXT.search(before) or after.startswith((")", "]"))):
            continue
        stated.setdefault(table[key], key if bare else word)
    if len(stated) > 1:
        raise InputError(f"{where}: the header names two acceleration units ({', '.join(stated.values())}); "
                         "give the units (--units on the command line, units= in Python)")
    return next(iter(stated.values()), None)


def read_benchmark(path: str | os.PathLike, dt: float | None = None, units: str | None = None,
                   name: str | None = None, labels: Sequence[str] | None = None) -> Record:
    """Read one of the benchmark's two-column record files.

    Parameters
    ----------
    path : path-like
        The file (``%`` header lines, two columns, CRLF or LF, tabs or spaces).
    dt : float, optional
        Time step [s]. Default: the ``dt=`` in the header, else the benchmark's 0.005 s.
    units : str, optional
        Units of the values. Default: the unit named in the header, else cm/s² (the benchmark's).
    name : str, optional
        Record name (default: the file stem).
    labels : sequence of str, optional
        Component labels (default ``("column 1", "column 2")``).

    Returns
    -------
    Record
        Two components in file order, in m/s² (cm/s² × 0.01).

    Raises
    ------
    InputError
        Malformed file, or an explicit ``dt``/``units`` that contradicts the header.
    """
    path, lines = _read_lines(path)
    # '%' is the benchmark's comment mark; '#' lines state a step or units as often
    header = "\n".join(line.lstrip()[1:] for line in lines if line.lstrip().startswith(("%", "#")))
    where = str(path)

    dt, dt_from, units, units_from = _stated(header, where, dt, units, "the header", "header")
    if dt is None:
        dt, dt_from = BENCHMARK_DT, "benchmark default 0.005 s (not in the header)"
    if units is None:
        units, units_from = "cm/s2", "benchmark default, not in the header"
    factor = unit_factor(units, where)

    values, _ = _parse_table(lines, path, 1, 2, ("%", "#"), "two columns of acceleration")
    return _record(
        path,
        name=name or path.stem,
        dt=dt,
        acceleration=_to_si(values, factor),
        labels=tuple(labels) if labels else ("column 1", "column 2"),
        source=str(path),
        synthetic=False,
        metadata={"format": "benchmark", "units_in_file": _canonical(units), "units_from": units_from,
                  "dt_from": dt_from, "header": header.strip()},
    )


# --------------------------------------------------------------------------- PEER NGA .AT2
_NPTS_DT_NEW = re.compile(r"NPTS\s*=\s*([^\s,]+)\s*,?\s*DT\s*=\s*([^\s,]+)", re.IGNORECASE)
_DT_NPTS = re.compile(r"DT\s*=\s*([^\s,]+)\s*(?:SEC\w*)?\s*,?\s*NPTS\s*=\s*([^\s,]+)", re.IGNORECASE)
_NPTS_DT_OLD = re.compile(r"^\s*(\S+)\s+(\S+)\s+NPTS\s*,\s*DT", re.IGNORECASE)


#: PEER's other histories: velocity (.VT2) and displacement (.DT2).
_NOT_ACCELERATION_FILE = {".vt2": "velocity", ".dt2": "displacement"}
_GLUED = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[EeDd][-+]?\d+)?")


def _fixed_width(token: str) -> list[str]:
    """Split Fortran fixed-width numbers written without a space between them
    (``1.2E-02-3.4E-02``), as full-width negative values are in some .AT2 files."""
    if not any(c in token for c in "EeDd"):
        return [token]  # "1.2.3" or "0.1-0.2" are corrupt, not glued
    parts = _GLUED.findall(token)
    return parts if len(parts) > 1 and "".join(parts) == token else [token]


def read_at2(path: str | os.PathLike, units: str | None = None, name: str | None = None) -> Record:
    """Read a PEER NGA ``.AT2`` acceleration file (one component).

    Parameters
    ----------
    path : path-like
        The file: line 1 title, line 2 event/station/component, line 3 units
        (``ACCELERATION TIME HISTORY IN UNITS OF G``), line 4 ``NPTS= n, DT= dt SEC``
        (or ``n dt NPTS, DT``), then the values.
    units : str, optional
        Units if line 3 does not name them (if it does, they must agree).
    name : str, optional
        Record name (default: the file stem).

    Returns
    -------
    Record
        One component in m/s², labelled with the component named on line 2.

    Raises
    ------
    InputError
        Missing header, NPTS/DT absent or not positive, a value count different from NPTS,
        text or non-finite values (message names the line).
    """
    path, lines = _read_lines(path)
    where = str(path)
    kind, said = _NOT_ACCELERATION_FILE.get(path.suffix.lower()), f"its suffix {path.suffix}"
    if kind is None and len(lines) > 2:
        m = re.search(r"\b(VELOCITY|DISPLACEMENT)\b", lines[2], re.IGNORECASE)
        kind, said = (m.group(1).lower() if m else None), "line 3"
    if kind:
        # a PEER velocity (.VT2) or displacement (.DT2) history read as acceleration would be silently wrong
        raise InputError(f"{where}: a PEER {kind} history ({said} says so); expected an acceleration "
                         "file (.AT2)")
    if len(lines) < 5:
        raise InputError(f"{where}: {len(lines)} lines; a PEER .AT2 file has 4 header lines then values")
    m = _NPTS_DT_NEW.search(lines[3]) or _NPTS_DT_OLD.search(lines[3])
    npts_text, dt_text = (m.group(1), m.group(2)) if m else (None, None)
    if not m and (m := _DT_NPTS.search(lines[3])):  # "DT= .005 SEC, NPTS= 4000"
        npts_text, dt_text = m.group(2), m.group(1)
    if npts_text is None or dt_text is None:
        raise InputError(f"{where}:4: expected 'NPTS= n, DT= dt SEC' (PEER .AT2 header), found {lines[3].strip()!r}")
    npts_value = _number(npts_text, path, 4, "NPTS (an integer)")
    if npts_value != int(npts_value) or npts_value < 2:
        raise InputError(f"{where}:4: NPTS = {npts_text}; expected an integer >= 2")
    npts = int(npts_value)
    # "DT= 10.0 MSEC": a step written in milliseconds (read as seconds it is a 10-s step)
    dt_scale = 1e-3 if re.search(r"DT\s*=\s*\S+?\s*(?:MSEC|MS)\b", lines[3], re.IGNORECASE) else 1.0
    dt_text = re.sub(r"(?i)(?<=[0-9.])(?:msec|ms|sec\w*|s)$", "", dt_text)  # "10.0MSEC", ".005SEC"
    dt = _check_dt(_number(dt_text, path, 4, "DT in seconds") * dt_scale, f"{where}:4")

    found_units = _header_units(lines[2], f"{where}:3")
    if found_units is None and re.search(r"\bG\s*$", lines[2].strip(), re.IGNORECASE):
        found_units = "g"
    if units is not None:
        factor = unit_factor(units, f"{where}: units argument")
        if found_units is not None and not math.isclose(factor, unit_factor(found_units)):
            raise InputError(f"{where}:3: units {units!r} given but the header says {found_units!r}")
        units_from = "argument"
    elif found_units is None:
        raise InputError(f"{where}:3: units not recognised in {lines[2].strip()!r}; give the units (--units g on the command line, units='g' in Python)")
    else:
        units, units_from = found_units, "header"
    factor = unit_factor(units, where)

    values: list[float] = []
    for lineno, line in enumerate(lines[4:], start=5):
        for token in line.split():
            for part in _fixed_width(token):
                values.append(_number(part, path, lineno, "acceleration values"))
    if len(values) != npts:
        raise InputError(f"{where}: header says NPTS = {npts} but the file holds {len(values)} values")
    component = lines[1].rsplit(",", 1)[-1].strip() if "," in lines[1] else "component 1"
    return _record(
        path,
        name=name or path.stem,
        dt=dt,
        acceleration=_to_si(values, factor),
        labels=(component or "component 1",),
        source=str(path),
        metadata={"format": "at2", "units_in_file": _canonical(units), "units_from": units_from,
                  "title": lines[0].strip(),
                  "event": lines[1].strip()},
    )


# --------------------------------------------------------------------------- single column
def read_single_column(path: str | os.PathLike, dt: float | None, units: str | None = None,
                       name: str | None = None, label: str | None = None) -> Record:
    """Read a one-value-per-line acceleration file (e.g. the USGS SLAMMER library).

    Parameters
    ----------
    path : path-like
        The file: one number per line; blank lines and lines starting with ``#`` or ``%`` skipped.
    dt : float or None
        Time step [s]; required unless a comment line states it (SLAMMER's files do not: it lists
        the step in its ``eq.sql`` table).
    units : str, optional
        Units of the values (default g, as in SLAMMER; ``metadata["units_from"]`` says which).
    name, label : str, optional
        Record name (default: the file stem) and component label (default: the file name).

    Raises
    ------
    InputError
        ``dt`` neither given nor stated, an argument that contradicts the file's comments, more
        than one value on a line, text or non-finite values.

    Notes
    -----
    Comment lines (``#``, ``%``) and a first text line (a column title such as
    ``Acceleration (g)``) may state the step (``dt=0.01 s``) and the unit (``units: m/s2``,
    ``[cm/s2]``), read as in the benchmark's headers; given arguments must agree with them.
    """
    where = str(path)
    path, lines = _read_lines(path)
    lines = list(lines)
    first = next((i for i, line in enumerate(lines) if line.strip() and not line.lstrip().startswith(("#", "%"))), None)
    if first is not None and not any(_is_number(t) for t in lines[first].replace(",", " ").replace(";", " ").split()):
        lines[first] = "#" + lines[first]  # a column title: read for a step or a unit, not as a value
    header = "\n".join(line.lstrip()[1:] for line in lines if line.lstrip().startswith(("#", "%")))
    dt, _, units, units_from = _stated(header, where, dt, units, "the file", "file comments", free=True)
    if dt is None:
        raise InputError(f"{where}: a single-column file holds no time step; give dt (option --dt)")
    if units is None:
        units, units_from = "g", "default for single-column files, give --units"
    factor = unit_factor(units, f"{where}: units")
    values, _ = _parse_table(lines, path, 1, 1, ("#", "%"), "one acceleration value per line")
    return _record(
        path,
        name=name or path.stem,
        dt=dt,
        acceleration=_to_si(values, factor),
        labels=(label or path.name,),
        source=str(path),
        metadata={"format": "single", "units_in_file": _canonical(units), "units_from": units_from},
    )


# --------------------------------------------------------------------------- generic CSV
_TRAILING_UNIT = re.compile(r"^(.*?)\s*([\[(])\s*([^\[\]()]*?)\s*[\])]\s*$")


#: Units of velocity and displacement: a column in one of them is not an acceleration record.
_NOT_ACCELERATION = {"m/s": "velocity", "cm/s": "velocity", "mm/s": "velocity", "in/s": "velocity",
                     "ft/s": "velocity", "m/sec": "velocity", "cm/sec": "velocity", "m": "displacement",
                     "cm": "displacement", "mm": "displacement", "in": "displacement", "ft": "displacement"}
#: A unit written as a name's suffix after ``_`` (``ax_cm_s2``, ``acc_gal``; ``_`` stands for ``/``; a bare ``_g``, as in ``a_g``, means ground).
_SUFFIX_UNIT = re.compile(r"^(.+?)_((?:c|m)?m_s(?:_s|\^?2)|cm_sec(?:_sec|\^?2)|m_sec(?:_sec|\^?2)|gal)$",
                          re.IGNORECASE)
_SUFFIX_NOT_ACCELERATION = re.compile(r"^.+?_((?:c|m)?m_s(?:ec)?)$", re.IGNORECASE)


def _split_header_unit(token: str, where: str) -> tuple[str, str | None]:
    """Split ``"ax [g]"`` into ``("ax", "g")``.

    A trailing ``[...]`` is always a unit; a trailing ``(...)`` only when it names a known
    unit (so ``"N-S (FN)"`` stays a label) or the time unit s/ms; a suffix after ``_`` when it
    is an acceleration unit with ``_`` for ``/`` (``ax_cm_s2``, ``acc_gal``; a bare ``_g`` is "ground", not g). A velocity or
    displacement unit (``vel (cm/s)``) is refused: the column is not an acceleration.
    """
    m = _TRAILING_UNIT.match(token)
    if not m:
        suffix = _SUFFIX_UNIT.match(token.strip())
        if suffix:
            return suffix.group(1).strip(), suffix.group(2).replace("_", "/")
        other = _SUFFIX_NOT_ACCELERATION.match(token.strip())
        if other:
            unit = other.group(1).replace("_", "/")
            raise InputError(f"{where}: column {token.strip()!r} is in {unit}, a "
                             f"{_NOT_ACCELERATION.get(unit.lower(), 'velocity')}; expected acceleration "
                             "(g, m/s2, cm/s2 or mm/s2)")
        return token.strip(), None
    name, bracket, unit = m.group(1).strip(), m.group(2), m.group(3)
    kind = _NOT_ACCELERATION.get(unit.lower().replace(" ", ""))
    if bracket == "(" and "/" not in unit and name.lower().startswith(("a", "ground a")):
        kind = None  # "acc (in)", "ax (out)": an acceleration column's label, not a length unit
    if kind and name.lower().replace(" ", "") not in _TIME_NAMES:
        # a velocity or displacement history read as acceleration would be silently wrong
        raise InputError(f"{where}: column {token.strip()!r} is in {unit}, a {kind}; expected "
                         "acceleration (g, m/s2, cm/s2 or mm/s2)")
    if bracket == "(":
        known = unit.lower() in ("s", "sec", "seconds", "ms")
        if not known:
            try:
                unit_factor(unit)
                known = True
            except InputError:
                known = False
        if not known:
            return token.strip(), None
    return name, unit


_UNITS_COMMENT = re.compile(r"^#\s*units?\s*[:=]\s*(\S+)", re.IGNORECASE)
#: write_csv's first line: "# [SYNTHETIC ]ground motion: <name>; source: <source>; written by sbib"
_WRITTEN_BY_SBIB = re.compile(r"^#\s*(SYNTHETIC\s+)?ground motion:\s*(.*?);\s*source:\s*(.*);\s*written by sbib\s*$")
_TIME_NAMES = {"t", "time", "times", "time_s", "t_s", "time(s)", "time[s]", "seconds", "sec", "s"}


def _split_csv(line: str, delimiter: str | None) -> list[str]:
    """Split one CSV line; quotes around a cell (spreadsheet exports) and one trailing empty
    cell (a delimiter ending every line) are dropped."""
    parts = line.split(delimiter) if delimiter else line.split()
    cells = [p.strip().strip('"').strip("'").strip() for p in parts]
    if len(cells) > 1 and delimiter and not cells[-1]:
        cells.pop()
    return cells


def _header_cells(header: str, delimiter: str | None, n_data: int) -> list[str]:
    """The header's names, one per data column where a reading gives that many.

    Over whitespace-separated data a name may hold spaces (``Time (s)<tab>Acc X (g)``): the
    header is then split at tabs, else at runs of two or more spaces, else with each bracketed
    unit joined to the name before it (``time [s] ax [g]``).
    """
    cells = _split_csv(header, delimiter)
    if delimiter is not None or len(cells) == n_data:
        return cells
    for split in (header.split("\t"), re.split(r"\s{2,}", header.strip())):
        split = [c.strip().strip('"').strip("'").strip() for c in split if c.strip()]
        if len(split) == n_data:
            return split
    joined: list[str] = []
    for c in cells:
        if joined and re.fullmatch(r"[\[(][^\[\]()]*[\])]", c):
            joined[-1] += " " + c
        else:
            joined.append(c)
    return joined if len(joined) == n_data else cells


def _decimals(token: str) -> int:
    """Digits after the decimal point of a plain number (``0.0033`` → 4; 0 with an exponent)."""
    if "." not in token or any(c in token for c in "eEdD"):
        return 0
    return len(token.split(".", 1)[1].strip())


def _is_number(token: str, decimal_comma: bool = False) -> bool:
    try:
        parse_float(token.replace(",", ".") if decimal_comma else token)
    except ValueError:
        return False
    return True


def _is_unit_row(line: str, delimiter: str | None) -> bool:
    """Whether every cell of ``line`` is a unit (``s, g, g``; empty cells allowed)."""
    cells = _split_csv(line, delimiter)
    known = 0
    for cell in cells:
        unit = cell.strip("[]() ")
        if not unit:
            continue
        if unit.lower() in ("s", "sec", "seconds", "ms") or unit.lower().replace(" ", "") in _NOT_ACCELERATION:
            known += 1
            continue
        try:
            unit_factor(unit)
        except InputError:
            return False
        known += 1
    return known > 0


_DECIMAL_COMMA_NUMBER = r"[-+]?\d+,\d+(?:[eE][-+]?\d+)?"
#: A line of numbers with decimal commas separated by whitespace ("0,005\t0,012").
_WHITESPACE_DECIMAL_COMMAS = re.compile(rf"\s*(?:{_DECIMAL_COMMA_NUMBER}|[-+]?\d+)(?:\s+(?:{_DECIMAL_COMMA_NUMBER}|[-+]?\d+))+\s*")


def _line_delimiter(line: str) -> str | None:
    """The column separator of one line: ``;`` before ``,`` (a semicolon file may use decimal
    commas), whitespace where every whitespace-separated cell is a number with a decimal comma
    or an integer (``0,005<tab>0,012``), then ``,``, else whitespace (tabs or spaces)."""
    if ";" in line:
        return ";"
    if "," in line:
        return None if _WHITESPACE_DECIMAL_COMMAS.fullmatch(line) else ","
    return None


def _bad_first_row(data_lines, where: str) -> None:
    """Under a header, a first data row with numbers and a bad cell: name that cell (not the header)."""
    if len(data_lines) < 2:
        return
    (_, header), (lineno, line) = data_lines[0], data_lines[1]
    delimiter = _line_delimiter(line)
    cells = _split_csv(line, delimiter)
    if any(c and _is_number(c) for c in cells):
        bad = next((c for c in cells if not (c and _is_number(c))), None)
        if bad is not None:
            raise InputError(f"{where}:{lineno}: {bad!r} is not a number; expected data rows time, ax[, ay]")
        if len(cells) != len(_split_csv(header, delimiter)):
            raise InputError(f"{where}:{lineno}: row has {len(cells)} values, expected "
                             f"{len(_split_csv(header, delimiter))} (time, ax[, ay]); ragged rows are not accepted")


def _numeric_row(line: str) -> tuple[str | None, bool] | None:
    """``(delimiter, decimal_comma)`` when every cell of ``line`` is a number, else ``None``.

    Decimal commas (``0,5``) are recognised only where the comma cannot be the separator:
    between semicolons or whitespace, the export of a spreadsheet in a European locale.
    """
    delimiter = _line_delimiter(line)
    cells = _split_csv(line, delimiter)
    decimal_comma = delimiter != "," and any("," in c for c in cells)
    if cells and all(c and _is_number(c, decimal_comma) for c in cells):
        return delimiter, decimal_comma
    return None


def _component_order(labels: Sequence[str], where: str) -> tuple[list[int], str | None]:
    """The file's acceleration columns in the record's order, from their header names.

    The record's components are taken in order (the first on x under ``FN-x``), so a header
    that names the directions is followed rather than the columns' positions: ``ay, ax`` is
    read as (ax, ay), ``FP, FN`` as (FN, FP). A vertical column (``az``, ``UP``) is not used:
    the building is excited horizontally. Names that give no direction keep the file's order.
    Returns the column indices to keep, in order, and a note saying what was done (None when
    the file's order is kept whole).
    """
    keys = [re.sub(r"[\s_.\-]", "", label.lower()) for label in labels]
    axes = [m.group(1) if (m := _AXIS_NAME.match(k)) else None for k in keys]
    vertical = [i for i, a in enumerate(axes) if a is not None and _AXIS_SLOT[a] is None]
    horizontal = [i for i in range(len(labels)) if i not in vertical]
    if not horizontal:
        raise InputError(f"{where}: only vertical acceleration ({', '.join(labels)}); the building is excited "
                         "horizontally: expected a horizontal column (time, ax[, ay])")
    slots = [_AXIS_SLOT[axes[i]] if axes[i] is not None else None for i in horizontal]
    if all(s is not None for s in slots):
        taken = list(slots)
        if len(set(taken)) < len(taken):
            twice = [labels[i] for i, s in zip(horizontal, slots) if taken.count(s) > 1]
            raise InputError(f"{where}: columns {', '.join(map(repr, twice))} name the same direction; "
                             "expected one column per direction (time, ax[, ay])")
        horizontal = [i for _, i in sorted(zip(slots, horizontal))]
    notes = []
    if horizontal != sorted(horizontal):
        notes.append("components taken by their header names: " + ", ".join(labels[i] for i in horizontal))
    if vertical:
        notes.append(f"vertical column{'s' if len(vertical) > 1 else ''} "
                     f"{', '.join(labels[i] for i in vertical)} not used (the building is excited horizontally)")
    return horizontal, "; ".join(notes) or None


def read_csv(path: str | os.PathLike, units: str | None = None, dt: float | None = None,
             name: str | None = None, dt_tolerance: float = 1e-3) -> Record:
    """Read a CSV record ``time, ax[, ay, ...]``.

    Parameters
    ----------
    path : path-like
        The file (see the module docstring for the layout).
    units : str, optional
        Units of the acceleration columns. Default: the units in the header brackets or a
        ``# units:`` comment, else m/s². An explicit value must agree with the file's.
    dt : float, optional
        Expected time step [s]; if given it must agree with the time column.
    name : str, optional
        Record name (default: the file stem).
    dt_tolerance : float
        Largest accepted relative deviation of a time step from the median step.

    Raises
    ------
    InputError
        Fewer than two columns, ragged rows, text or non-finite numbers, time that does not
        increase or is not uniformly sampled (the message names the line), unit conflicts.
    """
    path, lines = _read_lines(path)
    where = str(path)
    comment_units = None
    comment_keys: dict[str, str] = {}
    data_lines: list[tuple[int, str]] = []
    for lineno, line in enumerate(lines, start=1):
        stripped = line.strip()
        if not stripped:
            continue
        if stripped.startswith(("#", "%")):  # '%': the benchmark files' comment mark
            m = _WRITTEN_BY_SBIB.match(stripped)
            if m and not comment_keys:
                comment_keys = {"synthetic": "true" if m.group(1) else "false", "name": m.group(2),
                                "source": m.group(3)}
                continue  # its source may be a path: not a statement of units
            if comment_keys:
                # a file sbib wrote states its units in the column header; its other comments
                # (the original's units, before a conversion) are not statements of units
                continue
            m = _UNITS_COMMENT.match(stripped)
            # "# units: g", "% Acc. in cm/sec^2" (as the benchmark writes), "# acceleration [g]"
            found = m.group(1) if m else _header_units(stripped[1:], f"{where}:{lineno}")
            if found is not None:
                if comment_units is not None and not math.isclose(unit_factor(found, f"{where}:{lineno}"),
                                                                  unit_factor(comment_units, where)):
                    raise InputError(f"{where}:{lineno}: comments name two units ({comment_units}, {found}); "
                                     "expected one (or give --units)")
                comment_units = found
            continue
        data_lines.append((lineno, stripped))
    if not data_lines:
        raise InputError(f"{where}: no data rows; expected columns time, ax[, ay]")

    # The first row whose cells are all numbers starts the data; its separator is the file's.
    first_data = next((i for i, (_, line) in enumerate(data_lines) if _numeric_row(line)), None)
    if first_data is None:
        if len(data_lines) == 1:
            raise InputError(f"{where}: header row only; expected data rows time, ax[, ay]")
        _bad_first_row(data_lines, where)
        lineno, line = data_lines[1]
        bad = next((c for c in _split_csv(line, _line_delimiter(line)) if not _is_number(c)), line)
        raise InputError(f"{where}:{lineno}: {bad!r} is not a number; expected data rows time, ax[, ay] "
                         "after at most one header row")
    unit_row: list[str] | None = None
    data_delimiter = _numeric_row(data_lines[first_data][1])[0]  # type: ignore[index]
    if first_data == 2 and _is_unit_row(data_lines[1][1], data_delimiter):
        # a row of units under the names (time, ax / s, g), as some exports write them
        unit_row = _split_csv(data_lines[1][1], data_delimiter)
        del data_lines[1]
        first_data = 1
    if first_data > 1:
        _bad_first_row(data_lines, where)
        # text lines before the header: one header row is read, anything else must be a comment
        lineno, line = data_lines[0]
        raise InputError(f"{where}:{lineno}: {line[:60]!r} is neither the header row nor data; expected "
                         "one header row (time, ax[, ay]) then data; start other lines with '#'")
    delimiter = data_delimiter
    # a first row of whole numbers ("0;0") says nothing of the decimal mark: the rows below do
    decimal_comma = delimiter != "," and any("," in line for _, line in data_lines[first_data:])

    header_names: list[str] | None = None
    header_units: list[str | None] = []
    if first_data == 1:
        header_line, header = data_lines[0]
        header_names, header_units = [], []
        names = _header_cells(header, delimiter, len(_split_csv(data_lines[1][1], delimiter)))
        if unit_row is not None and len(unit_row) == len(names):
            names = [f"{n} [{u.strip('[]() ')}]" if u.strip("[]() ") else n for n, u in zip(names, unit_row)]
        for t in names:
            name_part, unit = _split_header_unit(t, f"{where}:{header_line}")
            header_names.append(name_part)
            header_units.append(unit)
        data_lines = data_lines[1:]
        n_data = len(_split_csv(data_lines[0][1], delimiter))
        if len(header_names) != n_data:
            sep = {";": "semicolons", ",": "commas", None: "spaces or tabs"}[delimiter]
            raise InputError(f"{where}:{header_line}: the header names {len(header_names)} column(s) but the "
                             f"data rows have {n_data} (separated by {sep}); expected the same separator "
                             "and one name per column (time, ax[, ay])")

    n_columns = len(header_names) if header_names else len(_split_csv(data_lines[0][1], delimiter))
    if n_columns < 2:
        raise InputError(f"{where}:{data_lines[0][0]}: {n_columns} column; expected time and at least one "
                         "acceleration column (time, ax[, ay])")
    rows = np.empty((len(data_lines), n_columns))
    time_decimals = 0  # the time column's printed resolution (rounded stamps, below)
    for i, (lineno, line) in enumerate(data_lines):
        parts = _split_csv(line, delimiter)
        if len(parts) != n_columns:
            raise InputError(f"{where}:{lineno}: row has {len(parts)} values, expected {n_columns} "
                             "(time, ax[, ay]); ragged rows are not accepted")
        for j, token in enumerate(parts):
            if decimal_comma:
                token = token.replace(",", ".")
            rows[i, j] = _number(token, path, lineno, "time" if j == 0 else "acceleration")
        time_decimals = max(time_decimals, _decimals(parts[0].replace(",", ".")))
    linenos = [lineno for lineno, _ in data_lines]
    if delimiter == "," and header_names is None and n_columns == 2 and not any(
            c in line for _, line in data_lines for c in ".eE"):
        # "0,5" on every line: one value per line with decimal commas, or integer (time, value)?
        raise InputError(f"{where}:{linenos[0]}: {data_lines[0][1]!r}: a comma and no decimal point on every "
                         "line: decimal commas (one value per line) or integer time, acceleration columns? "
                         "Write '.' as the decimal mark, or add a header row (time, ax)")

    # units: header brackets, then the '# units:' comment, then the argument, else m/s²
    acc_units = {u for u in header_units[1:] if u} if header_units else set()
    if len({unit_factor(u, where) for u in acc_units}) > 1:  # "g" and "G", "cm/s2" and "gal" agree
        raise InputError(f"{where}: acceleration columns have different units {sorted(acc_units)}")
    file_units = next(iter(acc_units)) if acc_units else comment_units
    if acc_units and comment_units is not None and not math.isclose(unit_factor(file_units, where),
                                                                    unit_factor(comment_units, where)):
        raise InputError(f"{where}: the header says {file_units!r} but a comment says {comment_units!r}; "
                         "expected one unit (or give --units)")
    if units is not None:
        factor = unit_factor(units, f"{where}: units argument")
        if file_units is not None and not math.isclose(factor, unit_factor(file_units, where)):
            raise InputError(f"{where}: units {units!r} given but the file says {file_units!r}")
        units_from = "argument"
    elif file_units is not None:
        units, units_from = file_units, "file"
    else:
        units, units_from = "m/s2", "default, no units in the file"
    factor = unit_factor(units, where)

    time_scale = 1.0
    if header_units and header_units[0]:
        tu = header_units[0].lower()
        if tu in ("s", "sec", "seconds"):
            time_scale = 1.0
        elif tu == "ms":
            time_scale = 1e-3
        else:
            raise InputError(f"{where}: time column unit {header_units[0]!r}; expected s or ms")
    if header_names and header_names[0].lower().replace(" ", "") not in _TIME_NAMES:
        raise InputError(f"{where}:{linenos[0] - 1}: first column is {header_names[0]!r}; expected the time "
                         "column (time, ax[, ay])")

    time = rows[:, 0] * time_scale
    if len(time) < 2:
        raise InputError(f"{where}: one data row; expected at least two samples")
    steps = np.diff(time)
    bad = np.flatnonzero(steps <= 0)
    if bad.size:
        k = bad[0] + 1
        raise InputError(f"{where}:{linenos[k]}: time {time[k]:g} s does not increase (previous {time[k - 1]:g} s); "
                         "expected increasing time")
    step = float(np.median(steps))
    off = np.flatnonzero(np.abs(steps - step) > dt_tolerance * step)
    rounded = False
    if off.size:
        # Stamps written to fewer decimals than the step needs (1/300 s as %.4f, 128 Hz as %.3f)
        # step unevenly but lie on a uniform grid to within half their last digit.
        k_index = np.arange(len(time), dtype=float)
        slope, intercept = np.polyfit(k_index, time, 1)  # the grid the stamps were rounded from
        digit = 10.0 ** -time_decimals * time_scale
        # each stamp within half a digit of the grid (0.6: the fitted grid's own error beside it)
        if time_decimals > 0 and digit < 0.5 * slope and \
                float(np.max(np.abs(time - (intercept + slope * k_index)))) <= 0.6 * digit + 1e-12 * np.max(np.abs(time)):
            rounded = True
        else:
            k = off[0] + 1
            raise InputError(f"{where}:{linenos[k]}: time step {steps[k - 1]:g} s differs from the record's "
                             f"step {step:g} s; expected uniform sampling (resample the record first)")
    # the mean step over the record is the best estimate when the times are rounded
    step = float((time[-1] - time[0]) / (len(time) - 1))
    # a time column in ms read as s (a 5-s step) would ask the simulator for 10⁵ times the steps
    _check_dt(step, f"{where}: the time column")
    if dt is not None:
        dt = _check_dt(dt, f"{where}: dt argument")
        if abs(dt - step) > dt_tolerance * step:
            raise InputError(f"{where}: dt = {dt} s given but the time column has step {step:g} s")

    labels = tuple(header_names[1:]) if header_names else tuple(
        ("ax", "ay", "az")[i] if i < 3 else f"component {i + 1}" for i in range(n_columns - 1))
    order, columns_note = _component_order(labels, where) if header_names else (list(range(len(labels))), None)
    acceleration = rows[:, 1:][:, order]
    labels = tuple(labels[i] for i in order)
    synthetic = comment_keys.get("synthetic") == "true"
    meta = {"format": "csv", "units_in_file": _canonical(units), "units_from": units_from,
            "time_start_s": float(time[0])}
    if rounded:
        meta["time_rounded"] = (f"time stamps written to {time_decimals} decimals: the step is the "
                                f"mean, {step:.6g} s")
    if columns_note:
        meta["columns"] = columns_note
        meta["file_columns"] = [i + 1 for i in order]  # each component's acceleration column in the file
    if synthetic:  # a generated motion stays labelled as one (write_csv's comments)
        meta["file"] = str(path)
    return _record(
        path,
        name=name or (comment_keys.get("name") if synthetic else None) or path.stem,
        dt=step,
        acceleration=_to_si(acceleration, factor),
        labels=labels,
        source=(comment_keys.get("source") or f"synthetic: read from {path}") if synthetic else str(path),
        synthetic=synthetic,
        metadata=meta,
    )


def write_csv(record: Record, path: str | os.PathLike, units: str = "m/s2", comments: Sequence[str] = ()) -> Path:
    """Write ``record`` as CSV (``time [s], <label> [units], ...``), atomically; :func:`read_csv` reads it back.

    Parameters
    ----------
    record : Record
        The record.
    path : path-like
        Output file.
    units : str
        Units of the written values (default m/s2; see :func:`unit_factor`).
    comments : sequence of str
        Further comment lines (without the ``#``) written after the first, e.g. how the record
        was processed and the provenance; :func:`read_csv` skips them.

    Returns
    -------
    Path
        The file written. A comment line states the name, the source and, for generated
        motions, that the record is synthetic; :func:`read_csv` reads them back.
    """
    factor = unit_factor(units, "units")
    path = Path(path)
    kind = "SYNTHETIC ground motion" if record.synthetic else "ground motion"
    first = f"# {kind}: {record.name}; source: {record.source}; written by sbib"
    # read back by read_csv (_WRITTEN_BY_SBIB): a synthetic record stays synthetic, with its name and source
    lines = [" ".join(first.splitlines())]
    lines.extend("# " + " ".join(str(c).splitlines()) for c in comments)
    lines += [",".join(["time [s]"] + [f"{label.replace(',', ';')} [{_canonical(units)}]" for label in record.labels])]
    data = np.column_stack([record.time, record.acceleration / factor])
    lines.extend(",".join(f"{v:.10g}" for v in row) for row in data)
    with atomic_path(path) as tmp:
        tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


# --------------------------------------------------------------------------- dispatch
def _first_column_is_time(rows: Sequence[str], stated_dt: float | None = None) -> bool:
    """Whether the first whitespace-separated column of ``rows`` (more than two) rises from the
    first row to the last at nearly every row (95 %), as a time column does (with ``stated_dt``,
    a header's step: whether its median step is that one, to 1 %), also one with a
    repeated or backward stamp (the CSV reader then names that line) or two runs pasted end to
    end; an acceleration turns back at about every other row."""
    try:
        first = np.array([parse_float(line.split()[0]) for line in rows])
    except (ValueError, IndexError):
        return False
    if first.size <= 2 or not first[-1] > first[0]:
        return False
    if stated_dt is not None:  # under a stated step, time steps by it
        return bool(abs(float(np.median(np.diff(first))) - stated_dt) <= 0.01 * stated_dt)
    return bool(np.mean(np.diff(first) > 0) >= 0.95)


def _one_value_per_line(rows: Sequence[str]) -> bool:
    """Whether the data rows hold one number each (after at most one text line: a column title)."""
    data = [r for r in rows[:50] if r.strip()]
    if data and not any(_is_number(t) for t in data[0].replace(",", " ").replace(";", " ").split()):
        data = data[1:]  # a column title (no number in it)
    return bool(data) and all(len(r.split()) == 1 and _is_number(r.strip()) for r in data)


def detect_format(path: str | os.PathLike) -> str:
    """Guess a file's format from its name and first lines (``benchmark``, ``at2``, ``single``,
    ``csv``, ``knet``, ``esm`` or ``cosmos``).

    Parameters
    ----------
    path : path-like
        The record file.

    Notes
    -----
    Rules, in order: a COSMOS first line (``(Format v01.20 with N text lines)``) → cosmos, a K-NET/KiK-net header (``Origin Time`` ... ``Scale Factor``) → knet, an ESM
    header (``EVENT_NAME:``, ``SAMPLING_INTERVAL_S:``) → esm (:mod:`records.station_files`); suffix ``.at2`` → at2, ``.csv`` → csv; ``NPTS`` within the first four
    lines or a first line starting with ``PEER`` → at2; every data row one number (after at most
    one text line, a column title) → single; a first line starting with ``%`` →
    benchmark, unless the first column is time (below; where the ``%`` lines state a step, only
    a first column that steps by it); a comma or semicolon in the first
    data line → csv; one value per line → single; a header row → csv; numeric columns whose
    first column rises at 95 % of the rows → csv (a time column: an acceleration turns back at
    about every other row; whether the step is uniform and always positive is the CSV reader's check);
    two values otherwise → benchmark.
    """
    path, lines = _read_lines(path)
    suffix = path.suffix.lower()
    if is_cosmos(lines):
        return "cosmos"
    if is_knet(lines):
        return "knet"
    if is_esm(lines):
        return "esm"
    if suffix == ".at2":
        return "at2"
    if suffix == ".csv":
        return "csv"
    head = [line.strip() for line in lines[:4]]
    if any("NPTS" in line.upper() for line in head) or (head and head[0].upper().startswith("PEER")):
        return "at2"
    nonblank = [line.strip() for line in lines if line.strip()]
    rows = [line for line in nonblank if not line.startswith(("#", "%"))]
    data = rows[:50]
    # the benchmark's '%' header states the step ("dt=0.005 sec"): its two columns are accelerations
    # whatever they do, unless the first steps by that dt (a time column under a stated step); a
    # '%' header without a step over a time column is a CSV with comments
    percent = "\n".join(line[1:] for line in nonblank if line.startswith("%"))
    if _one_value_per_line(rows):  # under '%' or '#' comments, or a one-line text header
        return "single"
    if nonblank[0].startswith("%") and not _first_column_is_time(rows, _header_dt(percent, str(path))):
        return "benchmark"
    if not data:
        raise InputError(f"{path}: no data rows; cannot tell the format")
    if "," in data[0] or ";" in data[0]:
        return "csv"
    width = len(data[0].split())
    if width == 1:
        return "single"
    if not all(_is_number(t) for t in data[0].split()):
        return "csv"
    # a first column that increases over the whole file is time, sampled uniformly or not (the
    # CSV reader says which); an acceleration always turns back
    if _first_column_is_time(rows):
        return "csv"
    if width == 2:
        return "benchmark"
    raise InputError(f"{path}: {width} columns without a header; cannot tell the format "
                     "(give --format csv for a time column then accelerations, or --format benchmark)")


def load_record(path: str | os.PathLike, format: str = "auto", dt: float | None = None,
                units: str | None = None, name: str | None = None) -> Record:
    """Read a record file in any supported format.

    Parameters
    ----------
    path : path-like
        The file.
    format : {"auto", "benchmark", "at2", "single", "csv", "knet", "esm", "cosmos"}
        File format; ``"auto"`` uses :func:`detect_format`. ``knet`` (NIED K-NET/KiK-net ASCII),
        ``esm`` (ESM ASCII, one component each) and ``cosmos`` (COSMOS V1/V2) are read by
        :mod:`records.station_files`.
    dt : float, optional
        Time step [s]: required for ``single``; for the other formats it must agree with the file.
    units : str, optional
        Units of the values (see :func:`unit_factor`); default per format: benchmark cm/s²
        (or the header's), at2 from the header, single g, csv from the header else m/s².
    name : str, optional
        Record name (default: the file stem).

    Returns
    -------
    Record
        In m/s².

    Raises
    ------
    InputError
        Unknown format, malformed file, or missing/inconsistent ``dt``/``units``.
    DataNotFoundError
        The file does not exist.
    """
    if format not in FORMATS:
        raise InputError(f"format {format!r} is not known; expected one of {', '.join(FORMATS)}")
    fmt = detect_format(path) if format == "auto" else format
    if fmt == "benchmark":
        record = read_benchmark(path, dt=dt, units=units, name=name)
        if format == "auto" and str(record.metadata.get("dt_from", "")).startswith("benchmark default"):
            # two columns of numbers taken for the benchmark's format: its 0.005-s step is a guess
            # that stretches or squeezes the whole record (a file at 0.01 s had run twice as fast,
            # nothing on screen); the benchmark's own files are read by name, or with --format benchmark
            raise InputError(f"{path}: two columns of acceleration and no time step (no 'dt=' in a '%' or '#' "
                             "line); give --dt (the benchmark's own records need none: by name, e.g. "
                             "--record newhall, or with --format benchmark, at 0.005 s)")
        return record
    if fmt == "at2":
        record = read_at2(path, units=units, name=name)
        if dt is not None and not math.isclose(_check_dt(dt, f"{path}: dt argument"), record.dt, rel_tol=1e-6):
            raise InputError(f"{path}: dt = {dt} s given but the .AT2 header says DT = {record.dt} s")
        return record
    if fmt == "single":
        return read_single_column(path, dt=dt, units=units, name=name)
    if fmt in ("knet", "esm", "cosmos"):
        if fmt != "esm" and units is not None:
            raise InputError(f"{path}: --units does not apply to a {'K-NET/KiK-net' if fmt == 'knet' else 'COSMOS'} "
                             "file (its header gives them)")
        record = (read_knet(path, name=name) if fmt == "knet" else read_cosmos(path, name=name) if fmt == "cosmos"
                  else read_esm(path, units=units, name=name))
        if dt is not None and not math.isclose(_check_dt(dt, f"{path}: dt argument"), record.dt, rel_tol=1e-6):
            raise InputError(f"{path}: dt = {dt} s given but the header says {record.dt:g} s")
        return record
    return read_csv(path, units=units, dt=dt, name=name)

