"""Identification of a hysteretic oscillator (:mod:`damper.hysteresis.oscillator`) from u and y.

Output-error least squares on the simulated displacement, in three steps, each physically reasoned:

1. **Linear part, frequency domain.** The best linear approximation
   :math:`H(f) = S_{uy}/S_{uu}` (Welch) is fitted by :math:`1/H = k_e - m\\omega^2 + j c_e\\omega`
   (linear least squares weighted by :math:`|H|^2` times the coherence, i.e. approximately an
   output error). The mass :math:`m` is a linear quantity, so it is estimated well here;
   :math:`k_e` and :math:`c_e` lump the hysteretic element's stiffness and dissipation.
2. **Hysteresis, equation error.** With :math:`m` known, the restoring force
   :math:`r = u - m\\ddot y = c\\dot y + k y + \\kappa_w w` (:math:`\\dot y`, :math:`\\ddot y` from the
   low-passed displacement) is linear in :math:`(c, k, \\kappa_w)` once the shape
   :math:`(\\rho, \\sigma, n, s)` fixes :math:`w(t)`, which depends on the displacement path only.
   A grid of shapes is scanned with linear least squares for the coefficients (variable
   projection, as :mod:`damper.diagnosis.base_fit` does for the damper), and the best shape is
   refined continuously.
3. **Output error.** All seven parameters are refined jointly by minimising
   :math:`\\sum_k (\\hat y_k(p) - y_k)^2` over the fit window, :math:`\\hat y` simulated from rest with
   the compiled Newmark kernel at ``upsample`` steps per sample, with the same engine as the
   damper identification (:func:`damper.identification.refine.fit_scaled`). The search runs on
   :math:`(m, c, k, \\alpha, \\theta_\\gamma, \\theta_\\delta, \\nu)` with
   :math:`\\theta_\\gamma = \\beta\\gamma Z^\\nu/\\alpha`,
   :math:`\\theta_\\delta = \\beta\\delta Z^\\nu/\\alpha` and
   :math:`Z` the start's RMS hysteretic force: dimensionless, continuous through
   :math:`\\gamma + \\delta = 0` (where the normalized form changes branch) and well conditioned
   in :math:`\\nu`.

The first ``skip`` seconds are left out of the fit window (default: the time for a transient of
the start's linear part to decay by :math:`10^{-4}`, at most a quarter of the record), so that
data that do not start at rest are fitted as well as data that do.

Uncertainty: the Jacobian at the optimum gives :math:`\\mathrm{cov} = s^2(J^TJ)^{-1}`
(:func:`~damper.fitting.jacobian_covariance`), mapped to the normalized and the
benchmark's parameters by the delta method. It assumes white output noise; read it as a lower
bound otherwise.
"""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass, field

import numba
import numpy as np

from benchmark.foundation.errors import InputError, NumericalError, ParameterError
from damper.hysteresis.oscillator import (DEFAULT_UPSAMPLE, PARAMETER_UNITS, HystereticOscillator,
                                          upsample_force)
from damper.hysteresis.oscillator_kernel import newmark_bouc_wen
from damper.fitting import jacobian_covariance
from damper.identification.refine import fit_scaled

__all__ = ["HystereticFit", "identify_hysteretic", "linear_start", "hysteresis_start",
           "MIN_SAMPLES", "SEARCH_NAMES"]

#: Fewest samples accepted (the frequency-domain start needs a few hundred).
MIN_SAMPLES = 256
#: The coordinates of the output-error search.
SEARCH_NAMES = ("mass", "damping", "stiffness", "alpha", "theta_gamma", "theta_delta", "nu")
_NU_MAX = 10.0
_SEARCH_UPSAMPLE = 5
_START_SAMPLES = 16384
# Shape grid of step 2: rho times the displacement RMS, sigma, n, branch.
_RHO_GRID = (0.03, 0.1, 0.3, 1.0, 3.0, 10.0)
_SIGMA_GRID = (-4.0, -2.0, -1.0, 0.0, 0.5, 1.0, 2.0)
_N_GRID = (1.0, 2.0)


