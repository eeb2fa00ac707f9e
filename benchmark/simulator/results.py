"""HDF5 result files: every time history with its units, configuration and provenance attributes.

Layout of a file written by :func:`write_result` (format ``sbib-result``, version 1)::

    /                       attrs: format, format_version, provenance (package_version,
                            git_commit, created_utc, python, numpy, scipy, numba, platform),
                            record, orientation, isolation, controller, record_step_s and
                            integration_step_s (the histories' time step), info_json
                            (the run's whole ``info`` dict as JSON), isolation_json (the
                            isolation layer's description, when given), plus ``extra``
    /run/time_histories/<field>   one dataset per time history; attrs ``units``,
                                  ``description``, ``axes``
    /run/energy/<term>            energy terms (n,) [J]; attrs ``units``, ``description``
    /run/peaks                    attrs: the peaks of :func:`benchmark.simulator.peaks.peaks_of` (SI),
                                  each with ``<name>_units``
    /reference/...                the uncontrolled reference run, same layout (optional)
    /evaluation                   attrs J1..J9 (NaN where undefined) and ``<Jk>_description``,
                                  ``<Jk>_formula``, ``<Jk>_source`` (optional)

All quantities are SI (m, m/s, m/s², rad, N, N·m, V, J, s). Histories are float64 unless the file
was written with ``precision="single"`` (root attribute ``precision``): then every float history
and energy term except the time vector is float32 (7 significant digits, relative rounding
6e-8, far below any response quantity's meaning), which halves the file; ``sbib run`` writes
single precision unless ``--full-histories``. The file is written to a
temporary file in the destination directory and renamed when complete
(:func:`benchmark.foundation.atomic.atomic_path`), so an interrupted run never leaves a partial file.
:func:`read_result` reads a run back into a :class:`StoredResult` with the same field names as
:class:`benchmark.simulator.simulation.SimulationResult`, so evaluation and plots work on it unchanged.
"""

from __future__ import annotations

import dataclasses
import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from benchmark.foundation.atomic import atomic_path
from benchmark.foundation.errors import DataNotFoundError, InputError
from benchmark.simulator.peaks import PEAK_UNITS, Peaks, peaks_of
from benchmark.simulator.evaluation import J_DESCRIPTIONS
from benchmark.foundation.provenance import provenance
from benchmark.simulator.criteria import CRITERIA

__all__ = ["write_result", "read_result", "read_evaluation", "StoredResult", "FIELD_UNITS",
           "FORMAT_NAME", "FORMAT_VERSION"]

FORMAT_NAME = "sbib-result"
FORMAT_VERSION = 1

