"""Cycles of a periodic damper test: reversals, the limit cycle, the loading and unloading branches.

The closed-form identification (Ikhouane & Rodellar 2007, ch. 3; Rodríguez et al. 2009; Bahar
et al. 2009, appendix) reads the parameters off the *limit cycle* of a test driven at constant
voltage by a periodic "wave" input, i.e. a displacement that increases from
:math:`X_{min}` to :math:`X_{max}` and decreases back over each period. This module

* finds the displacement reversals with a Schmitt trigger (robust to measurement noise),
* splits the test into cycles (minimum → maximum → next minimum),
* discards the leading cycles that are still transient ("wait for the limit cycle"),
* averages the loading and unloading branches of the remaining cycles over displacement bins,
* checks that the excitation is large enough for the plastic assumption :math:`\\bar w \\approx 1`.

The excitation check uses the exact limit cycle of the normalized Bouc-Wen model: on the
loading branch :math:`dw/dx = \\rho\\,h(w)` with :math:`h(w) = 1 - w^n` for :math:`w \\ge 0` and
:math:`h(w) = 1 + (2\\sigma - 1)|w|^n` for :math:`w < 0`, so the peak :math:`w_0` of the cycle solves

.. math:: H_{\\sigma,n}(w_0) + G_n(w_0) = \\rho\\,(X_{max} - X_{min}),

with :math:`G_n(w) = \\int_0^w d\\mu/(1-\\mu^n) = w\\,{}_2F_1(1, 1/n; 1 + 1/n; w^n)` and
:math:`H_{\\sigma,n}(w) = \\int_0^w d\\mu/(1 + (2\\sigma-1)\\mu^n) = w\\,{}_2F_1(1, 1/n; 1+1/n; -(2\\sigma-1) w^n)`.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np

from benchmark.foundation.errors import InputError
from damper.models.bouc_wen import g_integral, h_integral, limit_cycle_peak

__all__ = [
    "Cycle",
    "Branches",
    "ExcitationWarning",
    "detect_cycles",
    "steady_cycles",
    "average_branches",
    "plastic_distance",
    "check_excitation",
    "MIN_RHO_STROKE",
    "RECOMMENDED_RHO_STROKE",
]

#: Below this value of rho*(X_max - X_min) the closed-form steps are not applicable (w0 < 0.95
#: for n = 1, sigma = 1/2): :func:`check_excitation` raises.
MIN_RHO_STROKE = 4.0
#: Below this value the plastic region is short and the closed-form start is biased: a warning.
RECOMMENDED_RHO_STROKE = 7.0


class ExcitationWarning(UserWarning):
    """The test's stroke is only marginally large enough for the plastic assumption."""


@dataclass(frozen=True)
class Cycle:
    """One period of a wave input, as sample indices into the test arrays.

    Attributes
    ----------
    start : int
        Index of the displacement minimum that opens the cycle.
    peak : int
        Index of the maximum (end of the loading branch, start of the unloading branch).
    end : int
        Index of the next minimum (closes the cycle; the next cycle's ``start``).
    """

    start: int
    peak: int
    end: int

    @property
    def loading(self) -> slice:
        """Samples of the loading branch (increasing displacement)."""
        return slice(self.start, self.peak + 1)

    @property
    def unloading(self) -> slice:
        """Samples of the unloading branch (decreasing displacement)."""
        return slice(self.peak, self.end + 1)

    @property
    def samples(self) -> slice:
        """All samples of the cycle."""
        return slice(self.start, self.end + 1)


@dataclass(frozen=True)
class Branches:
    """Loading and unloading branches of the limit cycle, averaged over cycles in displacement bins.

    All arrays are ordered by increasing displacement and share the bin centres ``x`` [m]
    (bins that no sample of a branch fell into hold NaN).

    Attributes
    ----------
    x : ndarray
        Bin centres [m].
    force_loading, force_unloading : ndarray
        Mean force on each branch [N].
    velocity_loading, velocity_unloading : ndarray
        Mean velocity on each branch [m/s].
    count_loading, count_unloading : ndarray
        Number of samples in each bin.
    x_min, x_max : float
        Mean displacement minimum and maximum of the cycles [m].
    n_cycles : int
        Number of cycles averaged.
    """

    x: np.ndarray
    force_loading: np.ndarray
    force_unloading: np.ndarray
    velocity_loading: np.ndarray
    velocity_unloading: np.ndarray
    count_loading: np.ndarray
    count_unloading: np.ndarray
    x_min: float
    x_max: float
    n_cycles: int

    @property
    def stroke(self) -> float:
        """Peak-to-peak displacement :math:`X_{max} - X_{min}` [m]."""
        return self.x_max - self.x_min