@dataclass(frozen=True)
class HystereticFit:
    """Result of :func:`identify_hysteretic`.

    Attributes
    ----------
    model : HystereticOscillator
        The identified model.
    start : HystereticOscillator
        The start of the output-error search (steps 1-2).
    linear : dict
        Step 1: ``mass``, ``stiffness`` (:math:`k_e`), ``damping`` (:math:`c_e`) [SI],
        ``natural_frequency`` [Hz], ``damping_ratio``, ``band`` [Hz].
    standard_error : dict
        Standard errors of the normalized parameters and of :math:`\\alpha`,
        :math:`\\beta\\gamma`, :math:`\\beta\\delta`, :math:`\\nu` (SI).
    correlation : ndarray
        Correlation matrix of the search coordinates (:data:`SEARCH_NAMES`).
    fit_window : (int, int)
        First and one-past-last sample of the fit window.
    rms_error : float
        RMS error of the simulated displacement over the fit window [m].
    rms_displacement : float
        RMS of the measured displacement over the fit window [m].
    nfev : int
        Simulations used by the output-error search.
    elapsed : float
        Wall time of the identification [s].
    cpu_time : float
        Processor time of the identification (this process) [s].
    stages : list of dict
        Per output-error stage: ``upsample``, ``iterations``, ``simulations``, ``status`` (that of
        :func:`scipy.optimize.least_squares`; 0: iteration cap reached).
    warnings : list of str
        Conditions that make the estimates less trustworthy (iteration cap reached, parameter at
        a bound, stiffness and hysteresis not separable because the hysteresis is barely excited).
    success : bool
        The search converged (not stopped by the iteration cap).
    message : str
    """

    model: HystereticOscillator
    start: HystereticOscillator
    linear: dict
    standard_error: dict
    correlation: np.ndarray = field(repr=False)
    fit_window: tuple
    rms_error: float
    rms_displacement: float
    nfev: int
    elapsed: float
    cpu_time: float
    stages: list
    warnings: list
    success: bool
    message: str

    def to_dict(self) -> dict:
        """JSON-ready summary (SI units, named in ``units``)."""
        std = self.model.to_standard(beta=1.0)
        return {
            "model": "hysteretic_oscillator",
            "parameters": self.model.parameters(),
            "standard_form": std,
            "standard_form_note": "beta is the free scale of the standard form, set to 1",
            "standard_error": self.standard_error,
            "correlation": {"names": list(SEARCH_NAMES),
                            "matrix": np.where(np.isfinite(self.correlation), self.correlation,
                                               None).tolist()},
            "units": {**PARAMETER_UNITS, "alpha": "N/m", "beta*gamma": "N^(1-nu)/m",
                      "beta*delta": "N^(1-nu)/m", "nu": "1", "rms_error": "m"},
            "start": self.start.parameters(),
            "linear_start": self.linear,
            "fit_window": list(self.fit_window),
            "rms_error": self.rms_error,
            "rms_displacement": self.rms_displacement,
            "nfev": self.nfev,
            "elapsed_s": self.elapsed,
            "cpu_time_s": self.cpu_time,
            "stages": self.stages,
            "warnings": self.warnings,
            "success": self.success,
            "message": self.message,
        }


# ------------------------------------------------------------------ checks