_XYT = "m, m, rad"
#: field -> (units, description, axes) of every time history of a SimulationResult
FIELD_UNITS: dict[str, tuple[str, str, str]] = {
    "t": ("s", "time", "time"),
    "base_displacement": (_XYT, "base displacement relative to the ground at the base centre of mass",
                          "time, (x, y, theta)"),
    "base_velocity": ("m/s, m/s, rad/s", "base velocity relative to the ground", "time, (x, y, theta)"),
    "base_acceleration": ("m/s^2, m/s^2, rad/s^2", "base acceleration relative to the ground",
                          "time, (x, y, theta)"),
    "base_acceleration_absolute": ("m/s^2, m/s^2, rad/s^2", "absolute base acceleration",
                                   "time, (x, y, theta)"),
    "floor_displacement": (_XYT, "floor displacements relative to the base, floors 1..8",
                           "time, floor, (x, y, theta)"),
    "floor_velocity": ("m/s, m/s, rad/s", "floor velocities relative to the base, floors 1..8",
                       "time, floor, (x, y, theta)"),
    "floor_acceleration_absolute": ("m/s^2, m/s^2, rad/s^2", "absolute floor accelerations, floors 1..8",
                                    "time, floor, (x, y, theta)"),
    "drift_ratio": ("1", "inter-storey drift / storey height at the centre of mass (floor 1 vs base)",
                    "time, storey, (x, y)"),
    "isolation_force": ("N, N, N*m", "bearing forces at the base centre of mass", "time, (x, y, theta)"),
    "device_force_total": ("N, N, N*m", "device forces at the base centre of mass", "time, (x, y, theta)"),
    "base_shear": ("N, N, N*m", "isolation-level force: bearings + devices", "time, (x, y, theta)"),
    "structure_shear": ("N, N, N*m", "first-storey shear R^T (K u_s + C u_s')", "time, (x, y, theta)"),
    "bearing_force": ("N", "total force of each bearing", "time, bearing, (x, y)"),
    "bearing_displacement": ("m", "displacement of each bearing", "time, bearing, (x, y)"),
    "bearing_state": ("1", "internal (hysteretic) states of each bearing", "time, bearing, state"),
    "device_displacement": ("m", "stroke of each device along its direction", "time, device"),
    "device_velocity": ("m/s", "velocity of each device along its direction", "time, device"),
    "device_force": ("N", "force of each device along its direction", "time, device"),
    "device_state": ("1", "internal states of each device", "time, device, state"),
    "voltage": ("V", "command voltage of each device", "time, device"),
    "measurements": ("SI", "measurement vector at the control steps (benchmark.simulator.sensors order)",
                     "control step, measurement"),
    "control_time": ("s", "times of the control steps", "control step"),
    "desired_force": ("N", "desired device forces of the controller at the control steps",
                      "control step, device"),
    "ground_acceleration": ("m/s^2", "ground acceleration (record, oriented)", "time, (x, y)"),
    "iterations": ("1", "fixed-point iterations of each structural step", "time"),
    "state": ("m, rad, m/s, rad/s", "state of the stepping kernel [q, u_b, q', u_b'] "
              "(benchmark.simulator.linear_model ordering)", "time, state"),
}
_ENERGY_DESCRIPTIONS = {
    "input": "input energy", "kinetic": "kinetic energy", "strain": "elastic strain energy",
    "damping": "energy dissipated by viscous damping", "hysteretic": "energy dissipated by the bearings' hysteresis",
    "device": "energy dissipated by the devices",
}


@dataclass
class StoredResult:
    """A run read back from a result file: the fields of a SimulationResult (SI).

    Attributes
    ----------
    arrays : dict
        Every time history by field name (also reachable as attributes: ``r.base_displacement``).
    energy : dict
        Energy terms [J].
    info : dict
        The run's ``info`` dict (record, orientation, isolation, controller, settings).
    units : dict
        Field -> units string as stored.
    attrs : dict
        The file's root attributes (provenance, ...).
    peak_record : dict
        The peaks stored in the file under their ``peak_*`` names (SI), if any
        (:meth:`benchmark.simulator.peaks.Peaks.as_record` of the run when written). ``r.peaks``
        computes :class:`~benchmark.simulator.peaks.Peaks` from the histories read back.
    """

    arrays: dict[str, np.ndarray] = field(default_factory=dict)
    energy: dict[str, np.ndarray] = field(default_factory=dict)
    info: dict[str, Any] = field(default_factory=dict)
    units: dict[str, str] = field(default_factory=dict)
    attrs: dict[str, Any] = field(default_factory=dict)
    peak_record: dict[str, float] = field(default_factory=dict)

    @property
    def peaks(self) -> Peaks:
        """Named peaks of the histories read back (:func:`benchmark.simulator.peaks.peaks_of`)."""
        return peaks_of(self)

    def __getattr__(self, name: str) -> np.ndarray:
        arrays = self.__dict__.get("arrays", {})
        if name in arrays:
            return arrays[name]
        raise AttributeError(name)


def _result_items(result: Any) -> dict[str, Any]:
    if dataclasses.is_dataclass(result):
        return {f.name: getattr(result, f.name) for f in dataclasses.fields(result)}
    if isinstance(result, StoredResult):
        out = dict(result.arrays)
        out.update(energy=result.energy, info=result.info)
        return out
    return dict(vars(result))


