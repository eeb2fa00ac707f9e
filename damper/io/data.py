"""Damper test records: the :class:`DamperTest` type, CSV files and the UTFSM data adapter.

CSV format (SI units, one header line, optional ``#`` (or ``%``, as MATLAB writes) comment lines before it)::

    # name: virtual 0.4 m 0.8 Hz 0 V
    # source: damper.lab.laboratory.periodic_test(...)
    time,displacement,force,velocity,voltage
    0.0,0.0,-1234.5,2.01,0.0
    ...

Required columns ``time`` [s], ``displacement`` [m], ``force`` [N]; optional ``velocity``
[m/s] (the central difference of the displacement when absent) and one of ``voltage`` [V]
or ``current`` [A] (a constant value may instead be passed to :func:`read_csv`). A header
name may carry its unit in brackets or parentheses (``force [N]``, ``force (kN)``): a column
without one is SI; a rig's units (ms; mm, cm, in; mm/s, cm/s, in/s; kN, lbf, kip, kgf; mV; mA)
are converted to SI on reading (:mod:`benchmark.foundation.file_units`) and listed in the test's
``metadata["file_units"]``. Loggers' names are read too: ``t``; ``disp``, ``x``, ``position``,
``stroke``; ``vel``, ``xdot``; ``f``, ``load`` (any case). The columns may be separated by
commas, semicolons, tabs or spaces (the header line says which); with any separator but the comma, decimal commas (``0,25``) are read
as decimal points. Cells may be quoted and every line may end with the separator.

UTFSM files (``hysteresis_data/quiroz_utfsm_mr_damper_sinusoidal/Preprocesados``,
M. Quiroz, MIT licence): whitespace-separated columns t [s], x [mm], ẋ [mm/s], F [N];
the coil current is only in the file name, ``<amp>mm<freq>Hz<current>A.txt`` with ``x`` as
the decimal point (e.g. ``25mm0x1Hz0x75A.txt``: 25 mm, 0.1 Hz, 0.75 A). :func:`read_utfsm`
converts mm to m.
"""

from __future__ import annotations

import csv
import io
import math
import re
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from benchmark.foundation.atomic import atomic_path
from benchmark.foundation.errors import DataNotFoundError, InputError
from benchmark.foundation.file_units import (COLUMN_ALIASES, QUANTITY_UNITS, SI_UNIT, STANDARD_GRAVITY,
                                             column_name_unit, si_factor, unit_key)
from benchmark.foundation.paths import shared_dir as _shared
from benchmark.foundation.textfile import parse_float, read_text
from damper.io.screening import (clock_restarts, filled_samples, repair_samples, screened, screening_of,
                                 smoothed_derivative)

__all__ = ["DamperTest", "check_samples", "parse_row", "parse_rows", "read_csv", "read_csv_parts", "build_test", "column_of", "write_csv", "read_utfsm", "parse_utfsm_name",
           "utfsm_files", "read_utfsm_raw", "raw_current_from_name", "UTFSM_RAW_CHANNELS", "UTFSM_RAW_CURRENTS", "is_utfsm_raw_file",
           "split_utfsm_raw"]

_REQUIRED = ("time", "displacement", "force")
_OPTIONAL = ("velocity", "voltage", "current")
#: The quantity (:mod:`benchmark.foundation.file_units`) of each column, for its unit ...
_QUANTITY = {"time": "time", "displacement": "length", "force": "force", "velocity": "velocity",
             "voltage": "voltage", "current": "current"}
#: ... and the SI unit it is held and written in.
_UNITS = {name: SI_UNIT[quantity] for name, quantity in _QUANTITY.items()}


@dataclass(frozen=True)
class DamperTest:
    """One damper test record (SI units, time along the only axis).

    Attributes
    ----------
    time : ndarray (n,)
        Strictly increasing sample times [s].
    displacement : ndarray (n,)
        Device displacement [m].
    velocity : ndarray (n,)
        Device velocity [m/s].
    force : ndarray (n,)
        Measured device force [N].
    voltage : ndarray (n,) or None
        Coil voltage [V] (may be constant); ``None`` when the test gives a current.
    current : ndarray (n,) or None
        Coil current [A]; ``None`` when the test gives a voltage.
    name : str
        Short label.
    source : str
        File path, or how the test was generated.
    metadata : dict
        Anything else (amplitude, frequency, noise, ...); the readers put the
        :class:`~damper.io.screening.Screening` of the file under ``"screening"``.
    mask : ndarray (n,) of bool or None
        Samples usable for fits and errors (True); ``None``: all of them. Set by the screening
        (:mod:`damper.io.screening`); the model is still simulated over every sample.
    """

    time: np.ndarray
    displacement: np.ndarray
    velocity: np.ndarray
    force: np.ndarray
    voltage: np.ndarray | None = None
    current: np.ndarray | None = None
    name: str = ""
    source: str = ""
    metadata: dict = field(default_factory=dict, compare=False)
    mask: np.ndarray | None = field(default=None, compare=False)

    def __post_init__(self) -> None:
        label = self.source or self.name or "DamperTest"
        time = _vector(self.time, "time", label)
        n = time.size
        if n < 2:
            raise InputError(f"{label}: time: expected at least 2 samples, got {n}")
        steps = np.diff(time)
        if np.any(steps <= 0):
            i = int(np.argmax(steps <= 0)) + 1
            raise InputError(f"{label}: time: expected strictly increasing values, sample {i} "
                             f"({time[i]:g} s) does not follow {time[i - 1]:g} s")
        object.__setattr__(self, "time", time)
        for name in ("displacement", "velocity", "force"):
            object.__setattr__(self, name, _vector(getattr(self, name), name, label, n))
        if self.voltage is not None and self.current is not None:
            raise InputError(f"{label}: expected a voltage or a current, not both")
        for name in ("voltage", "current"):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, _vector(value, name, label, n, allow_scalar=True))
        object.__setattr__(self, "metadata", dict(self.metadata))
        if self.mask is not None:
            mask = np.asarray(self.mask)
            if mask.shape != (n,) or mask.dtype != bool:
                raise InputError(f"{label}: mask: expected {n} booleans (as many as time), got "
                                 f"shape {mask.shape} of {mask.dtype}")
            mask = mask.copy()
            mask.flags.writeable = False
            object.__setattr__(self, "mask", mask)

    @property
    def usable(self) -> np.ndarray:
        """Samples usable for fits and errors (all True without a mask)."""
        return np.ones(self.n_samples, dtype=bool) if self.mask is None else self.mask

    @property
    def n_samples(self) -> int:
        """Number of samples."""
        return int(self.time.size)

    @property
    def sample_rate(self) -> float:
        """Mean sampling rate [Hz]."""
        return float((self.n_samples - 1) / (self.time[-1] - self.time[0]))

    @property
    def constant_voltage(self) -> float | None:
        """The voltage [V] when it is constant over the test, else ``None``."""
        if self.voltage is None or np.ptp(self.voltage) > 1e-12:
            return None
        return float(self.voltage[0])

    def select(self, t_start: float = -math.inf, t_end: float = math.inf) -> "DamperTest":
        """The samples with ``t_start <= time <= t_end`` (e.g. to drop the transient).

        Parameters
        ----------
        t_start : float, optional
            First time kept [s].
        t_end : float, optional
            Last time kept [s].
        """
        keep = (self.time >= t_start) & (self.time <= t_end)
        if keep.sum() < 2:
            raise InputError(f"{self.name or 'DamperTest'}: select({t_start}, {t_end}) keeps "
                             f"fewer than 2 samples")
        return DamperTest(time=self.time[keep], displacement=self.displacement[keep],
                          velocity=self.velocity[keep], force=self.force[keep],
                          voltage=None if self.voltage is None else self.voltage[keep],
                          current=None if self.current is None else self.current[keep],
                          name=self.name, source=self.source, metadata=self.metadata,
                          mask=None if self.mask is None else self.mask[keep])