def _check(force, displacement, fs) -> tuple[np.ndarray, np.ndarray, float]:
    u = np.asarray(force, dtype=float)
    y = np.asarray(displacement, dtype=float)
    if u.ndim != 1 or y.shape != u.shape:
        raise InputError(f"force and displacement: expected 1-D arrays of equal length, got "
                         f"shapes {u.shape} and {y.shape}")
    if u.size < MIN_SAMPLES:
        raise InputError(f"data: expected at least {MIN_SAMPLES} samples, got {u.size}")
    for name, a in (("force", u), ("displacement", y)):
        if not np.all(np.isfinite(a)):
            i = int(np.argmax(~np.isfinite(a)))
            raise InputError(f"{name}: expected finite values, sample {i} is {a[i]}")
    if not np.ptp(u) > 0:
        raise InputError("force: constant; the identification needs an excitation")
    if not np.ptp(y) > 0:
        raise InputError("displacement: constant; the oscillator must move")
    fs = float(fs)
    if not (fs > 0 and math.isfinite(fs)):
        raise InputError(f"sampling rate: expected > 0 Hz, got {fs}")
    return u, y, fs


# ------------------------------------------------------------------ step 1

def linear_start(force: np.ndarray, displacement: np.ndarray, fs: float) -> dict:
    """Best linear approximation :math:`1/H = k_e - m\\omega^2 + jc_e\\omega` (step 1).

    Parameters
    ----------
    force : np.ndarray
        Input force [N].
    displacement : np.ndarray
        Output displacement [m].
    fs : float
        Sampling rate [Hz].

    Returns
    -------
    dict
        ``mass`` [kg], ``stiffness`` [N/m], ``damping`` [N s/m], ``natural_frequency`` [Hz],
        ``damping_ratio`` [-], ``band`` ([f_min, f_max] used, Hz).

    Raises
    ------
    NumericalError
        The frequency response does not look like a mass-spring-damper (e.g. negative mass).
    """
    from scipy import signal  # imported here: 0.37 s that every `sbib` command would pay at start

    u, y, fs = _check(force, displacement, fs)
    nper = int(2 ** math.floor(math.log2(max(u.size / 8, 64))))
    nper = min(nper, 8192)
    f, suu = signal.welch(u - u.mean(), fs, nperseg=nper)
    _, suy = signal.csd(u - u.mean(), y - y.mean(), fs, nperseg=nper)
    _, syy = signal.welch(y - y.mean(), fs, nperseg=nper)
    with np.errstate(divide="ignore", invalid="ignore"):
        h = suy / suu
        coh = np.abs(suy) ** 2 / (suu * syy)
    use = (f > 0) & (suu > 1e-3 * suu.max()) & np.isfinite(h) & (coh > 0.3) & (np.abs(h) > 0)
    if use.sum() < 3:
        raise NumericalError("identification: fewer than 3 frequencies with a usable input/output "
                             "coherence", hint="the force must excite the oscillator over a band")
    w = 2 * np.pi * f[use]
    inv = 1.0 / h[use]
    weight = np.abs(h[use]) * np.sqrt(coh[use])
    # Re(1/H) = k - m w^2 ; Im(1/H) = c w  (H = Y/U: displacement per force)
    a_re = np.column_stack([np.ones_like(w), -w ** 2]) * weight[:, None]
    k_e, m = np.linalg.lstsq(a_re, inv.real * weight, rcond=None)[0]
    c_e = float(np.sum(weight ** 2 * w * inv.imag) / np.sum(weight ** 2 * w ** 2))
    if not (m > 0 and k_e > 0):
        raise NumericalError(f"identification: the frequency response gives mass {m:.3g} kg and "
                             f"stiffness {k_e:.3g} N/m; expected positive values",
                             hint="check that the data are force [N] in and displacement [m] out")
    c_e = max(c_e, 1e-6 * math.sqrt(k_e * m))
    wn = math.sqrt(k_e / m)
    return {"mass": float(m), "stiffness": float(k_e), "damping": float(c_e),
            "natural_frequency": wn / (2 * math.pi), "damping_ratio": c_e / (2 * math.sqrt(k_e * m)),
            "band": [float(f[use].min()), float(f[use].max())]}


# ------------------------------------------------------------------ step 2

