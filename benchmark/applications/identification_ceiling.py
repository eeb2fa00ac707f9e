"""The structural ceiling: how well can each model form do at all on an earthquake's damper motion?

The earthquake validation (:mod:`~benchmark.applications.identification_validation`) compares the force of the
identified models with the device's. When the two models' errors come out close, the question
is whether the *identification* left accuracy on the table (test amplitudes, design points,
voltage laws) or whether the *model form* cannot do better. This module answers it:

1. the device is driven, in the virtual laboratory, along one damper's recorded displacement
   and velocity from an earthquake run, at a constant voltage (the two levels a bang-bang
   controller switches between, by default 0 and 1 V);
2. each identified model (voltage-dependent, from the periodic tests) is replayed on the same
   motion at that voltage: its error is what the identification achieved;
3. the same model form is then fitted by nonlinear least squares to this very motion, all its
   parameters free and started from the identified values: its error estimates the best the
   form can do on that motion (the "ceiling"; a local optimum within ``max_nfev`` evaluations,
   so an upper estimate of the true bound), which no identification from other tests can beat.

If the normalized and extended forms reach nearly the same ceiling, no identification procedure
can make one well below the other on that motion and voltage; if the identified error is far
above the ceiling, the identification (not the form) is what to improve.

The device is reached only through :func:`damper.lab.laboratory.general_test`. Errors are the
relative RMS force error over the whole motion (:func:`~damper.identification.metrics.relative_rms_error`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Sequence

import numpy as np

from benchmark.foundation.errors import InputError, NumericalError, ParameterError
from damper.identification.cycles import Cycle
from damper.identification.metrics import relative_rms_error
from damper.identification.refine import refine
from damper.models.response import simulate
from damper.lab.laboratory import general_test

__all__ = ["CeilingEntry", "structural_ceiling", "pick_damper", "DEFAULT_CEILING_VOLTAGES",
           "summarize_ceiling"]

#: The two voltages a bang-bang semi-active controller switches between [V].
DEFAULT_CEILING_VOLTAGES = (0.0, 1.0)


@dataclass(frozen=True)
class CeilingEntry:
    """One motion, voltage and model form.

    Attributes
    ----------
    record, orientation : str
        The earthquake run the motion comes from.
    damper : int
        Index of the damper whose motion drives the device.
    voltage : float
        Constant voltage of the test [V].
    model : str
        ``"normalized"`` or ``"extended"``.
    identified_error : float
        Relative RMS force error of the identified (periodic-test) model on this motion.
    best_error : float
        Relative RMS force error of the same form fitted to this motion (the ceiling).
    best_parameters : dict
        The fitted parameters (SI).
    note : str
        Why the fit fell back to the identified parameters, when it did (empty otherwise).
    """

    record: str
    orientation: str
    damper: int
    voltage: float
    model: str
    identified_error: float
    best_error: float
    best_parameters: dict
    note: str = ""

    def to_dict(self) -> dict:
        """The entry as a JSON-ready dict (field names as keys, SI values)."""
        return asdict(self)


def pick_damper(displacement: np.ndarray) -> int:
    """The damper with the largest RMS displacement (columns of ``displacement``).

    Parameters
    ----------
    displacement : np.ndarray
        Displacement histories [m], one column per damper.
    """
    x = np.asarray(displacement, dtype=float)
    if x.ndim != 2 or x.shape[1] == 0:
        raise InputError(f"displacement: expected (n_samples, n_devices), got shape {x.shape}")
    return int(np.argmax(np.sqrt(np.mean(x ** 2, axis=0))))


def _form(model) -> str:
    """The Bouc-Wen form of an identified model: ``"extended"`` when it has ``kappa_x``."""
    return "extended" if "kappa_x" in model.parameter_names else "normalized"


def structural_ceiling(device, t: np.ndarray, displacement: np.ndarray, velocity: np.ndarray,
                       identified: dict, voltages: Sequence[float] = DEFAULT_CEILING_VOLTAGES,
                       record: str = "", orientation: str = "", damper: int | None = None,
                       max_nfev: int = 100) -> list[CeilingEntry]:
    """Identified error and best-fit ceiling of each model form on one recorded damper motion.

    Parameters
    ----------
    device : damper model or str
        The device under test (reached through the virtual laboratory only).
    t : ndarray, shape (n,)
        Time [s].
    displacement, velocity : ndarray, shape (n,) or (n, n_devices)
        Recorded damper motion [m, m/s]; with several columns, ``damper`` picks one (default
        the one with the largest RMS displacement, :func:`pick_damper`).
    identified : dict
        ``name -> identified (voltage-dependent) normalized or extended Bouc-Wen model``; the
        same form is fitted for the ceiling.
    voltages : sequence of float
        Constant test voltages [V].
    record, orientation : str
        Labels of the run.
    damper : int, optional
        Column of ``displacement``/``velocity``.
    max_nfev : int
        Cap on model evaluations of each best fit.

    Returns
    -------
    list of CeilingEntry
        One per voltage and identified model, in that order.
    """

    t = np.asarray(t, dtype=float)
    x = np.asarray(displacement, dtype=float)
    xd = np.asarray(velocity, dtype=float)
    if x.shape != xd.shape:
        raise InputError(f"displacement and velocity must share a shape, got {x.shape} and {xd.shape}")
    if x.ndim == 2:
        d = pick_damper(x) if damper is None else int(damper)
        if not 0 <= d < x.shape[1]:
            raise InputError(f"damper: expected an index in [0, {x.shape[1]}), got {damper}")
        x, xd = x[:, d], xd[:, d]
    else:
        d = 0 if damper is None else int(damper)
    if t.ndim != 1 or t.size != x.size or t.size < 10:
        raise InputError(f"t: expected a 1-D time vector matching the motion ({x.size} samples), "
                         f"got shape {t.shape}")
    if not np.any(np.abs(x) > 0):
        raise InputError(f"{record} {orientation}: the damper does not move; no ceiling to measure")
    whole = [Cycle(0, t.size // 2, t.size - 1)]  # the whole motion is the fit window
    out = []
    for v in voltages:
        measured = general_test(device, t, x, float(v), xdot=xd).force
        for name, model in identified.items():
            form = _form(model)
            lo, hi = model.voltage_range
            vv = float(np.clip(v, lo, hi))
            predicted = simulate(model, t, x, xd, vv).force
            start = {"kappa_x": 0.0, **model.coefficients(vv)}
            identified_error = relative_rms_error(measured, predicted)
            note = ""
            try:
                best = refine(t, x, xd, measured, whole, start, model=form, max_nfev=max_nfev)
                candidate = (best.rel_rms_error, dict(best.parameters))
            except (NumericalError, ParameterError, InputError) as exc:
                candidate, note = (math.inf, {}), f"fit failed ({exc}); identified parameters kept"
            # The identified model is itself a member of the form: the ceiling is never above it.
            best_error, best_parameters = min(candidate, (identified_error, start), key=lambda p: p[0])
            out.append(CeilingEntry(record, orientation, d, float(v), name, identified_error,
                                    best_error, best_parameters, note))
    return out


def summarize_ceiling(entries: Sequence[CeilingEntry], pair: tuple[str, str] = ("normalized", "extended")
                      ) -> dict:
    """Per voltage: mean identified and best errors of each model, and the extended/normalized
    ratios of both over the motions (mean and range).

    Parameters
    ----------
    entries : Sequence[CeilingEntry]
        The ceiling entries of all runs.
    pair : tuple[str, str], optional
        The two model keys compared (``(normalized, extended)``).
    """
    nor, ext = pair
    out: dict = {}
    for v in sorted({e.voltage for e in entries}):
        at = [e for e in entries if e.voltage == v]
        entry: dict = {}
        for m in sorted({e.model for e in at}):
            sel = [e for e in at if e.model == m]
            entry[m] = {"mean_identified_error": float(np.mean([e.identified_error for e in sel])),
                        "mean_best_error": float(np.mean([e.best_error for e in sel])),
                        "n_motions": len(sel)}
        runs = {(e.record, e.orientation) for e in at}
        for kind in ("identified_error", "best_error"):
            ratios = []
            for r in sorted(runs):
                a = [getattr(e, kind) for e in at if (e.record, e.orientation) == r and e.model == ext]
                b = [getattr(e, kind) for e in at if (e.record, e.orientation) == r and e.model == nor]
                if a and b and b[0] > 0:
                    ratios.append(a[0] / b[0])
            if ratios:
                entry[f"{ext}_over_{nor}_{kind}"] = {"mean": float(np.mean(ratios)),
                                                     "min": float(np.min(ratios)),
                                                     "max": float(np.max(ratios))}
        out[f"{v:g} V"] = entry
    return out
