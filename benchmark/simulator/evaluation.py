r"""Evaluation criteria J1–J9 of the smart base-isolated benchmark, peaks and corner responses.

Every response is taken as the x–y resultant :math:`\|\cdot\|` at the centre of mass (of the
base, or of each floor), over the whole record. For a run (controlled) and the reference run
(same building and isolation, **no devices**, same record and orientation):

========  ==========================================================================  ============
J1        peak base shear :math:`\max_t \|V_0(t)\|`, the isolation-level force          ratio to ref.
          (bearings + devices, ``base_shear``)
J2        peak structure shear :math:`\max_t \|V_1(t)\|`, first storey,                  ratio to ref.
          :math:`R^T(K u_s + C \dot u_s)` (``structure_shear``)
J3        peak base displacement :math:`\max_t \|u_b(t)\|` (``base_displacement``)       ratio to ref.
J4        peak inter-storey drift ratio :math:`\max_{t,f} \|d_f(t)\| / h_f`             ratio to ref.
          (``drift_ratio``; floor 1 relative to the base)
J5        peak absolute floor acceleration :math:`\max_{t,f} \|a_f(t)\|`,                ratio to ref.
          every floor, 1–8 in the benchmark (``floor_acceleration_absolute``)
J6        peak total device force over the **controlled** peak base shear,             own run
          :math:`\max_t \|\sum_j f_{d,j}(t)\| / \max_t \|V_0(t)\|`
J7        RMS base displacement :math:`\sqrt{\overline{\|u_b\|^2}}`                      ratio to ref.
J8        RMS absolute floor acceleration, largest floor,                              ratio to ref.
          :math:`\max_f \sqrt{\overline{\|a_f\|^2}}`
J9        energy dissipated by the devices over the input energy at the end of the     own run
          record, :math:`E_d(T) / E_\mathrm{in}(T)` (``energy["device"]``,
          ``energy["input"]``)
========  ==========================================================================  ============

The definitions (name, formula, source, the project's own choices) live in one table,
:data:`benchmark.simulator.criteria.CRITERIA`, which every table, figure and JSON showing J's uses; the
prose is docs/criteria.md. This follows Narasimhan et al. (2006, Part I, section "Evaluation criteria"): J1–J5 peak
responses, J6 peak control force, J7–J8 RMS responses, J9 control energy. The project marks
the numbering of J6 and J9 as unverified; the project **chooses** the assignment above and
keeps it fixed. J6 and J9 are not ratios to the reference run (the reference has no devices);
they are ``None`` for a run without devices. A ratio whose reference value is zero is ``None``.

The un-normalised values are :class:`benchmark.simulator.peaks.Peaks`, computed by
:func:`benchmark.simulator.peaks.peaks_of` (the only place peaks are computed; ``device_force`` is
the peak of the resultant *total* device force, the numerator of J6). :func:`corner_responses` adds the responses at the outer corners of the
plan, where torsion makes them largest (the floors are assumed to share the base's plan).

References
----------
Narasimhan S., Nagarajaiah S., Johnson E.A., Gavin H.P. (2006) Smart base-isolated benchmark
building. Part I: problem definition. Struct. Control Health Monit. 13:573–588.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from benchmark.foundation.errors import InputError
from benchmark.simulator.structure import load_superstructure
from benchmark.simulator.criteria import CRITERIA
from benchmark.simulator.criteria import J_NAMES as _CRITERIA_NAMES
from benchmark.simulator.peaks import PEAK_NAMES, PEAK_UNITS, n_devices, peaks_of, result_array

__all__ = ["evaluate", "corner_responses", "plan_corners", "PEAK_NAMES", "PEAK_UNITS",
           "J_NAMES", "J_DESCRIPTIONS"]

#: J1..J9 and their one-line descriptions, from the single definition table benchmark.simulator.criteria
J_NAMES: tuple[str, ...] = _CRITERIA_NAMES
J_DESCRIPTIONS: dict[str, str] = {k: c.description for k, c in CRITERIA.items()}


def _ratio(a: float, b: float) -> float | None:
    return float(a / b) if b > 0.0 and np.isfinite(a) and np.isfinite(b) else None


def _check_same_case(result: Any, reference: Any) -> None:
    info_r = getattr(result, "info", {}) or {}
    info_0 = getattr(reference, "info", {}) or {}
    for key in ("record", "orientation", "isolation"):
        if key in info_r and key in info_0 and str(info_r[key]) != str(info_0[key]):
            raise InputError(f"evaluate: result and reference differ in {key} "
                             f"({info_r[key]!r} vs {info_0[key]!r}); expected the same {key}")
    t_r = np.asarray(getattr(result, "t", []))
    t_0 = np.asarray(getattr(reference, "t", []))
    if t_r.shape != t_0.shape:
        raise InputError(f"evaluate: result has {t_r.size} samples, reference {t_0.size}; "
                         "expected runs of the same record")


def evaluate(result: Any, reference: Any) -> dict[str, float | None]:
    """Evaluation criteria J1–J9 of ``result`` against the uncontrolled ``reference`` run.

    Parameters
    ----------
    result : SimulationResult
        The controlled run.
    reference : SimulationResult
        The uncontrolled run: same building and isolation, no devices, same record and
        orientation (checked on ``info`` where both carry it, and on the sample count).

    Returns
    -------
    dict
        ``{"J1": ..., ..., "J9": ...}`` (definitions in the module docstring); ``None`` where
        undefined (J6, J9 without devices; a zero reference value).

    Raises
    ------
    InputError
        If the runs are not of the same record, orientation and isolation.
    """
    _check_same_case(result, reference)
    p = peaks_of(result)
    p0 = peaks_of(reference)
    J: dict[str, float | None] = {
        "J1": _ratio(p.base_shear, p0.base_shear),
        "J2": _ratio(p.structure_shear, p0.structure_shear),
        "J3": _ratio(p.base_displacement, p0.base_displacement),
        "J4": _ratio(p.drift_ratio, p0.drift_ratio),
        "J5": _ratio(p.floor_acceleration, p0.floor_acceleration),
        "J6": None,
        "J7": _ratio(p.rms_base_displacement, p0.rms_base_displacement),
        "J8": _ratio(p.rms_floor_acceleration, p0.rms_floor_acceleration),
        "J9": None,
    }
    if n_devices(result):
        J["J6"] = _ratio(p.device_force, p.base_shear)
        energy = getattr(result, "energy", None) or {}
        if "device" in energy and "input" in energy:
            e_dev = np.asarray(energy["device"], dtype=float)
            e_in = np.asarray(energy["input"], dtype=float)
            if e_dev.size and e_in.size:
                J["J9"] = _ratio(float(e_dev[-1]), float(e_in[-1]))
    return J


def plan_corners(plan_xy: np.ndarray) -> np.ndarray:
    """Outer corners of a plan: the convex-hull vertices of the points ``plan_xy`` (n, 2) [m].

    For the benchmark's bearing positions these are the five outer corners of the L-shaped
    plan, (−17.25, 30.69), (−17.25, −47.79), (12.53, −47.79), (32.83, −11.16), (32.83, 30.69) m.

    Parameters
    ----------
    plan_xy : np.ndarray
        Plan points (n, 2) [m].
    """
    from scipy.spatial import ConvexHull

    plan_xy = np.asarray(plan_xy, dtype=float)
    if plan_xy.ndim != 2 or plan_xy.shape[1] != 2 or plan_xy.shape[0] < 3:
        raise InputError(f"plan_corners: expected an (n >= 3, 2) array of plan positions, got shape {plan_xy.shape}")
    try:
        return plan_xy[ConvexHull(plan_xy).vertices]
    except Exception as exc:  # scipy's QhullError: coincident or collinear points
        raise InputError(f"plan_corners: the plan positions span no area ({type(exc).__name__}); "
                         "expected points of a plan, not all on one line") from None


def corner_responses(result: Any, corners: np.ndarray | None = None,
                     storey_heights: np.ndarray | None = None) -> dict[str, Any]:
    r"""Peak responses at plan corners (torsion makes them exceed the centre-of-mass values).

    A point (x, y) of a rigid floor (or of the base) moves by :math:`T u` with
    :math:`T = [[1, 0, -y], [0, 1, x]]` (small rotations).

    Parameters
    ----------
    result : SimulationResult
    corners : (n_c, 2) array, optional
        Plan positions [m] relative to the centre of mass; default the outer corners of the
        benchmark plan (:func:`plan_corners` of the bearing positions, read from the structure
        file).
    storey_heights : (8,) array, optional
        Storey heights [m]; default from the structure file.

    Returns
    -------
    dict
        ``corners`` (n_c, 2) [m]; ``peak_corner_base_displacement`` (n_c,) [m] resultant per
        corner; ``peak_corner_drift_ratio`` (n_c,) [-] largest over floors; and the maxima over
        corners ``max_corner_base_displacement`` [m], ``max_corner_drift_ratio`` [-].
    """
    if corners is None or storey_heights is None:
        s = load_superstructure()
        corners = plan_corners(s.bearing_xy) if corners is None else corners
        storey_heights = s.storey_heights if storey_heights is None else storey_heights
    corners = np.asarray(corners, dtype=float).reshape(-1, 2)
    h = np.asarray(storey_heights, dtype=float)
    ub = result_array(result, "base_displacement", 2)          # (n, 3)
    us = result_array(result, "floor_displacement", 3)         # (n, 8, 3), relative to the base
    if us.shape[1] != h.size:
        raise InputError(f"corner_responses: {us.shape[1]} floors but {h.size} storey heights")
    cx, cy = corners[:, 0], corners[:, 1]
    # base corners: (n, n_c)
    bx = ub[:, 0:1] - ub[:, 2:3] * cy
    by = ub[:, 1:2] + ub[:, 2:3] * cx
    peak_base = np.max(np.hypot(bx, by), axis=0) if ub.shape[0] else np.zeros(corners.shape[0])
    # storey drifts at the corners: floor f relative to floor f-1 (floor 0 = base)
    below = np.concatenate([np.zeros_like(us[:, :1]), us[:, :-1]], axis=1)
    d = us - below                                           # (n, 8, 3)
    dx = d[:, :, 0:1] - d[:, :, 2:3] * cy                    # (n, 8, n_c)
    dy = d[:, :, 1:2] + d[:, :, 2:3] * cx
    ratio = np.hypot(dx, dy) / h[None, :, None]
    peak_drift = np.max(ratio, axis=(0, 1)) if us.shape[0] else np.zeros(corners.shape[0])
    return {
        "corners": corners,
        "peak_corner_base_displacement": peak_base,
        "peak_corner_drift_ratio": peak_drift,
        "max_corner_base_displacement": float(np.max(peak_base)) if peak_base.size else 0.0,
        "max_corner_drift_ratio": float(np.max(peak_drift)) if peak_drift.size else 0.0,
    }
