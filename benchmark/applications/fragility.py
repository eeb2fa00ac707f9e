"""Fragility: probability that the base displacement exceeds a limit, versus PGA, per controller.

A fragility study is an ensemble (:mod:`benchmark.applications.ensemble`) of synthetic benchmark-like
motions (``records.synthetic.benchmark_like``) scaled to a list of peak ground accelerations
(the stronger component's PGA equals the target), run under two or more controllers. For each
controller and PGA level :math:`a_j` it counts the runs whose response (default
``peak_base_displacement``, the peak x–y resultant at the base centre of mass) exceeds the
limit, :math:`z_j` of :math:`n_j`, and fits the lognormal fragility function

.. math::

    P(\\mathrm{EDP} > \\mathrm{limit} \\mid \\mathrm{PGA} = a) = \\Phi\\left(\\frac{\\ln(a/\\theta)}{\\beta}\\right)

by maximum likelihood on the binomial counts (Baker 2015),

.. math::

    (\\hat\\theta, \\hat\\beta) = \\arg\\max \\sum_j \\left[ z_j \\ln p_j + (n_j - z_j) \\ln(1 - p_j) \\right],
    \\quad p_j = \\Phi\\left(\\frac{\\ln(a_j/\\theta)}{\\beta}\\right),

with :math:`\\theta` the median capacity [m/s²] and :math:`\\beta` the logarithmic standard
deviation. Because every controller sees the same motions (``motion_seed`` depends on the
template and realisation only), the curves differ by the controller alone. Runs that fail
numerically are left out of :math:`n_j` and reported per level (``n_failed``), so that a bias
from dropped runs is visible. The ensemble uses the ``"peaks"`` run function (no uncontrolled
runs: the fragility needs no J's).

Reference: J. W. Baker, *Efficient analytical fragility function fitting using dynamic
structural analysis*, Earthquake Spectra 31(1):579–599, 2015.

The default displacement limit (0.40 m) is a choice of this project, a plausible displacement
capacity of the isolation layer (bearings and moat); the benchmark does not prescribe one.
"""

from __future__ import annotations

import json
import math
import os
import sys
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from benchmark.foundation.errors import InputError
from benchmark.applications.ensemble import EnsembleConfig
from benchmark.foundation.figures import save_figure
from benchmark.foundation.atomic import atomic_write_text
from benchmark.applications.ensemble import read_ensemble, run_ensemble

__all__ = [
    "STANDARD_GRAVITY",
    "DEFAULT_LIMIT",
    "LognormalFragility",
    "FragilityCurve",
    "fit_lognormal",
    "exceedance_counts",
    "fragility_curves",
    "fragility_config",
    "plot_fragility",
    "run_fragility",
]

#: Standard gravity [m/s²] (PGAs are given in m/s² and plotted in g).
STANDARD_GRAVITY = 9.80665
#: Default base-displacement limit [m] (a project choice; see the module docstring).
DEFAULT_LIMIT = 0.40


@dataclass(frozen=True)
class LognormalFragility:
    """A fitted lognormal fragility function.

    Attributes
    ----------
    median : float
        :math:`\\theta`, the PGA with 50 % probability of exceedance [m/s²] (NaN if not fitted).
    beta : float
        :math:`\\beta`, logarithmic standard deviation [-] (NaN if not fitted).
    log_likelihood : float
        Binomial log-likelihood at the optimum.
    fitted : bool
        False when the counts cannot identify both parameters (no exceedance at all, or
        exceedance at every level with too few levels); ``message`` says why.
    message : str
        Why the fit is missing or what to be careful about.
    """

    median: float
    beta: float
    log_likelihood: float
    fitted: bool = True
    message: str = ""

    def probability(self, pga: np.ndarray | float) -> np.ndarray:
        """:math:`\\Phi(\\ln(a/\\theta)/\\beta)` at PGA ``a`` [m/s²].

        Parameters
        ----------
        pga : np.ndarray | float
            Peak ground acceleration a [m/s²].
        """
        from scipy.special import ndtr

        a = np.asarray(pga, dtype=float)
        if not self.fitted:
            return np.full(a.shape, np.nan)
        with np.errstate(divide="ignore"):
            return ndtr(np.log(a / self.median) / self.beta)


