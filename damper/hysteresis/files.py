"""Files of the hysteretic oscillator: force/displacement data (CSV, HDF5) and model JSON.

CSV data (``#`` and ``%`` lines are comments; a header line names the columns, optionally with their
units in brackets or parentheses: SI where none is written, and a rig's units such as ``[ms]``,
``(mm)``, ``[kN]`` or ``[lbf]`` are converted to SI on reading, :mod:`benchmark.foundation.file_units`;
loggers' names ``t``, ``f``, ``load``, ``disp``, ``x``, ``position``, ``stroke`` are read too)::

    time [s], force [N], displacement [m]
    0.0, -27.35, 7.7e-06
    ...

``time`` must be uniformly spaced (to 1 % of its step); ``displacement`` is needed for fitting,
not for prediction. HDF5 data: a group (default ``multisine``, the benchmark's training file
layout) with datasets ``u`` (force [N]), ``y`` (displacement [m]) and ``fs`` (sampling rate [Hz]).
Every malformed file raises :class:`~benchmark.foundation.errors.InputError` naming the file, line or field.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from benchmark.foundation.atomic import atomic_write_text
from benchmark.foundation.errors import DataNotFoundError, InputError, ParameterError
from benchmark.foundation.file_units import column_name_unit, si_factor
from benchmark.foundation.textfile import read_text
from damper.io.data import COMMENT_MARKS, decimal_points, parse_rows, sniff_delimiter, split_rows
from damper.hysteresis.oscillator import DEFAULT_UPSAMPLE, HystereticOscillator
from damper.io.model_file import file_provenance, read_model_file, write_model_file
from benchmark.foundation.channel_runs import runs, spans_by_kind, stuck_spans
from damper.io.screening import PLAUSIBLE, POLARITY_SHARE, SPIKE_MAX_SHARE, net_work, spike_samples

__all__ = ["ForceData", "read_data", "read_force_csv", "read_hdf5", "write_displacement_csv",
           "save_model", "load_model", "data_flaws", "sampling_rate_flaw", "MODEL_KIND"]

MODEL_KIND = "hysteretic_oscillator"
#: Each column's quantity (:mod:`benchmark.foundation.file_units`: a unit in brackets is converted to SI).
_UNITS = {"time": "time", "force": "force", "displacement": "length"}


@dataclass(frozen=True)
class ForceData:
    """Uniformly sampled force (and displacement) of a test.

    Attributes
    ----------
    force : ndarray
        Force [N].
    displacement : ndarray or None
        Displacement [m].
    fs : float
        Sampling rate [Hz].
    t0 : float
        Time of the first sample [s].
    source : str
    """

    force: np.ndarray
    displacement: np.ndarray | None
    fs: float
    t0: float
    source: str

    @property
    def time(self) -> np.ndarray:
        """Sample instants [s]."""
        return self.t0 + np.arange(self.force.size) / self.fs


def sampling_rate_flaw(fs: float) -> str | None:
    """The phrase for a sampling rate no hysteresis test has (a time column in ms declared as s
    reads as ~1 Hz), or None.

    Parameters
    ----------
    fs : float
        Sampling rate [Hz].
    """
    lo, hi = PLAUSIBLE["sample_rate"]
    if lo <= fs <= hi:
        return None
    return f"sampling rate {fs:.4g} Hz is outside the plausible {lo:g}-{hi:g} Hz (a time column in ms?)"


def data_flaws(data: ForceData) -> list[str]:
    """What makes ``data`` unfit to identify from, one phrase per flaw (empty: none found).

    The damper screening's rules (:mod:`damper.io.screening`) on a force-driven test: a force
    channel clipped or stuck (the force that drove the specimen is unknown there), a
    displacement channel frozen or clipped (the response is unknown there), and a sampling rate
    no hysteresis test has (a time column in ms declared as s reads as ~1 Hz), spikes in either
    channel (a logger's glitch, :func:`damper.io.screening.spike_samples`), and a force
    that does net negative work on the response (the specimen dissipates what the force puts in,
    so the force's sign is inverted against the displacement: the benchmark's training data give
    +0.40 of the absolute work, negated -0.40). The output-error fit simulates the whole record,
    so such samples cannot simply be left out.

    Parameters
    ----------
    data : ForceData
        A test as read by :func:`read_data`.
    """
    out = []
    rate = sampling_rate_flaw(data.fs)
    if rate:
        out.append(rate)
    t = data.time
    for channel, values, unit in (("force", data.force, "N"), ("displacement", data.displacement, "m")):
        if values is None:
            continue
        for kind, hits in spans_by_kind(stuck_spans(values)).items():
            a, b, level = hits[0]
            word = "frozen" if kind == "stuck" and channel == "displacement" else kind
            why = ("the force that drove the specimen is unknown there" if channel == "force"
                   else "the response is unknown there")
            out.append(f"{channel} {word} in {len(hits)} span{'s' if len(hits) > 1 else ''} "
                       f"({sum(e - s for s, e, _ in hits)} samples; the first at "
                       f"{t[a]:.4g}-{t[b - 1]:.4g} s, {level:.6g} {unit}): {why}")
        spikes = spike_samples(values)
        if spikes.any() and spikes.sum() <= SPIKE_MAX_SHARE * values.size:
            hits = runs(spikes)
            out.append(f"{channel} spikes in {len(hits)} run{'s' if len(hits) > 1 else ''} ({int(spikes.sum())} "
                       f"samples; the first at {t[hits[0][0]]:.4g} s): a glitch, which the output-error fit "
                       "would follow")
    if data.displacement is not None and data.force.size > 8:
        # the damper screening's polarity rule (damper/io/screening.py)
        _, share = net_work(t, data.force, np.gradient(data.displacement, t))
        if share < -POLARITY_SHARE:
            out.append(f"the force does net negative work on the response ({share:+.2f} of its "
                       "absolute work): the specimen dissipates, so the force's sign is inverted against the "
                       "displacement")
    return out


def read_data(path, need_displacement: bool = True, group: str | None = None) -> ForceData:
    """Read a CSV or HDF5 data file (chosen by content, not by name).

    Parameters
    ----------
    path
        CSV or HDF5 data file.
    need_displacement : bool, optional
        Fail when the file has no displacement column.
    group : str | None, optional
        HDF5 group to read; None: the file's root or its only group.
    """
    path = Path(path)
    if not path.is_file():
        raise DataNotFoundError(f"{path}: data file not found")
    with open(path, "rb") as fh:
        head = fh.read(8)
    if head == b"\x89HDF\r\n\x1a\n":
        return read_hdf5(path, group, need_displacement)
    return read_force_csv(path, need_displacement)


def _column(cell: str, path: Path, line: int) -> tuple[str, float]:
    split = column_name_unit(cell)  # the damper tests' rule: brackets or parentheses, loggers' names
    if split is None or split[0] not in _UNITS:
        raise InputError(f"{path}:{line}: header: unknown column {cell.strip()!r}; expected "
                         "time, force[, displacement]")
    name, unit = split
    if unit is None:
        return name, 1.0
    return name, si_factor(_UNITS[name], unit, f"{path}:{line}: header: column {name!r}")


def read_force_csv(path, need_displacement: bool = True) -> ForceData:
    """Read a ``time, force[, displacement]`` CSV file (module docstring).

    Parameters
    ----------
    path
        CSV file.
    need_displacement : bool, optional
        Fail when the file has no displacement column.

    Raises
    ------
    DataNotFoundError
        No such file.
    InputError
        Binary or non-UTF-8 content, a missing or unknown column, a non-number, NaN or inf,
        time not strictly increasing or not uniform, fewer than 2 samples.
    """
    path = Path(path)
    if not path.is_file():
        raise DataNotFoundError(f"{path}: data file not found")
    header: list[str] | None = None
    rows: list[list[str]] = []
    lines: list[int] = []
    # the damper tests' reading (damper.io.data): a BOM, ',' ';' tab or spaces, decimal commas
    text = read_text(path, "data file")  # binary or not UTF-8: one-line InputError
    delimiter = sniff_delimiter(text)
    for line_no, row in split_rows(text, delimiter):
        if not row or all(not c.strip() for c in row) or row[0].lstrip().startswith(COMMENT_MARKS):
            continue
        row = decimal_points(row, delimiter)
        if len(row) > 1 and not row[-1].strip():
            row = row[:-1]  # a separator ending the line
        if header is None:
            named = [_column(c, path, line_no) for c in row]
            header = [n for n, _ in named]
            factors = dict(named)
            need = ["time", "force"] + (["displacement"] if need_displacement else [])
            missing = [c for c in need if c not in header]
            if missing:
                raise InputError(f"{path}:{line_no}: header: missing column(s) "
                                 f"{', '.join(missing)}; expected {', '.join(need)}")
            if len(set(header)) != len(header):
                raise InputError(f"{path}:{line_no}: header: repeated column name")
            continue
        rows.append(row)
        lines.append(line_no)
    if header is None:
        raise InputError(f"{path}: empty file; expected a header line time, force[, displacement]")
    if len(rows) < 2:
        raise InputError(f"{path}: expected at least 2 data lines, got {len(rows)}")
    data = parse_rows(path, header, rows, lines, missing=False)
    col = {c: data[:, i] * factors[c] for i, c in enumerate(header)}  # SI from here on
    fs, t0 = _uniform_rate(col["time"], path, lines)
    return ForceData(force=col["force"], displacement=col.get("displacement"), fs=fs, t0=t0,
                     source=str(path))


def _uniform_rate(t: np.ndarray, path: Path, lines: list[int]) -> tuple[float, float]:
    dt = np.diff(t)
    bad = np.flatnonzero(dt <= 0)
    if bad.size:
        i = int(bad[0]) + 1
        raise InputError(f"{path}:{lines[i]}: column 'time': expected strictly increasing values, "
                         f"got {t[i]:g} s after {t[i - 1]:g} s")
    step = (t[-1] - t[0]) / (t.size - 1)
    dev = np.abs(t - (t[0] + step * np.arange(t.size)))
    worst = int(np.argmax(dev))
    if dev[worst] > 1e-2 * step:
        raise InputError(f"{path}:{lines[worst]}: column 'time': expected uniform sampling "
                         f"(step {step:.6g} s), sample {worst} is off by {dev[worst]:.3g} s")
    return 1.0 / step, float(t[0])


def read_hdf5(path, group: str | None = None, need_displacement: bool = True) -> ForceData:
    """Read ``u``, ``y`` and ``fs`` from a group of an HDF5 file (the benchmark's layout).

    Parameters
    ----------
    path : path-like
    group : str, optional
        Group name (default: ``multisine`` if present, else the only group with ``u``).
    need_displacement : bool
        Require ``y``.
    """
    import h5py

    path = Path(path)
    try:
        fh = h5py.File(path, "r")
    except OSError as exc:
        raise InputError(f"{path}: unreadable HDF5 file ({exc})") from None
    with fh:
        if group is None:
            candidates = [k for k in fh if isinstance(fh[k], h5py.Group) and "u" in fh[k]]
            if "multisine" in candidates:
                group = "multisine"
            elif len(candidates) == 1:
                group = candidates[0]
            else:
                raise InputError(f"{path}: expected one group with datasets u, y, fs (or "
                                 f"'multisine'), found {candidates or 'none'}")
        if group not in fh or not isinstance(fh[group], h5py.Group):
            raise InputError(f"{path}: no group {group!r}")
        g = fh[group]
        need = ["u", "fs"] + (["y"] if need_displacement else [])
        missing = [k for k in need if k not in g]
        if missing:
            raise InputError(f"{path}: group {group!r}: missing dataset(s) {', '.join(missing)}; "
                             "expected u [N], y [m], fs [Hz]")
        try:
            u = np.asarray(g["u"][()], dtype=float).ravel()
            y = np.asarray(g["y"][()], dtype=float).ravel() if "y" in g else None
            fs_arr = np.asarray(g["fs"][()], dtype=float).ravel()
        except (TypeError, ValueError):
            raise InputError(f"{path}: group {group!r}: u, y and fs must be numeric") from None
    if fs_arr.size != 1 or not (fs_arr[0] > 0 and math.isfinite(fs_arr[0])):
        raise InputError(f"{path}: fs: expected one positive sampling rate [Hz]")
    if y is not None and y.size != u.size:
        raise InputError(f"{path}: u and y: expected equal lengths, got {u.size} and {y.size}")
    for name, a in (("u", u), ("y", y)):
        if a is not None and not np.all(np.isfinite(a)):
            i = int(np.argmax(~np.isfinite(a)))
            raise InputError(f"{path}: {group}/{name}: expected finite values, sample {i} is {a[i]}")
    if u.size < 2:
        raise InputError(f"{path}: expected at least 2 samples, got {u.size}")
    return ForceData(force=u, displacement=y, fs=float(fs_arr[0]), t0=0.0, source=str(path))


def write_displacement_csv(path, time: np.ndarray, displacement: np.ndarray) -> Path:
    """Write ``time [s], displacement [m]`` atomically (full double precision).

    Parameters
    ----------
    path
        CSV file to write (replaced atomically).
    time : np.ndarray
        Sample times [s].
    displacement : np.ndarray
        Displacement [m] at ``time``.
    """
    lines = ["time [s],displacement [m]"]
    lines += [f"{t:.17g},{y:.17g}" for t, y in zip(time, displacement)]
    return atomic_write_text(path, "\n".join(lines) + "\n")


def save_model(path, model: HystereticOscillator, fs: float, upsample: int = DEFAULT_UPSAMPLE,
               extra: dict | None = None, inputs=()) -> Path:
    """Write the model as a damper model file (:mod:`damper.io.model_file`, model
    ``hysteretic_oscillator``; atomic): parameters in SI with their units; the integration settings
    (``sampling_rate_hz``, ``upsample``), the standard form and ``extra`` (the fit) under
    ``quality``; ``inputs`` (data files) in the provenance with their SHA-256.

    Parameters
    ----------
    path : path-like
        Model file to write (replaced atomically).
    model : HystereticOscillator
        The fitted oscillator.
    fs : float
        Sampling rate [Hz] of the data the model was fitted on (its integration rate before
        upsampling).
    upsample : int, optional
        Integration substeps per sample used in the fit.
    extra : dict, optional
        More entries of ``quality`` (the fit's errors and settings).
    inputs : sequence of path-like, optional
        Data files the model was fitted on (recorded with their SHA-256).

    Returns
    -------
    Path
        The path written.
    """
    quality = {"standard_form": model.to_standard(beta=1.0), "sampling_rate_hz": float(fs),
               "upsample": int(upsample), **(extra or {})}
    return write_model_file(path, model, quality=quality, provenance=file_provenance(inputs))




def load_model(path) -> tuple[HystereticOscillator, dict]:
    """Read a model written by :func:`save_model` (the damper model file, or the earlier
    ``{"kind": "hysteretic_oscillator", ...}`` layout); return the model and a dict with
    ``kind``, ``parameters`` and the entries :func:`save_model` put under ``quality``
    (``sampling_rate_hz``, ``upsample``, ``fit``, ...).

    Parameters
    ----------
    path : path-like
        A model file of model ``hysteretic_oscillator``.

    Raises
    ------
    InputError
        The file is malformed or holds another model.
    """
    mf = read_model_file(path)
    if not isinstance(mf.model, HystereticOscillator):
        raise InputError(f"{path}: model {mf.model_name} is not a {MODEL_KIND}; expected a file of "
                         "sbib hysteresis fit")
    doc = {**mf.quality, "kind": MODEL_KIND, "parameters": mf.model.parameters()}
    return mf.model, doc
