"""Identification of one constant-voltage periodic test: cycles → closed form → refinement → errors.

:func:`identify` chains the steps of Bahar et al. (2009, Sec. 3) for one test (a
:class:`damper.io.data.DamperTest` from the virtual laboratory or a file):

1. detect the cycles and wait for the limit cycle (:mod:`~damper.identification.cycles`);
2. average the loading and unloading branches and compute the closed-form parameters, checking
   the excitation (:mod:`~damper.identification.closed_form`);
3. refine all parameters jointly by nonlinear least squares, with uncertainty
   (:mod:`~damper.identification.refine`);
4. report the force errors of the fitted model over the steady cycles
   (:mod:`~damper.identification.metrics`).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np

from benchmark.foundation.errors import InputError
from damper.identification.closed_form import ClosedFormResult, closed_form
from damper.identification.cycles import (MIN_RHO_STROKE, Branches, Cycle, average_branches,
                                          check_excitation,
                                          detect_cycles, steady_cycles)
from damper.identification.metrics import force_errors
from damper.identification.refine import RefinedFit, refine

__all__ = ["Identification", "identify", "identify_arrays"]


@dataclass(frozen=True)
class Identification:
    """Everything one identification produced.

    Attributes
    ----------
    name : str
        Test name.
    model_name : str
        ``"normalized"`` or ``"extended"``.
    level : float
        Constant coil voltage [V] (or current [A], see ``level_unit``) of the test; NaN if unknown.
    level_unit : str
        ``"V"`` or ``"A"``.
    closed_form : ClosedFormResult
        Closed-form start, design points and excitation check.
    fit : RefinedFit
        Refined parameters, uncertainty and the fitted force.
    cycles : list of Cycle
        The steady cycles used.
    n_cycles_discarded : int
        Leading cycles dropped as transient.
    branches : Branches
        Averaged limit-cycle branches (for plots).
    errors : dict
        :func:`~damper.identification.metrics.force_errors` of the fitted model over the steady cycles.
    t, x, xdot, force : ndarray
        The test histories (SI).
    warnings : tuple of str
        Warnings raised on the way (e.g. a marginal excitation).
    mask : ndarray of bool or None
        Usable samples (the screening's); ``None``: all.
    """

    name: str
    model_name: str
    level: float
    level_unit: str
    closed_form: ClosedFormResult
    fit: RefinedFit
    cycles: list = field(repr=False)
    n_cycles_discarded: int
    branches: Branches = field(repr=False)
    errors: dict
    t: np.ndarray = field(repr=False)
    x: np.ndarray = field(repr=False)
    xdot: np.ndarray = field(repr=False)
    force: np.ndarray = field(repr=False)
    warnings: tuple = ()
    mask: np.ndarray | None = field(default=None, repr=False)

    @property
    def parameters(self) -> dict[str, float]:
        """Refined parameters (SI)."""
        return dict(self.fit.parameters)

    @property
    def model(self):
        """The fitted damper model object."""
        return self.fit.model

    @property
    def window(self) -> slice:
        """Samples of the steady cycles."""
        return slice(self.cycles[0].start, self.cycles[-1].end + 1)

    def summary(self) -> dict:
        """JSON-ready summary: parameters, uncertainty, closed form, design points, errors."""
        cf = self.closed_form
        return {
            "name": self.name,
            "model": self.model_name,
            "level": None if math.isnan(self.level) else self.level,
            "level_unit": self.level_unit,
            "parameters": self.fit.parameters,
            "standard_error": self.fit.standard_error,
            "bootstrap_std": self.fit.bootstrap_std,
            "closed_form": cf.parameters(),
            "design_points": {"x_star": cf.design.x_star, "x1": cf.design.x1, "x2": cf.design.x2,
                              "x3": cf.design.x3},
            "kappa_x_inclination": cf.kappa_x_inclination,
            "kappa_x_method": cf.kappa_x_method,
            "free": list(self.fit.free),
            "n_derivative": None if math.isnan(cf.n_derivative) else cf.n_derivative,
            "n_integral": cf.n_integral,
            "rho_stroke": self.fit.parameters["rho"] * self.branches.stroke,
            "w0": cf.w0,
            "stroke": self.branches.stroke,
            "n_cycles": len(self.cycles),
            "n_cycles_discarded": self.n_cycles_discarded,
            "errors": self.errors,
            "fit_success": self.fit.success,
            "nfev": self.fit.nfev,
            "warnings": list(self.warnings),
        }


def _check_device_excitation(branches: Branches, cf: ClosedFormResult, fit: RefinedFit, model: str,
                             n_method: str, strict: bool) -> None:
    """Excitation check on the device's reading of rho (Ikhouane & Rodellar 2007; Bahar et al. 2009, step 1).

    The stroke is large enough when rho*(X_max - X_min) is, with rho the device's transition
    scale: for the extended model the refined fit's (the least-squares estimate; the closed-form
    rho is biased upwards exactly when the excitation is marginal: on the virtual damper's
    ±0.03 m test, the seed's Fig. 6, it reads 7.1-7.3 where the refined rho gives 6.0-6.7);
    for the normalized model the extended closed form's (which removes the elastic
    inclination before locating the transition). The normalized model's own rho is not used:
    on an inclined loop it trades the missing stiffness for a small rho, which says nothing
    about the test.
    """
    readings = []
    if model == "extended":
        readings = [(fit.parameters["rho"], fit.parameters["sigma"], fit.parameters["n"])]
    else:
        try:
            ext = closed_form(branches, model="extended", n_method=n_method, strict=False, check=False)
            readings = [(ext.rho, ext.sigma, ext.n)]
        except InputError:
            readings = [(cf.rho, cf.sigma, cf.n)]
    rho, sigma, n = max(readings, key=lambda r: r[0])
    check_excitation(rho, sigma, n, branches.stroke, strict=strict)


def identify_arrays(t: np.ndarray, x: np.ndarray, force: np.ndarray, xdot: np.ndarray | None = None,
                    model: str = "extended", name: str = "test", level: float = math.nan,
                    level_unit: str = "V", n_method: str = "integral", n_bootstrap: int = 0,
                    strict: bool = True, seed: int = 0, start: dict | None = None,
                    kappa_x: float | None = None, mask: np.ndarray | None = None) -> Identification:
    """Identify ``model`` from one constant-voltage periodic test given as arrays.

    Parameters
    ----------
    t, x, force : ndarray, shape (n,)
        Time [s], displacement [m], force [N].
    xdot : ndarray, optional
        Velocity [m/s]; by default the second-order finite difference of ``x``.
    model : {"extended", "normalized"}
    name : str
        Test name (reports).
    level, level_unit : float, str
        The constant voltage [V] or current [A] the test was run at (labels only).
    n_method : {"integral", "derivative"}
        Closed-form variant for :math:`n` (see :func:`~damper.identification.closed_form.closed_form`).
    n_bootstrap : int
        Cycle-bootstrap refits for the uncertainty (0: Jacobian only).
    strict : bool
        Raise :class:`InputError` when :math:`\\rho(X_{max} - X_{min})` is below
        :data:`~damper.identification.cycles.MIN_RHO_STROKE` (the closed-form steps' plastic
        assumption fails and near-equivalent parameter sets abound); otherwise only warn. The
        device's :math:`\\rho` is read as in :func:`_check_device_excitation`.
    seed : int
        Bootstrap seed.
    start : dict, optional
        Starting parameters for the refinement instead of the closed form (the closed form is
        still computed, non-strictly, and reported).
    kappa_x : float, optional
        Extended model only: hold :math:`\\kappa_x` [N/m] fixed at this value in the closed-form
        steps and the refinement (the seed paper's method: :math:`\\kappa_x` read once from a
        large-amplitude loop, the rest identified on :math:`F - \\kappa_x x`). Default: identified
        from this test.
    mask : ndarray of bool, optional
        Usable samples (the screening's, :attr:`damper.io.data.DamperTest.mask`): the others are
        simulated but count neither in the refinement's residuals nor in the errors.

    Returns
    -------
    Identification
    """
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    force = np.asarray(force, dtype=float)
    if not (t.ndim == x.ndim == force.ndim == 1 and t.size == x.size == force.size):
        raise InputError(f"{name}: time, displacement and force must be 1-D arrays of equal length, "
                         f"got {t.shape}, {x.shape}, {force.shape}")
    for label, arr in (("time", t), ("displacement", x), ("force", force)):
        if not np.all(np.isfinite(arr)):
            raise InputError(f"{name}: {label} has a non-finite value at sample "
                             f"{int(np.flatnonzero(~np.isfinite(arr))[0])}")
    if t.size < 3:
        raise InputError(f"{name}: {t.size} samples; a periodic test needs at least two periods of samples")
    if np.any(np.diff(t) <= 0):
        raise InputError(f"{name}: time must increase strictly")
    if xdot is None:
        xdot = np.gradient(x, t, edge_order=2)
    else:
        xdot = np.asarray(xdot, dtype=float)
        if xdot.shape != t.shape or not np.all(np.isfinite(xdot)):
            raise InputError(f"{name}: velocity must be a finite 1-D array as long as time, got shape {xdot.shape}")
    caught: list[str] = []
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        cycles = detect_cycles(x)
        # flagged samples (screening) are bridged for the limit-cycle and closed-form steps,
        # which average whole cycles; the averaged branches use the cycles without any
        f_seen = force
        if mask is not None and not np.all(mask):
            usable = np.asarray(mask, dtype=bool)
            f_seen = np.interp(t, t[usable], force[usable])
        kept, _ = steady_cycles(x, f_seen, cycles)
        if len(cycles) >= 3 and len(kept) == len(cycles):
            kept = kept[1:]   # the first cycle starts from rest: never part of the limit cycle
        clean = kept if mask is None else [c for c in kept if np.all(mask[c.start:c.end + 1])]
        branches = average_branches(x, xdot, f_seen, clean or kept)
        cf = closed_form(branches, model=model, n_method=n_method, strict=False, check=False,
                         kappa_x=kappa_x)
        fit = refine(t, x, xdot, force, kept, start if start is not None else cf.parameters(),
                     model=model, n_bootstrap=n_bootstrap, seed=seed,
                     fixed=None if kappa_x is None else {"kappa_x": float(kappa_x)}, mask=mask)
        _check_device_excitation(branches, cf, fit, model, n_method, strict)
    for w in record:
        caught.append(str(w.message))
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    window = slice(kept[0].start, kept[-1].end + 1)
    in_window = None if mask is None else np.asarray(mask, dtype=bool)[window]
    errors = force_errors(t[window], force[window], fit.force[window], x[window], xdot[window],
                          mask=in_window)
    return Identification(name=name, model_name=model, level=float(level), level_unit=level_unit,
                          closed_form=cf, fit=fit, cycles=kept,
                          n_cycles_discarded=len(cycles) - len(kept), branches=branches,
                          errors=errors, t=t, x=x, xdot=xdot, force=force, warnings=tuple(caught),
                          mask=None if mask is None else np.asarray(mask, dtype=bool))


def identify(test, model: str = "extended", **options) -> Identification:
    """Identify ``model`` from a :class:`damper.io.data.DamperTest` (constant voltage or current).

    The test's ``velocity`` is used when present; its constant ``voltage`` [V] (or ``current``
    [A]) labels the result. ``options`` are those of :func:`identify_arrays`.

    Parameters
    ----------
    test
        The test (:class:`damper.io.data.DamperTest`) at one voltage or current.
    model : str, optional
        ``"normalized"`` or ``"extended"``.
    **options
        Passed to :func:`damper.identification.refine.refine` (e.g. ``max_nfev``, ``kappa_x``).

    Raises
    ------
    InputError
        The voltage/current is not constant over the test, or any step's input check fails.
    """
    name = str(getattr(test, "name", "test"))
    level, unit = math.nan, "V"
    for attr, u in (("voltage", "V"), ("current", "A")):
        values = getattr(test, attr, None)
        if values is None:
            continue
        values = np.atleast_1d(np.asarray(values, dtype=float))
        if values.size and np.ptp(values) > 1e-6 * max(1.0, float(np.max(np.abs(values)))):
            raise InputError(f"{name}: {attr} varies over the test ({values.min():g}–{values.max():g} {u}); "
                             "identification needs a constant-voltage (or constant-current) test; a recording "
                             "with a changing command is fitted by `sbib diagnose --data FILE --model spencer`")
        if values.size:
            level, unit = float(values.flat[0]), u
            break
    velocity = getattr(test, "velocity", None)
    options.setdefault("mask", getattr(test, "mask", None))
    return identify_arrays(test.time, test.displacement, test.force, xdot=velocity, model=model,
                           name=name, level=level, level_unit=unit, **options)
