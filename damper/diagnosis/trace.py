"""Residual tracing: where the force residual lives, and whether what is left is white.

For a residual :math:`r = F - \\hat F` (measured minus model, over the held-out samples) and a
variable :math:`z` (displacement, velocity, ...), the *share of residual variance explained by
z* is the bias-adjusted correlation ratio of a binned partial dependence:

.. math::

   \\eta^2_z = \\frac{\\sum_g n_g (\\bar r_g - \\bar r)^2}{\\sum_k (r_k - \\bar r)^2}, \\qquad
   \\eta^2_{z,\\text{adj}} = 1 - (1 - \\eta^2_z)\\frac{N - 1}{N - G},

with :math:`G` equal-count bins of :math:`z` (quantiles) and :math:`\\bar r_g` the mean residual
in bin :math:`g`. It is nonparametric (any function of :math:`z`, not only a line) and near 0
for a residual independent of :math:`z`. Variables:

``displacement``, ``velocity``, ``acceleration``
    the prescribed motion;
``voltage``, ``voltage_rate``
    the coil input (the current when the tests give currents) and its time derivative;
``time``
    time since the start of each test (slow drifts: heating, fade); when a ``cycle`` signal
    (one label per period of the motion) is given, the bins are whole cycles, so that a
    periodic residual is not mistaken for a drift;
``sign``
    the sign of the motion (:math:`\\dot x > 0` or not, two groups);
``loop``
    the displacement on each branch separately (bins of :math:`x` within each sign of
    :math:`\\dot x`): the position along the hysteresis loop, where branch-dependent structure
    that cancels in the plain displacement shows up.

The mean of the residual is reported apart (``mean``: :math:`\\bar r^2/\\overline{r^2}`, the share
of the mean square that is a constant offset), since a constant is explained by no variable.

Whiteness: the Ljung-Box statistic :math:`Q = N(N+2)\\sum_{k=1}^{h}\\hat\\rho_k^2/(N-k)`, compared
with :math:`\\chi^2_h` (Ljung & Box 1978). Densely sampled, filtered measurements are never
white even when the model is right, so the loop does not decide on it alone; it also reports
the lag-one autocorrelation, an effective sample size :math:`N/\\tau` with the integrated
autocorrelation time :math:`\\tau = 1 + 2\\sum_k\\hat\\rho_k` summed while the autocorrelation
stays positive (Geyer 1992), and the fraction of the variance that looks like white noise,
:math:`\\overline{(\\Delta r)^2}/(2\\,\\mathrm{var}\\,r)`.

References
----------
Ljung G.M., Box G.E.P. (1978) *On a measure of lack of fit in time series models*,
Biometrika 65(2).
Geyer C.J. (1992) *Practical Markov chain Monte Carlo*, Statistical Science 7(4).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from benchmark.foundation.errors import InputError

__all__ = [
    "TRACE_VARIABLES",
    "Profile",
    "ResidualTrace",
    "trace_residual",
    "correlation_ratio",
    "autocorrelation",
    "ljung_box",
    "effective_sample_size",
    "heldout_bic",
    "bic_delta",
]

#: Variables a residual is traced against (``sign`` and ``loop`` derive from the motion).
TRACE_VARIABLES = ("displacement", "velocity", "acceleration", "voltage", "voltage_rate", "time",
                   "sign", "loop")
DEFAULT_BINS = 20
DEFAULT_LAGS = 20


@dataclass(frozen=True)
class Profile:
    """Binned partial dependence of the residual on one variable.

    Attributes
    ----------
    variable : str
    centers : ndarray
        Median of the variable in each bin (for ``loop``: the displacement, see ``branch``).
    means : ndarray
        Mean residual in each bin [N].
    counts : ndarray
        Samples per bin.
    branch : ndarray
        For ``loop`` and ``sign``: the sign of the velocity of each bin (+1, -1); else zeros.
    share : float
        Adjusted correlation ratio (share of residual variance explained).
    constant : bool
        The variable does not vary over the samples (share 0 by definition).
    """

    variable: str
    centers: np.ndarray
    means: np.ndarray
    counts: np.ndarray
    branch: np.ndarray
    share: float
    constant: bool = False


def _groups_quantile(z: np.ndarray, bins: int) -> np.ndarray:
    """Group labels of equal-count bins of ``z`` (ties kept together)."""
    edges = np.unique(np.quantile(z, np.linspace(0.0, 1.0, bins + 1)[1:-1]))
    return np.searchsorted(edges, z, side="right")


def correlation_ratio(residual: np.ndarray, groups: np.ndarray) -> float:
    """Bias-adjusted correlation ratio of ``residual`` on integer ``groups`` (0 if it explains nothing).

    See the module docstring; clipped to [0, 1].

    Parameters
    ----------
    residual : np.ndarray
        Force residual, measured minus model [N], in sample order.
    groups : np.ndarray
        Integer group label of each sample (a binned variable).
    """
    r = np.asarray(residual, dtype=float)
    g = np.asarray(groups)
    n = r.size
    _, inverse, counts = np.unique(g, return_inverse=True, return_counts=True)
    n_groups = counts.size
    if n_groups < 2 or n <= n_groups:
        return 0.0
    centred = r - r.mean()
    total = float(np.sum(centred ** 2))
    if total <= 0.0:
        return 0.0
    sums = np.bincount(inverse, weights=centred)
    between = float(np.sum(sums ** 2 / counts))
    eta2 = between / total
    adjusted = 1.0 - (1.0 - eta2) * (n - 1) / (n - n_groups)
    return float(min(max(adjusted, 0.0), 1.0))


def _profile(variable, residual, z, groups, branch_of_group=None) -> Profile:
    labels, inverse, counts = np.unique(groups, return_inverse=True, return_counts=True)
    means = np.bincount(inverse, weights=residual) / counts
    centers = np.array([np.median(z[inverse == j]) for j in range(labels.size)])
    branch = (np.zeros(labels.size) if branch_of_group is None
              else np.array([branch_of_group(lab) for lab in labels], dtype=float))
    return Profile(variable, centers, means, counts, branch, correlation_ratio(residual, groups))


def autocorrelation(residual: np.ndarray, max_lag: int | None = None) -> np.ndarray:
    """Sample autocorrelation :math:`\\hat\\rho_0 = 1, \\hat\\rho_1, \\ldots` (FFT, biased estimator).

    Parameters
    ----------
    residual : np.ndarray
        Force residual, measured minus model [N], in sample order.
    max_lag : int | None, optional
        Largest lag returned; None: all.
    """
    r = np.asarray(residual, dtype=float) - np.mean(residual)
    n = r.size
    max_lag = n - 1 if max_lag is None else min(int(max_lag), n - 1)
    size = 1 << int(np.ceil(np.log2(2 * n)))
    spec = np.fft.rfft(r, size)
    acov = np.fft.irfft(spec * np.conj(spec), size)[:max_lag + 1]
    if acov[0] <= 0:
        out = np.zeros(max_lag + 1)
        out[0] = 1.0
        return out
    return acov / acov[0]


def ljung_box(residual: np.ndarray, lags: int = DEFAULT_LAGS) -> tuple[float, float, int]:
    """Ljung-Box statistic, its :math:`\\chi^2_h` p-value and the number of lags ``h`` used.

    Parameters
    ----------
    residual : np.ndarray
        Force residual, measured minus model [N], in sample order.
    lags : int, optional
        Number of lags h (fewer for a short residual).
    """
    n = int(np.size(residual))
    h = int(max(1, min(lags, n // 5)))
    rho = autocorrelation(residual, h)[1:h + 1]
    k = np.arange(1, h + 1)
    q = float(n * (n + 2) * np.sum(rho ** 2 / (n - k)))
    from scipy.stats import chi2  # only where a trace is tested (damper/diagnosis/dataset.py says why)

    return q, float(chi2.sf(q, h)), h


def effective_sample_size(residual: np.ndarray) -> float:
    """:math:`N/\\tau`, :math:`\\tau = 1 + 2\\sum_k \\hat\\rho_k` over the initial positive sequence.

    For white noise about :math:`N`; for a smooth, periodic residual about four per period.
    Clipped to [1, N].

    Parameters
    ----------
    residual : np.ndarray
        Force residual, measured minus model [N], in sample order.
    """
    r = np.asarray(residual, dtype=float)
    n = r.size
    if n < 3:
        return float(max(n, 1))
    rho = autocorrelation(r, n // 2)
    negative = np.flatnonzero(rho[1:] <= 0.0)
    stop = negative[0] + 1 if negative.size else rho.size
    tau = 1.0 + 2.0 * float(np.sum(rho[1:stop]))
    return float(min(max(n / max(tau, 1e-12), 1.0), n))


@dataclass(frozen=True)
class ResidualTrace:
    """Where a residual lives (see the module docstring).

    Parameters
    ----------
    lags : int
        Number of lags of the Ljung-Box statistic.

    Attributes
    ----------
    shares : dict of str to float
        Share of the residual variance explained by each variable of :data:`TRACE_VARIABLES`.
    mean_share : float
        :math:`\\bar r^2/\\overline{r^2}`: the constant part of the residual.
    profiles : dict of str to Profile
        The binned partial dependences (for plots).
    rms : float
        RMS of the residual [N].
    ljung_box, ljung_box_p : float
        Whiteness statistic and its p-value; ``lags`` the lags used.
    lag1 : float
        Lag-one autocorrelation.
    effective_samples : float
        :func:`effective_sample_size`.
    noise_fraction : float
        Share of the residual variance that looks like white noise.
    n_samples : int
    """

    shares: dict
    mean_share: float
    profiles: dict = field(repr=False)
    rms: float
    ljung_box: float
    ljung_box_p: float
    lags: int
    lag1: float
    effective_samples: float
    noise_fraction: float
    n_samples: int

    @property
    def white(self) -> bool:
        """Ljung-Box does not reject whiteness at the 5 % level."""
        return self.ljung_box_p > 0.05

    def dominant(self) -> tuple[str, float]:
        """The variable with the largest share, and that share."""
        name = max(self.shares, key=lambda k: self.shares[k])
        return name, float(self.shares[name])

    def to_dict(self) -> dict:
        """Plain dict for JSON: shares (plus ``mean``) and the whiteness figures."""
        return {"shares": {**{k: round(float(v), 4) for k, v in self.shares.items()},
                           "mean": round(float(self.mean_share), 4)},
                "rms": float(self.rms), "ljung_box": float(self.ljung_box),
                "ljung_box_p": float(self.ljung_box_p), "lags": int(self.lags),
                "lag1_autocorrelation": float(self.lag1),
                "effective_samples": float(self.effective_samples),
                "noise_fraction": float(self.noise_fraction), "white": bool(self.white)}


def trace_residual(residual: np.ndarray, signals: dict, bins: int = DEFAULT_BINS,
                   lags: int = DEFAULT_LAGS) -> ResidualTrace:
    """Trace ``residual`` against the variables in ``signals``.

    Parameters
    ----------
    residual : ndarray (N,)
        Force residual :math:`F - \\hat F` [N] (held-out samples, tests concatenated).
    signals : dict of str to ndarray (N,)
        ``displacement``, ``velocity``, ``acceleration``, ``voltage``, ``voltage_rate``, ``time``
        (as :meth:`damper.diagnosis.DiagnosisData.signals` returns); ``sign`` and ``loop`` are
        derived from ``velocity`` and ``displacement``.
    bins : int
        Equal-count bins per variable (per branch for ``loop``).
    lags : int
        Lags of the Ljung-Box test.

    Returns
    -------
    ResidualTrace

    Raises
    ------
    InputError
        Missing signals, mismatched lengths, too few samples or non-finite values.
    """
    r = np.asarray(residual, dtype=float)
    if r.ndim != 1 or r.size < 4 * max(bins, 2):
        raise InputError(f"trace_residual: expected a 1-D residual of at least {4 * max(bins, 2)} "
                         f"samples, got shape {r.shape}")
    if not np.all(np.isfinite(r)):
        raise InputError("trace_residual: the residual has non-finite values")
    needed = TRACE_VARIABLES[:6]
    missing = [k for k in needed if k not in signals]
    if missing:
        raise InputError(f"trace_residual: signals missing {', '.join(missing)}")
    z = {}
    for k in needed:
        a = np.asarray(signals[k], dtype=float)
        if a.shape != r.shape:
            raise InputError(f"trace_residual: signal {k!r} has shape {a.shape}, expected {r.shape}")
        z[k] = a
    profiles: dict[str, Profile] = {}
    for k in needed:
        a = z[k]
        if np.ptp(a) <= 1e-12 * max(1.0, float(np.max(np.abs(a)))):
            profiles[k] = Profile(k, np.array([a[0]]), np.array([r.mean()]), np.array([r.size]),
                                  np.zeros(1), 0.0, constant=True)
            continue
        if k == "time" and "cycle" in signals:
            cycle = np.asarray(signals["cycle"])
            if cycle.shape != r.shape:
                raise InputError(f"trace_residual: signal 'cycle' has shape {cycle.shape}, "
                                 f"expected {r.shape}")
            profiles[k] = _profile(k, r, a, cycle)
            continue
        profiles[k] = _profile(k, r, a, _groups_quantile(a, bins))
    direction = np.where(z["velocity"] > 0.0, 1, -1)
    profiles["sign"] = _profile("sign", r, direction.astype(float), direction,
                                branch_of_group=lambda g: g)
    loop_groups = np.empty(r.size, dtype=np.int64)
    for s, offset in ((1, 0), (-1, bins + 1)):
        sel = direction == s
        if sel.any():
            loop_groups[sel] = offset + _groups_quantile(z["displacement"][sel], bins)
    profiles["loop"] = _profile("loop", r, z["displacement"], loop_groups,
                                branch_of_group=lambda g: 1.0 if g <= bins else -1.0)
    shares = {k: profiles[k].share for k in TRACE_VARIABLES}
    ms = float(np.mean(r ** 2))
    mean_share = float(r.mean() ** 2 / ms) if ms > 0 else 0.0
    q, p, h = ljung_box(r, lags)
    rho1 = float(autocorrelation(r, 1)[1])
    var = float(np.var(r))
    noise = float(np.mean(np.diff(r) ** 2) / (2.0 * var)) if var > 0 else 1.0
    return ResidualTrace(shares=shares, mean_share=mean_share, profiles=profiles,
                         rms=float(np.sqrt(ms)), ljung_box=q, ljung_box_p=p, lags=h, lag1=rho1,
                         effective_samples=effective_sample_size(r),
                         noise_fraction=float(min(noise, 1.0)), n_samples=int(r.size))


def heldout_bic(rss: float, n_samples: int, n_effective: float, n_parameters: int) -> float:
    """:math:`N_\\text{eff}\\ln(\\mathrm{RSS}/N) + k\\ln N_\\text{eff}` (the residual loop's criterion: :mod:`damper.diagnosis.selection`).

    Parameters
    ----------
    rss : float
        Residual sum of squares [N²].
    n_samples : int
        Number of samples N.
    n_effective : float
        Effective number of independent samples (:func:`damper.diagnosis.trace.effective_sample_size`).
    n_parameters : int
        Number of free parameters k.
    """
    if not (rss > 0 and n_samples > 0 and n_effective >= 1):
        raise InputError(f"heldout_bic: expected rss > 0, n > 0, n_eff >= 1; got {rss}, "
                         f"{n_samples}, {n_effective}")
    return float(n_effective * math.log(rss / n_samples) + n_parameters * math.log(n_effective))


def bic_delta(rss_old: float, rss_new: float, n_effective: float, added_parameters: int) -> float:
    """Change of :func:`heldout_bic` when ``added_parameters`` bring the RSS from old to new.

    Parameters
    ----------
    rss_old : float
        Residual sum of squares before [N²].
    rss_new : float
        Residual sum of squares after [N²].
    n_effective : float
        Effective number of independent samples (:func:`damper.diagnosis.trace.effective_sample_size`).
    added_parameters : int
        Number of parameters added.
    """
    if not (rss_old > 0 and rss_new > 0):
        return -math.inf if rss_new <= 0 < rss_old else math.inf
    return float(n_effective * math.log(rss_new / rss_old) + added_parameters * math.log(n_effective))