def _log_likelihood(log_theta: float, log_beta: float, log_a: np.ndarray, z: np.ndarray,
                    n: np.ndarray) -> float:
    from scipy.special import log_ndtr

    u = (log_a - log_theta) / math.exp(log_beta)
    # log Φ(u) and log(1 − Φ(u)) = log Φ(−u), both accurate far in the tails
    return float(np.sum(z * log_ndtr(u) + (n - z) * log_ndtr(-u)))


def fit_lognormal(pga: Sequence[float], n_exceed: Sequence[int], n_total: Sequence[int]) -> LognormalFragility:
    """Fit a lognormal fragility function to exceedance counts by maximum likelihood.

    Parameters
    ----------
    pga : sequence of float
        PGA levels :math:`a_j` [m/s²], > 0.
    n_exceed : sequence of int
        Runs exceeding the limit at each level, :math:`z_j`.
    n_total : sequence of int
        Runs at each level, :math:`n_j` (levels with :math:`n_j = 0` are ignored).

    Returns
    -------
    LognormalFragility
        ``fitted=False`` (median and beta NaN) when the data cannot identify the curve.

    Raises
    ------
    InputError
        On inconsistent inputs (lengths, negative counts, ``z > n``, PGA <= 0).
    """
    from scipy.optimize import minimize

    a = np.asarray(pga, dtype=float)
    z = np.asarray(n_exceed, dtype=float)
    n = np.asarray(n_total, dtype=float)
    if not (a.shape == z.shape == n.shape) or a.ndim != 1:
        raise InputError(f"fit_lognormal: pga, n_exceed and n_total must be 1-D of one length, got "
                         f"{a.shape}, {z.shape}, {n.shape}")
    if np.any(a <= 0) or not np.all(np.isfinite(a)):
        raise InputError("fit_lognormal: PGA levels must be finite and > 0")
    if np.any(z < 0) or np.any(n < 0) or np.any(z > n):
        raise InputError("fit_lognormal: counts must satisfy 0 <= n_exceed <= n_total")
    keep = n > 0
    a, z, n = a[keep], z[keep], n[keep]
    if z.sum() == 0:
        return LognormalFragility(math.nan, math.nan, 0.0, fitted=False,
                                  message="no run exceeded the limit: the median lies above the largest PGA")
    if z.sum() == n.sum():
        return LognormalFragility(math.nan, math.nan, 0.0, fitted=False,
                                  message="every run exceeded the limit: the median lies below the smallest PGA")
    log_a = np.log(a)
    frac = z / n
    # start: median where the empirical fraction crosses 1/2, beta 0.4
    order = np.argsort(a)
    above = np.nonzero(frac[order] >= 0.5)[0]
    theta0 = log_a[order][above[0]] if above.size else log_a.max() + 0.3
    x0 = np.array([theta0, math.log(0.4)])

    def objective(x: np.ndarray) -> float:
        return -_log_likelihood(x[0], x[1], log_a, z, n)

    best = minimize(objective, x0, method="Nelder-Mead",
                    options={"xatol": 1e-10, "fatol": 1e-12, "maxiter": 4000})
    log_theta, log_beta = float(best.x[0]), float(best.x[1])
    message = ""
    separable = bool(np.all((frac[order] == 0) | (frac[order] == 1))) and np.all(np.diff(frac[order]) >= 0)
    if separable or log_beta < math.log(1e-3):
        message = ("counts jump from 0 to 1 between two levels: beta is not identified (tends to 0); "
                   "add PGA levels or realisations")
        log_beta = max(log_beta, math.log(1e-3))
    return LognormalFragility(median=math.exp(log_theta), beta=math.exp(log_beta),
                              log_likelihood=-float(best.fun), fitted=not separable, message=message)


