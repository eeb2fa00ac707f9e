"""Named peak responses of one run, with units: what ``result.peaks`` returns.

A :class:`~benchmark.simulator.simulation.SimulationResult` stores time histories whose last axis mixes
directions: ``base_displacement`` is (n, 3) with columns x [m], y [m] and θ [rad], so
``result.base_displacement.max()`` is the largest signed value over three different quantities,
not a peak displacement. :class:`Peaks` names each peak once, in SI units, as the benchmark's
evaluation criteria define it (Narasimhan et al. 2006, Part I, "Evaluation criteria": the
x–y resultant :math:`\\max_t \\|u(t)\\|` at the centre of mass). The resultant peaks are the
numerators of J1–J8 and equal :func:`benchmark.simulator.evaluation.peaks`; the per-direction peaks
(``*_x``, ``*_y``, ``base_rotation``) are given beside them for reading, never mixed in.

References
----------
Narasimhan S., Nagarajaiah S., Johnson E.A., Gavin H.P. (2006) Smart base-isolated benchmark
building. Part I: problem definition. Struct. Control Health Monit. 13:573–588.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields
from typing import Any

import numpy as np

from benchmark.simulator.evaluation import peaks as _peaks

__all__ = ["Peaks", "peaks_of", "PEAK_FIELD_UNITS"]

#: SI unit and meaning of every :class:`Peaks` field
PEAK_FIELD_UNITS: dict[str, tuple[str, str]] = {
    "base_displacement": ("m", "peak x–y resultant base displacement (J3's numerator)"),
    "base_displacement_x": ("m", "peak |x| base displacement"),
    "base_displacement_y": ("m", "peak |y| base displacement"),
    "base_rotation": ("rad", "peak |θ| base rotation"),
    "rms_base_displacement": ("m", "RMS x–y resultant base displacement (J7's numerator)"),
    "drift_ratio": ("1", "peak x–y resultant inter-storey drift / storey height, any storey (J4)"),
    "floor_acceleration": ("m/s^2", "peak x–y resultant absolute floor acceleration, floors 1–8 (J5)"),
    "rms_floor_acceleration": ("m/s^2", "RMS x–y resultant absolute floor acceleration, largest floor (J8)"),
    "base_shear": ("N", "peak x–y resultant isolation-level force, bearings + devices (J1)"),
    "structure_shear": ("N", "peak x–y resultant first-storey shear (J2)"),
    "device_force": ("N", "peak x–y resultant total device force (J6's numerator); 0 without devices"),
    "single_device_force": ("N", "peak |force| of any one device; 0 without devices"),
}


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

    def __str__(self) -> str:
        width = max(len(f.name) for f in fields(self))
        return "\n".join(f"{f.name:<{width}}  {getattr(self, f.name):.6g} {PEAK_FIELD_UNITS[f.name][0]}"
                         for f in fields(self))


def _abs_peak(a: Any, column: int | None = None) -> float:
    a = np.asarray(a, dtype=float)
    if column is not None:
        a = a[..., column] if a.ndim >= 2 and a.shape[-1] > column else np.zeros(0)
    return float(np.max(np.abs(a))) if a.size else 0.0


def peaks_of(result: Any) -> Peaks:
    """Named peaks of ``result`` (a :class:`~benchmark.simulator.simulation.SimulationResult`, or a run
    read back by :func:`benchmark.simulator.results.read_result`).

    The resultant peaks are those of :func:`benchmark.simulator.evaluation.peaks` (the numerators of the
    J's), so ``peaks_of(r).base_displacement == evaluation.peaks(r)["peak_base_displacement"]``.

    Parameters
    ----------
    result : Any
        A simulation result, or a run holding one.

    Raises
    ------
    InputError
        If ``result`` lacks a field or a field has the wrong shape.
    """
    p = _peaks(result)
    ub = np.asarray(result.base_displacement, dtype=float)
    device_force = getattr(result, "device_force", None)
    return Peaks(
        base_displacement=p["peak_base_displacement"],
        base_displacement_x=_abs_peak(ub, 0),
        base_displacement_y=_abs_peak(ub, 1),
        base_rotation=_abs_peak(ub, 2),
        rms_base_displacement=p["rms_base_displacement"],
        drift_ratio=p["peak_drift_ratio"],
        floor_acceleration=p["peak_floor_acceleration"],
        rms_floor_acceleration=p["rms_floor_acceleration"],
        base_shear=p["peak_base_shear"],
        structure_shear=p["peak_structure_shear"],
        device_force=p["peak_device_force"],
        single_device_force=_abs_peak(device_force) if device_force is not None else 0.0,
    )