def _as_1d(name: str, a: np.ndarray) -> np.ndarray:
    arr = np.asarray(a, dtype=float)
    if arr.ndim != 1:
        raise InputError(f"{name}: expected a one-dimensional array, got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        bad = int(np.flatnonzero(~np.isfinite(arr))[0])
        raise InputError(f"{name}: non-finite value at sample {bad}")
    return arr


def detect_cycles(displacement: np.ndarray, hysteresis: float = 0.25) -> list[Cycle]:
    """Split a periodic wave test into cycles (minimum → maximum → minimum).

    A Schmitt trigger finds the reversals: while the displacement rises, a maximum is
    confirmed once it has fallen by ``hysteresis`` times the stroke below the running
    maximum, and symmetrically for minima. Noise smaller than that band cannot create
    spurious reversals.

    Parameters
    ----------
    displacement : ndarray, shape (n,)
        Displacement history [m].
    hysteresis : float
        Fraction of the stroke (robust peak-to-peak, 0.5–99.5 percentiles) a reversal must be
        confirmed by; in (0, 0.5).

    Returns
    -------
    list of Cycle
        Complete cycles, in time order; the partial cycles at both ends are dropped.

    Raises
    ------
    InputError
        If the displacement is not finite, has no stroke, or holds no complete cycle.
    """
    x = _as_1d("displacement", displacement)
    if not 0.0 < hysteresis < 0.5:
        raise InputError(f"hysteresis: expected a fraction in (0, 0.5), got {hysteresis}")
    lo, hi = np.percentile(x, [0.5, 99.5])
    stroke = hi - lo
    if not stroke > 0.0:
        raise InputError("displacement: the test has no stroke (constant displacement)")
    band = hysteresis * stroke
    extrema: list[tuple[int, int]] = []  # (index, +1 for max / -1 for min)
    i_max = i_min = 0
    direction = 0  # unknown until the first band crossing
    for i in range(1, x.size):
        xi = x[i]
        if xi > x[i_max]:
            i_max = i
        if xi < x[i_min]:
            i_min = i
        # An extreme is recorded once the signal has left it by the band. The first one is
        # confirmed on one side only (the record may start mid-branch) and is therefore not
        # recorded: a cycle starts at a genuine minimum.
        if direction >= 0 and xi < x[i_max] - band:
            if direction == 1:
                extrema.append((i_max, +1))
            direction = -1
            i_min = i
        elif direction <= 0 and xi > x[i_min] + band:
            if direction == -1:
                extrema.append((i_min, -1))
            direction = +1
            i_max = i
    extrema.sort()
    cycles = []
    for k in range(len(extrema) - 2):
        (a, ka), (b, kb), (c, kc) = extrema[k], extrema[k + 1], extrema[k + 2]
        if ka == -1 and kb == +1 and kc == -1:
            cycles.append(Cycle(a, b, c))
    if not cycles:
        raise InputError(f"displacement: no complete cycle (minimum → maximum → minimum) found in "
                         f"{x.size} samples; a periodic test needs at least two periods")
    return cycles


def _loop_on_grid(x: np.ndarray, force: np.ndarray, cycle: Cycle, grid: np.ndarray) -> np.ndarray:
    """Force of one cycle's loading then unloading branch on a common displacement grid."""
    out = []
    for sl in (cycle.loading, cycle.unloading):
        xb, fb = x[sl], force[sl]
        order = np.argsort(xb, kind="stable")
        out.append(np.interp(grid, xb[order], fb[order]))
    return np.concatenate(out)


def steady_cycles(displacement: np.ndarray, force: np.ndarray, cycles: list[Cycle],
                  tol: float = 0.01, stroke_tol: float = 0.05) -> tuple[list[Cycle], np.ndarray]:
    """Wait for the limit cycle: keep the full-amplitude cycles that have reached the steady loop.

    First the longest run of consecutive cycles whose stroke is within ``stroke_tol`` of the
    largest is selected (tests that ramp the amplitude up and down keep only their plateau).
    Each cycle's loop (loading and unloading force on a common displacement grid) is compared
    with the median loop of the second half of the cycles; its deviation is
    :math:`d_k = \\|F_k - F_{med}\\|_2 / \\|F_{med}\\|_2`. Leading cycles with
    :math:`d_k > \\max(\\mathrm{tol}, 3\\,\\mathrm{median}(d))` are transient (the median
    deviation is the noise floor, so noisy data are not rejected wholesale).

    Parameters
    ----------
    displacement, force : ndarray, shape (n,)
        Test histories [m], [N].
    cycles : list of Cycle
        From :func:`detect_cycles`.
    tol : float
        Relative deviation accepted as "steady" on noise-free data.
    stroke_tol : float
        Relative shortfall of stroke that still counts as full amplitude.

    Returns
    -------
    kept : list of Cycle
        The steady cycles (at least one), consecutive.
    deviation : ndarray
        :math:`d_k` of every input cycle (``inf`` for cycles outside the full-amplitude run).
    """
    x = _as_1d("displacement", displacement)
    f = _as_1d("force", force)
    if f.size != x.size:
        raise InputError(f"force: expected {x.size} samples like the displacement, got {f.size}")
    if not cycles:
        raise InputError("cycles: at least one cycle is needed")
    # Full-amplitude cycles only: tests often ramp the amplitude up and down (UTFSM files);
    # keep the longest run of consecutive cycles whose stroke is within stroke_tol of the largest.
    strokes = np.array([x[c.peak] - 0.5 * (x[c.start] + x[c.end]) for c in cycles])
    full = strokes >= (1.0 - stroke_tol) * strokes.max()
    best, run_start = (0, 0), None
    for k, ok in enumerate(list(full) + [False]):
        if ok and run_start is None:
            run_start = k
        elif not ok and run_start is not None:
            if k - run_start > best[1] - best[0]:
                best = (run_start, k)
            run_start = None
    offset = best[0]
    all_cycles = cycles
    cycles = list(cycles[best[0]:best[1]])
    lo = max(x[c.start] for c in cycles)
    hi = min(x[c.peak] for c in cycles)
    deviation = np.full(len(all_cycles), np.inf)
    if not hi > lo:
        deviation[offset:offset + len(cycles)] = 0.0
        return cycles, deviation
    grid = np.linspace(lo, hi, 64)
    loops = np.array([_loop_on_grid(x, f, c, grid) for c in cycles])
    reference = np.median(loops[len(cycles) // 2:], axis=0)
    scale = np.linalg.norm(reference) or 1.0
    dev = np.linalg.norm(loops - reference, axis=1) / scale
    deviation[offset:offset + len(cycles)] = dev
    threshold = max(tol, 3.0 * float(np.median(dev)))
    first = 0
    while first < len(cycles) - 1 and dev[first] > threshold:
        first += 1
    return cycles[first:], deviation


def average_branches(displacement: np.ndarray, velocity: np.ndarray, force: np.ndarray,
                     cycles: list[Cycle], n_bins: int | None = None) -> Branches:
    """Average the loading and unloading branches of the given cycles in displacement bins.

    Binning (rather than interpolation) tolerates noise that makes the displacement locally
    non-monotonic near the reversals, and averages the cycles in one pass.

    Parameters
    ----------
    displacement, velocity, force : ndarray, shape (n,)
        Test histories [m, m/s, N].
    cycles : list of Cycle
        Steady cycles.
    n_bins : int, optional
        Number of displacement bins between the mean minimum and maximum, uniform in the phase
        :math:`u` of :math:`x = X_{min} + (X_{max} - X_{min})(1 - \\cos u)/2`; by default one bin
        per sample of one branch of one cycle, clipped to [100, 2000].
    """
    x = _as_1d("displacement", displacement)
    v = _as_1d("velocity", velocity)
    f = _as_1d("force", force)
    if not cycles:
        raise InputError("cycles: at least one cycle is needed")
    x_min = float(np.mean([x[c.start] for c in cycles] + [x[c.end] for c in cycles]))
    x_max = float(np.mean([x[c.peak] for c in cycles]))
    if n_bins is None:
        per_branch = np.mean([c.peak - c.start for c in cycles])
        n_bins = int(np.clip(per_branch, 100, 2000))
    # Bins uniform in the phase u of a sinusoid between the extremes, x = x_min + stroke (1 - cos u)/2:
    # dense near the reversals, where the hysteretic transition (length ~ 1/rho) lies and where a
    # sinusoidal test spends most samples per unit of displacement.
    u = np.linspace(0.0, np.pi, n_bins + 1)
    edges = x_min + (x_max - x_min) * 0.5 * (1.0 - np.cos(u))
    centres = 0.5 * (edges[1:] + edges[:-1])

    def binned(sl_name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        idx = np.concatenate([np.arange(getattr(c, sl_name).start, getattr(c, sl_name).stop)
                              for c in cycles])
        b = np.clip(np.searchsorted(edges, x[idx], side="right") - 1, 0, n_bins - 1)
        count = np.bincount(b, minlength=n_bins).astype(float)
        with np.errstate(invalid="ignore", divide="ignore"):
            fm = np.bincount(b, weights=f[idx], minlength=n_bins) / count
            vm = np.bincount(b, weights=v[idx], minlength=n_bins) / count
        return fm, vm, count

    fl, vl, cl = binned("loading")
    fu, vu, cu = binned("unloading")
    return Branches(centres, fl, fu, vl, vu, cl, cu, x_min, x_max, len(cycles))


def plastic_distance(rho: float, sigma: float, n: float, w0: float, level: float = 0.99) -> float:
    """Distance along a branch from its reversal to where :math:`\\bar w` reaches ``level`` [m].

    :math:`(H_{\\sigma,n}(w_0) + G_n(\\mathrm{level}))/\\rho`: from :math:`-w_0` to 0, then to
    ``level``. Beyond it the branch is "plastic" (:math:`\\bar w \\approx 1`) and the force is
    :math:`\\kappa_x x + \\kappa_{\\dot x}\\dot x \\pm \\kappa_w`.

    Parameters
    ----------
    rho : float
        Normalized Bouc-Wen rate parameter ρ [1/m] (> 0).
    sigma : float
        Normalized Bouc-Wen shape parameter σ (≥ 1/2).
    n : float
        Bouc-Wen exponent n (≥ 1).
    w0 : float
        Peak w₀ of the limit cycle.
    level : float, optional
        Level of w̄ that counts as plastic.
    """
    return float(h_integral(w0, sigma, n) + g_integral(min(level, w0), n)) / rho


def check_excitation(rho: float, sigma: float, n: float, stroke: float,
                     strict: bool = True) -> tuple[float, float]:
    """Check the stroke is large enough for the plastic assumption; return ``(rho*stroke, w0)``.

    Parameters
    ----------
    rho, sigma, n : float
        (Estimated) normalized Bouc-Wen parameters [1/m, -, -].
    stroke : float
        :math:`X_{max} - X_{min}` [m].
    strict : bool
        Raise :class:`InputError` below :data:`MIN_RHO_STROKE`; otherwise only warn.

    Warns
    -----
    ExcitationWarning
        If :math:`\\rho \\cdot \\mathrm{stroke}` is below :data:`RECOMMENDED_RHO_STROKE`.
    """
    rho_stroke = rho * stroke
    w0 = limit_cycle_peak(rho_stroke, sigma, n)
    message = (f"excitation: rho*(X_max - X_min) = {rho_stroke:.3g} (rho = {rho:.4g} 1/m, stroke = "
               f"{stroke:.4g} m) gives a limit-cycle peak w0 = {w0:.3f}")
    if rho_stroke < MIN_RHO_STROKE:
        text = (message + f"; the closed-form steps need rho*stroke >= {MIN_RHO_STROKE:g} "
                f"(plastic assumption w0 ~ 1): increase the test amplitude")
        if strict:
            raise InputError(text)
        warnings.warn(text, ExcitationWarning, stacklevel=2)
    elif rho_stroke < RECOMMENDED_RHO_STROKE:
        warnings.warn(message + f"; below the recommended {RECOMMENDED_RHO_STROKE:g}, the closed-form "
                      "start is biased (the refinement corrects it)", ExcitationWarning, stacklevel=2)
    return rho_stroke, w0