@numba.njit(cache=True)
def _w_path(y, rho, sigma, n, branch, out):
    """w along the displacement path y (rate-independent, RK4 in displacement); False on blow-up."""
    w = 0.0
    out[0] = 0.0
    for i in range(1, y.shape[0]):
        dy = y[i] - y[i - 1]
        if dy == 0.0:
            out[i] = w
            continue
        d = 1.0 if dy > 0 else -1.0
        growth = rho * abs(dy) * (1.0 + n * (abs(sigma) + abs(1.0 - sigma)) * max(1.0, abs(w)) ** n)
        m = int(min(max(1.0, math.ceil(growth / 0.3)), 100.0))
        step = dy / m
        for _ in range(m):
            k1 = _dw(w, d, rho, sigma, n, branch)
            k2 = _dw(w + 0.5 * step * k1, d, rho, sigma, n, branch)
            k3 = _dw(w + 0.5 * step * k2, d, rho, sigma, n, branch)
            k4 = _dw(w + step * k3, d, rho, sigma, n, branch)
            w += step * (k1 + 2 * k2 + 2 * k3 + k4) / 6.0
        if not (abs(w) < 1e6):
            return False
        out[i] = w
    return True


@numba.njit(cache=True, inline="always")
def _dw(w, d, rho, sigma, n, branch):
    aw = abs(w)
    p = aw if n == 1.0 else aw ** n
    sw = 1.0 if w > 0 else (-1.0 if w < 0 else 0.0)
    return rho * (1.0 - branch * p * (sigma * d * sw + 1.0 - sigma))


def _smooth_derivatives(y: np.ndarray, fs: float, cutoff: float) -> tuple[np.ndarray, ...]:
    """Low-passed y and its first two derivatives (zero-phase Butterworth, then spectral)."""
    from scipy import signal  # see linear_start

    wn = min(cutoff / (0.5 * fs), 0.95)
    sos = signal.butter(6, wn, output="sos")
    ys = signal.sosfiltfilt(sos, y)
    n = ys.size
    # Spectral derivatives of the (mirrored, hence smoothly periodic) record.
    ext = np.concatenate([ys, ys[::-1]])
    om = 2 * np.pi * np.fft.rfftfreq(ext.size, 1.0 / fs)
    spec = np.fft.rfft(ext)
    v = np.fft.irfft(1j * om * spec, ext.size)[:n]
    a = np.fft.irfft(-(om ** 2) * spec, ext.size)[:n]
    return ys, v, a


@dataclass
class _EquationError:
    """Residual r - (c ydot + k y + kappa_w w) for a shape; linear part by least squares."""

    y: np.ndarray
    v: np.ndarray
    r: np.ndarray
    window: slice
    y_rms: float

    def linear(self, rho, sigma, n, branch):
        w = np.empty(self.y.size)
        if not _w_path(self.y, rho, sigma, n, branch, w):
            return None
        a = np.column_stack([self.v, self.y, w])[self.window]
        b = self.r[self.window]
        scale = np.sqrt(np.mean(a ** 2, axis=0))
        if not np.all(scale > 0):
            return None
        coef, *_ = np.linalg.lstsq(a / scale, b, rcond=None)
        coef = coef / scale
        res = a @ coef - b
        return coef, res