@dataclass(frozen=True)
class FragilityCurve:
    """Counts and fit for one controller.

    Attributes
    ----------
    controller : str
    pga : numpy.ndarray
        PGA levels [m/s²].
    n_exceed, n_total : numpy.ndarray
        Runs exceeding the limit and runs finished at each level.
    fit : LognormalFragility
    n_failed : numpy.ndarray, optional
        Runs that failed numerically at each level (not counted in ``n_total``; reported so
        that a bias from dropped runs is visible).
    """

    controller: str
    pga: np.ndarray
    n_exceed: np.ndarray
    n_total: np.ndarray
    fit: LognormalFragility
    n_failed: np.ndarray | None = None

    def as_dict(self) -> dict[str, Any]:
        """The curve as a JSON-ready dict: PGA levels [m/s², g], exceedance counts and the fit."""
        return {"controller": self.controller, "pga_m_s2": self.pga.tolist(),
                "pga_g": (self.pga / STANDARD_GRAVITY).tolist(),
                "n_exceed": self.n_exceed.tolist(), "n_total": self.n_total.tolist(),
                "n_failed": None if self.n_failed is None else self.n_failed.tolist(),
                "fit": asdict(self.fit)}


def exceedance_counts(results: Any, controller: str, metric: str = "peak_base_displacement",
                      limit: float = DEFAULT_LIMIT) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Count runs exceeding ``limit`` per PGA level for one controller.

    Parameters
    ----------
    results : benchmark.applications.ensemble.EnsembleResults
        Results with a ``pga`` case field (scaled motions).
    controller : str
    metric : str
        Result metric compared with the limit (SI units).
    limit : float
        Threshold in the metric's units (default: 0.40 m of base displacement).

    Returns
    -------
    pga, n_exceed, n_total : numpy.ndarray
        Levels [m/s²] (sorted), exceeding runs and finished (status ok) runs per level.
    """
    if metric not in results.results:
        raise InputError(f"metric {metric!r} not in the results; have {sorted(results.results)}")
    pga_all = np.asarray(results.cases["pga"], dtype=float)
    if np.isnan(pga_all).all():
        raise InputError("the ensemble's motions are not scaled (no 'pga' in its config)")
    mask = (results.cases["controller"] == controller) & (results.cases["status"] == "ok")
    if not mask.any():
        raise InputError(f"no finished run for controller {controller!r}; have "
                         f"{sorted(set(results.cases['controller']))}")
    values = np.asarray(results.results[metric], dtype=float)
    if values.ndim != 1:
        raise InputError(f"metric {metric!r} is not a scalar per run (shape {values.shape[1:]})")
    levels = np.unique(pga_all[mask])
    n_exceed = np.array([np.sum(values[mask & (pga_all == a)] > limit) for a in levels])
    n_total = np.array([np.sum(mask & (pga_all == a)) for a in levels])
    return levels, n_exceed, n_total


def fragility_curves(results: Any, controllers: Sequence[str] | None = None,
                     metric: str = "peak_base_displacement", limit: float = DEFAULT_LIMIT) -> dict[str, FragilityCurve]:
    """Counts and lognormal fits for each controller of an ensemble.

    Parameters
    ----------
    results : benchmark.applications.ensemble.EnsembleResults
        A fragility ensemble read back (:func:`benchmark.applications.ensemble.read_ensemble`).
    controllers : sequence of str, optional
        Which controllers (default: all, in the ensemble's order).
    metric : str
        Response metric compared with ``limit``.
    limit : float
        Threshold in the metric's SI unit (default 0.40 m).

    Returns
    -------
    dict
        Controller → :class:`FragilityCurve`.
    """
    if controllers is None:
        controllers = list(dict.fromkeys(results.cases["controller"].tolist()))
    curves = {}
    pga_all = np.asarray(results.cases["pga"], dtype=float)
    for controller in controllers:
        pga, z, n = exceedance_counts(results, controller, metric, limit)
        failed = (results.cases["controller"] == controller) & (results.cases["status"] == "failed")
        n_failed = np.array([np.sum(failed & (pga_all == a)) for a in pga])
        curves[controller] = FragilityCurve(controller, pga, z, n, fit_lognormal(pga, z, n), n_failed)
    return curves


def fragility_config(controllers: Sequence[str] = ("passive-off", "clipped-optimal"),
                     templates: Sequence[str] = ("newhall", "sylmar", "rinaldi", "kobe"),
                     realisations: int = 10,
                     pga_g: Sequence[float] = (0.2, 0.4, 0.6, 0.8, 1.0, 1.2, 1.4),
                     orientations: Sequence[str] = ("FN-x",), base_seed: int = 2006,
                     run: str = "peaks"):
    """The ensemble of a fragility study (synthetic motions × PGA levels × controllers).

    Parameters
    ----------
    controllers : sequence of str
        Controllers compared (registry names).
    templates : sequence of str
        Benchmark records the synthetic motions imitate.
    realisations : int
        Synthetic realisations per template (the same motions for every controller and PGA).
    pga_g : sequence of float
        PGA levels in g (converted to m/s² here).
    orientations : sequence of str
        ``"FN-x"`` and/or ``"FP-x"``.
    base_seed : int
        Seed all case seeds derive from.
    run : str
        Run function (default ``"peaks"``: no uncontrolled runs).
    """

    text = "\n".join([
        "# fragility study (benchmark.applications.fragility.fragility_config)",
        f"name = \"fragility\"", f"base_seed = {int(base_seed)}", f"run = {json.dumps(run)}",
        f"controllers = {json.dumps(list(controllers))}", f"orientations = {json.dumps(list(orientations))}",
        f"pga = {json.dumps([round(g * STANDARD_GRAVITY, 12) for g in pga_g])}",
        "[synthetic]", f"templates = {json.dumps(list(templates))}", f"realisations = {int(realisations)}", ""])
    import tomllib

    return EnsembleConfig.from_dict(tomllib.loads(text), source="<fragility>", text=text)


def plot_fragility(curves: dict[str, FragilityCurve], path: str | os.PathLike, limit: float = DEFAULT_LIMIT,
                   metric: str = "peak_base_displacement") -> Path:
    """Plot empirical exceedance fractions (with 90 % Wilson intervals) and fitted curves (PNG, atomic).

    Parameters
    ----------
    curves : dict
        Controller → :class:`FragilityCurve` (:func:`fragility_curves`).
    path : path-like
        PNG file.
    limit : float
        The limit (for the axis label) in the metric's SI unit.
    metric : str
        The metric (for the axis label).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from scipy.stats import norm


    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    a_max = max(float(c.pga.max()) for c in curves.values())
    grid = np.linspace(1e-3, 1.15 * a_max, 400)
    zq = norm.ppf(0.95)
    for k, curve in enumerate(curves.values()):
        color = f"C{k}"
        p = curve.n_exceed / np.maximum(curve.n_total, 1)
        n = np.maximum(curve.n_total, 1)
        centre = (p + zq ** 2 / (2 * n)) / (1 + zq ** 2 / n)
        half = zq * np.sqrt(p * (1 - p) / n + zq ** 2 / (4 * n ** 2)) / (1 + zq ** 2 / n)
        dodge = (k - (len(curves) - 1) / 2) * 0.012 * a_max / STANDARD_GRAVITY  # keep the bars apart
        ax.errorbar(curve.pga / STANDARD_GRAVITY + dodge, p, yerr=[p - (centre - half), centre + half - p], fmt="o",
                    color=color, capsize=3, ms=5, label=f"{curve.controller}: fraction of runs (90 % CI)")
        if curve.fit.fitted:
            ax.plot(grid / STANDARD_GRAVITY, curve.fit.probability(grid), "-", color=color,
                    label=f"{curve.controller}: lognormal, θ = {curve.fit.median / STANDARD_GRAVITY:.2f} g, "
                          f"β = {curve.fit.beta:.2f}")
    unit = "m" if "displacement" in metric else ""
    ax.set_xlabel("PGA of the stronger component [g]")
    ax.set_ylabel(f"P({metric.replace('_', ' ')} > {limit:g} {unit})")
    ax.set_ylim(-0.03, 1.03)
    ax.set_xlim(0, 1.15 * a_max / STANDARD_GRAVITY)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7.5, loc="upper left")
    ax.set_title("Fragility of the isolation layer (synthetic benchmark-like motions)", fontsize=10)
    fig.tight_layout()
    return save_figure(fig, path, dpi=130)


