"""Damper test records: the :class:`DamperTest` type, CSV files and the UTFSM data adapter.

CSV format (SI units, one header line, optional ``#`` comment lines before it)::

    # name: virtual 0.4 m 0.8 Hz 0 V
    # source: damper.laboratory.periodic_test(...)
    time,displacement,force,velocity,voltage
    0.0,0.0,-1234.5,2.01,0.0
    ...

Required columns ``time`` [s], ``displacement`` [m], ``force`` [N]; optional ``velocity``
[m/s] (the central difference of the displacement when absent) and one of ``voltage`` [V]
or ``current`` [A] (a constant value may instead be passed to :func:`read_csv`). A header
name may carry its unit in brackets (``force [N]``); only the SI unit is accepted.

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
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from benchmark.foundation.atomic import atomic_path
from benchmark.foundation.errors import DataNotFoundError, InputError
from benchmark.foundation.paths import shared_dir as _shared
from benchmark.foundation.textfile import read_text

__all__ = ["DamperTest", "check_samples", "read_csv", "write_csv", "read_utfsm", "parse_utfsm_name",
           "utfsm_files"]

_REQUIRED = ("time", "displacement", "force")
_OPTIONAL = ("velocity", "voltage", "current")
_UNITS = {"time": "s", "displacement": "m", "force": "N", "velocity": "m/s", "voltage": "V",
          "current": "A"}


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
        Anything else (amplitude, frequency, noise, ...).
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
        """The samples with ``t_start <= time <= t_end`` (e.g. to drop the transient)."""
        keep = (self.time >= t_start) & (self.time <= t_end)
        if keep.sum() < 2:
            raise InputError(f"{self.name or 'DamperTest'}: select({t_start}, {t_end}) keeps "
                             f"fewer than 2 samples")
        return DamperTest(time=self.time[keep], displacement=self.displacement[keep],
                          velocity=self.velocity[keep], force=self.force[keep],
                          voltage=None if self.voltage is None else self.voltage[keep],
                          current=None if self.current is None else self.current[keep],
                          name=self.name, source=self.source, metadata=self.metadata)


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


def _header_name(cell: str, path: Path, line: int) -> str:
    text = cell.strip()
    m = re.fullmatch(r"([A-Za-z_]+)\s*(?:\[\s*([^\]]*)\s*\])?", text)
    if not m:
        raise InputError(f"{path}:{line}: header: unreadable column name {cell!r}; expected "
                         "time, displacement, force[, velocity][, voltage|current]")
    name, unit = m.group(1).lower(), m.group(2)
    if name not in _UNITS:
        raise InputError(f"{path}:{line}: header: unknown column {name!r}; expected "
                         "time, displacement, force[, velocity][, voltage|current]")
    if unit is not None and unit.strip() != _UNITS[name]:
        raise InputError(f"{path}:{line}: header: column {name!r} in {unit.strip()!r}; expected SI "
                         f"unit [{_UNITS[name]}]")
    return name


def parse_row(path, line_no: int, header: list[str], row: list[str]) -> list[float]:
    """The finite numbers of one CSV data row, one per header column.

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
        try:
            value = float(cell)
        except ValueError:
            raise InputError(f"{path}:{line_no}: column {col!r}: expected a number, "
                             f"got {cell.strip()!r}") from None
        if not math.isfinite(value):
            raise InputError(f"{path}:{line_no}: column {col!r}: expected a finite "
                             f"number, got {cell.strip()!r}")
        values.append(value)
    return values


def read_csv(path, voltage: float | None = None, current: float | None = None,
             name: str | None = None) -> DamperTest:
    """Read a damper test CSV file (format in the module docstring).

    Parameters
    ----------
    path : path-like
        The CSV file.
    voltage, current : float, optional
        Constant coil voltage [V] or current [A] for a file without that column.
    name : str, optional
        Label (default: the ``# name:`` comment, else the file stem).

    Raises
    ------
    DataNotFoundError
        The file does not exist.
    InputError
        Malformed file: the message names the file, line and column.
    """
    path = Path(path)
    if not path.is_file():
        raise DataNotFoundError(f"{path}: damper test file not found")
    if voltage is not None and current is not None:
        raise InputError("read_csv: give a constant voltage or a current, not both")
    comments: dict[str, str] = {}
    header: list[str] | None = None
    header_line = 0
    rows: list[list[float]] = []
    row_lines: list[int] = []
    text = read_text(path, "damper test file")  # binary or not UTF-8: one-line InputError
    with io.StringIO(text, newline="") as fh:
        for line_no, row in enumerate(csv.reader(fh), start=1):
            if not row or all(not c.strip() for c in row):
                continue
            if row[0].lstrip().startswith("#"):
                text = ",".join(row).lstrip()[1:]
                if ":" in text:
                    key, value = text.split(":", 1)
                    comments[key.strip().lower()] = value.strip()
                continue
            if header is None:
                header = [_header_name(c, path, line_no) for c in row]
                header_line = line_no
                missing = [c for c in _REQUIRED if c not in header]
                if missing:
                    raise InputError(f"{path}:{line_no}: header: missing column(s) "
                                     f"{', '.join(missing)}; expected time, displacement, force"
                                     "[, velocity][, voltage|current]")
                if len(set(header)) != len(header):
                    raise InputError(f"{path}:{line_no}: header: repeated column name")
                if "voltage" in header and "current" in header:
                    raise InputError(f"{path}:{line_no}: header: expected a voltage or a current "
                                     "column, not both")
                continue
            rows.append(parse_row(path, line_no, header, row))
            row_lines.append(line_no)
    if header is None:
        raise InputError(f"{path}: empty file; expected a header line "
                         "time, displacement, force[, velocity][, voltage|current]")
    if len(rows) < 2:
        raise InputError(f"{path}: expected at least 2 data lines after the header "
                         f"(line {header_line}), got {len(rows)}")
    data = np.array(rows)
    col = {c: data[:, i] for i, c in enumerate(header)}
    time = col["time"]
    bad = np.flatnonzero(np.diff(time) <= 0)
    if bad.size:
        i = int(bad[0]) + 1
        raise InputError(f"{path}:{row_lines[i]}: column 'time': expected strictly increasing "
                         f"values, got {time[i]:g} s after {time[i - 1]:g} s")
    if ("voltage" in col or "current" in col) and (voltage is not None or current is not None):
        raise InputError(f"{path}: the file has a {'voltage' if 'voltage' in col else 'current'} "
                         "column; do not also give a constant value")
    velocity = col.get("velocity")
    metadata = {"velocity_from_file": velocity is not None}
    if velocity is None:
        velocity = np.gradient(col["displacement"], time, edge_order=2)
    return DamperTest(time=time, displacement=col["displacement"], velocity=velocity,
                      force=col["force"],
                      voltage=col.get("voltage", voltage),
                      current=col.get("current", current),
                      name=name or comments.get("name") or path.stem,
                      source=str(path), metadata={**comments, **metadata})


