"""Fit of the base model (normalized or extended Bouc-Wen) to the training samples of many tests.

The base model is linear in its force coefficients once the shape parameters are fixed:
for given :math:`(\\rho, \\sigma, n)` the hysteretic variable :math:`w(t)` of each test does not
depend on :math:`\\kappa_x, \\kappa_{\\dot x}, \\kappa_w`, and

.. math:: F \\approx \\sum_j \\varphi_j(v)\\,\\big(\\kappa_{x,j}\\,x + \\kappa_{\\dot x,j}\\,\\dot x
          + \\kappa_{w,j}\\,w\\big)

(with :math:`\\varphi_j` the piecewise-linear hat functions of the voltage nodes, or
:math:`\\varphi \\equiv 1` for constant parameters) is a bounded linear least-squares problem
(:func:`scipy.optimize.lsq_linear`, coefficients >= 0). :func:`fit_base` scans a grid of shape
parameters this way (variable projection), then refines the best few jointly with
:func:`damper.diagnosis.augmented.refit` and keeps the best on the training samples. No test needs to be
a clean periodic wave, so measured, multi-amplitude and multi-voltage data sets all work.
(For a single periodic test at constant voltage the closed-form method of
:mod:`damper.identification` is the textbook start; the grid gives the same optimum here and
copes with what the closed form cannot: offsets, several tests, voltage changes.)
"""

from __future__ import annotations

import itertools
import math

import numpy as np
from scipy.optimize import lsq_linear

from benchmark.foundation.errors import InputError, NumericalError
from damper.diagnosis.augmented import AugmentedModel, RefitResult, make_base, refit
from damper.models.bouc_wen import NormalizedBoucWen
from damper.diagnosis.dataset import DiagnosisData
from damper.models.response import simulate
from damper.models.voltage_laws import Tabulated

__all__ = ["fit_base", "shape_grid", "hat_weights"]

#: rho times the median half-stroke of the tests, scanned by the grid.
RHO_STROKE_GRID = (0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 128.0)
SIGMA_GRID = (0.5, 1.0, 2.0)
N_GRID = (1.0, 2.0)
#: Residual evaluations (optimizer iterations) each start gets before the best one goes on.
START_NFEV = 4


def hat_weights(v: np.ndarray, nodes: np.ndarray | None) -> np.ndarray:
    """Piecewise-linear interpolation weights :math:`\\varphi_j(v)`, shape (len(v), len(nodes)).

    Parameters
    ----------
    v : np.ndarray
        Coil inputs [V].
    nodes : np.ndarray | None
        Increasing nodes [V]; None: one constant weight.
    """
    v = np.asarray(v, dtype=float)
    if nodes is None:
        return np.ones((v.size, 1))
    nodes = np.asarray(nodes, dtype=float)
    out = np.zeros((v.size, nodes.size))
    vc = np.clip(v, nodes[0], nodes[-1])
    j = np.clip(np.searchsorted(nodes, vc, side="right") - 1, 0, nodes.size - 2)
    frac = (vc - nodes[j]) / (nodes[j + 1] - nodes[j])
    rows = np.arange(v.size)
    out[rows, j] = 1.0 - frac
    out[rows, j + 1] += frac
    return out


def _half_stroke(data: DiagnosisData) -> float:
    strokes = [0.5 * float(np.percentile(m.x, 99.5) - np.percentile(m.x, 0.5)) for m in data.motions]
    strokes = [s for s in strokes if s > 0]
    if not strokes:
        raise InputError("diagnose: every test has zero stroke; the damper must move")
    return float(np.median(strokes))


def shape_grid(data: DiagnosisData) -> list[tuple[float, float, float]]:
    """The (rho, sigma, n) grid scanned for the start.

    Parameters
    ----------
    data : DiagnosisData
        The prepared tests (:class:`damper.diagnosis.dataset.DiagnosisData`).
    """
    x_ref = _half_stroke(data)
    return [(c / x_ref, s, n) for c, s, n in itertools.product(RHO_STROKE_GRID, SIGMA_GRID, N_GRID)]


def _linear_fit(data: DiagnosisData, kind: str, rho: float, sigma: float, n: float, nodes):
    """Best nonnegative force coefficients for fixed shape parameters; returns (rss, coefs)."""
    probe = NormalizedBoucWen(1.0, 1.0, rho, sigma, n, voltage_range=data.voltage_range())
    blocks, targets = [], []
    for m, f, k in zip(data.motions, data.forces, data.train):
        if not k.any():
            continue
        w = simulate(probe, m.t, m.x, m.xdot, data.voltage_range()[0]).states[:, 0]
        phi = hat_weights(m.v, nodes)[k]
        cols = [m.xdot[k], w[k]] if kind == "normalized" else [m.x[k], m.xdot[k], w[k]]
        blocks.append(np.hstack([phi * c[:, None] for c in cols]))
        targets.append(f[k])
    a = np.vstack(blocks)
    b = np.concatenate(targets)
    col_scale = np.sqrt(np.mean(a ** 2, axis=0))
    col_scale[col_scale == 0] = 1.0
    sol = lsq_linear(a / col_scale, b, bounds=(0.0, np.inf), method="bvls")
    coef = sol.x / col_scale
    rss = float(np.sum((a @ coef - b) ** 2))
    return rss, coef