def _json_default(obj: Any) -> Any:
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (np.floating,)):
        return float(obj)
    if isinstance(obj, Path):
        return str(obj)
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: getattr(obj, f.name) for f in dataclasses.fields(obj)}
    return repr(obj)


#: storage precision -> numpy type of the float histories (:func:`write_result`)
_PRECISIONS = {"double": np.float64, "single": np.float32}


def _write_run(group: Any, result: Any, dtype: Any = np.float64) -> None:
    items = _result_items(result)
    th = group.create_group("time_histories")
    n = None
    for name, value in items.items():
        if name in ("energy", "info") or value is None or isinstance(value, (str, bytes, dict)):
            continue
        arr = np.asarray(value)
        if arr.dtype.kind not in "fiub" or arr.ndim == 0:
            continue
        if name == "t":
            n = arr.shape[0]
        elif arr.dtype.kind == "f":
            arr = arr.astype(dtype, copy=False)
        units, description, axes = FIELD_UNITS.get(
            name, ("SI", "field not in the results schema (see benchmark.simulator.simulation)", ""))
        kwargs = {"compression": "gzip", "compression_opts": 4, "shuffle": True} if arr.size > 4096 else {}
        ds = th.create_dataset(name, data=arr, **kwargs)
        ds.attrs["units"] = units
        ds.attrs["description"] = description
        ds.attrs["axes"] = axes
    if n is None:
        raise InputError("write_result: the result has no time vector 't'; expected a SimulationResult")
    energy = items.get("energy") or {}
    eg = group.create_group("energy")
    for term, values in energy.items():
        ds = eg.create_dataset(term, data=np.asarray(values, dtype=dtype))
        ds.attrs["units"] = "J"
        ds.attrs["description"] = _ENERGY_DESCRIPTIONS.get(term, term)
    info = items.get("info") or {}
    group.attrs["info_json"] = json.dumps(info, default=_json_default)
    try:
        pk = peaks_of(result).as_record()
    except InputError:
        pk = {}
    pg = group.create_group("peaks")
    for key, value in pk.items():
        pg.attrs[key] = value
        pg.attrs[f"{key}_units"] = PEAK_UNITS[key]


def write_result(result: Any, path: str | os.PathLike, *, reference: Any = None,
                 evaluation: dict[str, float | None] | None = None, isolation: Any = None,
                 precision: str = "double", **extra: object) -> Path:
    """Write a run (and optionally its reference run and J1–J9) to an HDF5 file, atomically.

    Parameters
    ----------
    result : SimulationResult
        The run (all fields SI).
    path : path-like
        Destination ``.h5`` file (its directory is created if needed).
    reference : SimulationResult, optional
        The uncontrolled reference run, stored under ``/reference``.
    evaluation : dict, optional
        J1–J9 (:func:`benchmark.simulator.evaluation.evaluate`), stored as attributes of ``/evaluation``.
    isolation : IsolationLayer, optional
        Stored as JSON (``isolation_json``) so the file documents the bearing parameters.
    precision : {"double", "single"}
        Storage type of the float histories and energies (the time vector stays float64);
        ``"single"`` halves the file (module docstring). Peaks and J's are computed before
        storing, in double precision, either way.
    **extra
        Further root attributes (converted to ``str``), e.g. ``record_source``.

    Returns
    -------
    Path
        The destination.
    """
    import h5py


    if precision not in _PRECISIONS:
        raise InputError(f"write_result: precision {precision!r} unknown; expected one of "
                         f"{', '.join(_PRECISIONS)}")
    dtype = _PRECISIONS[precision]
    path = Path(path)
    info = _result_items(result).get("info") or {}
    attrs = provenance(**extra)
    for key in ("record", "orientation", "isolation", "controller"):
        if key in info:
            attrs[key] = str(info[key])
    # the time grid of the histories and the record's own step, in s (the record is interpolated
    # onto the integration step when they differ)
    for key in ("record_step", "integration_step"):
        if key in info:
            attrs[f"{key}_s"] = str(info[key])
    with atomic_path(path) as tmp:
        with h5py.File(tmp, "w") as f:
            f.attrs["format"] = FORMAT_NAME
            f.attrs["format_version"] = FORMAT_VERSION
            f.attrs["precision"] = precision
            for key, value in attrs.items():
                f.attrs[key] = value
            if isolation is not None:
                f.attrs["isolation_json"] = (isolation.to_json() if hasattr(isolation, "to_json")
                                             else json.dumps(isolation, default=_json_default))
            _write_run(f.create_group("run"), result, dtype)
            if reference is not None:
                _write_run(f.create_group("reference"), reference, dtype)
            if evaluation is not None:
                eg = f.create_group("evaluation")
                for key, value in evaluation.items():
                    eg.attrs[key] = np.nan if value is None else float(value)
                    if key in J_DESCRIPTIONS:
                        eg.attrs[f"{key}_description"] = J_DESCRIPTIONS[key]
                        eg.attrs[f"{key}_formula"] = CRITERIA[key].formula
                        eg.attrs[f"{key}_source"] = CRITERIA[key].source
    return path