def hysteresis_start(force: np.ndarray, displacement: np.ndarray, fs: float, linear: dict,
                     window: slice | None = None) -> HystereticOscillator:
    """Step 2: the normalized hysteresis and (c, k) by equation error, given the mass.

    Parameters
    ----------
    force, displacement : ndarray
        Samples [N, m].
    fs : float
        Sampling rate [Hz].
    linear : dict
        Result of :func:`linear_start` (its ``mass`` and ``band`` are used).
    window : slice, optional
        Samples used (default: all but 5 % at each end, against the filter's edge effects).

    Returns
    -------
    HystereticOscillator
    """
    u, y, fs = _check(force, displacement, fs)
    m = linear["mass"]
    cutoff = min(max(2.0 * linear["band"][1], 3.0 * linear["natural_frequency"]), 0.45 * fs)
    ys, v, a = _smooth_derivatives(y - y.mean(), fs, cutoff)
    from scipy import signal  # see linear_start

    us = signal.sosfiltfilt(signal.butter(6, min(cutoff / (0.5 * fs), 0.95), output="sos"), u)
    r = us - m * a
    if window is None:
        edge = max(u.size // 20, 1)
        window = slice(edge, u.size - edge)
    y_rms = float(np.sqrt(np.mean(ys[window] ** 2)))
    problem = _EquationError(ys, v, r, window, y_rms)
    scored = []
    for rho_y, sigma, n, branch in itertools.product(_RHO_GRID, _SIGMA_GRID, _N_GRID, (1, -1)):
        got = problem.linear(rho_y / y_rms, sigma, n, branch)
        if got is None:
            continue
        coef, res = got
        if not (coef[2] > 0):
            continue
        scored.append((float(res @ res), rho_y / y_rms, sigma, n, branch))
    if not scored:
        raise NumericalError("identification: no hysteresis shape of the start grid fits the "
                             "restoring force", hint="check the units and the sign of the data")
    scored.sort()
    best = None
    for rss, rho, sigma, n, branch in scored[:2]:
        refined = _refine_shape(problem, rho, sigma, n, branch)
        if refined is not None and (best is None or refined[0] < best[0]):
            best = refined
        elif best is None:
            best = (rss, rho, sigma, n, branch)
    _, rho, sigma, n, branch = best
    coef, _ = problem.linear(rho, sigma, n, branch)
    c, k, kappa_w = (float(x) for x in coef)
    c = max(c, 1e-3 * linear["damping"])
    return HystereticOscillator(m, c, k, kappa_w, rho, sigma, n, branch)


class _ShapeProblem:
    """Equation error over (log rho, sigma, n) for a fixed branch, for the engine."""

    def __init__(self, problem: _EquationError, rho0: float, sigma0: float, n0: float, branch: int):
        self.problem, self.rho0, self.branch = problem, rho0, branch
        # A start only: the shape is kept in a plausible box (the output-error search is not).
        self.lower = np.array([-5.0, -10.0, 1.0])
        self.upper = np.array([5.0, 10.0, 6.0])
        self.q0 = np.array([0.0, sigma0, n0])
        self.size = problem.r[problem.window].size
        self.scale = float(np.sqrt(np.mean(problem.r[problem.window] ** 2))) or 1.0

    def shape(self, q):
        return self.rho0 * math.exp(q[0]), float(q[1]), float(q[2])

    def residuals(self, q):
        got = self.problem.linear(*self.shape(q), self.branch)
        if got is None:
            return np.full(self.size, 1e3)
        return got[1] / self.scale


def _refine_shape(problem, rho, sigma, n, branch):
    sp = _ShapeProblem(problem, rho, sigma, n, branch)
    try:
        sol = fit_scaled(sp, sp.q0, 40)
    except (ValueError, FloatingPointError):
        return None
    got = problem.linear(*sp.shape(sol.x), branch)
    if got is None or not got[0][2] > 0:
        return None
    return (float(got[1] @ got[1]),) + sp.shape(sol.x) + (branch,)


# ------------------------------------------------------------------ step 3

class _OutputError:
    """Simulated-displacement residuals on the search coordinates q = p / scale (see module)."""

    def __init__(self, u, y, fs, upsample, window, start: HystereticOscillator, z_ref: float):
        self.u, self.y, self.fs, self.upsample = u, y, fs, upsample
        self.window = window
        self.z_ref = z_ref
        alpha, bg, bd, nu = start.kernel_coefficients()
        p0 = np.array([start.mass, start.damping, start.stiffness, alpha,
                       bg * z_ref ** nu / alpha, bd * z_ref ** nu / alpha, nu])
        k_scale = abs(start.stiffness) + alpha
        self.scale = np.array([p0[0], max(p0[1], 1e-6 * math.sqrt(k_scale * p0[0])), k_scale,
                               alpha, max(1.0, abs(p0[4])), max(1.0, abs(p0[5])), 1.0])
        self.q0 = p0 / self.scale
        self.lower = np.array([1e-6, 0.0, -np.inf, 1e-6, -np.inf, -np.inf, 1.0]) / self.scale
        self.upper = np.array([np.inf, np.inf, np.inf, np.inf, np.inf, np.inf, _NU_MAX]) / self.scale
        self.y_scale = float(np.sqrt(np.mean(y[window] ** 2))) or 1.0
        self.nsim = 0
        self.n_sim = window.stop  # simulate only up to the end of the window

    def physical(self, q) -> np.ndarray:
        return np.asarray(q, dtype=float) * self.scale

    def kernel(self, q):
        m, c, k, alpha, tg, td, nu = self.physical(q)
        zn = self.z_ref ** nu
        return m, c, k, alpha, tg * alpha / zn, td * alpha / zn, nu

    def model(self, q) -> HystereticOscillator:
        return HystereticOscillator.from_kernel(*self.kernel(q))

    def simulate(self, q) -> np.ndarray:
        self.nsim += 1
        m, c, k, alpha, bg, bd, nu = self.kernel(q)
        if not (m > 0 and c >= 0 and alpha > 0 and nu >= 1):
            return np.full(self.n_sim, np.nan)
        h = 1.0 / (self.fs * self.upsample)
        out = np.empty((self.n_sim, 3))
        newmark_bouc_wen(self.u_fine, h, m, c, k, alpha, bg, bd, nu, 0.0, 0.0, 0.0,
                         self.upsample, out)
        return out[:, 0]

    def residuals(self, q) -> np.ndarray:
        r = (self.simulate(q)[self.window] - self.y[self.window]) / self.y_scale
        if not np.all(np.isfinite(r)):
            return np.full(r.size, 1e3)
        return r


def _settling_samples(linear: dict, fs: float) -> int:
    zeta, fn = linear["damping_ratio"], linear["natural_frequency"]
    return int(math.ceil(math.log(1e4) / (2 * math.pi * fn * max(zeta, 1e-4)) * fs))


def identify_hysteretic(force: np.ndarray, displacement: np.ndarray, fs: float,
                        upsample: int = DEFAULT_UPSAMPLE, skip: float | None = None,
                        max_nfev: int = 40, search_upsample: int | None = None,
                        polish_nfev: int = 10) -> HystereticFit:
    """Identify a :class:`~damper.hysteresis.oscillator.HystereticOscillator` (module docstring).

    Parameters
    ----------
    force, displacement : ndarray, shape (n,)
        Input force [N] and output displacement [m], sampled at ``fs`` from the start of the
        excitation (the model is simulated from rest; see ``skip``).
    fs : float
        Sampling rate [Hz].
    upsample : int
        Integration steps per sample of the final model (the benchmark's 20).
    skip : float, optional
        Seconds left out at the start of the fit window (default: see the module docstring).
    max_nfev : int
        Cap on the iterations (residual evaluations) of the output-error search; each costs one
        simulation plus seven for its finite-difference Jacobian.
    search_upsample : int, optional
        Integration steps per sample during the search (default 5, four times cheaper than the
        benchmark's 20 and within 1e-3 of its response); the search then ends with at most
        ``polish_nfev`` iterations at ``upsample``.
    polish_nfev : int
        Cap on the iterations at ``upsample`` after a coarser search.

    Returns
    -------
    HystereticFit

    Raises
    ------
    InputError
        Malformed data (lengths, NaN, constant signals, too short).
    NumericalError
        No start could be found, or the output-error search did not converge.
    """
    t0 = time.perf_counter()
    c0 = time.process_time()
    u, y, fs = _check(force, displacement, fs)
    upsample = int(upsample)
    if upsample < 1:
        raise InputError(f"upsample: expected >= 1, got {upsample}")
    linear = linear_start(u, y, fs)
    # The start needs no more than a few thousand samples (it is refined by the output error).
    n_start = min(u.size, _START_SAMPLES)
    start = hysteresis_start(u[:n_start], y[:n_start], fs, linear)
    if skip is not None and not (float(skip) >= 0 and math.isfinite(float(skip))):
        raise InputError(f"skip: expected a finite number >= 0 s, got {skip}")
    if skip is not None and int(round(float(skip) * fs)) > u.size // 4:
        # it had been cut to a quarter of the record without a word
        raise InputError(f"skip: {float(skip):g} s is more than a quarter of the fitted record "
                         f"({u.size / fs:g} s); expected at most {u.size // 4 / fs:g} s")
    n_skip = _settling_samples(linear, fs) if skip is None else int(round(float(skip) * fs))
    n_skip = min(n_skip, u.size // 4)
    window = slice(n_skip, u.size)
    # Reference force of the theta coordinates: RMS of the start's hysteretic force.
    z_start = start.simulate(u, fs, upsample=max(2, min(upsample, 5)), states=True)[:, 2]
    z_ref = float(np.sqrt(np.mean(z_start ** 2)))
    if not (z_ref > 0 and math.isfinite(z_ref)):
        z_ref = start.kappa_w
    problem = _OutputError(u, y, fs, upsample, window, start, z_ref)

    q = problem.q0
    nfev = 0
    stages = []
    search_upsample = min(_SEARCH_UPSAMPLE, upsample) if search_upsample is None else int(search_upsample)
    if search_upsample < 1:
        raise InputError(f"search_upsample: expected >= 1, got {search_upsample}")
    if search_upsample < upsample:
        stages.append((search_upsample, max_nfev))
        stages.append((upsample, polish_nfev))
    else:
        stages.append((upsample, max_nfev))
    sol = None
    stage_log: list[dict] = []
    for ups, cap in stages:
        problem.upsample = ups
        problem.u_fine = upsample_force(u, ups)[:(u.size - 1) * ups + 1]
        r0 = problem.residuals(q)
        if np.all(r0 == 1e3):
            raise NumericalError("identification: the start cannot be simulated",
                                 state=start.parameters(), hint="check the data's units")
        sol = fit_scaled(problem, q, cap)
        q = sol.x
        stage_log.append({"upsample": ups, "iterations": int(sol.nfev), "simulations": problem.nsim,
                          "status": int(sol.status)})
        nfev += problem.nsim
        problem.nsim = 0
    try:
        model = problem.model(q)
    except ParameterError as exc:
        raise NumericalError(f"identification: the search ended outside the model class ({exc})",
                             hint="the data may not be an oscillator with Bouc-Wen hysteresis") from None
    res = sol.fun * problem.y_scale
    rms = float(np.sqrt(np.mean(res ** 2)))
    y_rms = float(np.sqrt(np.mean(y[window] ** 2)))
    if not (np.isfinite(rms) and rms < 0.5 * y_rms):
        raise NumericalError(f"identification: the fit did not converge (RMS error {rms:.3g} m for "
                             f"a displacement RMS of {y_rms:.3g} m)",
                             hint="the data may not be an oscillator with Bouc-Wen hysteresis"
                                  + _offset_hint(y[window]))
    cov = jacobian_covariance(sol.jac, sol.fun, problem.scale)
    std, corr = _uncertainty(problem, q, cov)
    warnings = []
    offset = _offset_warning(u, y)
    if offset:
        warnings.append(offset)
    bias = float(np.mean(res))
    if not offset and rms > 0 and abs(bias) > OFFSET_SHARE * rms:
        # the model has no output offset: a displacement channel zeroed off by c leaves a residual of
        # mean c (a probe's +0.5 mm gave an RMS error of exactly 0.5 mm and biased c and k)
        warnings.append(f"the residual has a mean of {bias:.3g} m, {100 * abs(bias) / rms:.0f} % of its RMS: the "
                        "displacement channel's zero is off by about that (the model has no offset); subtract it "
                        "and fit again")
    converged = all(st["status"] > 0 for st in stage_log[:1])
    if not converged:
        warnings.append(f"the search stopped at its cap of {max_nfev} iterations before converging")
    if np.isclose(model.n, 1.0, rtol=0, atol=1e-9):
        warnings.append("nu is at its lower bound 1 (its standard error is one-sided)")
    k_alpha = corr[2, 3]
    if np.isfinite(k_alpha) and abs(k_alpha) > 0.995:
        warnings.append(f"stiffness and alpha are nearly inseparable (correlation {k_alpha:.4f}): "
                        "the data barely excite the hysteresis")
    return HystereticFit(model=model, start=start, linear=linear, standard_error=std,
                         correlation=corr, fit_window=(window.start, window.stop), rms_error=rms,
                         rms_displacement=y_rms, nfev=nfev, elapsed=time.perf_counter() - t0,
                         cpu_time=time.process_time() - c0, stages=stage_log, warnings=warnings,
                         success=converged, message=str(sol.message))


#: Share of the residual's RMS above which its mean is named as a displacement zero offset.
OFFSET_SHARE = 0.5


#: A displacement whose mean exceeds this share of its spread, under a force of (nearly) zero
#: mean, is named as a zero offset before the fit: the model can bend a part of an offset into
#: its hysteresis, so the residual alone may not show it (the benchmark's data: 0.02).
OFFSET_SPREAD = 0.25


def _offset_warning(u: np.ndarray, y: np.ndarray) -> str | None:
    """A warning for a displacement that sits off zero under a force of zero mean, or None."""
    mean, spread = float(np.mean(y)), float(np.std(y))
    if spread > 0 and abs(mean) > OFFSET_SPREAD * spread and abs(float(np.mean(u))) < 0.1 * float(np.std(u)):
        return (f"the displacement's mean is {mean:.3g} m, {abs(mean) / spread:.2g} of its motion about it, under a "
                "force of zero mean: a zero offset of the displacement channel? The model has no offset: subtract "
                "it and fit again")
    return None


def _offset_hint(y: np.ndarray) -> str:
    """``"; or ..."`` naming a displacement whose mean dwarfs its motion (a zero offset), else ``""``."""
    mean, spread = float(np.mean(y)), float(np.std(y))
    if abs(mean) > OFFSET_SHARE * spread:
        return (f"; or its displacement carries a zero offset (mean {mean:.3g} m against {spread:.3g} m of motion "
                "about it): subtract it")
    return ""


def _derived(problem: _OutputError, q) -> dict[str, float]:
    m, c, k, alpha, bg, bd, nu = problem.kernel(q)
    out = {"mass": m, "damping": c, "stiffness": k, "alpha": alpha, "beta*gamma": bg,
           "beta*delta": bd, "nu": nu}
    try:
        model = HystereticOscillator.from_kernel(m, c, k, alpha, bg, bd, nu)
        out.update(kappa_w=model.kappa_w, rho=model.rho, sigma=model.sigma, n=model.n)
    except ParameterError:
        out.update(kappa_w=math.nan, rho=math.nan, sigma=math.nan, n=math.nan)
    return out


def _uncertainty(problem: _OutputError, q, cov) -> tuple[dict, np.ndarray]:
    """Delta-method standard errors of the derived parameters; correlation of the search ones."""
    base = _derived(problem, q)
    names = list(base)
    grad = np.zeros((len(names), q.size))
    for j in range(q.size):
        dq = 1e-6 * max(1.0, abs(q[j]))
        qp = q.copy()
        qp[j] += dq
        plus = _derived(problem, qp)
        grad[:, j] = [(plus[k] - base[k]) / (dq * problem.scale[j]) for k in names]
    var = np.einsum("ij,jk,ik->i", grad, cov, grad)
    std = {k: float(math.sqrt(v)) if v >= 0 else math.nan for k, v in zip(names, var)}
    d = np.sqrt(np.clip(np.diag(cov), 0, None))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(d, d)
    return std, corr