def _model_from(kind: str, coef: np.ndarray, rho: float, sigma: float, n: float, nodes,
                voltage_range, floor: dict) -> AugmentedModel:
    names = ("kappa_xdot", "kappa_w") if kind == "normalized" else ("kappa_x", "kappa_xdot", "kappa_w")
    n_nodes = 1 if nodes is None else len(nodes)
    params = {}
    for i, name in enumerate(names):
        vals = coef[i * n_nodes:(i + 1) * n_nodes].copy()
        if name != "kappa_x":
            vals = np.maximum(vals, floor[name])  # the admissible class needs kappa > 0
        params[name] = (float(vals[0]) if nodes is None
                        else Tabulated(tuple(nodes), tuple(float(x) for x in vals)))
    params.update(rho=rho, sigma=sigma, n=n)
    return AugmentedModel(make_base(kind, params, voltage_range))


def fit_base(data: DiagnosisData, kind: str = "normalized", n_starts: int = 3,
             max_nfev: int = 200, tolerance: float = 1e-10,
             progress=None) -> RefitResult:
    """Fit the base model of ``kind`` to the training samples of ``data``.

    Parameters
    ----------
    data : DiagnosisData
    kind : {"normalized", "extended"}
    n_starts : int
        Best grid points (distinct rho) refined by joint least squares.
    max_nfev : int
        Cap on residual evaluations per refinement.
    tolerance : float
        Stopping tolerance of each refinement (:func:`damper.diagnosis.augmented.refit`).
    progress : callable, optional
        Receives one line per refined start.

    Returns
    -------
    RefitResult
        The best refined base model (wrapped as an :class:`~damper.diagnosis.augmented.AugmentedModel`
        without effects) and its training error.

    Raises
    ------
    InputError
        Unknown ``kind`` or unusable data.
    NumericalError
        No start could be refined.
    """
    if kind not in ("normalized", "extended"):
        raise InputError(f"--model: expected 'normalized' or 'extended', got {kind!r}")
    nodes = data.nodes()
    vr = data.voltage_range()
    f_rms = data.force_rms("train")
    if not f_rms > 0:
        raise InputError("diagnose: the measured force is identically zero over the training samples")
    v_rms = float(np.sqrt(np.mean(data.concat([m.xdot for m in data.motions], "train") ** 2)))
    floor = {"kappa_xdot": 1e-6 * f_rms / max(v_rms, 1e-12), "kappa_w": 1e-6 * f_rms}
    scored = []
    for rho, sigma, n in shape_grid(data):
        try:
            rss, coef = _linear_fit(data, kind, rho, sigma, n, nodes)
        except NumericalError:
            continue
        scored.append((rss, rho, sigma, n, coef))
    if not scored:
        raise NumericalError("diagnose: no grid start of the base model could be simulated")
    scored.sort(key=lambda s: s[0])
    starts, seen_rho = [], set()
    for rss, rho, sigma, n, coef in scored:
        if rho in seen_rho:
            continue
        seen_rho.add(rho)
        starts.append(_model_from(kind, coef, rho, sigma, n, nodes, vr, floor))
        if len(starts) >= n_starts:
            break
    # every start takes a few steps, then only the best goes on (the starts of the grid mostly
    # reach the same optimum; refining each to the end tripled the cost of the base fit)
    best: RefitResult | None = None
    budget = START_NFEV if len(starts) > 1 else max_nfev
    for i, start in enumerate(starts):
        try:
            result = refit(start, data.motions, data.forces, data.train, nodes=nodes,
                           max_nfev=min(budget, max_nfev), tolerance=tolerance)
        except NumericalError:
            continue
        if progress:
            progress(f"  base start {i + 1}/{len(starts)} (rho {start.base.rho:.4g} 1/m): training "
                     f"error {result.relative_rms_error:.4f} after {result.nfev} evaluations")
        if best is None or result.relative_rms_error < best.relative_rms_error:
            best = result
    if best is not None and budget < max_nfev and not best.success:
        try:
            more = refit(best.model, data.motions, data.forces, data.train, nodes=nodes,
                         max_nfev=max_nfev, tolerance=tolerance)
        except NumericalError:
            more = None
        if more is not None and more.relative_rms_error <= best.relative_rms_error:
            best = more
        if progress:
            progress(f"  base model refined: training error {best.relative_rms_error:.4f}")
    if best is None:
        raise NumericalError("diagnose: the base model could not be refined from any start",
                             hint="check the data (units, force sign) or try the other --model")
    return best