def _open(path: str | os.PathLike):
    import h5py

    path = Path(path)
    if not path.is_file():
        raise DataNotFoundError(f"result file {path} not found")
    try:
        f = h5py.File(path, "r")
    except OSError as exc:
        raise InputError(f"{path}: not an HDF5 file ({exc})") from None
    fmt = _attr(f.attrs.get("format"))
    if fmt != FORMAT_NAME:
        f.close()
        raise InputError(f"{path}: attribute 'format' is {fmt!r}; expected "
                         f"{FORMAT_NAME!r} (a file written by sbib)")
    return f


def _attr(value: Any) -> Any:
    if isinstance(value, bytes):
        return value.decode()
    if isinstance(value, np.generic):
        return value.item()
    return value


def _as_float64(value: np.ndarray) -> np.ndarray:
    # single-precision files are read back as float64, as every computation expects
    return value.astype(np.float64) if value.dtype == np.float32 else value


def read_result(path: str | os.PathLike, which: str = "run") -> StoredResult:
    """Read a run (``which="run"``) or its reference run (``"reference"``) from a result file.

    Parameters
    ----------
    path : path-like
        A file written by :func:`write_result`.
    which : {"run", "reference"}

    Raises
    ------
    DataNotFoundError
        If the file is absent.
    InputError
        If it is not an sbib result file or lacks the requested group.
    """
    with _open(path) as f:
        if which not in f:
            raise InputError(f"{path}: no group '/{which}'; expected one of "
                             f"{', '.join(k for k in f.keys() if k in ('run', 'reference'))}")
        g = f[which]
        out = StoredResult()
        for name, ds in g["time_histories"].items():
            out.arrays[name] = _as_float64(ds[()])
            out.units[name] = _attr(ds.attrs.get("units", ""))
        for name, ds in g["energy"].items():
            out.energy[name] = _as_float64(ds[()])
        out.info = json.loads(_attr(g.attrs.get("info_json", "{}")))
        if "peaks" in g:
            out.peak_record = {k: _attr(v) for k, v in g["peaks"].attrs.items() if not k.endswith("_units")}
        out.attrs = {k: _attr(v) for k, v in f.attrs.items()}
    return out


def read_evaluation(path: str | os.PathLike) -> dict[str, float | None]:
    """J1–J9 stored in the result file ``path`` (``None`` where undefined); empty if none were stored."""
    with _open(path) as f:
        if "evaluation" not in f:
            return {}
        out: dict[str, float | None] = {}
        for key, value in f["evaluation"].attrs.items():
            if key.endswith(("_description", "_formula", "_source")):
                continue
            v = float(value)
            out[key] = None if np.isnan(v) else v
        return dict(sorted(out.items(), key=lambda kv: int(kv[0][1:]) if kv[0][1:].isdigit() else 99))
