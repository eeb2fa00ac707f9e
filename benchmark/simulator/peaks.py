"""Named peak responses of one run, with units: :class:`Peaks`, computed in one place, :func:`peaks_of`.

A :class:`~benchmark.simulator.simulation.SimulationResult` stores time histories whose last axis mixes
directions: ``base_displacement`` is (n, 3) with columns x [m], y [m] and θ [rad], so
``result.base_displacement.max()`` is the largest signed value over three different quantities,
not a peak displacement. :class:`Peaks` names each peak once, in SI units, as the benchmark's
evaluation criteria define it (Narasimhan et al. 2006, Part I, "Evaluation criteria": the
x–y resultant :math:`\\max_t \\|u(t)\\|` at the centre of mass). The resultant peaks are the
numerators of J1–J8 (:func:`benchmark.simulator.evaluation.evaluate` takes them from here); the
per-direction peaks (``*_x``, ``*_y``, ``base_rotation``, ``base_torque``) are given beside them for
reading, never mixed in.

:func:`peaks_of` is the only place peaks are computed: for a run of
:func:`~benchmark.simulator.simulation.simulate`, a run read back by
:func:`benchmark.simulator.results.read_result`, and the ``solve_ivp`` oracle's
:class:`~benchmark.simulator.oracle.OracleResult` (same attribute names). Files (``sbib run --json``,
the HDF5 ``/run/peaks`` attrs, ensemble datasets) keep their ``peak_*`` names; the mapping is
:data:`PEAK_RECORD_KEYS`, used through :meth:`Peaks.as_record`.

References
----------
Narasimhan S., Nagarajaiah S., Johnson E.A., Gavin H.P. (2006) Smart base-isolated benchmark
building. Part I: problem definition. Struct. Control Health Monit. 13:573–588.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields
from typing import Any

import numpy as np

from benchmark.foundation.errors import InputError

__all__ = ["Peaks", "peaks_of", "PEAK_FIELD_UNITS", "PEAK_RECORD_KEYS", "PEAK_NAMES", "PEAK_UNITS"]

#: SI unit and meaning of every :class:`Peaks` field
PEAK_FIELD_UNITS: dict[str, tuple[str, str]] = {
    "base_displacement": ("m", "peak x–y resultant base displacement (J3's numerator)"),
    "base_displacement_x": ("m", "peak |x| base displacement"),
    "base_displacement_y": ("m", "peak |y| base displacement"),
    "base_rotation": ("rad", "peak |θ| base rotation"),
    "rms_base_displacement": ("m", "RMS x–y resultant base displacement (J7's numerator)"),
    "drift_ratio": ("1", "peak x–y resultant inter-storey drift / storey height, any storey (J4)"),
    "floor_acceleration": ("m/s^2", "peak x–y resultant absolute floor acceleration, every floor (J5)"),
    "rms_floor_acceleration": ("m/s^2", "RMS x–y resultant absolute floor acceleration, largest floor (J8)"),
    "base_shear": ("N", "peak x–y resultant isolation-level force, bearings + devices (J1)"),
    "base_torque": ("N*m", "peak |torque| of the isolation-level force about the base centre of mass"),
    "structure_shear": ("N", "peak x–y resultant first-storey shear (J2)"),
    "device_force": ("N", "peak x–y resultant total device force (J6's numerator); 0 without devices"),
    "single_device_force": ("N", "peak |force| of any one device; 0 without devices"),
}

#: :class:`Peaks` field -> its key in files (``sbib run --json`` ``peaks``, HDF5 ``/run/peaks``
#: attrs, ensemble datasets), in the files' order. The one place these names are defined.
PEAK_RECORD_KEYS: dict[str, str] = {
    "base_shear": "peak_base_shear",
    "structure_shear": "peak_structure_shear",
    "base_displacement": "peak_base_displacement",
    "drift_ratio": "peak_drift_ratio",
    "floor_acceleration": "peak_floor_acceleration",
    "rms_base_displacement": "rms_base_displacement",
    "rms_floor_acceleration": "rms_floor_acceleration",
    "device_force": "peak_device_force",
}
#: the file keys of :meth:`Peaks.as_record`, in order
PEAK_NAMES: tuple[str, ...] = tuple(PEAK_RECORD_KEYS.values())
#: SI unit of each file key
PEAK_UNITS: dict[str, str] = {key: PEAK_FIELD_UNITS[name][0] for name, key in PEAK_RECORD_KEYS.items()}


@dataclass(frozen=True)
class Peaks:
    """Peak and RMS responses of one run, SI units (see :data:`PEAK_FIELD_UNITS`).

    Attributes
    ----------
    base_displacement, base_displacement_x, base_displacement_y : float
        Peak base displacement at the centre of mass [m]: x–y resultant, and \\|x\\|, \\|y\\|.
    base_rotation : float
        Peak \\|θ\\| of the base [rad].
    rms_base_displacement : float
        RMS of the x–y resultant base displacement [m].
    drift_ratio : float
        Peak inter-storey drift ratio, x–y resultant, largest storey [-].
    floor_acceleration, rms_floor_acceleration : float
        Peak and RMS (largest floor) x–y resultant absolute floor acceleration [m/s²].
    base_shear, structure_shear : float
        Peak x–y resultant base shear (bearings + devices) and first-storey shear [N].
    base_torque : float
        Peak \\|torque\\| of the isolation-level force about the base centre of mass [N·m].
    device_force, single_device_force : float
        Peak x–y resultant total device force, and peak force of any single device [N].
    """

    base_displacement: float
    base_displacement_x: float
    base_displacement_y: float
    base_rotation: float
    rms_base_displacement: float
    drift_ratio: float
    floor_acceleration: float
    rms_floor_acceleration: float
    base_shear: float
    base_torque: float
    structure_shear: float
    device_force: float
    single_device_force: float

    @property
    def units(self) -> dict[str, str]:
        """SI unit of every field (``"1"`` for a ratio)."""
        return {name: unit for name, (unit, _) in PEAK_FIELD_UNITS.items()}

    def as_dict(self) -> dict[str, float]:
        """The fields as a plain ``{name: value}`` dict (SI)."""
        return asdict(self)

    def as_record(self) -> dict[str, float]:
        """The peaks written to files, under their file keys (:data:`PEAK_RECORD_KEYS`), SI."""
        return {key: getattr(self, name) for name, key in PEAK_RECORD_KEYS.items()}

    def relative_differences(self, reference: "Peaks") -> dict[str, float]:
        """``self / reference - 1`` for every field (0 where both are 0, inf where only the
        reference is): how far two runs of one case agree, e.g. the kernel against the oracle.

        Parameters
        ----------
        reference : Peaks
            The peaks compared with.

        Returns
        -------
        dict
            Field name -> relative difference [-].
        """
        out = {}
        for f in fields(self):
            a, b = getattr(self, f.name), getattr(reference, f.name)
            out[f.name] = a / b - 1.0 if b else (0.0 if a == b else float("inf"))
        return out

    def __str__(self) -> str:
        width = max(len(f.name) for f in fields(self))
        return "\n".join(f"{f.name:<{width}}  {getattr(self, f.name):.6g} {PEAK_FIELD_UNITS[f.name][0]}"
                         for f in fields(self))


def result_array(result: Any, name: str, ndim: int) -> np.ndarray:
    """Field ``name`` of ``result`` as a float array of ``ndim`` dimensions (:class:`InputError` if not).

    Parameters
    ----------
    result : object
        A run (any object with the field).
    name : str
        The field.
    ndim : int
        Its expected number of dimensions.
    """
    try:
        value = np.asarray(getattr(result, name), dtype=float)
    except AttributeError:
        raise InputError(f"result has no field {name!r}; expected a SimulationResult") from None
    if value.ndim != ndim:
        raise InputError(f"result.{name} has shape {value.shape}; expected {ndim} dimensions")
    return value


def _resultant(a: np.ndarray) -> np.ndarray:
    """x–y resultant of the last axis' first two components."""
    return np.hypot(a[..., 0], a[..., 1])