def run_fragility(out: str | os.PathLike, limit: float = DEFAULT_LIMIT, metric: str = "peak_base_displacement",
                  jobs: int = 1, progress: bool = True, config: Any = None, **config_options: Any) -> dict[str, Any]:
    """Run (or resume) a fragility study: ensemble, counts, fits, JSON summary and plot.

    Parameters
    ----------
    out : path-like
        Output directory: ``fragility.h5`` (+ journal), ``fragility.json``, ``fragility.png``.
    limit : float
        Limit on ``metric`` (default 0.40 m of peak base displacement).
    metric : str
        Response metric.
    jobs : int
        Local worker processes.
    progress : bool
        Show a progress bar.
    config : EnsembleConfig, optional
        The ensemble; default :func:`fragility_config` with ``config_options``.
    **config_options
        Fields of the ensemble configuration (:class:`~benchmark.applications.ensemble.EnsembleConfig`) when
        ``config`` is not given (e.g. ``records``, ``scales``, ``seed``).

    Returns
    -------
    dict
        The JSON summary (curves with counts and fits, ensemble summary, file paths).
    """

    if not (isinstance(limit, (int, float)) and limit > 0):
        raise InputError(f"fragility limit must be > 0, got {limit!r}")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    config = config if config is not None else fragility_config(**config_options)
    summary = run_ensemble(config, out / "fragility.h5", jobs=jobs, progress=progress)
    results = read_ensemble(out / "fragility.h5")
    curves = fragility_curves(results, metric=metric, limit=limit)
    png = plot_fragility(curves, out / "fragility.png", limit=limit, metric=metric)
    report = {"metric": metric, "limit": limit, "curves": [c.as_dict() for c in curves.values()],
              "ensemble": summary.as_dict(), "plot": str(png),
              "reference": "Baker (2015), Earthquake Spectra 31(1):579-599 (binomial maximum likelihood)"}
    atomic_write_text(out / "fragility.json", json.dumps(report, indent=2))
    return report


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m benchmark.applications.fragility --out DIR [--quick] [--jobs N] [--limit M]``."""
    import argparse

    parser = argparse.ArgumentParser(prog="python -m benchmark.applications.fragility", description=__doc__.split("\n")[0])
    parser.add_argument("--out", default="results/fragility")
    parser.add_argument("--limit", type=float, default=DEFAULT_LIMIT, help="base displacement limit [m]")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--quick", action="store_true", help="2 templates, 4 realisations, 4 PGA levels")
    args = parser.parse_args(argv)
    options: dict[str, Any] = {}
    if args.quick:
        options = {"templates": ("newhall", "kobe"), "realisations": 4, "pga_g": (0.4, 0.7, 1.0, 1.3)}
    try:
        if args.jobs < 1:
            raise InputError(f"--jobs {args.jobs}: expected at least 1 process")
        report = run_fragility(args.out, limit=args.limit, jobs=args.jobs, **options)
    except InputError as exc:  # one line and status 2, as every sbib command (a traceback before)
        print(f"{parser.prog}: error: {exc}", file=sys.stderr)
        return 2
    for curve in report["curves"]:
        fit = curve["fit"]
        print(f"{curve['controller']:>18}: theta = {fit['median'] / STANDARD_GRAVITY:.3f} g, beta = {fit['beta']:.3f}"
              f"  exceed {curve['n_exceed']} of {curve['n_total']} (failed {curve['n_failed']})  {fit['message']}")
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