def write_csv(test: DamperTest, path) -> Path:
    """Write ``test`` as CSV (atomically), with ``# name:`` and ``# source:`` comment lines.

    The header names each column with its SI unit (``time [s],displacement [m],force [N],
    velocity [m/s],voltage [V]``); :func:`read_csv` reads it back.
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
            np.savetxt(fh, data, delimiter=",", fmt="%.10g")
    return path


_UTFSM_NAME = re.compile(r"^(?P<amp>\d+(?:x\d+)?)mm(?P<freq>\d+(?:x\d+)?)Hz(?P<cur>\d+(?:x\d+)?)A$")


def parse_utfsm_name(path) -> dict[str, float]:
    """Amplitude [m], frequency [Hz] and current [A] from a UTFSM file name.

    ``25mm0x1Hz0x75A.txt`` -> ``{"amplitude": 0.025, "frequency": 0.1, "current": 0.75}``.
    """
    stem = Path(path).stem
    m = _UTFSM_NAME.match(stem)
    if not m:
        raise InputError(f"{path}: file name: expected <amp>mm<freq>Hz<current>A.txt with 'x' as "
                         f"decimal point (e.g. 25mm0x1Hz0x75A.txt), got {Path(path).name!r}")
    num = {k: float(v.replace("x", ".")) for k, v in m.groupdict().items()}
    return {"amplitude": num["amp"] * 1e-3, "frequency": num["freq"], "current": num["cur"]}


def read_utfsm(path) -> DamperTest:
    """Read one preprocessed UTFSM file (t [s], x [mm], ẋ [mm/s], F [N]) into SI units.

    The current [A] comes from the file name (:func:`parse_utfsm_name`); displacement and
    velocity are converted from mm to m. Raises :class:`InputError` naming the file and
    line for a malformed file.
    """
    path = Path(path)
    if not path.is_file():
        raise DataNotFoundError(f"{path}: UTFSM file not found")
    info = parse_utfsm_name(path)
    rows = []
    text = read_text(path, "UTFSM file")  # binary or not UTF-8: one-line InputError
    with io.StringIO(text) as fh:
        for line_no, line in enumerate(fh, start=1):
            cells = line.split()
            if not cells:
                continue
            if len(cells) != 4:
                raise InputError(f"{path}:{line_no}: expected 4 columns (t [s], x [mm], "
                                 f"xdot [mm/s], F [N]), got {len(cells)}")
            try:
                values = [float(c) for c in cells]
            except ValueError:
                raise InputError(f"{path}:{line_no}: expected 4 numbers, got {line.strip()!r}") from None
            if not all(math.isfinite(v) for v in values):
                raise InputError(f"{path}:{line_no}: expected finite numbers, got {line.strip()!r}")
            rows.append(values)
    if len(rows) < 2:
        raise InputError(f"{path}: expected at least 2 data lines, got {len(rows)}")
    data = np.array(rows)
    return DamperTest(time=data[:, 0], displacement=data[:, 1] * 1e-3, velocity=data[:, 2] * 1e-3,
                      force=data[:, 3], current=np.full(len(rows), info["current"]),
                      name=path.stem, source=str(path),
                      metadata={**info, "units_in_file": "t [s], x [mm], xdot [mm/s], F [N]",
                                "provider": "M. Quiroz, UTFSM (MIT licence)"})


def utfsm_files(shared_dir=None) -> list[Path]:
    """The preprocessed UTFSM test files, sorted by name (raises :class:`DataNotFoundError`)."""
    if shared_dir is None:
        shared_dir = _shared()
    folder = Path(shared_dir) / "hysteresis_data" / "quiroz_utfsm_mr_damper_sinusoidal" / "Preprocesados"
    if not folder.is_dir():
        raise DataNotFoundError(f"{folder}: UTFSM data folder not found (set SBIB_SHARED)")
    return sorted(folder.glob("*.txt"))