def _peak(a: np.ndarray) -> float:
    return float(np.max(a)) if a.size else 0.0


def _rms_time(a: np.ndarray) -> np.ndarray:
    """RMS over time (axis 0) of a resultant array."""
    return np.sqrt(np.mean(a * a, axis=0)) if a.shape[0] else np.zeros(a.shape[1:])


def _abs_peak(a: np.ndarray, column: int | None = None) -> float:
    if column is not None:
        a = a[..., column] if a.ndim >= 2 and a.shape[-1] > column else np.zeros(0)
    return float(np.max(np.abs(a))) if a.size else 0.0


def n_devices(result: Any) -> int:
    """Number of devices of ``result`` (columns of ``device_force``; 0 without devices).

    Parameters
    ----------
    result : object
        A run.
    """
    df = getattr(result, "device_force", None)
    if df is None:
        return 0
    df = np.asarray(df)
    return int(df.shape[1]) if df.ndim == 2 else 0


def peaks_of(result: Any) -> Peaks:
    """Named peaks of ``result``, SI.

    Parameters
    ----------
    result : SimulationResult
        A run of :func:`~benchmark.simulator.simulation.simulate`, a run read back by
        :func:`benchmark.simulator.results.read_result`, or an
        :class:`~benchmark.simulator.oracle.OracleResult`: anything with ``base_displacement``,
        ``base_shear``, ``structure_shear`` (n, 3), ``drift_ratio`` (n, 8, 2),
        ``floor_acceleration_absolute`` (n, 8, ≥2), and, with devices, ``device_force``
        (n, n_devices) and ``device_force_total`` (n, ≥2).

    Returns
    -------
    Peaks

    Raises
    ------
    InputError
        If ``result`` lacks a field or a field has the wrong number of dimensions.
    """
    shear_xyz = result_array(result, "base_shear", 2)
    ub_xyz = result_array(result, "base_displacement", 2)
    base_shear = _resultant(shear_xyz)
    structure_shear = _resultant(result_array(result, "structure_shear", 2))
    ub = _resultant(ub_xyz)
    drift = _resultant(result_array(result, "drift_ratio", 3))
    acc = _resultant(result_array(result, "floor_acceleration_absolute", 3))
    if n_devices(result):
        device_total = _resultant(result_array(result, "device_force_total", 2))
        single = _abs_peak(np.asarray(result.device_force, dtype=float))
    else:
        device_total, single = np.zeros(0), 0.0
    return Peaks(
        base_displacement=_peak(ub),
        base_displacement_x=_abs_peak(ub_xyz, 0),
        base_displacement_y=_abs_peak(ub_xyz, 1),
        base_rotation=_abs_peak(ub_xyz, 2),
        rms_base_displacement=float(_rms_time(ub)) if ub.size else 0.0,
        drift_ratio=_peak(drift),
        floor_acceleration=_peak(acc),
        rms_floor_acceleration=_peak(_rms_time(acc)),
        base_shear=_peak(base_shear),
        base_torque=_abs_peak(shear_xyz, 2),
        structure_shear=_peak(structure_shear),
        device_force=_peak(device_total),
        single_device_force=single,
    )
