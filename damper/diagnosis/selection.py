"""Matching the residual against the effect library and choosing terms by held-out BIC.

One round of the forward selection, from the current (fitted) model :math:`\\hat F(p)`:

1. **Screen** (a score, or Lagrange-multiplier, test). For each candidate effect :math:`e` not
   yet in the model, its sensitivity :math:`j_e = \\partial \\hat F/\\partial\\theta_e` at the neutral
   value (finite difference) is projected off the span of the model's own sensitivities
   :math:`J = \\partial\\hat F/\\partial p`, :math:`j_e^\\perp = (I - JJ^+)j_e`. On the training
   residual :math:`r`, the first-order share of the residual sum of squares the term can remove is

   .. math:: s_e = \\frac{(j_e^{\\perp\\top} r)^2}{(j_e^{\\perp\\top} j_e^\\perp)\\,(r^\\top r)},
             \\qquad \\hat\\theta_e = \\frac{j_e^{\\perp\\top} r}{j_e^{\\perp\\top} j_e^\\perp},

   and a candidate whose :math:`\\hat\\theta_e` leaves its admissible interval (a negative mass,
   stiffness, turbulent coefficient or time constant) scores 0.
2. **Refit** the best-scoring candidates, and every candidate the trace of the training
   residual names (:func:`effects_for_trace`: an effect is tried whenever a variable it depends
   on holds a share of the residual), first alone (the candidate's own parameter, the model
   held: two simulations per iteration), then the ``joint_trials`` most promising jointly
   with the model (:func:`damper.diagnosis.augmented.refit`): the best screening score, then those that
   alone lower the held-out error by at least half of ``min_gain``, and always a series term
   and, when the input changes, an input term (a model fitted without them compensates, so
   their effect-only refit says little).
3. **Choose** by the Bayesian information criterion on the held-out samples,

   .. math:: \\mathrm{BIC} = N_\\text{eff}\\ln(\\mathrm{RSS}_h/N_h) + k\\ln N_\\text{eff},

   with :math:`k` the number of free parameters and :math:`N_\\text{eff}` the effective sample size of
   the current held-out residual (:func:`~damper.diagnosis.trace.effective_sample_size`): model
   residuals are strongly autocorrelated, and the raw sample count would make any term look
   worth its parameter. The best candidate is added when it lowers the BIC *and* lowers the
   held-out relative RMS error by at least ``min_gain`` (a fraction of the current error).
   Rounds repeat while a term pays.

References
----------
Schwarz G. (1978) *Estimating the dimension of a model*, Ann. Statist. 6(2).
Breusch T.S., Pagan A.R. (1980) *The Lagrange multiplier test and its applications to model
specification in econometrics*, Rev. Econ. Stud. 47(1).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

from benchmark.foundation.errors import InputError, NumericalError, ParameterError
from damper.diagnosis.augmented import (BASE_DECLARES, AugmentedModel, Parametrization, RefitResult, refit,
                                       refit_from_starts)
from damper.diagnosis.dataset import DiagnosisData
from damper.diagnosis.trace import bic_delta, effective_sample_size, trace_residual
from damper.diagnosis.effects import Effect, effect_names, get_effect
# the package's one relative RMS error (mask and weights), re-exported here for the loop
from damper.fitting import DEFAULT_STALL
from damper.identification.metrics import relative_rms_error

__all__ = [
    "ScreenScore",
    "Trial",
    "Step",
    "SelectionResult",
    "relative_rms_error",
    "screen_columns",
    "screen_effects",
    "model_jacobian",
    "select_effects",
    "effects_for_trace",
    "with_candidate",
    "DEFAULT_MIN_GAIN",
    "DEFAULT_TRACE_SHARE",
    "DEFAULT_STALL",
]

#: An effect must lower the held-out error by at least this fraction of the current error.
DEFAULT_MIN_GAIN = 0.02
#: Candidates refitted per round (the best screening scores).
DEFAULT_TRIALS = 3
#: Screening scores below this are not refitted.
MIN_SCORE = 1e-3
#: A trace variable explaining at least this share of the training residual's variance (or a
#: mean holding this share of its mean square) *names* its effects: they are refitted whatever
#: their screening score.
DEFAULT_TRACE_SHARE = 0.1
#: Candidates refitted jointly with the model per round, after each was refitted alone.
DEFAULT_JOINT_TRIALS = 2
#: Stopping tolerance of the loop's refits (see :func:`damper.diagnosis.augmented.refit`).
DEFAULT_TOLERANCE = 1e-6


def effects_for_trace(shares: dict, mean_share: float, names, min_share: float = DEFAULT_TRACE_SHARE
                      ) -> dict[str, list[str]]:
    """The effects (among ``names``) a residual trace points to: effect -> variables naming it.

    Each effect declares the trace variables where its missing term shows up
    (:attr:`damper.diagnosis.effects.Effect.traces`: displacement, velocity, acceleration, voltage,
    voltage_rate, time, sign, loop, mean); a variable holding at least ``min_share`` of the
    residual's variance names every effect that depends on it.

    Parameters
    ----------
    shares : dict
        Share of the residual variance per trace variable.
    mean_share : float
        Share of the constant part of the residual.
    names
        Effect names considered.
    min_share : float, optional
        Smallest share of a variable that names its effects.
    """
    held = {k for k, v in shares.items() if v >= min_share}
    if mean_share >= min_share:
        held.add("mean")
    out: dict[str, list[str]] = {}
    for n in names:
        hit = [v for v in get_effect(n).traces if v in held]
        if hit:
            out[n] = hit
    return out


@dataclass(frozen=True)
class ScreenScore:
    """Screening of one candidate: ``score`` (share of the training RSS it can remove to first
    order), ``estimate`` (its parameter at that first order), ``reason`` when it scores 0.

    Parameters
    ----------
    name : str
        Effect name (:data:`damper.diagnosis.effects.EFFECTS`).
    score : float
        Share of the training RSS the candidate can remove, to first order.
    estimate : float
        Its parameter at that first order (SI).
    reason : str, optional
        Why it scores 0, when it does.
    """

    name: str
    score: float
    estimate: float
    reason: str = ""


def screen_columns(residual: np.ndarray, base_columns: np.ndarray | None,
                   columns: dict, lower: dict | None = None) -> dict:
    """Score candidate columns against a residual, orthogonally to ``base_columns``.

    Parameters
    ----------
    residual : ndarray (N,)
        Residual :math:`F - \\hat F` to explain.
    base_columns : ndarray (N, p) or None
        Directions the current model can already move in (its sensitivities).
    columns : dict of str to ndarray (N,)
        Candidate sensitivities :math:`\\partial\\hat F/\\partial\\theta_e`.
    lower : dict of str to float, optional
        Lower bound of each candidate's parameter relative to its neutral value (0: only
        positive changes are admissible); absent means unbounded below.

    Returns
    -------
    dict of str to ScreenScore
    """
    r = np.asarray(residual, dtype=float)
    rr = float(r @ r)
    lower = dict(lower or {})
    q = None
    if base_columns is not None and np.size(base_columns):
        b = np.asarray(base_columns, dtype=float)
        norms = np.linalg.norm(b, axis=0)
        b = b[:, norms > 0] / norms[norms > 0]
        if b.shape[1]:
            u, s, _ = np.linalg.svd(b, full_matrices=False)
            q = u[:, s > 1e-10 * s[0]]
    out = {}
    for name, col in columns.items():
        j = np.asarray(col, dtype=float)
        if j.shape != r.shape:
            raise InputError(f"screen: column {name!r} has shape {j.shape}, expected {r.shape}")
        jp = j - q @ (q.T @ j) if q is not None else j
        jj = float(jp @ jp)
        if not np.isfinite(jj) or jj <= 1e-20 * max(float(j @ j), 1e-300) or rr <= 0:
            out[name] = ScreenScore(name, 0.0, 0.0, "no direction of its own (collinear with the "
                                    "model's parameters or zero)")
            continue
        jr = float(jp @ r)
        estimate = jr / jj
        if name in lower and estimate < lower[name]:
            out[name] = ScreenScore(name, 0.0, estimate, "the residual asks for an inadmissible "
                                    "(negative) value")
            continue
        out[name] = ScreenScore(name, jr * jr / (jj * rr), estimate)
    return out


def _train_forces(model: AugmentedModel, data: DiagnosisData) -> np.ndarray:
    return data.concat([model.force(m) for m in data.motions], "train")


def model_jacobian(model: AugmentedModel, data: DiagnosisData, nodes=None,
                   relative_step: float = 1e-4) -> np.ndarray:
    """Forward-difference sensitivities of the training force to every free parameter, (N, p).

    Parameters
    ----------
    model : AugmentedModel
        The current (augmented) model.
    data : DiagnosisData
        The prepared tests (:class:`damper.diagnosis.dataset.DiagnosisData`).
    nodes : ndarray, optional
        Coil-input nodes [V] of the piecewise-linear voltage laws (:meth:`DiagnosisData.nodes`); None:
        parameters constant.
    relative_step : float, optional
        Forward-difference step relative to each parameter's size.
    """
    par = Parametrization(model, nodes=nodes)
    p0 = par.vector(model)
    f0 = _train_forces(model, data)
    cols = []
    for i in range(par.size):
        step = relative_step * max(abs(p0[i]), par.scale[i] * 1e-3, 1e-12)
        p = p0.copy()
        p[i] = p0[i] + step if p0[i] + step <= par.upper[i] else p0[i] - step
        try:
            fi = _train_forces(par.model(p, validate=False), data)
        except (ParameterError, NumericalError):
            continue
        cols.append((fi - f0) / (p[i] - p0[i]))
    return np.column_stack(cols) if cols else np.zeros((f0.size, 0))


def with_candidate(model: AugmentedModel, effect: Effect, nodes=None) -> AugmentedModel:
    """``model`` with ``effect`` added; for a ``series`` effect (``roll_off``) on a base whose
    shape parameters vary with the coil input, those are first replaced by their mean over the
    ``nodes`` (the series model needs them independent of the input, see
    :class:`~damper.diagnosis.augmented.Parametrization`), so that the effect can be tried at all.

    Parameters
    ----------
    model : AugmentedModel
        The current (augmented) model.
    effect : Effect
        The candidate effect.
    nodes : ndarray, optional
        Coil-input nodes [V] of the piecewise-linear voltage laws (:meth:`DiagnosisData.nodes`); None:
        parameters constant.
    """
    trial = model.with_effect(effect)
    if effect.role != "series" or nodes is None:
        return trial
    par = Parametrization(trial, nodes=nodes)
    return par.model(par.vector(trial))


def screen_effects(model: AugmentedModel, data: DiagnosisData, candidates: Sequence[str],
                   scales: dict, nodes=None) -> dict:
    """Screen ``candidates`` (effect names) for the current ``model`` (see the module docstring).

    Returns a dict of :class:`ScreenScore`; a candidate that cannot be seen in these data
    (e.g. ``voltage_lag`` at constant voltage) scores 0 with the reason.

    Parameters
    ----------
    model : AugmentedModel
        The current (augmented) model.
    data : DiagnosisData
        The prepared tests (:class:`damper.diagnosis.dataset.DiagnosisData`).
    candidates : Sequence[str]
        Names of the effects to screen.
    scales : dict
        Typical parameter size of each candidate (:meth:`damper.diagnosis.effects.Effect.scale`).
    nodes : ndarray, optional
        Coil-input nodes [V] of the piecewise-linear voltage laws (:meth:`DiagnosisData.nodes`); None:
        parameters constant.
    """
    f0 = _train_forces(model, data)
    residual = data.measured("train") - f0
    columns, lower, out = {}, {}, {}
    for name in candidates:
        cls = get_effect(name)
        why = cls.not_identifiable(list(data.motions))
        if why:
            out[name] = ScreenScore(name, 0.0, 0.0, f"not identifiable: {why}")
            continue
        step = 1e-2 * scales[name]
        try:
            trial = with_candidate(model, cls(cls.neutral + step), nodes)
            reference = with_candidate(model, cls.off(), nodes)
            f_ref = f0 if reference.base is model.base else _train_forces(reference, data)
            columns[name] = (_train_forces(trial, data) - f_ref) / step
        except (ParameterError, NumericalError, InputError) as exc:
            out[name] = ScreenScore(name, 0.0, 0.0, f"cannot be evaluated: {exc}")
            continue
        if cls.lower >= cls.neutral:
            lower[name] = 0.0
    base_columns = model_jacobian(model, data, nodes=nodes)
    out.update(screen_columns(residual, base_columns, columns, lower))
    for name, s in list(out.items()):
        if s.score > 0:  # estimate is a change from neutral
            out[name] = ScreenScore(name, s.score, get_effect(name).neutral + s.estimate, s.reason)
    return {name: out[name] for name in candidates}


@dataclass(frozen=True)
class Trial:
    """One candidate refitted in a round: its held-out error and BIC change.

    Parameters
    ----------
    name : str
        Effect name (:data:`damper.diagnosis.effects.EFFECTS`).
    score : float
        Screening score of the candidate.
    error : float
        Held-out relative RMS force error after the refit.
    bic_delta : float
        Change of the held-out BIC (negative: better).
    parameters : dict
        Fitted parameter values of the effect, by name (SI).
    accepted : bool, optional
        Whether the effect was added.
    note : str, optional
        Why it was refused or failed, when it was.
    """

    name: str
    score: float
    error: float
    bic_delta: float
    parameters: dict
    accepted: bool = False
    note: str = ""


@dataclass(frozen=True)
class Step:
    """One effect added: the model after it and the held-out errors around it.

    Parameters
    ----------
    name : str
        Effect name (:data:`damper.diagnosis.effects.EFFECTS`).
    parameters : dict
        Fitted parameter values of the effect, by name (SI).
    error_before : float
        Held-out relative RMS force error before the step.
    error_after : float
        Held-out relative RMS force error after the step.
    bic_delta : float
        Change of the held-out BIC (negative: better).
    effective_samples : float
        Effective number of independent held-out samples
        (:func:`damper.diagnosis.trace.effective_sample_size`).
    model : AugmentedModel
        The model after the step.
    """

    name: str
    parameters: dict
    error_before: float
    error_after: float
    bic_delta: float
    effective_samples: float
    model: AugmentedModel = field(repr=False)


@dataclass(frozen=True)
class SelectionResult:
    """Outcome of :func:`select_effects`: the steps taken, the rounds' trials and screens.

    Parameters
    ----------
    model : AugmentedModel
        The final model.
    steps : tuple
        The :class:`Step` of each effect added, in order.
    rounds : tuple
        Each round's trials and screens.
    stopped_by_budget : bool
        The time budget ended the selection before it had nothing more to add.
    """

    model: AugmentedModel
    steps: tuple
    rounds: tuple  # per round: (screen dict, list of Trial)
    stopped_by_budget: bool = False


def _heldout_rss(model: AugmentedModel, data: DiagnosisData) -> tuple[float, np.ndarray]:
    residual = data.residual(model, "heldout")
    return float(residual @ residual), residual


def select_effects(model: AugmentedModel, data: DiagnosisData,
                   candidates: Sequence[str] | None = None, *, nodes=None,
                   min_gain: float = DEFAULT_MIN_GAIN, trials: int = DEFAULT_TRIALS,
                   max_effects: int | None = None, max_nfev: int = 200,
                   progress: Callable[[str], None] | None = None,
                   tolerance: float = DEFAULT_TOLERANCE,
                   trace_share: float = DEFAULT_TRACE_SHARE,
                   joint_trials: int | None = DEFAULT_JOINT_TRIALS,
                   deadline: float | None = None,
                   stall: tuple[int, float] | None = DEFAULT_STALL) -> SelectionResult:
    """Forward selection of library effects by held-out BIC (see the module docstring).

    Parameters
    ----------
    model : AugmentedModel
        The fitted starting model (usually the base model alone).
    data : DiagnosisData
    candidates : sequence of str, optional
        Effect names to consider (default: the whole library, minus what the model declares).
    nodes : sequence of float, optional
        Voltage nodes of the base parameters' laws (as used for the base fit).
    min_gain : float
        Smallest relative drop of the held-out error that counts as paying.
    trials : int
        Candidates refitted per round.
    max_effects : int, optional
        Stop after this many effects.
    max_nfev : int
        Residual evaluations per joint refit (an effect with a start grid takes
        :data:`~damper.diagnosis.augmented.START_NFEV` more from each of its starts).
    progress : callable, optional
        Called with a one-line message after each trial.
    tolerance : float
        Stopping tolerance of each refit.
    trace_share : float
        Variables of the training residual's trace holding at least this share name their
        effects (:func:`effects_for_trace`), which are refitted besides the ``trials`` best
        screening scores.
    joint_trials : int or None
        Each candidate is first refitted alone (its own parameter, the model held); the
        ``joint_trials`` that lower the held-out error most are then refitted jointly with the
        model, and only those can be added (``None``: all).
    deadline : float, optional
        A :func:`time.perf_counter` value: no round starts after it (the round under way
        finishes), and the result says so (``stopped_by_budget``).
    stall : (int, float) or None
        Each trial's refit stops once that many iterations in a row lowered its cost by less
        than that share of it (:data:`DEFAULT_STALL`; None: the tolerance alone).

    Returns
    -------
    SelectionResult
    """
    if not 0.0 <= min_gain < 1.0:
        raise InputError(f"min_gain: expected 0 <= min_gain < 1, got {min_gain}")
    names = list(effect_names() if candidates is None else candidates)
    for n in names:
        get_effect(n)
    # the base may declare a term already (kappa_x x; the Spencer-type base's c1 and field lag)
    names = [n for n in names if n not in BASE_DECLARES[model.base_kind]]
    motions = list(data.motions)
    f_rms = data.force_rms("train")
    scales = {n: get_effect(n).scale(motions, f_rms) for n in effect_names()}
    measured_h = data.measured("heldout")
    norm_h = float(np.linalg.norm(measured_h))
    steps, rounds = [], []
    current = model
    stopped = False
    # No memory of an earlier round's failed joint refits: a term may pay only once another is in
    # (shear thinning beside quadratic damping: its joint refit went to k = 0 in round 1 and
    # recovered the truth in round 2), and since trials stop when they stall, trying again costs
    # nothing measurable (UTFSM 0 A and 1 A, the Dyke recording: the same effects and time).
    while True:
        remaining = [n for n in names if n not in current.effect_names]
        if not remaining or (max_effects is not None and len(steps) >= max_effects):
            break
        if deadline is not None and time.perf_counter() >= deadline:
            stopped = True
            if progress:
                progress(f"time budget spent: no round {len(rounds) + 1}; the model so far is kept")
            break
        rss_old, res_old = _heldout_rss(current, data)
        err_old = math.sqrt(rss_old) / norm_h
        n_eff = effective_sample_size(res_old)
        screens = screen_effects(current, data, remaining, scales, nodes=nodes)
        ranked = sorted((s for s in screens.values() if s.score >= MIN_SCORE),
                        key=lambda s: -s.score)[:trials]
        # the trace of the training residual names the effects that depend on where it lives
        train_res = data.residual(current, "train")
        tr = trace_residual(train_res, data.signals("train"))
        named = effects_for_trace(tr.shares, tr.mean_share, remaining, trace_share)
        if data.input_varies_within_tests:
            # a field lag leaves a residual that follows each input change for a few time
            # constants: no binned variable holds it, and its first-order score at tau = 0 is a
            # derivative through a step; so an input term is always tried when the input changes
            for n in remaining:
                if get_effect(n).role == "input" and n not in named:
                    named[n] = ["voltage_rate"]
        for name, variables in named.items():
            sc = screens[name]
            if any(s.name == name for s in ranked) or sc.reason.startswith(("not identifiable",
                                                                           "cannot be evaluated")):
                continue
            cls = get_effect(name)
            estimate = sc.estimate if sc.score > 0 else cls.neutral + 0.05 * scales[name]
            ranked.append(ScreenScore(name, sc.score, estimate,
                                      "named by the trace: " + ", ".join(variables)))
        if progress and ranked:
            progress(f"round {len(rounds) + 1}: held-out error {err_old:.4f}; refitting "
                     + ", ".join(s.name for s in ranked))
        round_trials, best = [], None
        base_scales = {**scales, **{k: abs(v) for k, v in _base_scales(current).items()}}
        # stage 1, cheap: each candidate's own parameter alone (two simulations per iteration)
        quick = []
        for s in ranked:
            cls = get_effect(s.name)
            try:
                start = with_candidate(current, cls.from_value(s.estimate), nodes)
                fit = refit(start, motions, data.forces, data.train, nodes=nodes,
                            scales=base_scales, fixed_base=True, max_nfev=max_nfev,
                            tolerance=tolerance, stall=stall)
                rss_q, _ = _heldout_rss(fit.model, data)
            except (NumericalError, ParameterError, InputError) as exc:
                round_trials.append(Trial(s.name, s.score, math.nan, math.inf, {}, note=str(exc)))
                continue
            quick.append((rss_q, s, fit.model))
        quick.sort(key=lambda item: item[0])
        # a term that cannot lower the error by half the required gain on its own is not
        # refitted jointly (the joint refit costs a simulation per model parameter and step)
        promising = [item for item in quick
                     if math.sqrt(item[0]) / norm_h <= (1.0 - 0.5 * min_gain) * err_old]
        # ... except the best screening score, whose first-order estimate already allows for
        # the model's own parameters moving (a term the model partly absorbs shows only jointly)
        by_score = [item for item in quick if item[1].score >= MIN_SCORE]
        if by_score:
            top = max(by_score, key=lambda item: item[1].score)
            promising = [top] + [item for item in promising if item is not top]
        joint = promising[:joint_trials] if joint_trials is not None else promising
        # a series term changes the base model's own parameters (shape shared over the nodes),
        # so its effect-only refit says little: it is always refitted jointly
        # so does an input term on data whose input changes (the model was fitted without it
        # and compensates: its effect-only refit can even raise the error)
        joint += [item for item in quick if item not in joint
                  and (get_effect(item[1].name).role == "series"
                       or (get_effect(item[1].name).role == "input"
                           and data.input_varies_within_tests))]
        # and so does a term the trace names whose effect-only refit stayed at its neutral value:
        # the model fitted without it compensated in the other direction (an inertial force the
        # base absorbed as a softer pre-yield branch), so only a joint refit can show it
        joint += [item for item in quick if item not in joint and item[1].name in named
                  and _at_neutral(item[2].effect(item[1].name), scales[item[1].name])]
        chosen = {id(item) for item in joint}
        for rss_q, s, _ in (item for item in quick if id(item) not in chosen):
            err_q = math.sqrt(rss_q) / norm_h
            round_trials.append(Trial(s.name, s.score, err_q, bic_delta(rss_old, rss_q, n_eff, 1),
                                      {}, note="effect-only refit; not refitted jointly"))
            if progress:
                progress(f"  screened {s.name} alone: held-out error {err_old:.4f} -> {err_q:.4f}")
        # stage 2: the most promising refitted jointly with the model
        for _, s, quick_model in joint:
            if deadline is not None and time.perf_counter() >= deadline:
                stopped = True  # end cleanly: the trials left are reported, not refitted
                round_trials.append(Trial(s.name, s.score, math.nan, math.inf, {},
                                          note="not refitted jointly: time budget spent"))
                if progress:
                    progress(f"  time budget spent: {s.name} not refitted jointly")
                continue
            try:
                fit = _joint_refit(quick_model, current, s.name, data, nodes, base_scales, max_nfev,
                                   tolerance, stall)
                rss_new, _ = _heldout_rss(fit.model, data)
            except (NumericalError, ParameterError, InputError) as exc:
                round_trials.append(Trial(s.name, s.score, math.nan, math.inf, {}, note=str(exc)))
                continue
            err_new = math.sqrt(rss_new) / norm_h
            delta = bic_delta(rss_old, rss_new, n_eff, 1)
            effect = fit.model.effect(s.name)
            trial = Trial(s.name, s.score, err_new, delta, effect.parameters)
            round_trials.append(trial)
            if progress:
                progress(f"  tried {s.name}: held-out error {err_old:.4f} -> {err_new:.4f}, "
                         f"BIC change {delta:+.1f}")
            pays = delta < 0.0 and err_new <= (1.0 - min_gain) * err_old
            if pays and (best is None or delta < best[0].bic_delta):
                best = (trial, fit.model)
        if best is not None:
            trial, new_model = best
            round_trials = [Trial(**{**t.__dict__, "accepted": t is trial}) for t in round_trials]
            steps.append(Step(trial.name, trial.parameters, err_old, trial.error, trial.bic_delta,
                              n_eff, new_model))
            current = new_model
        rounds.append((screens, round_trials))
        if best is None or stopped:
            break
    return SelectionResult(current, tuple(steps), tuple(rounds), stopped)


def _joint_refit(quick_model: AugmentedModel, current: AugmentedModel, name: str, data: DiagnosisData,
                 nodes, scales: dict, max_nfev: int, tolerance: float,
                 stall: tuple[int, float] | None) -> RefitResult:
    """The joint refit of the candidate ``name`` from its effect-only refit ``quick_model``.

    A parameter whose landscape has several minima (the effect's
    :meth:`~damper.diagnosis.effects.Effect.start_grid`: a field lag under a command that changes
    within the tests) is refitted jointly from the effect-only value and from each value of the
    grid for :data:`~damper.diagnosis.augmented.START_NFEV` evaluations; the start with the least
    training error goes on to convergence (its short refit stands if that fails or ends worse).
    Others: one refit from ``quick_model``."""
    cls = get_effect(name)
    grid = cls.start_grid(list(data.motions))
    starts = [quick_model, *(with_candidate(current, cls.from_value(g), nodes) for g in grid)]
    best = refit_from_starts(starts, data.motions, data.forces, data.train, nodes=nodes, scales=scales,
                             max_nfev=max_nfev, tolerance=tolerance, stall=stall)
    if best is None:
        raise NumericalError(f"{name}: no start of its joint refit could be evaluated")
    return best


def _at_neutral(effect: Effect, scale: float) -> bool:
    """Whether ``effect`` sits at its neutral value, within 1e-3 of its typical size."""
    return abs(effect.value - type(effect).neutral) <= 1e-3 * abs(scale)


def _base_scales(model: AugmentedModel) -> dict:
    out = {}
    for k, v in model.base_parameters().items():
        try:
            out[k] = float(v) if not hasattr(v, "values") else float(np.max(np.abs(v.values)))
        except TypeError:
            continue
    return out
