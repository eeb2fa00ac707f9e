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
from dataclasses import dataclass

import numpy as np
from scipy.optimize import lsq_linear

from benchmark.foundation.errors import InputError, NumericalError
from damper.diagnosis.augmented import AugmentedModel, RefitResult, make_base, refit, refit_from_starts
from damper.fitting import DEFAULT_STALL
from damper.models.base import with_coarser_substeps
from damper.models.bouc_wen import NormalizedBoucWen
from damper.diagnosis.dataset import DiagnosisData
from damper.diagnosis.trace import bic_delta, effective_sample_size
from damper.diagnosis.effects import FIELD_LAG_STARTS, Offset
from damper.models.field_filter import first_order_filter
from damper.models.series_dashpot import SpencerBoucWen
from damper.models.response import simulate
from damper.models.voltage_laws import Tabulated

__all__ = ["fit_base", "fit_spencer_base", "shape_grid", "hat_weights", "BaseFit"]

#: rho times the median half-stroke of the tests, scanned by the grid.
RHO_STROKE_GRID = (0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 128.0)
SIGMA_GRID = (0.5, 1.0, 2.0)
N_GRID = (1.0, 2.0)
#: Field time constants [s] scanned by the Spencer-type base's projection stage when the input
#: changes (MR dampers' coils and eddy currents: a few to a few tens of milliseconds).
TAU_GRID = (0.0,) + FIELD_LAG_STARTS
#: Starting roll-off velocities of the series dashpot, as fractions of the training velocity RMS
#: (c1 = kappa_w / v_r): a sharp and a soft roll-off.
ROLL_OFF_STARTS = (0.05, 0.3)
#: Law nodes tried for the Spencer-type base when the input varies: 2 (linear in the field) and
#: 3 (PCHIP through a middle node: a saturating or accelerating shape).
LAW_NODE_COUNTS = (2, 3)


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
        w = simulate(with_coarser_substeps(probe, m.substep_scale), m.t, m.x, m.xdot,
                     data.voltage_range()[0]).states[:, 0]
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

    def report(i, start, result):
        if progress:
            progress(f"  base start {i + 1}/{len(starts)} (rho {start.base.rho:.4g} 1/m): training "
                     f"error {result.relative_rms_error:.4f} after {result.nfev} evaluations")

    best = refit_from_starts(starts, data.motions, data.forces, data.train, nodes=nodes,
                             max_nfev=max_nfev, tolerance=tolerance, stall=DEFAULT_STALL,
                             on_start=report)
    if progress and best is not None:
        progress(f"  base model refined: training error {best.relative_rms_error:.4f}")
    if best is None:
        raise NumericalError("diagnose: the base model could not be refined from any start",
                             hint="check the data (units, force sign) or try the other --model")
    return best


@dataclass(frozen=True)
class BaseFit:
    """A fitted base model with the law nodes it was fitted on.

    Parameters
    ----------
    result : RefitResult
        The refit (its ``model`` is the base, as an :class:`AugmentedModel` without effects).
    nodes : ndarray or None
        Input nodes of the base's laws (``None``: constant parameters).
    note : str
        What was chosen (e.g. the voltage laws), for the report.
    """

    result: RefitResult
    nodes: np.ndarray | None
    note: str = ""

    @property
    def model(self) -> AugmentedModel:
        return self.result.model


def _input_span(data: DiagnosisData) -> tuple[float, float] | None:
    """Ends of the law grid: the loop's node span (levels, or the bulk of a varying input)."""
    nodes = data.nodes()
    if nodes is None:
        return None
    return float(nodes[0]), float(nodes[-1])


def _projection(data: DiagnosisData, rho: float, sigma: float, n: float, taus, nodes):
    """Variable projection of the Spencer-type base without its series dashpot (large c1):
    :math:`F \\approx \\sum_j \\varphi_j(u_\\tau)(c_{0,j}\\dot x + \\kappa_{w,j} w) + k_1 x + f_0` for each
    field lag ``tau`` (``w`` does not depend on the laws); returns [(rss, tau, coef)]."""
    probe = NormalizedBoucWen(1.0, 1.0, rho, sigma, n, voltage_range=data.voltage_range())
    ws = []
    for m, k in zip(data.motions, data.train):
        ws.append(simulate(with_coarser_substeps(probe, m.substep_scale), m.t, m.x, m.xdot,
                           data.voltage_range()[0]).states[:, 0]
                  if k.any() else None)
    out = []
    for tau in taus:
        blocks, targets = [], []
        for m, f, k, w in zip(data.motions, data.forces, data.train, ws):
            if w is None:
                continue
            u = first_order_filter(m.t, m.v, tau) if tau > 0 else m.v
            phi = hat_weights(u, nodes)[k]
            blocks.append(np.hstack([phi * m.xdot[k][:, None], phi * w[k][:, None], m.x[k][:, None],
                                     np.ones((int(k.sum()), 1))]))
            targets.append(f[k])
        a = np.vstack(blocks)
        b = np.concatenate(targets)
        col_scale = np.sqrt(np.mean(a ** 2, axis=0))
        col_scale[col_scale == 0] = 1.0
        lower = np.zeros(a.shape[1])
        lower[-1] = -np.inf  # the offset has either sign
        sol = lsq_linear(a / col_scale, b, bounds=(lower, np.inf), method="bvls")
        coef = sol.x / col_scale
        out.append((float(np.sum((a @ coef - b) ** 2)), float(tau), coef))
    return out