def check_samples(values, name: str, n: int | None = None, allow_scalar: bool = False,
                  reference: str = "time") -> np.ndarray:
    """A validated 1-D float64 copy of ``values`` (finite, ``n`` samples when given).

    Parameters
    ----------
    values : array-like or float
        The samples; a scalar is broadcast to ``n`` samples when ``allow_scalar``.
    name : str
        What the array is, for the message (e.g. ``"file.csv: force"``).
    n : int, optional
        Required number of samples.
    allow_scalar : bool
        Accept a scalar (e.g. a constant voltage).
    reference : str
        Name of the array that sets ``n`` (for the message).

    Raises
    ------
    InputError
        Non-numeric values, wrong shape or length, NaN or inf (the first bad sample is named).
    """
    try:
        arr = np.array(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(f"{name}: expected numbers") from None
    if allow_scalar and arr.ndim == 0 and n is not None:
        arr = np.full(n, float(arr))
    if arr.ndim != 1:
        raise InputError(f"{name}: expected a 1-D array, got shape {arr.shape}")
    if n is not None and arr.size != n:
        raise InputError(f"{name}: expected {n} samples (as many as {reference}), got {arr.size}")
    if not np.all(np.isfinite(arr)):
        i = int(np.argmax(~np.isfinite(arr)))
        raise InputError(f"{name}: expected finite values, sample {i} is {arr[i]}")
    return arr


def _vector(values, name: str, label: str, n: int | None = None, allow_scalar: bool = False):
    arr = check_samples(values, f"{label}: {name}", n, allow_scalar)
    arr.flags.writeable = False
    return arr



def column_of(cell: str, where: str, dyke_letters: bool = True) -> tuple[str | None, float, str | None]:
    """The quantity a column's name gives (None for a channel no damper test uses), the factor
    that takes its values to SI and the unit written, if any: the rule of every tabular reader
    (a CSV header cell, a MATLAB or HDF5 variable's name).

    ``"force [kN]"``, ``"Force (kN)"`` and a logger's ``"force_kN"`` give ``("force", 1000.0,
    "kN")``; ``"disp"`` gives ``("displacement", 1.0, None)`` (:data:`COLUMN_ALIASES`);
    ``"temperature [C]"`` gives ``(None, 1.0, None)``.

    Parameters
    ----------
    cell : str
        The name as written, with its unit if any.
    where : str
        Where it is written, for messages (``"file.csv:1: header"``).
    dyke_letters : bool
        Refuse ``D``, ``V``, ``Y`` (the Dyke records' columns, in cm and cm/s, out of their
        format); else they are channels not used (a MATLAB workspace's ``y``).

    Raises
    ------
    InputError
        A cell that is no name, the Dyke records' single letters out of their format, or a unit
        the quantity does not have.
    """
    split = column_name_unit(cell)
    if split is None:
        raise InputError(f"{where}: unreadable column name {cell!r}; expected "
                         "time, displacement, force[, velocity][, voltage|current]")
    name, unit = split
    if name not in _UNITS and unit is None and "_" in name:
        # a logger's "force_kN", "disp_mm", "time_s": the unit after the last underscore
        stem, _, suffix = name.rpartition("_")
        stem = COLUMN_ALIASES.get(stem, stem)
        if stem in _UNITS and unit_key(suffix) in QUANTITY_UNITS[_QUANTITY[stem]]:
            name, unit = stem, cell.strip().strip('"').strip("'").rpartition("_")[2]  # as written: kN
    if name not in _UNITS:
        if dyke_letters and name in ("d", "v", "y"):
            raise InputError(f"{where}: unknown column {name!r}; expected time, displacement, "
                             "force[, velocity][, voltage|current] (D, V, F, Y are the Dyke records' names, "
                             "read in their units only beside their A and fs columns)")
        return None, 1.0, None  # another channel of the rig (a temperature, a command): not used
    if unit is None:
        return name, 1.0, None
    factor = si_factor(_QUANTITY[name], unit, f"{where}: column {name!r}")
    return name, factor, unit


def parse_row(path, line_no: int, header: list[str], row: list[str],
              missing: bool = False) -> list[float]:
    """The finite numbers of one CSV data row, one per header column.

    With ``missing``, a ``nan`` or empty cell (a logger's dropout) is returned as NaN for the
    screening (:func:`damper.io.screening.repair_samples`) to flag and fill.

    Parameters
    ----------
    path : path-like
        The file, for messages.
    line_no : int
        The row's line number in the file.
    header : list of str
        The columns' names.
    row : list of str
        The row's cells.
    missing : bool
        Return a missing cell as NaN instead of refusing it.

    Raises
    ------
    InputError
        A row with the wrong number of values, or a cell that is not a finite number; the
        message names the file, the line and the column.
    """
    if len(row) != len(header):
        raise InputError(f"{path}:{line_no}: expected {len(header)} values "
                         f"({', '.join(header)}), got {len(row)}")
    values = []
    for col, cell in zip(header, row):
        if missing and not cell.strip():
            values.append(math.nan)
            continue
        try:
            value = parse_float(cell)
        except ValueError:
            raise InputError(f"{path}:{line_no}: column {col!r}: expected a number, "
                             f"got {cell.strip()!r}") from None
        if missing and math.isnan(value):
            values.append(value)
            continue
        if not math.isfinite(value):
            raise InputError(f"{path}:{line_no}: column {col!r}: expected a finite "
                             f"number, got {cell.strip()!r}")
        values.append(value)
    return values


#: :func:`clock_seconds` takes the time column's form from the first of this many non-empty cells
#: that is a clock.
CLOCK_PROBE = 5
_TIME_OF_DAY = re.compile(r"^\s*(\d{1,2}):(\d{2}):(\d{2}(?:\.\d*)?)\s*$")


def _time_of_day(cell: str) -> float | None:
    """Seconds since midnight of ``HH:MM:SS[.fff]`` (None: not a valid time of day)."""
    m = _TIME_OF_DAY.match(cell)
    if m is None:
        return None
    h, mi, sec = int(m.group(1)), int(m.group(2)), float(m.group(3))
    if h > 23 or mi > 59 or sec >= 61.0:
        return None
    return 3600.0 * h + 60.0 * mi + sec


def _date_time(cell: str) -> np.datetime64 | None:
    """``cell`` as an ISO 8601 date-time (UTC where a zone is written), or None."""
    if not any(ch in cell for ch in "-:") or _is_float(cell):
        return None
    with warnings.catch_warnings():  # numpy warns that it converts a written zone to UTC
        warnings.simplefilter("ignore", UserWarning)
        try:
            return np.datetime64(cell, "ns")
        except ValueError:
            return None


def clock_seconds(cells: list[str]) -> tuple[np.ndarray, str] | None:
    """Seconds since the first stamp of a time column written as a clock, or ``None`` when the
    column is numbers (or no clock).

    Two forms are read: ISO 8601 date-times (``2022-05-13 17:06:51.728``, ``2022-05-13T17:06:51``,
    a zone such as ``Z`` or ``+02:00`` taken to UTC; numpy's ``datetime64`` to the nanosecond)
    and times of day (``17:06:51.728``). The form is that of the first of the first
    :data:`CLOCK_PROBE` non-empty cells that is one (a first cell written as ``n/a`` does not
    decide it); a first non-empty cell that is a number means a numeric column. A time of day
    that returns to the early hours within an hour after a late one is the next day; any other
    step back stays a step back, for the screening. A cell that is no clock is NaN (a missing
    stamp).

    Parameters
    ----------
    cells : list of str
        The time column's cells, in file order.

    Returns
    -------
    (seconds, origin) or None
        The seconds since the first stamp (NaN where a cell is not a clock) and the first stamp
        as written.
    """
    text = [c.strip().strip('"').strip() for c in cells]
    probe = [c for c in text[:10 * CLOCK_PROBE] if c][:CLOCK_PROBE]
    if not probe or _is_float(probe[0]):
        return None
    if any(_time_of_day(c) is not None for c in probe):
        out = np.full(len(text), np.nan)
        day = 0.0
        last = -math.inf
        for i, c in enumerate(text):
            value = _time_of_day(c)
            if value is None:
                continue
            value += day
            if value < last and 0.0 <= value + 86400.0 - last < 3600.0:
                day += 86400.0  # past midnight: 23:59:59.9 then 00:00:00.1
                value += 86400.0
            out[i] = value
            if value >= last:
                last = value  # a stamp that steps back is the screening's, not a new reference
        first = int(np.flatnonzero(np.isfinite(out))[0])
        return out - out[first], text[first]
    origin = next((c for c in probe if _date_time(c) is not None), None)
    if origin is None:
        return None
    stamp0 = _date_time(origin)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        try:  # a logger's column at once; a malformed cell, cell by cell
            return (np.array(text, dtype="datetime64[ns]") - stamp0) / np.timedelta64(1, "ns") * 1e-9, origin
        except ValueError:
            pass
    out = np.full(len(text), np.nan)
    for i, c in enumerate(text):
        stamp = _date_time(c)
        if stamp is not None:
            out[i] = (stamp - stamp0) / np.timedelta64(1, "ns") * 1e-9
    return out, origin


def parse_rows(path, header: list[str], rows: list[list[str]], lines: list[int],
               missing: bool = True) -> np.ndarray:
    """The numbers of the data rows as a ``(rows, columns)`` array (:func:`parse_row` of each).

    Rows that all have the header's width and cells numpy reads as finite numbers (a logger's
    file) are converted at once (numpy reads a number's text as :func:`float` does, to the bit;
    0.3 s instead of 2.3 s for 191 000 rows); anything else (a missing cell, a Fortran
    ``D`` exponent, a malformed cell) goes row by row through :func:`parse_row`, for the NaN the
    screening fills or the message that names the line and the column.

    Parameters
    ----------
    path : path-like
        The file, for messages.
    header : list of str
        The columns' names.
    rows : list of list of str
        The cells of each data row.
    lines : list of int
        Each row's line number in the file.
    missing : bool
        As for :func:`parse_row`: a missing cell is NaN (else an error).
    """
    width = len(header)
    if rows and all(len(r) == width for r in rows):
        try:
            data = np.array(rows, dtype=np.float64)
        except ValueError:
            pass
        else:
            if np.isfinite(data).all():
                return data
    return np.array([parse_row(path, line_no, header, row, missing=missing) for line_no, row in zip(lines, rows)],
                    dtype=np.float64)


#: Lines starting with these are comments: ``#``, and ``%`` as MATLAB writes its headers.
COMMENT_MARKS = ("#", "%")


def sniff_delimiter(text: str) -> str | None:
    """The column separator of a damper CSV, from its first line that is not a comment:
    ``,``, else ``;``, else a tab, else ``None`` (runs of spaces).

    Parameters
    ----------
    text : str
        The file's text.
    """
    for line in text.splitlines():
        stripped = line.strip()
        if stripped and not stripped.startswith(COMMENT_MARKS):
            return next((d for d in (",", ";", "\t") if d in stripped), None)
    return ","


def split_rows(text: str, delimiter: str | None):
    """``(line number, cells)`` of each line, quotes handled by :mod:`csv` (``None``: split at spaces).

    Parameters
    ----------
    text : str
        The file's text.
    delimiter : str or None
        The column separator (:func:`sniff_delimiter`).
    """
    if delimiter is None:
        for line_no, line in enumerate(text.splitlines(), start=1):
            cells: list[str] = []
            for c in line.split():
                c = c.strip('"')
                if cells and c[:1] in "[(" and c[-1:] in "])" and not _is_float(cells[-1]):
                    cells[-1] = f"{cells[-1]} {c}"  # "time [s]": a unit spaced from its column name
                else:
                    cells.append(c)
            yield line_no, cells
        return
    with io.StringIO(text, newline="") as fh:
        yield from enumerate(csv.reader(fh, delimiter=delimiter), start=1)


def decimal_points(row: list[str], delimiter: str | None) -> list[str]:
    """``row`` with decimal commas (``0,25``) made points where the comma cannot be the separator
    (``;``, tab or spaces between the columns: a spreadsheet in a European locale).

    Parameters
    ----------
    row : list of str
        Cells of one line.
    delimiter : str or None
        The file's column separator (:func:`sniff_delimiter`; ``None``: runs of spaces).
    """
    return row if delimiter == "," else [c.replace(",", ".") for c in row]


def _is_float(cell: str) -> bool:
    try:
        parse_float(cell)
    except ValueError:
        return False
    return True


def read_csv(path, voltage: float | None = None, current: float | None = None,
             name: str | None = None, keep_flagged: bool = False) -> DamperTest:
    """Read a damper test CSV file (format in the module docstring), screened.

    The file is screened (:mod:`damper.io.screening`): ``nan`` cells are filled and flagged,
    repeated or backward time stamps dropped and flagged, and the test's ``mask`` leaves the
    flagged samples out of fits and errors (``metadata["screening"]`` holds the findings).

    Parameters
    ----------
    path : path-like
        The CSV file.
    voltage, current : float, optional
        Constant coil voltage [V] or current [A] for a file without that column.
    name : str, optional
        Label (default: the ``# name:`` comment, else the file stem).
    keep_flagged : bool
        Keep the flagged samples in the mask (only missing values stay out).

    Raises
    ------
    DataNotFoundError
        The file does not exist.
    InputError
        Malformed file (the message names the file, line and column), or so many missing
        values or bad time stamps that too little is left.
    """
    path = Path(path)
    if voltage is not None and current is not None:
        raise InputError("read_csv: give a constant voltage or a current, not both")
    col, lines, metadata = _csv_columns(path)
    return build_test(path, col, voltage=voltage, current=current, name=name or metadata.get("name") or path.stem,
                      lines=lines, metadata=metadata, keep_flagged=keep_flagged)


def read_csv_parts(path, voltage: float | None = None, current: float | None = None,
                   name: str | None = None, keep_flagged: bool = False) -> list[DamperTest]:
    """The tests of a damper test CSV file: one, or one per recording where the file's clock
    restarts (a second recording appended, :func:`damper.io.screening.clock_restarts`).

    Each part is screened on its own, named ``<name> part k`` and carries ``span_s`` and
    ``part`` in its metadata (the report keys its screening by the file and the part).
    :func:`read_csv` reads the first part and says the rest was dropped.

    Parameters
    ----------
    path : path-like
        The CSV file.
    voltage, current : float, optional
        Constant coil voltage [V] or current [A] for a file without that column.
    name : str, optional
        Label (default: the ``# name:`` comment, else the file stem).
    keep_flagged : bool
        Keep the flagged samples in the mask (only missing values stay out).

    Raises
    ------
    DataNotFoundError, InputError
        As :func:`read_csv`.
    """
    path = Path(path)
    if voltage is not None and current is not None:
        raise InputError("read_csv: give a constant voltage or a current, not both")
    col, lines, metadata = _csv_columns(path)
    label = name or metadata.get("name") or path.stem
    cuts = clock_restarts(col["time"], {k: v for k, v in col.items() if k != "time"})
    if not cuts:
        return [build_test(path, col, voltage=voltage, current=current, name=label, lines=lines,
                           metadata=metadata, keep_flagged=keep_flagged)]
    bounds = [0, *cuts, col["time"].size]
    out = []
    for k, (a, b) in enumerate(zip(bounds, bounds[1:]), start=1):
        part = {c: v[a:b] for c, v in col.items()}
        out.append(build_test(path, part, voltage=voltage, current=current, name=f"{label} part {k}",
                              lines=lines[a:b],
                              metadata={**metadata, "part": f"{k} of {len(bounds) - 1}",
                                        "span_s": (float(part["time"][0]), float(part["time"][-1])),
                                        "first_line": int(lines[a])},
                              keep_flagged=keep_flagged))
    return out


def _csv_columns(path: Path) -> tuple[dict[str, np.ndarray], list[int], dict]:
    """A damper CSV file's columns in SI (NaN where a cell is empty), each row's line, and what
    the file says of itself (comments, units, columns not used)."""
    path = Path(path)
    if not path.exists():
        raise DataNotFoundError(f"{path}: damper test file not found")
    comments: dict[str, str] = {}
    header: list[str] | None = None
    header_line = 0
    rows: list[list[str]] = []
    row_lines: list[int] = []
    ignored: list[str] = []
    text = read_text(path, "damper test file")  # binary or not UTF-8: one-line InputError
    delimiter = sniff_delimiter(text)
    trailing = False  # every line ends with the delimiter (as the Dyke files do)
    for line_no, row in split_rows(text, delimiter):
        if not row or all(not c.strip() for c in row):
            continue
        if row[0].lstrip().startswith(COMMENT_MARKS):
            comment = (delimiter or " ").join(row).lstrip()[1:]
            if ":" in comment:
                key, value = comment.split(":", 1)
                comments[key.strip().lower()] = value.strip()
            continue
        row = decimal_points(row, delimiter)
        if header is None and len(row) > 1 and not row[-1].strip():
            trailing = True
        if trailing and len(row) > 1 and not row[-1].strip():
            row = row[:-1]
        if header is None:
            if all(_is_float(c) for c in row):
                raise InputError(f"{path}:{line_no}: the first line is data, not a header; expected a header "
                                 "line time, displacement, force[, velocity][, voltage|current]"
                                 + (" (a UTFSM test is recognised by its file name, "
                                    "<amp>mm<freq>Hz<current>A.txt)" if path.suffix.lower() == ".txt" else ""))
            named = [column_of(c, f"{path}:{line_no}: header") for c in row]
            width = len(row)
            # the columns used, by position; the others (a temperature, a command, an
            # acceleration) are named in the report and never parsed
            used = [i for i, (n, _, _) in enumerate(named) if n is not None]
            ignored = [row[i].strip().strip('"') for i, (n, _, _) in enumerate(named) if n is None]
            header = [str(named[i][0]) for i in used]
            factors = {str(n): f for n, f, _ in named if n is not None}
            written = {str(n): u for n, f, u in named if n is not None and u is not None and f != 1.0}
            # read as SI because the header names no unit: said with the amplitudes as read
            unstated = [str(n) for n, _, u in named if n in ("displacement", "force") and u is None]
            header_line = line_no
            missing = [c for c in _REQUIRED if c not in header]
            if missing:
                raise InputError(f"{path}:{line_no}: header: missing column(s) "
                                 f"{', '.join(missing)}; expected time, displacement, force"
                                 "[, velocity][, voltage|current]"
                                 + (f" (not read: {', '.join(repr(c) for c in ignored)})" if ignored else ""))
            if len(set(header)) != len(header):
                twice = next(n for n in header if header.count(n) > 1)
                cells = [row[i].strip() for i in used if named[i][0] == twice]
                raise InputError(f"{path}:{line_no}: header: columns {' and '.join(repr(c) for c in cells)} "
                                 f"both name the {twice}; expected one")
            if "voltage" in header and "current" in header:
                raise InputError(f"{path}:{line_no}: header: expected a voltage or a current "
                                 "column, not both")
            continue
        if ignored:
            if len(row) != width:
                raise InputError(f"{path}:{line_no}: expected {width} values, got {len(row)}")
            row = [row[i] for i in used]
        rows.append(row)
        row_lines.append(line_no)
    if header is None:
        raise InputError(f"{path}: empty file; expected a header line "
                         "time, displacement, force[, velocity][, voltage|current]")
    if len(rows) < 2:
        raise InputError(f"{path}: expected at least 2 data lines after the header "
                         f"(line {header_line}), got {len(rows)}")
    clock = clock_seconds([r[header.index("time")] if len(r) == len(header) else "" for r in rows])
    if clock is not None:
        # date-time stamps (a logger's wall clock): seconds since the first, in the cells' place
        seconds, origin = clock
        i_time = header.index("time")
        for r, value in zip(rows, seconds):
            if len(r) == len(header):
                r[i_time] = repr(float(value))
        factors["time"] = 1.0
        written.pop("time", None)  # a unit beside a clock (timestamp [ms]) says nothing of seconds
        comments["clock_origin"] = origin
    data = parse_rows(path, header, rows, row_lines)
    # units converted at the edge: everything past here is SI (module docstring)
    col = {c: data[:, i] * factors[c] for i, c in enumerate(header)}
    metadata: dict = {}
    if written:
        metadata["file_units"] = written  # e.g. {"displacement": "mm"}: converted to SI on reading
    if unstated:
        metadata["units_unstated"] = unstated
    if ignored:
        metadata["columns_ignored"] = ignored  # the rig's other channels, named in the report
    return col, row_lines, {**comments, **metadata}


def build_test(path: Path, col: dict, voltage: float | None = None, current: float | None = None,
               name: str | None = None, lines: list[int] | None = None, metadata: dict | None = None,
               keep_flagged: bool = False) -> DamperTest:
    """The screened test of a file's columns, already in SI (every reader of a tabular format).

    Parameters
    ----------
    path : Path
        The file, for messages and the test's ``source``.
    col : dict of str to np.ndarray
        ``time``, ``displacement``, ``force`` and any of ``velocity``, ``voltage``, ``current``,
        in SI, NaN where a value is missing.
    voltage, current : float, optional
        Constant coil input for a file without that column.
    name : str, optional
        The test's name (default: the file's stem).
    lines : list of int, optional
        Each sample's line in the file (for the screening's messages).
    metadata : dict, optional
        What the reader learnt of the file (units, columns not used, comments).
    keep_flagged : bool
        Keep the flagged samples in the mask (only missing values stay out).

    Raises
    ------
    InputError
        A coil-input column beside a constant value, or what the screening's repair refuses.
    """
    if ("voltage" in col or "current" in col) and (voltage is not None or current is not None):
        raise InputError(f"{path}: the file has a {'voltage' if 'voltage' in col else 'current'} "
                         "column; do not also give a constant value")
    time, col, excluded, prior = repair_samples(
        col["time"], {c: col.get(c) for c in ("displacement", "force", "velocity", "voltage", "current")},
        label=str(path), lines=lines, keep_flagged=keep_flagged)
    velocity = col.get("velocity")
    if velocity is None:
        velocity = smoothed_derivative(time, col["displacement"])
    test = DamperTest(time=time, displacement=col["displacement"], velocity=velocity,
                      force=col["force"],
                      voltage=col["voltage"] if col.get("voltage") is not None else voltage,  # type: ignore[arg-type]
                      current=col["current"] if col.get("current") is not None else current,  # type: ignore[arg-type]
                      name=name or path.stem, source=str(path),
                      metadata={**(metadata or {}), "velocity_from_file": col.get("velocity") is not None})
    return screened(test, prior, excluded, keep_flagged=keep_flagged)


def write_csv(test: DamperTest, path) -> Path:
    """Write ``test`` as CSV (atomically), with ``# name:`` and ``# source:`` comment lines.

    The header names each column with its SI unit (``time [s],displacement [m],force [N],
    velocity [m/s],voltage [V]``); :func:`read_csv` reads it back. The channels keep 10
    significant digits (more than any sensor resolves); the time keeps as many as its steps need
    against its largest value (a logger's absolute time stamps, 1.7e9 s at 0.3-ms steps, need
    17: with 10 every stamp of a second would be one).

    Parameters
    ----------
    test : DamperTest
        The test to write.
    path
        CSV file to write (replaced atomically).
    """
    path = Path(path)
    columns = [("time", test.time), ("displacement", test.displacement), ("force", test.force),
               ("velocity", test.velocity)]
    if test.voltage is not None:
        columns.append(("voltage", test.voltage))
    elif test.current is not None:
        columns.append(("current", test.current))
    data = np.column_stack([c for _, c in columns])
    with atomic_path(path) as tmp:
        with open(tmp, "w", encoding="utf-8", newline="\n") as fh:
            for key in ("name", "source"):
                value = getattr(test, key)
                if value:
                    fh.write(f"# {key}: {' '.join(str(value).split())}\n")
            fh.write(",".join(f"{name} [{_UNITS[name]}]" for name, _ in columns) + "\n")
            np.savetxt(fh, data, delimiter=",", fmt=[f"%.{_time_digits(test.time)}g"] + ["%.10g"] * (len(columns) - 1))
    return path


def _time_digits(t: np.ndarray) -> int:
    """Significant digits that keep every step of ``t`` to a millionth of itself (10 to 17)."""
    steps = np.diff(np.asarray(t, dtype=float))
    top = float(np.max(np.abs(t))) if t.size else 0.0
    if steps.size == 0 or not steps.min() > 0.0 or not top > 0.0:
        return 10
    return int(min(17, max(10, math.ceil(math.log10(top / float(steps.min()))) + 6)))


_UTFSM_NAME = re.compile(r"^(?P<amp>\d+(?:x\d+)?)mm(?P<freq>\d+(?:x\d+)?)Hz(?P<cur>\d+(?:x\d+)?)A$")


def parse_utfsm_name(path) -> dict[str, float]:
    """Amplitude [m], frequency [Hz] and current [A] from a UTFSM file name.

    ``25mm0x1Hz0x75A.txt`` -> ``{"amplitude": 0.025, "frequency": 0.1, "current": 0.75}``.

    Parameters
    ----------
    path
        A UTFSM file name or path (``25mm0x1Hz0x75A.txt``).
    """
    stem = Path(path).stem
    m = _UTFSM_NAME.match(stem)
    if not m:
        raise InputError(f"{path}: file name: expected <amp>mm<freq>Hz<current>A.txt with 'x' as "
                         f"decimal point (e.g. 25mm0x1Hz0x75A.txt), got {Path(path).name!r}")
    num = {k: float(v.replace("x", ".")) for k, v in m.groupdict().items()}
    return {"amplitude": num["amp"] * 1e-3, "frequency": num["freq"], "current": num["cur"]}


def read_utfsm(path, keep_flagged: bool = False) -> DamperTest:
    """Read one preprocessed UTFSM file (t [s], x [mm], ẋ [mm/s], F [N]) into SI units, screened.

    The current [A] comes from the file name (:func:`parse_utfsm_name`); displacement and
    velocity are converted from mm to m. Raises :class:`InputError` naming the file and
    line for a malformed file. The test is screened as in :func:`read_csv` (``nan`` values
    are filled and flagged).

    Parameters
    ----------
    path : str or Path
        A preprocessed UTFSM file (name pattern ``25mm0x1Hz0x75A.txt``).
    keep_flagged : bool
        Keep the samples the screening flags in fits and errors.
    """
    path = Path(path)
    if not path.exists():
        raise DataNotFoundError(f"{path}: UTFSM file not found")
    info = parse_utfsm_name(path)
    rows: list[list[float]] = []
    lines: list[int] = []
    text = read_text(path, "UTFSM file")  # binary or not UTF-8: one-line InputError
    with io.StringIO(text) as fh:
        for line_no, line in enumerate(fh, start=1):
            cells = line.split()
            if not cells:
                continue
            if len(cells) != 4:
                raise InputError(f"{path}:{line_no}: expected 4 columns (t [s], x [mm], "
                                 f"xdot [mm/s], F [N]), got {len(cells)}")
            if any("," in c for c in cells) and not any("." in c for c in cells):
                # whitespace-separated columns with decimal commas (a spreadsheet's export in a
                # European locale): the comma can only be the decimal mark here
                cells = [c.replace(",", ".") for c in cells]
            try:
                values = [parse_float(c) for c in cells]
            except ValueError:
                raise InputError(f"{path}:{line_no}: expected 4 numbers, got {line.strip()!r}") from None
            if any(math.isinf(v) for v in values):
                raise InputError(f"{path}:{line_no}: expected finite numbers, got {line.strip()!r}")
            rows.append(values)
            lines.append(line_no)
    if len(rows) < 2:
        raise InputError(f"{path}: expected at least 2 data lines, got {len(rows)}")
    data = np.array(rows)
    time, col, excluded, prior = repair_samples(
        data[:, 0], {"displacement": data[:, 1] * 1e-3, "velocity": data[:, 2] * 1e-3,
                     "force": data[:, 3]}, label=str(path), lines=lines, keep_flagged=keep_flagged)
    test = DamperTest(time=time, displacement=col["displacement"], velocity=col["velocity"],
                      force=col["force"], current=np.full(time.size, info["current"]),
                      name=path.stem, source=str(path),
                      metadata={**info, "units_in_file": "t [s], x [mm], xdot [mm/s], F [N]",
                                "provider": "M. Quiroz, UTFSM (MIT licence)"})
    return screened(test, prior, excluded, keep_flagged=keep_flagged)


#: Raw UTFSM logger exports: (CHANNEL0, CHANNEL1) by sampling rate [Hz] (the data notes of the
#: shared folder: 200 Hz files hold force then displacement, 1 kHz files the other way round).
UTFSM_RAW_CHANNELS = {200.0: ("force", "displacement"), 1000.0: ("displacement", "force")}
_KGF = STANDARD_GRAVITY   # the logger's force channel is in units of 100 kgf: x 980.665 -> N
_RAW_CURRENT_NAME = re.compile(r"(?<![\dx])(?P<cur>\d+(?:x\d+)?)A(?:_\d+)?$")


def raw_current_from_name(path) -> float | None:
    """The coil current [A] a raw UTFSM export of one current carries at the end of its name.

    ``15Hz1A.txt`` -> 1.0, ``15Hz0x5A.txt`` -> 0.5, ``15Hz1A_2.txt`` (a repeat) -> 1.0 (``x`` is
    the decimal point, as in the preprocessed files' names); ``ME10mm2Hz.txt`` -> None (an export of
    the five currents, :func:`split_utfsm_raw`).

    Parameters
    ----------
    path : str or Path
        The file.
    """
    m = _RAW_CURRENT_NAME.search(Path(path).stem)
    return None if m is None else float(m.group("cur").replace("x", "."))


def read_utfsm_raw(path, keep_flagged: bool = False) -> DamperTest:
    """Read one raw UTFSM logger export (``Datos_crudos/ME*.txt``, ``Validacion/MRDAMPER/15Hz1A.txt``)
    into SI units, screened.

    Seven header lines (``Sampling Interval:`` [s] among them), then ``Sample Number,
    Date/Time, CHANNEL0, CHANNEL1[, CHANNEL2][, Events]``. Force x 980.665 -> N, displacement
    x 10 -> mm -> m; which of CHANNEL0 and CHANNEL1 is the force follows from the sampling rate
    (:data:`UTFSM_RAW_CHANNELS`). A CHANNEL2 is the actuator's commanded displacement (the
    campaign's own preprocessing, ``Cap6_ModeloActuador/Preprocesamiento/sincronize.m`` of the
    source repository, ``../shared/SOURCES.md``), not used: the model is driven by the measured
    one. The coil current is not recorded: an export of one current names
    it at the end of its file name (:func:`raw_current_from_name`) and is read at it; an export of
    the five currents back to back, with idle spans between them, has no coil input here
    (:func:`split_utfsm_raw` cuts it into its levels). The velocity is the derivative of the
    displacement.

    Parameters
    ----------
    path : str or Path
        A raw logger export.
    keep_flagged : bool
        Keep the samples the screening flags (the idle spans among them) in fits and errors.
    """
    path = Path(path)
    if not path.exists():
        raise DataNotFoundError(f"{path}: raw UTFSM file not found")
    text = read_text(path, "raw UTFSM file")
    lines = text.splitlines()
    interval = None
    for line in lines[:10]:
        if line.lower().startswith("sampling interval:"):
            try:
                interval = float(line.split(":", 1)[1])
            except ValueError:
                raise InputError(f"{path}: 'Sampling Interval:' is not a number: {line!r}") from None
    if interval is None or not interval > 0:
        raise InputError(f"{path}: expected a 'Sampling Interval: <s>' header line (raw UTFSM export)")
    rate = round(1.0 / interval)
    if float(rate) not in UTFSM_RAW_CHANNELS:
        raise InputError(f"{path}: sampling rate {rate} Hz: expected one of "
                         f"{sorted(UTFSM_RAW_CHANNELS)} Hz (the channel order is known for these)")
    names = UTFSM_RAW_CHANNELS[float(rate)]
    samples, ch0, ch1, line_nos = [], [], [], []
    command = False
    for line_no, line in enumerate(lines, start=1):
        cells = [c.strip() for c in line.split(",")]
        if len(cells) < 4 or not cells[0].isdigit():
            continue
        try:
            samples.append(int(cells[0]))
            ch0.append(float(cells[2]))
            ch1.append(float(cells[3]))
        except ValueError:
            raise InputError(f"{path}:{line_no}: expected numbers in CHANNEL0, CHANNEL1, got "
                             f"{line.strip()!r}") from None
        if len(cells) > 4 and not command:  # CHANNEL2, where the export has one (else the Events column)
            try:
                command = math.isfinite(parse_float(cells[4]))
            except ValueError:
                pass
        line_nos.append(line_no)
    if len(samples) < 2:
        raise InputError(f"{path}: expected at least 2 data lines, got {len(samples)}")
    raw = {names[0]: np.array(ch0), names[1]: np.array(ch1)}
    time = (np.array(samples, dtype=float) - samples[0]) * interval
    time, col, excluded, prior = repair_samples(
        time, {"displacement": raw["displacement"] * 10.0 * 1e-3, "force": raw["force"] * 100.0 * _KGF},
        label=str(path), lines=line_nos, keep_flagged=keep_flagged)
    velocity = smoothed_derivative(time, col["displacement"])
    current = raw_current_from_name(path)
    units = f"CHANNEL0 {names[0]}, CHANNEL1 {names[1]}: force x 980.665 -> N, displacement x 10 -> mm"
    if command:
        units += "; CHANNEL2 the commanded displacement (not used)"
    metadata = {"velocity_from_file": False, "sample_rate": float(rate), "units_in_file": units,
                "provider": "M. Quiroz, UTFSM (MIT licence)"}
    if current is not None:
        metadata["current_from"] = "the file name"
    test = DamperTest(time=time, displacement=col["displacement"], velocity=velocity, force=col["force"],
                      current=None if current is None else np.full(time.size, current),
                      name=path.stem, source=str(path), metadata=metadata)
    return screened(test, prior, excluded, keep_flagged=keep_flagged)


#: The coil currents [A] of a raw UTFSM logger export, in the order its spans of motion follow one
#: another (``../shared/SOURCES.md``: each file holds the five currents 0...1 A back to back,
#: separated by idle periods; the preprocessed files give the same five levels).
UTFSM_RAW_CURRENTS = (0.0, 0.25, 0.5, 0.75, 1.0)


def is_utfsm_raw_file(path) -> bool:
    """Whether ``path`` begins as a raw UTFSM logger export does (a ``Header Size:`` line).

    Parameters
    ----------
    path : str or Path
        The file.
    """
    try:
        with open(path, "rb") as fh:
            head = fh.read(64)
    except OSError:
        return False
    return head.lstrip(b"\xef\xbb\xbf").lower().startswith(b"header size:")


def split_utfsm_raw(test: DamperTest, currents=UTFSM_RAW_CURRENTS, keep_flagged: bool = False) -> list[DamperTest]:
    """The coil-current levels of a raw UTFSM logger export, one test each.

    :func:`read_utfsm_raw` reads the whole file, whose coil current is not recorded; its screening
    finds the rig's idle spans between the levels. The spans of motion between them (those
    longer than a fifth of the median one: a few samples of motion between two idle spans are no
    level) are the levels, given ``currents`` in order, which their force must follow (an MR
    damper's force rises with its current). Each is a test of its own, named
    ``"<file> <current> A"``, with the time of the file kept, and screened anew.

    Parameters
    ----------
    test : DamperTest
        A raw export as :func:`read_utfsm_raw` returns it.
    currents : sequence of float
        The coil currents [A] of the levels, in order (default :data:`UTFSM_RAW_CURRENTS`).
    keep_flagged : bool
        Keep the samples each level's screening flags in fits and errors.

    Raises
    ------
    InputError
        The spans of motion are not as many as ``currents``, or their force does not rise with
        them: which current each one had would be a guess.
    """
    t = np.asarray(test.time, dtype=float)
    idle = np.zeros(t.size, dtype=bool)
    for f in screening_of(test).findings:
        if f.kind == "idle":
            idle |= (t >= f.t_start) & (t <= f.t_end)
    edges = np.flatnonzero(np.diff(np.r_[0, (~idle).astype(np.int8), 0]))
    runs = list(zip(edges[::2], edges[1::2]))
    if runs:
        typical = float(np.median([t[b - 1] - t[a] for a, b in runs]))
        runs = [(a, b) for a, b in runs if t[b - 1] - t[a] > 0.2 * typical]
    if len(runs) != len(currents):
        raise InputError(f"{test.source or test.name}: {len(runs)} span(s) of motion between the idle spans; "
                         f"expected {len(currents)}, one per coil current {', '.join(f'{c:g}' for c in currents)} A "
                         "in order (which current each span had would be a guess; an export of one current "
                         "names it at the end of the file name, e.g. 15Hz1A.txt or 15Hz0x5A.txt)")
    # an MR damper's force rises with its coil current: levels out of that order are not the
    # order assumed (a level repeated, one left out), and a fit on them would be of the wrong device
    force = np.abs(np.asarray(test.force, dtype=float))
    peaks = [float(np.percentile(force[a:b], 95)) for a, b in runs]
    if any(hi <= lo for lo, hi in zip(peaks, peaks[1:])):
        raise InputError(f"{test.source or test.name}: the force of the spans of motion "
                         f"({', '.join(f'{v:.4g}' for v in peaks)} N, 95th percentiles) does not rise with "
                         f"the coil currents {', '.join(f'{c:g}' for c in currents)} A assumed in order")
    metadata = {k: v for k, v in test.metadata.items() if k != "screening"}
    findings = screening_of(test).findings
    out = []
    for (a, b), current in zip(runs, currents):
        # what the reader filled in the level (missing values, held readings, spikes, lost
        # slots) carries no measurement: it stays out of the level's fit and error
        prior, filled = filled_samples(findings, t[a:b])
        level = DamperTest(time=t[a:b], displacement=np.asarray(test.displacement)[a:b],
                           velocity=np.asarray(test.velocity)[a:b], force=np.asarray(test.force)[a:b],
                           current=np.full(b - a, float(current)), name=f"{test.name} {current:g} A",
                           source=test.source,
                           metadata={**metadata, "current_from": "the order of the levels in the file "
                                                                 "(UTFSM_RAW_CURRENTS)",
                                     "span_s": (float(t[a]), float(t[b - 1]))})
        out.append(screened(level, prior=prior, prior_excluded=filled, keep_flagged=keep_flagged))
    return out


def utfsm_files(shared_dir=None) -> list[Path]:
    """The preprocessed UTFSM test files, sorted by name (raises :class:`DataNotFoundError`).

    Parameters
    ----------
    shared_dir : str or path-like, optional
        The shared data directory; None: the default (:mod:`benchmark.foundation.paths`).
    """
    if shared_dir is None:
        shared_dir = _shared()
    folder = Path(shared_dir) / "hysteresis_data" / "quiroz_utfsm_mr_damper_sinusoidal" / "Preprocesados"
    if not folder.is_dir():
        raise DataNotFoundError(f"{folder}: UTFSM data folder not found (set SBIB_SHARED)")
    return sorted(folder.glob("*.txt"))
