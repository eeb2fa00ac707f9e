"""The low-level pieces every record reader shares: reading a text file, parsing a number,
checking a time step, converting to m/s² and building the :class:`records.Record`.

Each failure is one :class:`~benchmark.foundation.errors.InputError` line naming the file, the
line and what was expected. The format readers (:mod:`records.readers`,
:mod:`records.station_files`) sit on top of this module, which also holds the names that tell a
component's direction (:data:`AXIS_NAME`, :func:`is_vertical_label`), for every format alike.
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path
from typing import Any

import numpy as np

from benchmark.foundation.errors import DataNotFoundError, InputError
from benchmark.foundation.file_units import si_factor
from benchmark.foundation.textfile import decode_text, parse_float
from records.record import STANDARD_GRAVITY, Record

__all__ = ["DT_RANGE", "LARGEST_SI", "AXIS_NAME", "AXIS_SLOT", "is_vertical_label", "unit_factor",
           "canonical_units", "read_lines", "parse_number",
           "check_dt", "to_si", "build_record"]

#: Time steps a record file may state [s]: strong-motion instruments sample at 50 Hz to 10 kHz
#: (digitised analogue records at 0.01-0.02 s); a wider margin each way, no more.
DT_RANGE = (1e-5, 1.0)

_CANONICAL_UNITS = {"g": "g", 1.0: "m/s2", 0.01: "cm/s2", 0.001: "mm/s2"}


def unit_factor(units: str, where: str = "units") -> float:
    """Return the factor that converts ``units`` to m/s².

    Parameters
    ----------
    units : str
        A name from the module docstring (``"g"``, ``"cm/s2"``, ``"gal"``, ``"m/s^2"``, ...).
    where : str
        What to name in the error message (a file, an option).

    Raises
    ------
    InputError
        If the unit is not known.
    """
    return si_factor("acceleration", units, where)  # the project's one table of file units


def canonical_units(units: str) -> str:
    """The project's spelling of ``units`` (``"g"``, ``"m/s2"``, ``"cm/s2"`` or ``"mm/s2"``).

    Parameters
    ----------
    units : str
        Any spelling :func:`unit_factor` accepts.
    """
    f = unit_factor(units)
    return "g" if f == STANDARD_GRAVITY else _CANONICAL_UNITS[f]


# --------------------------------------------------------------------------- low-level parsing
def read_lines(path: str | os.PathLike) -> tuple[Path, list[str]]:
    """The file's lines, decoded; a missing, non-regular, binary or empty file is refused.

    Parameters
    ----------
    path : path-like
        The record file.
    """
    path = Path(path)
    if not path.exists():
        raise DataNotFoundError(f"{path}: record file not found")
    if not path.is_file():
        raise InputError(f"{path}: not a regular file")
    raw = path.read_bytes()
    # binary or not UTF-8: one line naming the file and the line (benchmark.foundation.textfile)
    text = decode_text(raw, str(path)) if raw.strip() else ""
    if not text.replace("\ufeff", "").strip():  # a byte-order mark or a no-break space is no content
        raise InputError(f"{path}: file is empty; expected acceleration values")
    return path, text.splitlines()


def parse_number(token: str, path: Path, lineno: int, what: str) -> float:
    """``token`` as a finite float (Fortran exponents too), or an error naming ``path:lineno``.

    Parameters
    ----------
    token : str
        The text of one value.
    path : Path
        The file, for the message.
    lineno : int
        Its line number (1-based), for the message.
    what : str
        What the value should be (``"acceleration values"``), for the message.
    """
    try:
        value = parse_float(token)  # Fortran exponents (1.0D-03) too
    except ValueError:
        raise InputError(f"{path}:{lineno}: {token!r} is not a number; expected {what}") from None
    if not math.isfinite(value):
        raise InputError(f"{path}:{lineno}: {token!r} is not finite; expected {what}")
    return value


def check_dt(dt: float | None, where: str) -> float:
    """``dt`` [s] when it is a positive finite step within :data:`DT_RANGE`, else an error.

    Parameters
    ----------
    dt : float or None
        The step [s].
    where : str
        What to name in the message (a file and line, an option).
    """
    try:
        value = float(dt)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise InputError(f"{where}: time step dt = {dt!r}; expected a positive number of seconds") from None
    if not math.isfinite(value) or value <= 0.0:
        raise InputError(f"{where}: time step dt = {dt!r} s; expected a positive finite number of seconds")
    if not DT_RANGE[0] <= value <= DT_RANGE[1]:
        # 500 s would ask the simulator for millions of steps; 1e-200 s is a misread header
        raise InputError(f"{where}: time step dt = {value:g} s; a ground-motion record is sampled every "
                         f"{DT_RANGE[0]:g}-{DT_RANGE[1]:g} s (a step in ms given as s?)")
    return value



def to_si(values: Any, factor: float) -> np.ndarray:
    """``values * factor`` without numpy's overflow warning: :func:`build_record` reports the
    non-finite sample with its file instead.

    Parameters
    ----------
    values : array-like
        The file's values.
    factor : float
        Their units' factor to m/s² (:func:`unit_factor`).
    """
    with np.errstate(over="ignore", invalid="ignore"):
        return np.asarray(values, dtype=np.float64) * factor


#: Largest acceleration accepted from a file [m/s²] (about 1e7 g).
LARGEST_SI = 1e8


def build_record(path: Path, **fields: Any) -> Record:
    """Build the :class:`Record`; a value that overflows on unit conversion or any other
    inconsistency is reported against the file (the Record alone only knows its name).

    Parameters
    ----------
    path : Path
        The file, for the message.
    **fields
        The :class:`Record`'s fields (``acceleration`` in m/s²).
    """
    acc = np.asarray(fields["acceleration"], dtype=float)
    # Beyond LARGEST_SI no unit mix-up reaches (mm/s² read as g gives ~1e5 m/s²): the file is
    # corrupt, and such values would overflow the record's measures and the integration.
    with np.errstate(invalid="ignore"):
        bad = ~(np.abs(acc) <= LARGEST_SI)
    if bad.any():
        row = int(np.argwhere(bad)[0][0])
        raise InputError(f"{path}: sample {row + 1} is {acc[tuple(np.argwhere(bad)[0])]:.3g} m/s² after "
                         f"conversion; expected accelerations below {LARGEST_SI:.0e} m/s² (no unit "
                         "mix-up gives more: a corrupt value?)")
    try:
        return Record(**fields)
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from None


#: A column name that gives its direction: an optional acceleration prefix, then the axis
#: (``ax``, ``acc_y``, ``ag-x``, ``FN``, ``a_FP``, ``UP``, ``vertical``); spaces, ``_ - .`` ignored.
AXIS_NAME = re.compile(r"^(?:a|acc|accel|acceleration|ag|ug|ground|groundacc|groundacceleration)?"
                       r"(x|y|z|fn|fp|up|ud|v|vert|vertical)$")
#: Which slot of the record (component 0, then 1) each horizontal direction takes; None: vertical.
AXIS_SLOT = {"x": 0, "fn": 0, "y": 1, "fp": 1, "z": None, "up": None, "ud": None, "v": None, "vert": None,
              "vertical": None}  # "V" beside "H1, H2": the vertical, as PEER names the components


#: Component names that mean the vertical beyond :data:`AXIS_NAME`'s: PEER's ``DWN``/``VER``, and
#: SEED channel codes ending in Z (``HNZ``, ``HGZ``).
_VERTICAL_NAMES = re.compile(r"^(?:dwn|down|ver|updown|[a-z]{2}z)$")


def is_vertical_label(label: str) -> bool:
    """True when a component's name says it is the vertical (``UP``, ``az``, ``V``, ``DWN``,
    ``HNZ``): the building is excited horizontally, so such a component is never run.

    Parameters
    ----------
    label : str
        The component's name (a CSV column, the component on an ``.AT2`` file's second line).
    """
    key = re.sub(r"[\s_.\-]", "", str(label).lower())
    m = AXIS_NAME.match(key)
    return bool((m and AXIS_SLOT[m.group(1)] is None) or _VERTICAL_NAMES.match(key))