def _law(values, nodes):
    values = [float(v) for v in np.atleast_1d(values)]
    return values[0] if nodes is None else Tabulated(tuple(float(v) for v in nodes), tuple(values))


def _law_values_at(law, nodes) -> np.ndarray:
    if nodes is None:
        return np.array([float(law(0.0)) if hasattr(law, "values") else float(law)])
    if hasattr(law, "values"):
        return np.array([float(law(float(v))) for v in nodes])
    return np.full(len(nodes), float(law))


def _spencer_on_nodes(model: SpencerBoucWen, nodes, voltage_range) -> SpencerBoucWen:
    """``model`` with its three laws re-tabulated on ``nodes``."""
    laws = {k: _law(_law_values_at(getattr(model, k), nodes), nodes)
            for k in ("kappa_xdot", "kappa_w", "c1")}
    return SpencerBoucWen(model.kappa_x, model.k0, laws["kappa_xdot"], laws["kappa_w"], laws["c1"],
                          model.rho, model.sigma, model.n, model.field_lag,
                          voltage_range=voltage_range)


def _training_rss(result: RefitResult, data: DiagnosisData) -> tuple[float, np.ndarray]:
    r = data.residual(result.model, "train")
    return float(r @ r), r


def fit_spencer_base(data: DiagnosisData, n_starts: int = 3, max_nfev: int = 200,
                     tolerance: float = 1e-10, progress=None) -> BaseFit:
    """Fit the Spencer-type base (:class:`~damper.models.series_dashpot.SpencerBoucWen`) to the
    training samples of ``data``.

    1. **Starting values from the data**, by variable projection: for each Bouc-Wen shape of
       :func:`shape_grid` and, when the input changes, each field lag of :data:`TAU_GRID`, the
       element's dashpot and force scale (linear in the field between the input's ends) and the
       accumulator stiffness and force offset (Spencer's :math:`-k_1 x_0`, carried as the
       ``offset`` term of the base) are the bounded linear least-squares fit of the training force
       (the series dashpot left out): the yield force, the viscous slope per input level and the
       pre-yield slope (ρ κ_w) all come from the data.
    2. **Global stage**: the ``n_starts`` best shapes (distinct ρ), each with the roll-offs of
       :data:`ROLL_OFF_STARTS` (c1 = κ_w/v_r), take a few joint least-squares steps; the best
       goes on to convergence.
    3. **Voltage laws chosen by the data** (input varying within or across tests): the laws on
       two nodes (linear in the field) and on three (PCHIP, so saturating or accelerating) are
       both refined; the training BIC with the residual's effective sample size
       (:func:`~damper.diagnosis.trace.effective_sample_size`) decides.

    Parameters
    ----------
    data : DiagnosisData
        The tests with their training and held-out samples.
    n_starts : int
        Shapes (distinct ρ) taken from the start grid into the global stage.
    max_nfev : int
        Cap on residual evaluations of the final refinement.
    tolerance : float
        ``xtol = ftol = gtol`` of the least-squares fits (:func:`damper.fitting.least_squares_fit`).
    progress : callable, optional
        ``progress(message)`` for one line per stage.

    Returns
    -------
    BaseFit
        The model, the law nodes it was fitted on, and a note on the law chosen.

    Raises
    ------
    InputError
        Unusable data.
    NumericalError
        No start could be refined.
    """
    vr = data.voltage_range()
    f_rms = data.force_rms("train")
    if not f_rms > 0:
        raise InputError("diagnose: the measured force is identically zero over the training samples")
    xs = data.concat([m.x for m in data.motions], "train")
    vs = data.concat([m.xdot for m in data.motions], "train")
    x_rms = float(np.sqrt(np.mean((xs - xs.mean()) ** 2))) or _half_stroke(data)
    v_rms = max(float(np.sqrt(np.mean(vs ** 2))), 1e-12)
    span = _input_span(data)
    lin_nodes = None if span is None or not span[1] > span[0] else np.array(span)
    taus = TAU_GRID if data.input_varies_within_tests else (0.0,)
    # at a constant input within each test the field lag is invisible (the warm-up is not
    # scored): it is held at zero rather than fitted
    held = () if data.input_varies_within_tests else ("field_lag",)
    scored = []
    for rho, sigma, n in shape_grid(data):
        try:
            for rss, tau, coef in _projection(data, rho, sigma, n, taus, lin_nodes):
                scored.append((rss, rho, sigma, n, tau, coef))
        except NumericalError:
            continue
    if not scored:
        raise NumericalError("diagnose: no grid start of the Spencer-type base could be simulated")
    scored.sort(key=lambda s: s[0])
    nn = 1 if lin_nodes is None else len(lin_nodes)
    floor_c, floor_w = 1e-3 * f_rms / v_rms, 1e-3 * f_rms
    starts, seen = [], set()
    for rss, rho, sigma, n, tau, coef in scored:
        if rho in seen:
            continue
        seen.add(rho)
        c0 = np.maximum(coef[:nn], floor_c)
        kw = np.maximum(coef[nn:2 * nn], floor_w)
        for frac in ROLL_OFF_STARTS:
            c1 = kw / (frac * v_rms)
            starts.append(AugmentedModel(SpencerBoucWen(
                float(coef[-2]), 1e-2 * f_rms / x_rms, _law(c0, lin_nodes), _law(kw, lin_nodes),
                _law(c1, lin_nodes), rho, sigma, n, tau, voltage_range=vr), (Offset(float(coef[-1])),),
                held))
        if len(seen) >= n_starts:
            break
    scales = {"kappa_x": f_rms / x_rms, "k0": f_rms / x_rms, "kappa_xdot": f_rms / v_rms,
              "kappa_w": f_rms, "c1": 10.0 * f_rms / v_rms, "field_lag": 0.01, "offset": f_rms}

    def report(i, start, result):
        if progress:
            b = start.base
            progress(f"  spencer start {i + 1}/{len(starts)} (rho {b.rho:.4g} 1/m, tau "
                     f"{1e3 * b.field_lag:.3g} ms): training error {result.relative_rms_error:.4f}")

    # the refinement's stall rule: one that crawled along a flat optimum had run 200 s on ranran_50
    best = refit_from_starts(starts, data.motions, data.forces, data.train, nodes=lin_nodes,
                             scales=scales, max_nfev=max_nfev, tolerance=tolerance,
                             stall=DEFAULT_STALL, on_start=report)
    if best is None:
        raise NumericalError("diagnose: the Spencer-type base could not be refined from any start",
                             hint="check the data (units, force sign) or try another --model")
    note = "constant parameters" if lin_nodes is None else "laws linear in the field (2 nodes)"
    if progress:
        progress(f"  spencer base refined: training error {best.relative_rms_error:.4f} ({note})")
    chosen = BaseFit(best, lin_nodes, note)
    if lin_nodes is None:
        return chosen
    # BIC on the training samples, with the effective sample size of the linear laws' residual
    # (one for both, so the comparison is of the residuals, not of their correlation times)
    rss_lin, r_lin = _training_rss(best, data)
    n_eff = effective_sample_size(r_lin)
    for count in LAW_NODE_COUNTS:
        if count <= len(lin_nodes):
            continue
        nodes = np.linspace(lin_nodes[0], lin_nodes[-1], count)
        try:
            start = AugmentedModel(_spencer_on_nodes(best.model.base, nodes, vr), best.model.effects,
                                   best.model.held)
            alt = refit(start, data.motions, data.forces, data.train, nodes=nodes, scales=scales,
                        max_nfev=max_nfev, tolerance=tolerance, stall=DEFAULT_STALL)
        except NumericalError:
            continue
        rss_alt, _ = _training_rss(alt, data)
        delta = bic_delta(rss_lin, rss_alt, n_eff, 3 * (count - len(lin_nodes)))
        if progress:
            progress(f"  spencer laws on {count} nodes: training error {alt.relative_rms_error:.4f}, "
                     f"BIC change {delta:+.1f}")
        if delta < 0:
            chosen = BaseFit(alt, nodes, f"laws on {count} nodes (saturating or accelerating in "
                                         "the field)")
    return chosen
