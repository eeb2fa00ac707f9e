"""The residual loop end to end: base fit, residual trace, effect selection, verdict.

:func:`diagnose` runs, on a set of damper tests,

1. the fit of a base model (normalized or extended Bouc-Wen; constant parameters for one coil
   input level, voltage laws otherwise) on the training samples (:mod:`~damper.diagnosis.base_fit`);
2. the trace of its held-out residual (:mod:`~damper.diagnosis.trace`);
3. the forward selection of library effects by held-out BIC, each refitted jointly with the
   model (:mod:`~damper.diagnosis.selection`);
4. the trace of the final held-out residual and the verdict: the residual keeps *unexplained*
   structure when some variable explains at least ``structure_share`` of its variance **and** that
   part is at least ``structure_level`` of the measured force RMS (a tiny residual may be
   structured without mattering). Where it lives is reported (``unexplained_in``), no term is
   forced.

Steps 1 and 3 run on the tests decimated to about ``coarse_samples`` fitted samples (on windows of
them where the motion's bandwidth bounds the decimation) and simulated at a coarser sub-step
tolerance (:func:`~damper.diagnosis.coarse.coarse_pass`); every
held-out error, trace and the verdict are computed on all samples at the model's own tolerance.

Errors are relative RMS force errors :math:`\\|F - \\hat F\\|_2/\\|F\\|_2` on the held-out samples.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Callable, Sequence

import numpy as np

from benchmark.foundation.errors import InputError, NumericalError, ParameterError
from damper.diagnosis.alignment import force_alignment
from damper.diagnosis.interference import interference_lines, mains_lines
from damper.diagnosis.levels import force_levels, level_lines
from damper.diagnosis.augmented import AugmentedModel, base_at_bounds, refit
from damper.io.data import DamperTest
from damper.diagnosis.base_fit import fit_base, fit_spencer_base
from damper.diagnosis.coarse import DEFAULT_COARSE_SAMPLES, Progress, coarse_pass, decimation_factor
from damper.diagnosis.coverage import coverage_lines, motion_coverage
from damper.diagnosis.dataset import DEFAULT_HOLDOUT, DiagnosisData
from damper.io.reader import check_coil_inputs, count_reversals
from damper.diagnosis.effects import Motion
from damper.diagnosis.selection import (DEFAULT_MIN_GAIN, DEFAULT_JOINT_TRIALS, DEFAULT_TOLERANCE,
                                        DEFAULT_TRACE_SHARE,
                                        DEFAULT_TRIALS, SelectionResult, Step, select_effects)
from damper.diagnosis.trace import DEFAULT_BINS, TRACE_VARIABLES, ResidualTrace, trace_residual

__all__ = ["Diagnosis", "diagnose", "unexplained_structure", "tare_matters", "force_zero_text", "TARE_SHARE", "DEFAULT_STRUCTURE_SHARE",
           "DEFAULT_STRUCTURE_LEVEL", "BASE_MODELS", "UNLOCATED"]

#: Base models of :func:`diagnose` (``"auto"``: chosen from the tests' coil input).
BASE_MODELS = ("normalized", "extended", "spencer", "auto")

#: A variable "holds" residual structure when it explains at least this share of its variance ...
DEFAULT_STRUCTURE_SHARE = 0.2
#: ... and that part is at least this fraction of the measured force RMS.
DEFAULT_STRUCTURE_LEVEL = 0.02


#: The ``unexplained_in`` entry of structure that no trace variable locates (a residual that is not
#: white: :func:`unexplained_structure`).
UNLOCATED = "unlocated"


def unexplained_structure(trace: ResidualTrace, force_rms: float,
                          min_share: float = DEFAULT_STRUCTURE_SHARE,
                          min_level: float = DEFAULT_STRUCTURE_LEVEL) -> list[tuple[str, float, float]]:
    """Variables holding residual structure: ``(variable, share, level)``, largest level first.

    ``level`` is the RMS of the part of the residual the variable explains over ``force_rms``:
    :math:`\\sqrt{\\eta^2\\,\\mathrm{var}(r)}/F_{rms}`; for ``mean`` the constant part
    :math:`|\\bar r|/F_{rms}`.
    Where no variable holds such structure but the residual is not white, the entry
    :data:`UNLOCATED` holds the structured part: share :math:`1 - w` (``w`` the white-noise share
    of the variance, :attr:`~damper.diagnosis.trace.ResidualTrace.noise_fraction`), level
    :math:`\\sqrt{1 - w}\\,r_{rms}/F_{rms}`, under the same two thresholds.

    Parameters
    ----------
    trace : ResidualTrace
        The residual trace.
    force_rms : float
        RMS of the measured force [N].
    min_share : float, optional
        Smallest share of the residual variance that counts as structure.
    min_level : float, optional
        Smallest level (explained RMS over ``force_rms``) that counts.
    """
    if not force_rms > 0:
        raise InputError("unexplained_structure: force_rms must be > 0")
    var = max(trace.rms ** 2 * (1.0 - trace.mean_share), 0.0)
    found = []
    for name, share in trace.shares.items():
        level = math.sqrt(share * var) / force_rms
        if share >= min_share and level >= min_level:
            found.append((name, float(share), float(level)))
    mean_level = math.sqrt(trace.mean_share) * trace.rms / force_rms
    if trace.mean_share >= min_share and mean_level >= min_level:
        found.append(("mean", float(trace.mean_share), float(mean_level)))
    structured = 1.0 - trace.noise_fraction
    level = math.sqrt(max(structured, 0.0)) * trace.rms / force_rms
    if not found and structured >= min_share and level >= min_level:
        # structure no trace variable locates (a dead zone a few samples long after each
        # reversal, a heating the tests' power drives, a channel skew): the residual is not white,
        # and its structured part is above the level; a probe's loose joint had left 9 % of the
        # force with no variable over the share and the verdict 'nothing unexplained'
        found.append((UNLOCATED, float(structured), float(level)))
    return sorted(found, key=lambda f: -f[2])


@dataclass(frozen=True)
class Diagnosis:
    """Result of :func:`diagnose`.

    Parameters
    ----------
    settings : dict, optional
        The loop's settings (hold-out, validation, minimum gain, trials, …), as written to the JSON report.

    Attributes
    ----------
    data : DiagnosisData
    model_kind : str
        Base model kind.
    base_model, final_model : AugmentedModel
        The fitted base model and the augmented model the loop ends with.
    error_before, error_after : float
        Held-out relative RMS force errors of the two.
    selection : SelectionResult
        Steps (one per effect added, with the error after each) and the trials of each round.
    trace_before, trace_after : ResidualTrace
        Held-out residual traces of the two models.
    unexplained : bool
        The final residual keeps structure no library term explained.
    unexplained_in : list of (variable, share, level)
        Where it lives (:func:`unexplained_structure`).
    errors_by_test : dict
        Test name -> (error before, error after) on its held-out samples.
    errors_by_input : dict
        Coil-input level -> (error before, error after) (tests at a constant input only).
    settings : dict
        The options of the run, its time and whether the time budget ended it.
    validation : dict or None
        Errors on other recordings of the same device (``cross_validate``), never fitted:
        ``{"tests", "error_before", "error_after", "errors_by_test"}``.
    alignment : dict or None
        The measured force's time shift against the final model
        (:func:`damper.diagnosis.alignment.force_alignment`); None when it cannot be searched.
    interference : dict or None
        Mains lines of the final residual (:func:`damper.diagnosis.interference.mains_lines`:
        ``lines``, ``searched``, ``tests``, ``error``, ``error_without``,
        ``error_without_by_frequency``); None when no test could be searched.
    force_levels : dict or None
        Each test's force level against the final model and the held-out error with one level
        per test (:func:`damper.diagnosis.levels.force_levels`); None with fewer than two tests.
    validation_histories : tuple of ValidationHistory
        The ``cross_validate`` recordings with both models' forces, for the report's figure
        (not in the JSON).
    forces_before, forces_after : tuple of ndarray
        The base and the final model's force histories [N] over every test of ``data``, as
        the errors above were computed from them (the report's figures draw them; not in the
        JSON). Empty: not kept.
    """

    data: DiagnosisData = field(repr=False)
    model_kind: str
    base_model: AugmentedModel
    final_model: AugmentedModel
    error_before: float
    error_after: float
    selection: SelectionResult = field(repr=False)
    trace_before: ResidualTrace = field(repr=False)
    trace_after: ResidualTrace = field(repr=False)
    unexplained: bool
    unexplained_in: list
    errors_by_test: dict
    errors_by_input: dict
    settings: dict = field(default_factory=dict)
    validation: dict | None = None
    alignment: dict | None = None
    validation_histories: tuple = field(default=(), repr=False)
    interference: dict | None = None
    force_levels: dict | None = None
    forces_before: tuple = field(default=(), repr=False)
    forces_after: tuple = field(default=(), repr=False)

    @property
    def effects(self) -> list[str]:
        """Names of the effects added, in order."""
        return [s.name for s in self.selection.steps]

    @property
    def base_at_bounds(self) -> dict[str, str]:
        """The final model's base shape parameters at a bound of the search (not identified by
        the data; :func:`damper.diagnosis.augmented.base_at_bounds`)."""
        return base_at_bounds(self.final_model)

    def to_json(self) -> dict:
        """The ``sbib diagnose --json`` document.

        Keys: ``model``, ``error_before``, ``error_after``, ``effects`` (``name``, ``parameters``,
        ``error_after_adding``), ``unexplained``, ``residual_trace`` (variable -> share of the
        final held-out residual's variance), plus ``unexplained_in``, ``residual_trace_before``,
        ``whiteness``, ``errors_by_test``, ``errors_by_input``, ``input``, ``final_model``,
        ``base_at_bounds`` (the final base's shape parameters at a bound of the search,
        :func:`damper.diagnosis.augmented.base_at_bounds`), ``validation`` (errors on the
        ``cross_validate`` recordings) when there are some, and
        ``force_alignment`` (the measured force's time shift against the final model,
        :func:`damper.diagnosis.alignment.force_alignment`) and ``interference`` (mains lines of the
        final residual, :func:`damper.diagnosis.interference.mains_lines`) when they could be searched.
        """
        final_effects = {e.name: e.parameters for e in self.final_model.effects}
        return {
            "model": self.model_kind,
            "error_before": float(self.error_before),
            "error_after": float(self.error_after),
            "effects": [{"name": s.name, "parameters": final_effects.get(s.name, s.parameters),
                         "error_after_adding": float(s.error_after)}
                        for s in self.selection.steps],
            "unexplained": bool(self.unexplained),
            "unexplained_in": [{"variable": v, "share": round(s, 4), "level": round(lv, 4)}
                               for v, s, lv in self.unexplained_in],
            "residual_trace": {**{k: round(float(v), 4) for k, v in self.trace_after.shares.items()},
                               "mean": round(float(self.trace_after.mean_share), 4)},
            "residual_trace_before": {**{k: round(float(v), 4)
                                         for k, v in self.trace_before.shares.items()},
                                      "mean": round(float(self.trace_before.mean_share), 4)},
            "whiteness": {"before": _whiteness(self.trace_before),
                          "after": _whiteness(self.trace_after)},
            "errors_by_test": {k: {"before": b, "after": a} for k, (b, a) in self.errors_by_test.items()},
            "errors_by_input": {f"{k:g}": {"before": b, "after": a}
                                for k, (b, a) in self.errors_by_input.items()},
            "input": self.data.input_name,
            **({} if self.data.input_recorded else {"input_recorded": False}),
            "base_model": self.base_model.to_dict(),
            "base_at_bounds": self.base_at_bounds,
            "final_model": self.final_model.to_dict(),
            "settings": dict(self.settings),
            **({} if self.validation is None else {"validation": self.validation}),
            **({} if self.alignment is None else {"force_alignment": dict(self.alignment)}),
            **({} if self.interference is None else {"interference": {
                **self.interference,
                "error_without_by_frequency": {f"{k:g}": v for k, v in
                                               self.interference["error_without_by_frequency"].items()}}}),
            **({} if self.force_levels is None else {"force_levels": self.force_levels}),
        }


def _whiteness(trace: ResidualTrace) -> dict:
    return {"ljung_box": float(trace.ljung_box), "p_value": float(trace.ljung_box_p),
            "lags": int(trace.lags), "lag1_autocorrelation": float(trace.lag1),
            "effective_samples": float(trace.effective_samples),
            "noise_fraction": float(trace.noise_fraction)}


def _errors(data: DiagnosisData, before: list, after: list) -> tuple[dict, dict]:
    by_test, grouped = {}, {}
    for m, f, k, fb, fa in zip(data.motions, data.forces, data.heldout, before, after):
        if not k.any():
            continue
        norm = float(np.linalg.norm(f[k]))
        eb = float(np.linalg.norm(f[k] - fb[k]) / norm)
        ea = float(np.linalg.norm(f[k] - fa[k]) / norm)
        by_test[m.name] = (eb, ea)
        if np.ptp(m.v) == 0.0:
            g = grouped.setdefault(round(float(m.v[0]), 9), [0.0, 0.0, 0.0])
            g[0] += float(np.sum((f[k] - fb[k]) ** 2))
            g[1] += float(np.sum((f[k] - fa[k]) ** 2))
            g[2] += norm ** 2
    by_input = {lvl: (math.sqrt(g[0] / g[2]), math.sqrt(g[1] / g[2])) for lvl, g in sorted(grouped.items())}
    return by_test, by_input


@dataclass(frozen=True)
class ValidationHistory:
    """One ``--validate`` recording with both models' forces (SI), for the report's figure.

    Parameters
    ----------
    motion : Motion
        The recording's motion and coil input (the input held at the fitted range's edge).
    force : ndarray
        Measured force [N].
    scored : ndarray of bool
        The samples its error counts.
    before, after : ndarray
        The base and the final model's forces [N].
    """

    motion: Motion
    force: np.ndarray
    scored: np.ndarray
    before: np.ndarray
    after: np.ndarray


#: The validation's error with each recording's force zero re-estimated is worth a line when it
#: is below this share of the error as scored (a tare, not noise, is then part of the error).
TARE_SHARE = 0.9


def tare_matters(validation: dict) -> bool:
    """Whether re-estimating each other recording's force zero lowers the final model's error
    there below :data:`TARE_SHARE` of it (the report and the command line then say so).

    Parameters
    ----------
    validation : dict
        :attr:`Diagnosis.validation`.
    """
    after, zeroed = validation.get("error_after"), validation.get("error_after_force_zero")
    return (after is not None and zeroed is not None and math.isfinite(after) and math.isfinite(zeroed)
            and zeroed < TARE_SHARE * after)


def force_zero_text(validation: dict) -> str:
    """Each other recording's force zero as the output and the report write it (``a -1.6 N, b -153 N``).

    Parameters
    ----------
    validation : dict
        :attr:`Diagnosis.validation`.
    """
    return ", ".join(f"{n} {z['after']:+.4g} N" for n, z in validation["force_zero"].items())


def _fingerprint(test: DamperTest) -> bytes:
    """The samples of a test (time, displacement, force), to tell a fitted recording given again."""
    return b"".join(np.ascontiguousarray(a, dtype=float).tobytes()
                    for a in (test.time, test.displacement, test.force))


def check_recordings(tests: Sequence[DamperTest], data: DiagnosisData,
                     recordings: Sequence[DamperTest]) -> DiagnosisData:
    """Refuse, before any fit, other recordings (``--validate``) that cannot score the model.

    Parameters
    ----------
    tests : sequence of DamperTest
        The fitted tests.
    data : DiagnosisData
        ``tests`` prepared (their coil-input levels).
    recordings : sequence of DamperTest
        The other recordings.

    Returns
    -------
    DiagnosisData
        ``recordings`` prepared for scoring (every sample after each one's first reversal).

    Raises
    ------
    InputError
        A recording without the coil-input column the fitted tests have (or the reverse: its
        force would be predicted at an input nobody measured); one that is a fitted test again
        (its score would be a training score); one shorter than a cycle of motion or with fewer
        scored samples than a held-out part needs; one at another level of the input when the
        fitted tests are all at one level (that model has no law of the input).
    """
    recordings = list(recordings)
    label = [(t.name or t.source or "a recording", t) for t in recordings]
    check_coil_inputs([(t.name or t.source or "a test", t) for t in tests] + label, "--validate")
    fitted = {_fingerprint(t) for t in tests}
    for name, t in label:
        if _fingerprint(t) in fitted:
            raise InputError(f"--validate: {name} is also a fitted test (--data): its score would be "
                             "a training score; expected another recording of the device")
    prepared = DiagnosisData.from_tests(recordings, validate=recordings)
    if prepared.input_name != data.input_name and prepared.input_recorded:
        raise InputError(f"--validate: the recordings give a {prepared.input_name}, the fitted "
                         f"tests a {data.input_name}; expected the same coil input")
    n = len(recordings)
    need = 4 * DEFAULT_BINS  # as for the held-out part of the fitted tests (diagnose)
    levels = data.levels()
    for m, k in zip(prepared.motions[n:], prepared.heldout[n:]):
        scored = int(k.sum())
        turns = count_reversals(m.x)
        if scored < need or turns < 2:
            raise InputError(f"--validate: {m.name}: {scored} scored samples, {turns} reversal(s) of the "
                             f"displacement; expected at least {need} samples and a cycle of motion")
        if data.input_recorded and levels.size == 1:
            # a measured input wanders around its level: 5 % of the larger of the two, or 0.02 A (V)
            tol = max(0.05 * abs(float(levels[0])), 0.05 * float(np.max(np.abs(m.v[k]))), 0.02)
            off = np.abs(m.v - levels[0]) > tol
            if np.mean(off[k]) > 0.05:
                unit = data.input_unit
                raise InputError(
                    f"--validate: {m.name} is at {float(np.median(m.v[k])):.4g} {unit} where the fitted tests "
                    f"are all at {float(levels[0]):.4g} {unit}: a model fitted at one {data.input_name} "
                    f"has no law of the {data.input_name} (fit tests at several levels, or validate at "
                    f"{float(levels[0]):.4g} {unit})")
    return prepared


def _cross_validation(prepared: DiagnosisData, before: AugmentedModel,
                      after: AugmentedModel, levels: np.ndarray | None = None) -> tuple[dict, tuple]:
    """Errors of the base and final models on other recordings (``prepared`` by
    :func:`check_recordings`: every sample after each one's first reversal; nothing of them was
    fitted or used to choose), and their histories.

    Beside them, the errors with each recording's force zero re-estimated on it
    (``error_*_force_zero``, the constants in ``force_zero`` [N]): a load cell zeroed anew for each
    recording moves the whole force by a constant that no model of the device predicts (the
    LabControl UTFPR files sit at -25 to +150 N at rest; docs/diagnosis.md)."""
    n = len(prepared.motions) // 2  # prepared with validate=the recordings: each one twice
    motions, forces, masks = prepared.motions[n:], prepared.forces[n:], prepared.heldout[n:]
    sums = {"before": [0.0, 0.0], "after": [0.0, 0.0]}
    zeroed = {"before": 0.0, "after": 0.0}  # residual sums of squares with each recording's force zero re-estimated
    by_test = {}
    zeros = {}
    clipped = {}
    beyond = {}
    histories: list = []
    lo, hi = before.base.voltage_range
    for m, f, k in zip(motions, forces, masks):
        if levels is not None and levels.size > 1:
            # between the fitted levels the laws interpolate; past them they extrapolate
            tol = 1e-3 * max(1.0, float(np.max(np.abs(levels))))
            out = k & ((m.v < levels[0] - tol) | (m.v > levels[-1] + tol))
            if out.any():
                beyond[m.name] = {"samples": int(out.sum()), "share": float(out.sum() / max(1, k.sum())),
                                  "levels": [float(levels[0]), float(levels[-1])]}
        # another recording's input may reach a little past the range the fitted tests spanned
        # (the model's laws are checked only over that range): held at its edge, and said so
        outside = (m.v < lo) | (m.v > hi)
        if outside.any():
            excess = float(np.max(np.maximum(lo - m.v, m.v - hi)))
            clipped[m.name] = {"samples": int(outside.sum()), "largest_excess": excess}
            m = replace(m, v=np.clip(m.v, lo, hi))
        norm2 = float(np.sum(f[k] ** 2))
        errs = {}
        predicted = {}
        zeros[m.name] = {}
        for label, model in (("before", before), ("after", after)):
            predicted[label] = model.force(m)
            r = f[k] - predicted[label][k]
            sums[label][0] += float(r @ r)
            sums[label][1] += norm2
            errs[label] = float(math.sqrt(float(r @ r) / norm2)) if norm2 > 0 else math.nan
            # a load cell's zero (tare) is the recording's, not the device's: the constant that
            # best explains this recording's residual, and the error left without it
            c = float(np.mean(r)) if r.size else 0.0
            zeros[m.name][label] = c
            zeroed[label] += float((r - c) @ (r - c))
            errs[f"{label}_force_zero"] = (float(math.sqrt(float((r - c) @ (r - c)) / norm2))
                                           if norm2 > 0 else math.nan)
        by_test[m.name] = errs
        histories.append(ValidationHistory(m, f, k, predicted["before"], predicted["after"]))
    return ({"tests": [m.name for m in motions],
             "error_before": math.sqrt(sums["before"][0] / sums["before"][1]),
             "error_after": math.sqrt(sums["after"][0] / sums["after"][1]),
             "errors_by_test": by_test, "input_clipped": clipped, "input_beyond_levels": beyond,
             # the same errors with each recording's own force zero (a constant per recording,
             # re-estimated on it): how much of the error is a load cell's tare, not the model
             "error_before_force_zero": math.sqrt(zeroed["before"] / sums["before"][1]),
             "error_after_force_zero": math.sqrt(zeroed["after"] / sums["after"][1]),
             "force_zero": zeros}, tuple(histories))


def _polish(model: AugmentedModel, data: DiagnosisData, nodes, nfev: int, tolerance: float,
            say, label: str) -> AugmentedModel:
    """Refit ``model`` on every sample with at most ``nfev`` evaluations; keep it if it is better."""
    if nfev <= 0:
        return model
    before = data.relative_error(model, "train")
    try:
        fit = refit(model, data.motions, data.forces, data.train, nodes=nodes, max_nfev=nfev,
                    tolerance=tolerance)
    except (NumericalError, ParameterError, InputError):
        return model
    if fit.relative_rms_error < before:
        say(f"polished the {label} on all samples: training error {before:.4f} -> "
            f"{fit.relative_rms_error:.4f}")
        return fit.model
    return model


def _full_rate_steps(selection: SelectionResult, final: AugmentedModel, data: DiagnosisData,
                     forces_before: list, forces_after: list) -> tuple[SelectionResult, list]:
    """The steps' held-out errors recomputed on every sample: the first step starts from the
    base model's histories ``forces_before``, the last ends at ``final``'s ``forces_after``
    (both already simulated), the steps between are simulated. Also returns each step's force
    histories (the loop falls back on them when it leaves a last step out)."""
    last = len(selection.steps) - 1
    steps, histories, previous = [], [], data.relative_error(None, "heldout", forces=forces_before)
    for i, s in enumerate(selection.steps):
        model = final if i == last else s.model
        forces = forces_after if i == last else [model.force(m) for m in data.motions]
        after = data.relative_error(None, "heldout", forces=forces)
        steps.append(replace(s, error_before=previous, error_after=after, model=model))
        histories.append(forces)
        previous = after
    return SelectionResult(final, tuple(steps), selection.rounds, selection.stopped_by_budget), histories


def diagnose(tests: Sequence[DamperTest], model: str = "normalized",
             holdout: float | None = DEFAULT_HOLDOUT, validate: Sequence[DamperTest] | None = None,
             candidates: Sequence[str] | None = None, *, min_gain: float = DEFAULT_MIN_GAIN,
             trials: int = DEFAULT_TRIALS, max_effects: int | None = None,
             structure_share: float = DEFAULT_STRUCTURE_SHARE,
             structure_level: float = DEFAULT_STRUCTURE_LEVEL, max_nfev: int = 200,
             progress: Callable[[str], None] | None = None,
             coarse_samples: int | None = DEFAULT_COARSE_SAMPLES, polish_nfev: int = 0,
             tolerance: float = DEFAULT_TOLERANCE,
             trace_share: float = DEFAULT_TRACE_SHARE,
             joint_trials: int | None = DEFAULT_JOINT_TRIALS,
             cross_validate: Sequence[DamperTest] | None = None,
             time_budget: float | None = None) -> Diagnosis:
    """Run the residual loop on damper tests (see the module docstring).

    Parameters
    ----------
    tests : sequence of DamperTest
        Tests to fit (any motion, constant or varying coil input; all voltage or all current).
    model : {"normalized", "extended", "spencer", "auto"}
        Base model: a Bouc-Wen model (normalized or extended), or Spencer et al.'s (1997)
        model with voltage laws and its field lag
        (:class:`~damper.models.series_dashpot.SpencerBoucWen`, fitted by
        :func:`~damper.diagnosis.base_fit.fit_spencer_base`). ``"auto"`` takes ``"spencer"``
        when the coil input changes within a test (the field lag belongs in the base then: a
        random command, voltage steps) and ``"normalized"`` otherwise.
    holdout : float
        Fraction of each test, at its end, held out (ignored with ``validate``).
    validate : sequence of DamperTest, optional
        Separate held-out tests (then every sample of ``tests`` is fitted and the effects are
        chosen on these).
    candidates : sequence of str, optional
        Effect names to consider (default: the whole library).
    min_gain : float
        Smallest relative drop of the held-out error an effect must bring.
    trials : int
        Candidates refitted per round.
    max_effects : int, optional
        At most this many effects.
    structure_share, structure_level : float
        Thresholds of the unexplained-structure verdict (:func:`unexplained_structure`).
    max_nfev : int
        Residual evaluations per joint refit.
    progress : callable, optional
        Receives one-line progress messages (each prefixed with the elapsed time).
    coarse_samples : int or None
        The base fit and the selection run on the tests decimated to about this many fitted
        samples (on windows of them where the motion's bandwidth bounds the decimation),
        simulated at a coarser sub-step tolerance (:mod:`~damper.diagnosis.coarse`);
        ``None`` fits every sample at the model's own tolerance.
    polish_nfev : int
        After a coarse pass, the base and the final models are refitted on every sample with at
        most this many residual evaluations and kept where the training error falls. Default 0:
        on the virtual laboratory's 1-3 kHz tests the polish changed the training error by
        1e-4 at a third of the loop's cost (the models are continuous-time, the coarse fit is
        already the fit).
    tolerance : float
        Stopping tolerance of the refits (:func:`damper.diagnosis.augmented.refit`).
    trace_share : float
        Share of the training residual a trace variable must hold to name its effects
        (:func:`~damper.diagnosis.selection.effects_for_trace`).
    joint_trials : int or None
        Candidates refitted jointly with the model per round, the most promising after each was
        refitted alone (:func:`~damper.diagnosis.selection.select_effects`).

    cross_validate : sequence of DamperTest, optional
        Other recordings of the same device (``sbib diagnose --validate``): the base and final
        models are scored on all of them (:attr:`Diagnosis.validation`); they are never fitted
        and never choose an effect.
    time_budget : float, optional
        Seconds the effect selection may start new rounds for: once spent, the round under way
        finishes its refits, no new round starts, and ``settings["stopped_by_budget"]`` says so
        (the base fit always runs to its end).

    Returns
    -------
    Diagnosis

    Raises
    ------
    InputError
        Bad tests or options.
    NumericalError
        The base model could not be fitted.
    """
    say = Progress(progress, quiet=progress is None)
    if time_budget is not None and not (isinstance(time_budget, (int, float)) and time_budget > 0):
        raise InputError(f"--time-budget: expected a number of seconds > 0, got {time_budget!r}")
    if model not in BASE_MODELS:
        raise InputError(f"model: expected one of {', '.join(BASE_MODELS)}, got {model!r}")
    data = DiagnosisData.from_tests(tests, holdout=holdout, validate=validate)
    recordings = check_recordings(tests, data, cross_validate) if cross_validate else None
    need = 4 * DEFAULT_BINS  # the residual trace's equal-count bins (damper.diagnosis.trace)
    for masks, label in ((data.heldout, "held-out"), (data.train, "fitted")):
        count = sum(int(k.sum()) for k in masks)
        if count < need:
            names = ", ".join(m.name for m in data.motions)  # which tests: the user may have passed several
            raise InputError(f"diagnose ({names}): {count} usable {label} samples; the residual trace needs at "
                             f"least {need} (longer tests, another --holdout, or --validate with "
                             "another recording)")
    if model == "auto":
        model = "spencer" if data.input_varies_within_tests else "normalized"
        say(f"base model: {model} (the {data.input_name} "
            + ("changes within the tests: the field lag belongs in the base)" if model == "spencer"
               else "is constant within each test)"))
    elif model != "spencer" and data.input_varies_within_tests:
        # the normalized and extended bases follow the command at once (a lag is the
        # voltage_lag effect's to find); say where the standard model of such data is
        say(f"the {data.input_name} changes within the tests: --model spencer (or auto) starts from "
            "Spencer et al.'s model with its field lag")
    nodes = data.nodes()
    q = decimation_factor(data, coarse_samples)
    # the Spencer-type base filters the input through its own field; the others read it in their laws
    work = data if coarse_samples is None else coarse_pass(data, q, coarse_samples,
                                                           "mean" if model == "spencer" else "end")
    # a window carries the time its test began (Motion.origin); the tests themselves do not
    n_windows = sum(m.origin is not None for m in work.motions)
    if q > 1 or n_windows:
        windowed = ("" if not n_windows else
                    f" in {n_windows} windows of {len(data.motions)} test(s), "
                    f"{sum(float(m.t[-1] - m.t[0]) for m in work.motions):.1f} of "
                    f"{sum(float(m.t[-1] - m.t[0]) for m in data.motions):.1f} s simulated")
        say(f"coarse pass: one sample in {q}{windowed} ({sum(int(k.sum()) for k in work.train)} of "
            f"{sum(int(k.sum()) for k in data.train)} fitted samples)")
    if model == "spencer":
        say(f"fitting the Spencer-type base model to {len(data.motions)} test(s)")
        fitted = fit_spencer_base(work, max_nfev=max_nfev, tolerance=tolerance, progress=say)
        base, nodes = fitted.model, fitted.nodes
        if nodes is not None:
            say(f"  {data.input_name} laws on nodes {[round(float(v), 4) for v in nodes]}: {fitted.note}")
    else:
        say(f"fitting the {model} base model to {len(data.motions)} test(s)"
            + ("" if nodes is None else f" with {data.input_name} laws on nodes {[round(float(v), 4) for v in nodes]}"))
        base = fit_base(work, model, max_nfev=max_nfev, tolerance=tolerance, progress=say).model
    if work is not data:
        base = _polish(base, data, nodes, polish_nfev, tolerance, say, "base model")
    forces_before = [base.force(m) for m in data.motions]
    residual_before = data.measured("heldout") - data.concat(forces_before, "heldout")
    norm_h = float(np.linalg.norm(data.measured("heldout")))
    error_before = float(np.linalg.norm(residual_before) / norm_h)
    say(f"base model: held-out relative RMS error {error_before:.4f}")
    signals = data.signals("heldout")
    trace_before = trace_residual(residual_before, signals)
    selection = select_effects(base, work, candidates, nodes=nodes, min_gain=min_gain,
                               trials=trials, max_effects=max_effects, max_nfev=max_nfev,
                               progress=say, tolerance=tolerance, trace_share=trace_share,
                               joint_trials=joint_trials,
                               deadline=None if time_budget is None else
                               say.start + float(time_budget))
    final = selection.model
    if work is not data and selection.steps:  # the model's tolerance at every sample
        final = _polish(final, data, nodes, polish_nfev, tolerance, say, "final model")
    forces_after = [final.force(m) for m in data.motions]
    dropped: list[str] = []
    if work is not data and selection.steps:  # the steps' errors at every sample
        selection, histories = _full_rate_steps(selection, final, data, forces_before, forces_after)
        # an effect chosen on the coarse pass that does not lower the held-out error at every
        # sample did not pay: the last such steps go (a probe's noisy copy of ranran_50 had
        # ended with fade at 0.1305 -> 0.1309); an earlier step stays, the later ones build on it
        while selection.steps and selection.steps[-1].error_after >= selection.steps[-1].error_before:
            last = selection.steps[-1]
            say(f"{last.name}: held-out error at every sample {last.error_before:.4f} -> {last.error_after:.4f}; "
                "it paid on the coarse pass only: left out")
            dropped.append(last.name)
            steps = selection.steps[:-1]
            final = steps[-1].model if steps else base
            selection = SelectionResult(final, steps, selection.rounds, selection.stopped_by_budget)
            forces_after = histories[len(steps) - 1] if steps else forces_before
        if dropped and selection.steps and polish_nfev > 0:
            # the model the loop ends with is polished on every sample, as the dropped one was
            final = _polish(final, data, nodes, polish_nfev, tolerance, say, "final model")
            forces_after = [final.force(m) for m in data.motions]
            last = replace(selection.steps[-1], model=final,
                           error_after=data.relative_error(None, "heldout", forces=forces_after))
            selection = replace(selection, model=final, steps=selection.steps[:-1] + (last,))
    residual_after = data.measured("heldout") - data.concat(forces_after, "heldout")
    error_after = float(np.linalg.norm(residual_after) / norm_h)
    trace_after = trace_residual(residual_after, signals)
    f_rms = float(norm_h / math.sqrt(residual_after.size))
    where = unexplained_structure(trace_after, f_rms, structure_share, structure_level)
    by_test, by_input = _errors(data, forces_before, forces_after)
    seen = [tr | ho for tr, ho in zip(data.train, data.heldout)]  # every usable sample of each test
    # the force channel's skew against the final model, over every usable sample
    alignment = force_alignment([m.t for m in data.motions], data.forces, forces_after, seen,
                                velocities=[m.xdot for m in data.motions], inputs=[m.v for m in data.motions])
    if alignment is not None and alignment["finding"]:
        say(f"the measured force is {1e3 * alignment['shift_s']:+.3g} ms ({alignment['shift_samples']:+.1f} "
            f"samples) off the final model: error {alignment['error_unshifted']:.4f} -> "
            f"{alignment['error_shifted']:.4f} if shifted; check the channels' timing")
    # a mains hum on the force channel: a line of the residual no motion drives
    interference = mains_lines([m.name for m in data.motions], [m.t for m in data.motions], data.forces,
                               forces_after, [m.x for m in data.motions], [m.xdot for m in data.motions],
                               seen, data.heldout)
    for text, _ in interference_lines(interference):
        say(text)
    # the force level of each test against the final model: a device that changed between tests
    levels = force_levels([m.name for m in data.motions], data.forces, forces_after, data.train, data.heldout)
    for text, _ in level_lines(levels):
        say(text)
    for s in selection.steps:
        say(f"added {s.name} {s.parameters}: held-out error {s.error_before:.4f} -> {s.error_after:.4f}")
    if where:
        say("unexplained structure in " + ", ".join(
            f"{'no trace variable (the residual is not white)' if v == UNLOCATED else v} "
            f"(share {s:.2f}, level {lv:.3f})" for v, s, lv in where))
    settings = {"holdout": data.holdout, "validated": data.holdout is None, "min_gain": min_gain,
                "trials": trials, "structure_share": structure_share,
                "structure_level": structure_level,
                "nodes": None if nodes is None else [float(x) for x in nodes],
                "candidates": list(candidates) if candidates is not None else None,
                "decimation": q, "coarse_samples": coarse_samples, "polish_nfev": polish_nfev,
                "coarse_windows": n_windows,
                "tolerance": tolerance, "trace_share": trace_share, "joint_trials": joint_trials,
                "time_budget": time_budget, "stopped_by_budget": selection.stopped_by_budget,
                "dropped_at_full_rate": dropped,
                "seconds": round(say.elapsed, 3)}
    validation, validation_histories = None, ()
    if recordings is not None:
        validation, validation_histories = _cross_validation(recordings, base, final,
                                                             data.levels() if data.input_recorded else None)
        say(f"validation on {', '.join(validation['tests'])}: error "
            f"{validation['error_before']:.4f} -> {validation['error_after']:.4f}")
        # what of that error is extrapolation: the other recordings' motion beyond the fitted tests'
        validation["coverage"] = motion_coverage(
            data.motions, seen, validation_histories)
        for text, _ in coverage_lines(validation["coverage"]):
            say(text)
    return Diagnosis(data=data, model_kind=model, base_model=base, final_model=final,
                     error_before=error_before, error_after=error_after, selection=selection,
                     trace_before=trace_before, trace_after=trace_after,
                     unexplained=bool(where), unexplained_in=where, errors_by_test=by_test,
                     errors_by_input=by_input, settings=settings, validation=validation,
                     alignment=alignment, validation_histories=validation_histories,
                     interference=interference, force_levels=levels,
                     forces_before=tuple(forces_before), forces_after=tuple(forces_after))

