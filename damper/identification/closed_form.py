"""Closed-form identification of the (extended) normalized Bouc-Wen model from a periodic test.

The model (Ikhouane & Rodellar 2007; extended by Bahar et al. 2009, eq. 3–4):

.. math::

    F = \\kappa_x x + \\kappa_{\\dot x}\\dot x + \\kappa_w w, \\qquad
    \\dot w = \\rho\\,(\\dot x - \\sigma|\\dot x||w|^{n-1}w + (\\sigma - 1)\\dot x |w|^n),

with :math:`\\kappa_x = 0` for the normalized model. At constant voltage, under a periodic
wave input, the force settles on a limit cycle whose loading branch :math:`\\bar F(x)` gives
the parameters in closed form (the seed paper's appendix, eq. 13–22):

(a) :math:`\\kappa_x`: the average inclination of the force–displacement loop (Bahar et al. 2009,
    Fig. 2), taken as the slope of the loop's mid-line :math:`(\\bar F_{load}(x) +
    \\bar F_{unload}(x))/2` over the displacements where both branches are plastic.
(b) :math:`\\kappa_{\\dot x}` (and the plateau :math:`\\kappa_w`): Rodríguez et al.'s linear regression
    on the plastic region (:math:`\\bar w \\approx \\pm 1`) of both branches,
    :math:`\\bar F - \\kappa_x x = \\kappa_{\\dot x}\\dot x \\pm \\kappa_w + c` (:math:`c`, a force
    offset, is reported and removed).
(c) :math:`\\theta(x) = \\bar F - \\kappa_x x - \\kappa_{\\dot x}\\dot x - c` on the loading branch, its zero
    :math:`x^*`, :math:`a = \\theta'(x^*)` (eq. 15–16);
    ``n_method="derivative"`` (the original method): :math:`n` from two design points
    :math:`x_2^* > x_1^* > x^*` (eq. 17), :math:`b = (a - \\theta'(x_2^*))/\\theta(x_2^*)^n` (18),
    :math:`\\kappa_w = (a/b)^{1/n}` (19), :math:`\\rho = a/\\kappa_w` (20), :math:`\\bar w = \\theta/\\kappa_w` (21),
    :math:`\\sigma = \\tfrac12[(\\bar w'(x_3^*)/\\rho - 1)/(-\\bar w(x_3^*))^n + 1]` at :math:`x_3^* < x^*` (22);
    ``n_method="integral"`` (derivative-free, robust to noise): with :math:`\\kappa_w` from (b) and
    :math:`\\bar w = \\theta/\\kappa_w`, :math:`G_n(\\bar w(x)) = \\rho(x - x^*)` for :math:`x > x^*` gives
    :math:`n` from :math:`G_n(\\bar w(x_2^*))/G_n(\\bar w(x_1^*)) = (x_2^* - x^*)/(x_1^* - x^*)`, then
    :math:`\\rho = G_n(\\bar w(x_2^*))/(x_2^* - x^*)`; and :math:`H_{\\sigma,n}(-\\bar w(x_3^*)) = \\rho(x^* - x_3^*)`
    gives :math:`\\sigma` (see :mod:`damper.identification.cycles` for :math:`G_n`, :math:`H_{\\sigma,n}`).

The plastic region depends on :math:`\\rho` (it starts where :math:`\\bar w` reaches 0.99), so
steps (a)–(c) are iterated from a first guess (the second half of each branch). The design
points are chosen automatically where :math:`\\bar w` takes fixed levels and are reported.

References
----------
F. Ikhouane, J. Rodellar, *Systems with Hysteresis*, Wiley 2007, ch. 3.
A. Rodríguez, N. Iwata, F. Ikhouane, J. Rodellar, Smart Mater. Struct. 18 (2009) 015010.
A. Bahar, F. Pozo, L. Acho, J. Rodellar, A. Barbat, preprint 2009 (the seed paper), appendix.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import asdict, dataclass, field

import numpy as np
from scipy.optimize import brentq

from benchmark.foundation.errors import InputError
from damper.models.bouc_wen import g_integral, h_integral, limit_cycle_peak
from damper.identification.cycles import Branches, ExcitationWarning, check_excitation, plastic_distance

__all__ = ["DesignPoints", "ClosedFormResult", "closed_form", "MODEL_FORMS", "PARAMETER_NAMES"]

#: The model forms the identification fits (the seed paper's two; registered damper models are `damper.models.registry.MODELS`).
MODEL_FORMS = ("normalized", "extended")
#: Parameter names, in the order used throughout the identification (SI units: N/m, N·s/m, N, 1/m, -, -).
PARAMETER_NAMES = ("kappa_x", "kappa_xdot", "kappa_w", "rho", "sigma", "n")

_N_MAX = 20.0
_SIGMA_MAX = 50.0


@dataclass(frozen=True)
class DesignPoints:
    """Design points on the loading branch [m] and the levels of :math:`\\bar w` they were chosen at.

    ``x_star`` is the zero of :math:`\\theta`; ``x1 < x2`` lie above it, ``x3`` below it.

    Parameters
    ----------
    x_star : float
        Displacement [m] on the loading branch from which w̄ is taken as plastic.
    x1 : float
        First design point [m].
    x2 : float
        Second design point [m].
    x3 : float
        Third design point [m].
    w1 : float
        Level of w̄ at ``x1``.
    w2 : float
        Level of w̄ at ``x2``.
    w3 : float
        Level of w̄ at ``x3``.
    """

    x_star: float
    x1: float
    x2: float
    x3: float
    w1: float
    w2: float
    w3: float


@dataclass(frozen=True)
class ClosedFormResult:
    """Parameters from the closed-form steps, with what they were computed from.

    Attributes
    ----------
    model : str
        ``"normalized"`` (:math:`\\kappa_x = 0`) or ``"extended"``.
    kappa_x, kappa_xdot, kappa_w, rho, sigma, n : float
        Parameters [N/m, N·s/m, N, 1/m, -, -] (``n_method``'s estimate).
    n_method : str
        ``"integral"`` or ``"derivative"``.
    kappa_x_inclination : float
        Slope of the loop's mid-line (seed step a) [N/m].
    kappa_x_regression : float
        :math:`\\kappa_x` of the joint plastic regression [N/m].
    kappa_w_plastic : float
        Plateau of the plastic regression [N].
    force_offset : float
        Constant force offset found by the regression (removed before the closed-form steps) [N].
    a : float
        :math:`d\\theta/dx` at :math:`x^*` [N/m].
    n_derivative, n_integral : float
        :math:`n` by eq. 17 and by the :math:`G_n` ratio (NaN where not computable).
    design : DesignPoints
    rho_stroke, w0 : float
        :math:`\\rho(X_{max}-X_{min})` and the limit-cycle peak of :math:`\\bar w` it implies.
    plastic_distance : float
        Distance from a reversal beyond which the branch was treated as plastic [m].
    iterations : int
        Plastic-region iterations used.
    notes : tuple of str
        What the steps had to work around.
    kappa_x_method : str
        How :math:`\\kappa_x` was obtained: ``"fixed"`` (given), ``"inclination"``,
        ``"regression"`` or ``"none"`` (normalized model).
    """

    model: str
    kappa_x: float
    kappa_xdot: float
    kappa_w: float
    rho: float
    sigma: float
    n: float
    n_method: str
    kappa_x_inclination: float
    kappa_x_regression: float
    kappa_w_plastic: float
    force_offset: float
    a: float
    n_derivative: float
    n_integral: float
    design: DesignPoints
    rho_stroke: float
    w0: float
    plastic_distance: float
    iterations: int
    notes: tuple[str, ...] = field(default_factory=tuple)
    kappa_x_method: str = ""

    def parameters(self) -> dict[str, float]:
        """The six parameters by name (``kappa_x`` is 0 for the normalized model)."""
        return {name: float(getattr(self, name)) for name in PARAMETER_NAMES}

    def to_dict(self) -> dict:
        """Everything as plain Python types (for JSON)."""
        d = asdict(self)
        d["notes"] = list(self.notes)
        return d


def _local_poly(x: np.ndarray, y: np.ndarray, x0: float, half_width: float,
                split: bool = False) -> tuple[float, float]:
    """Value and slope at ``x0`` of a least-squares quadratic through the points within ``half_width``.

    With ``split`` the curvature may differ on both sides of ``x0`` (the normalized Bouc-Wen
    branch has a jump of :math:`\\theta''` at :math:`x^*` when :math:`n = 1`).
    """
    sel = np.abs(x - x0) <= half_width
    if np.count_nonzero(sel) < 6:
        sel = np.argsort(np.abs(x - x0))[:6]
    dx = x[sel] - x0
    if split:
        cols = [np.ones_like(dx), dx, np.where(dx > 0, dx * dx, 0.0), np.where(dx < 0, dx * dx, 0.0)]
    else:
        cols = [np.ones_like(dx), dx, dx * dx]
    coef = np.linalg.lstsq(np.column_stack(cols), y[sel], rcond=None)[0]
    return float(coef[0]), float(coef[1])


def _crossing(x: np.ndarray, y: np.ndarray, level: float, after: float | None = None,
              before: float | None = None) -> float:
    """Displacement where the increasing curve y(x) first reaches ``level`` (linear interpolation)."""
    mask = np.ones_like(x, dtype=bool)
    if after is not None:
        mask &= x >= after
    if before is not None:
        mask &= x <= before
    xs, ys = x[mask], y[mask]
    above = np.flatnonzero(ys >= level)
    if above.size == 0:
        return math.nan
    i = int(above[0])
    if i == 0:
        return float(xs[0])
    x0, x1, y0, y1 = xs[i - 1], xs[i], ys[i - 1], ys[i]
    return float(x0 + (level - y0) * (x1 - x0) / (y1 - y0)) if y1 != y0 else float(x1)


def _zero_of_theta(x: np.ndarray, theta: np.ndarray, plateau: float) -> float:
    """:math:`x^*`: the last zero crossing of :math:`\\theta` before it reaches half its plateau."""
    hi = np.flatnonzero(theta >= 0.5 * plateau)
    if hi.size == 0:
        return math.nan
    neg = np.flatnonzero(theta[: hi[0]] < 0.0)
    if neg.size == 0:
        return math.nan
    i = int(neg[-1])
    x0, x1, y0, y1 = x[i], x[i + 1], theta[i], theta[i + 1]
    return float(x0 - y0 * (x1 - x0) / (y1 - y0))


def _solve_n_integral(w1: float, w2: float, ratio: float) -> float:
    """Solve :math:`G_n(w_2)/G_n(w_1) = \\mathrm{ratio}` for :math:`n` (clipped to [1, 20])."""
    def gap(n: float) -> float:
        return float(g_integral(w2, n) / g_integral(w1, n)) - ratio

    lo, hi = 1.0, _N_MAX
    # The ratio decreases with n (larger n: straighter rise, ratio -> w2/w1).
    g_lo, g_hi = gap(lo), gap(hi)
    if g_lo <= 0.0:
        return lo
    if g_hi >= 0.0:
        return hi
    return brentq(gap, lo, hi, xtol=1e-10)


def _solve_sigma(w3: float, n: float, target: float) -> float:
    """Solve :math:`H_{\\sigma,n}(w_3) = \\mathrm{target}` for :math:`\\sigma \\in [1/2, 50]`."""
    def gap(s: float) -> float:
        return float(h_integral(w3, s, n)) - target

    if gap(0.5) <= 0.0:
        return 0.5
    if gap(_SIGMA_MAX) >= 0.0:
        return _SIGMA_MAX
    return brentq(gap, 0.5, _SIGMA_MAX, xtol=1e-12)


def closed_form(branches: Branches, model: str = "extended", n_method: str = "integral",
                kappa_x_method: str = "inclination", kappa_x: float | None = None,
                levels: tuple[float, float, float] = (0.5, 0.85, -0.5), max_iterations: int = 6,
                strict: bool = True, check: bool = True) -> ClosedFormResult:
    """Closed-form parameters of the (extended) normalized Bouc-Wen model from the limit cycle.

    Parameters
    ----------
    branches : Branches
        Averaged loading/unloading branches of the limit cycle
        (:func:`damper.identification.cycles.average_branches`).
    model : {"extended", "normalized"}
        Whether to identify :math:`\\kappa_x` (seed paper) or fix it at 0 (Ikhouane–Rodellar).
    n_method : {"integral", "derivative"}
        How :math:`n`, :math:`\\rho`, :math:`\\sigma` (and for ``"derivative"`` :math:`\\kappa_w`) are
        computed: the derivative-free :math:`G_n` variant or the original eq. 17–22.
    kappa_x_method : {"inclination", "regression"}
        Extended model only: :math:`\\kappa_x` from the loop's average inclination (the seed's step a,
        then the regression on :math:`F - \\kappa_x x`), or jointly with :math:`\\kappa_{\\dot x}`,
        :math:`\\kappa_w` in the plastic regression (less biased at moderate strokes). The
        inclination falls back to the regression when it leaves no dry friction.
    kappa_x : float, optional
        Extended model only: hold :math:`\\kappa_x` [N/m] at this value (the seed's method: one
        :math:`\\kappa_x`, read once from a large-amplitude loop, eq. 5) and run steps (b)–(c)
        on :math:`F - \\kappa_x x`; overrides ``kappa_x_method``. The loop's own inclination
        and regression values are still computed and reported.
    levels : (float, float, float)
        Levels of :math:`\\bar w` at which the design points :math:`x_1^*, x_2^*, x_3^*` are placed
        (:math:`0 < w_1 < w_2 < 1`, :math:`-1 < w_3 < 0`; :math:`w_3` is scaled by the cycle peak
        :math:`w_0`).
    max_iterations : int
        Iterations of the plastic-region estimate.
    strict : bool
        Raise :class:`InputError` when the excitation is too small for the plastic assumption
        (otherwise warn and return the biased estimate).
    check : bool
        Run the excitation check at all (:func:`~damper.identification.identify.identify_arrays`
        runs its own, on the device's reading).

    Returns
    -------
    ClosedFormResult

    Raises
    ------
    InputError
        Unknown ``model``/``n_method``, a loop without plastic region, a test whose velocity
        amplitude is constant over the plastic region (:math:`\\kappa_{\\dot x}` and :math:`\\kappa_w`
        cannot be separated), or (``strict``) insufficient excitation.
    """
    if model not in MODEL_FORMS:
        raise InputError(f"model: expected one of {MODEL_FORMS}, got {model!r}")
    if kappa_x_method not in ("inclination", "regression"):
        raise InputError(f"kappa_x_method: expected 'inclination' or 'regression', got {kappa_x_method!r}")
    if kappa_x is not None:
        if model != "extended":
            raise InputError(f"kappa_x: a fixed kappa_x applies to the extended model only, got model {model!r}")
        if not (math.isfinite(kappa_x) and kappa_x >= 0.0):
            raise InputError(f"kappa_x: expected a finite value >= 0 N/m, got {kappa_x!r}")
        kappa_x_method = "fixed"
    kappa_x_fixed = float(kappa_x) if kappa_x is not None else math.nan
    if n_method not in ("integral", "derivative"):
        raise InputError(f"n_method: expected 'integral' or 'derivative', got {n_method!r}")
    w1_level, w2_level, w3_level = levels
    if not (0.0 < w1_level < w2_level < 1.0 and -1.0 < w3_level < 0.0):
        raise InputError(f"levels: expected 0 < w1 < w2 < 1 and -1 < w3 < 0, got {levels}")

    ok = (branches.count_loading > 0) & (branches.count_unloading > 0)
    x = branches.x[ok]
    fl, fu = branches.force_loading[ok], branches.force_unloading[ok]
    vl, vu = branches.velocity_loading[ok], branches.velocity_unloading[ok]
    if x.size < 20:
        raise InputError(f"branches: only {x.size} displacement bins hold both branches; "
                         "the test needs more samples per cycle")
    x_min, x_max, stroke = branches.x_min, branches.x_max, branches.stroke
    extended = model == "extended"
    notes: list[str] = []

    distance = 0.5 * stroke  # first guess of the plastic distance: half a stroke
    result = None
    for iteration in range(1, max_iterations + 1):
        pl_load = (x - x_min) >= distance
        pl_unload = (x_max - x) >= distance
        both = pl_load & pl_unload
        # (a) kappa_x: average inclination (mid-line slope) where both branches are plastic.
        mid = 0.5 * (fl + fu)
        if np.count_nonzero(both) >= 5:
            central = both
        else:
            central = np.abs(x - 0.5 * (x_min + x_max)) <= 0.25 * stroke
        kappa_x_incl = float(np.polyfit(x[central], mid[central], 1)[0])
        # (b) plastic regression F - kappa_x x = kappa_xdot xdot + kappa_w s + c on both branches.
        if np.count_nonzero(pl_load) < 3 or np.count_nonzero(pl_unload) < 3:
            raise InputError(f"branches: no plastic region (distance {distance:.4g} m from a reversal "
                             f"exceeds the stroke {stroke:.4g} m): increase the test amplitude")
        x_pl = np.concatenate([x[pl_load], x[pl_unload]])
        v_pl = np.concatenate([vl[pl_load], vu[pl_unload]])
        f_pl = np.concatenate([fl[pl_load], fu[pl_unload]])
        s_pl = np.concatenate([np.ones(np.count_nonzero(pl_load)), -np.ones(np.count_nonzero(pl_unload))])
        speed = np.abs(v_pl)
        q25, q50, q75 = np.percentile(speed, [25, 50, 75])
        if q75 - q25 < 0.02 * q50:
            raise InputError("test: the velocity is (nearly) constant over the plastic region, so the "
                             "viscous term kappa_xdot*xdot cannot be told from the dry friction kappa_w; "
                             "use a sinusoidal displacement")
        columns = [v_pl, s_pl, np.ones_like(v_pl)]
        joint = np.linalg.lstsq(np.column_stack([x_pl] + columns), f_pl, rcond=None)[0]
        kappa_x_regression = float(joint[0])
        method = kappa_x_method if extended else "none"
        if method == "fixed":
            coef = np.linalg.lstsq(np.column_stack(columns), f_pl - kappa_x_fixed * x_pl, rcond=None)[0]
            kappa_x = kappa_x_fixed
        if method == "inclination":
            kappa_x = kappa_x_incl
            coef = np.linalg.lstsq(np.column_stack(columns), f_pl - kappa_x * x_pl, rcond=None)[0]
            if not coef[1] > 0.0:
                notes.append(f"the loop's inclination {kappa_x_incl:.4g} N/m leaves no dry friction "
                             f"(kappa_w = {coef[1]:.4g} N): kappa_x taken from the joint plastic "
                             "regression instead (is the excitation large enough?)")
                method = "regression"
        if method == "regression":
            kappa_x = kappa_x_regression
            coef = joint[1:]
        elif method == "none":
            kappa_x = 0.0
            coef = np.linalg.lstsq(np.column_stack(columns), f_pl, rcond=None)[0]
        kappa_xdot, kappa_w_pl, offset = (float(c) for c in coef)
        disagreement = abs(kappa_x_incl - kappa_x_regression) / max(abs(kappa_x_regression), 1e-300)
        if not (kappa_w_pl > 0.0):
            raise InputError(f"branches: the plastic regression gives kappa_w = {kappa_w_pl:.4g} N <= 0; "
                             "the loop shows no dry friction (too small an excitation for the plastic "
                             "assumption, or a force sign inconsistent with the velocity)")
        if kappa_xdot <= 0.0:
            notes.append(f"plastic regression gave kappa_xdot = {kappa_xdot:.4g} N s/m <= 0; "
                         "started the refinement from 1 % of kappa_w/|xdot|_max instead")
            kappa_xdot = 0.01 * kappa_w_pl / float(np.max(np.abs(vl)))
        # (c) theta on the loading branch.
        theta = fl - kappa_x * x - kappa_xdot * vl - offset
        x_star = _zero_of_theta(x, theta, kappa_w_pl)
        if not math.isfinite(x_star):
            raise InputError("branches: theta = F - kappa_x x - kappa_xdot xdot has no zero on the "
                             "loading branch; the loop is not a Bouc-Wen-like hysteresis loop")
        x_plateau = _crossing(x, theta, 0.9 * kappa_w_pl, after=x_star)
        transition = (x_plateau - x_star) if math.isfinite(x_plateau) else 0.1 * stroke
        bin_width = float(np.median(np.diff(x)))
        half_width = max(0.12 * transition, 3.0 * bin_width)
        _, a = _local_poly(x, theta, x_star, half_width, split=True)
        x1 = _crossing(x, theta, w1_level * kappa_w_pl, after=x_star)
        x2 = _crossing(x, theta, w2_level * kappa_w_pl, after=x_star)
        if not (math.isfinite(x1) and math.isfinite(x2) and x2 > x1 > x_star and a > 0.0):
            raise InputError("branches: the loading branch does not rise through the design levels "
                             f"w = {w1_level}, {w2_level}; the loop is not Bouc-Wen-like")
        theta1, dtheta1 = _local_poly(x, theta, x1, half_width)
        theta2, dtheta2 = _local_poly(x, theta, x2, half_width)
        # Original method (eq. 17-20).
        with np.errstate(all="ignore"):
            n_der = math.log((a - dtheta2) / (a - dtheta1)) / math.log(theta2 / theta1) \
                if (a > dtheta2 and a > dtheta1 and theta2 > theta1 > 0) else math.nan
        # Derivative-free variant.
        n_int = _solve_n_integral(theta1 / kappa_w_pl, min(theta2 / kappa_w_pl, 0.999),
                                  (x2 - x_star) / (x1 - x_star))
        if n_method == "derivative" and math.isfinite(n_der):
            n = min(max(n_der, 1.0), _N_MAX)
            b = (a - dtheta2) / theta2 ** n
            kappa_w = (a / b) ** (1.0 / n)
            rho = a / kappa_w
        else:
            if n_method == "derivative":
                notes.append("eq. 17 not computable (theta' not below a at the design points); "
                             "used the integral variant")
            n = n_int
            kappa_w = kappa_w_pl
            rho = float(g_integral(min(theta2 / kappa_w, 0.999), n)) / (x2 - x_star)
        w0 = limit_cycle_peak(rho * stroke, 0.5, n)  # sigma not known yet: lower bound of w0
        w3_target = w3_level * w0
        x3 = _crossing(x, theta, w3_target * kappa_w, before=x_star)
        if not math.isfinite(x3) or x3 >= x_star:
            x3 = x_min + 0.5 * (x_star - x_min)
        theta3, dtheta3 = _local_poly(x, theta, x3, half_width)
        wbar3 = theta3 / kappa_w
        if n_method == "derivative" and wbar3 < 0.0:
            sigma = 0.5 * ((dtheta3 / kappa_w / rho - 1.0) / (-wbar3) ** n + 1.0)
        elif wbar3 < 0.0:
            sigma = _solve_sigma(-wbar3, n, rho * (x_star - x3))
        else:
            sigma = 0.5
        sigma = min(max(sigma, 0.5), _SIGMA_MAX)
        w0 = limit_cycle_peak(rho * stroke, sigma, n)
        result = ClosedFormResult(
            model=model, kappa_x=kappa_x, kappa_xdot=kappa_xdot, kappa_w=float(kappa_w), rho=float(rho),
            sigma=float(sigma), n=float(n), n_method=n_method, kappa_x_inclination=kappa_x_incl,
            kappa_x_regression=kappa_x_regression,
            kappa_w_plastic=kappa_w_pl, force_offset=offset, a=a, n_derivative=n_der, n_integral=n_int,
            design=DesignPoints(x_star, x1, x2, x3, w1_level, w2_level, w3_target),
            rho_stroke=float(rho * stroke), w0=float(w0), plastic_distance=float(distance),
            iterations=iteration, notes=tuple(notes), kappa_x_method=method)
        new_distance = plastic_distance(rho, sigma, n, w0, 0.99)
        if new_distance >= 0.9 * stroke or rho * stroke < 4.0:
            break
        if abs(new_distance - distance) <= 1e-3 * stroke:
            break
        distance = new_distance

    assert result is not None
    if extended and kappa_x_method != "fixed" and disagreement > 0.1:
        warnings.warn(f"kappa_x: the loop's inclination ({kappa_x_incl:.4g} N/m) and the plastic "
                      f"regression ({kappa_x_regression:.4g} N/m) differ by {100 * disagreement:.0f} %: "
                      "the branches are not plastic over most of the stroke (increase the amplitude)",
                      ExcitationWarning, stacklevel=2)
    if check:
        check_excitation(result.rho, result.sigma, result.n, stroke, strict=strict)
    return result
