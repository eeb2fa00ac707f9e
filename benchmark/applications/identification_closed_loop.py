"""The identification study closes its own loop: laboratory campaign, residual loop, building models.

After the seed paper's protocol (:mod:`~damper.identification.voltage_grid`), the study

1. runs the laboratory campaign of :mod:`~benchmark.applications.identification_campaign` on the device
   (voltage steps and switching, small amplitudes, random motion with random voltage), through
   :mod:`damper.lab.laboratory` only;
2. runs the residual loop (:func:`damper.diagnosis.diagnose`) on it, from the normalized and
   from the extended base model, the training tests fitted and the separate held-out tests
   judging every term. The loop adds what it finds; nothing here names an effect;
3. for the seed's claim, builds the normalized model *with the effects the loop found from the
   extended base* (refitted jointly, :func:`damper.diagnosis.augmented.refit`): the two forms then differ
   only by the extended model's elastic term :math:`\\kappa_x x`, which is the premise of the
   claim (the seed compares the forms, nothing else);
4. turns each augmented model into a model the building's compiled kernels run
   (:func:`building_model`), so that it is validated like the seed's models: replayed with the
   *commanded* voltage (a field lag the loop found is part of the model) and re-run in the
   building in place of the device.

It also gives the seed's own two models of Fig. 11 (:func:`closed_form_models`): the
"original method" (Rodríguez et al.'s closed form on the normalized model, no elastic term, no
refinement) and "proposed" (the seed's step (a), then the same closed form on
:math:`F - \\kappa_x x`), each with the seed's voltage laws (eq. 5-10).
"""

from __future__ import annotations

import sys
import time
import warnings
from dataclasses import dataclass, field
from functools import partial
from typing import Callable, Sequence

import numpy as np

from benchmark.foundation.errors import InputError, ParameterError
from damper.identification.refine import free_parameters
from damper.identification.voltage_grid import fit_voltage_laws, voltage_model
from damper.diagnosis import diagnose
from damper.diagnosis.augmented import AugmentedModel, make_base, refit
from damper.diagnosis import DiagnosisData
from benchmark.applications.identification_campaign import laboratory_campaign
from benchmark.foundation.pools import run_tasks

__all__ = ["ORIGINAL", "PROPOSED", "CLOSED_LOOP_NORMALIZED", "CLOSED_LOOP_EXTENDED", "LOOP_FROM_NORMALIZED",
           "ClosedLoopResult", "building_model", "closed_form_models", "close_the_loop", "start_loops",
           "finish_loops",
           "claim_object", "claim_summary"]

#: Validation names of the seed's Fig. 11 models and of the closed loop's models.
ORIGINAL = "original"
PROPOSED = "proposed"
CLOSED_LOOP_EXTENDED = "closed-loop-extended"
CLOSED_LOOP_NORMALIZED = "closed-loop-normalized"
#: The loop's own result from the normalized base (reported; it may add the elastic term itself).
LOOP_FROM_NORMALIZED = "loop-from-normalized"

def building_model(model):
    """The registered damper model that computes what the augmented ``model`` computes.

    :meth:`damper.diagnosis.augmented.AugmentedModel.building_model` (κ_x, the series dashpot with
    its field lag, the memoryless force terms), refusing a model with an effect the building
    cannot run: the closed loop re-runs its models in the building, and a model that left an
    effect out would be scored as something it is not.

    Parameters
    ----------
    model : damper.diagnosis.augmented.AugmentedModel or a registered damper model

    Returns
    -------
    damper model
        A registered model (``model_id``, ``to_array``).

    Raises
    ------
    InputError
        An effect has no counterpart in a registered model (a ``voltage_lag`` without
        ``roll_off`` included: the Bouc-Wen kernels have no field state), named in the message.
    """
    if not isinstance(model, AugmentedModel):
        return model
    built, dropped = model.building_model()
    if dropped:
        raise InputError("building model: no compiled kernel carries " + "; ".join(dropped))
    return built


def closed_form_models(grid, voltage_range: tuple[float, float] = (0.0, 1.0), notes: list | None = None) -> dict:
    """The seed's Fig. 11 models from a voltage grid's closed-form steps (no refinement).

    ``"original"``: Rodríguez et al.'s closed form of the normalized model at each voltage;
    ``"proposed"``: the extended model's closed form with the grid's :math:`\\kappa_x` (the seed's
    step (a), held fixed), at each voltage. Each gets the seed's voltage laws (eq. 5-10), a law
    leaving the admissible class being replaced by PCHIP through the values
    (:func:`~damper.identification.voltage_grid.voltage_model`).

    Parameters
    ----------
    grid : VoltageGridResult
        With the normalized and extended identifications.
    voltage_range : tuple of float
    notes : list, optional
        Receives a line for each law replaced and each value clipped into the admissible class.
    """

    # Admissible class of the closed-form values (DOMAIN.md §4): kappa > 0, sigma >= 1/2, n >= 1.
    floors = {"kappa_xdot": 1e-9, "kappa_w": 1e-9, "rho": 1e-9, "sigma": 0.5, "n": 1.0, "kappa_x": 0.0}
    out = {}
    for name, kind in ((ORIGINAL, "normalized"), (PROPOSED, "extended")):
        if kind not in grid.identifications:
            continue
        names = free_parameters(kind)
        table = np.array([[i.closed_form.parameters()[k] for k in names] for i in grid.identifications[kind]])
        for j, k in enumerate(names):
            low = table[:, j] < floors[k]
            if np.any(low) and notes is not None:
                notes.append(f"{name}: closed-form {k} below its admissible floor at "
                             f"{np.count_nonzero(low)} voltage(s); clipped to {floors[k]:g}")
            table[:, j] = np.maximum(table[:, j], floors[k])
        laws = fit_voltage_laws(grid.voltages, table, names)
        out[name] = voltage_model(kind, laws["seed"], laws["generic"], notes, voltage_range)
    return out


@dataclass
class ClosedLoopResult:
    """Result of :func:`close_the_loop`.

    Attributes
    ----------
    campaign : Campaign
    diagnoses : dict
        Base kind -> :class:`damper.diagnosis.Diagnosis`.
    models : dict
        Validation name -> augmented model (:data:`CLOSED_LOOP_EXTENDED`,
        :data:`CLOSED_LOOP_NORMALIZED`, :data:`LOOP_FROM_NORMALIZED`).
    building : dict
        Validation name -> registered model (:func:`building_model`), or the reason it has none.
    heldout_errors : dict
        Validation name -> held-out relative RMS force error on the campaign.
    timings : dict
    """

    campaign: object = field(repr=False)
    diagnoses: dict = field(repr=False)
    models: dict = field(repr=False)
    building: dict = field(repr=False)
    heldout_errors: dict
    timings: dict

    def to_json(self) -> dict:
        """JSON-ready: campaign tests, each loop's steps and verdict, the models, held-out errors."""
        loops = {}
        for kind, d in self.diagnoses.items():
            loops[kind] = {"error_before": d.error_before, "error_after": d.error_after,
                           "effects": [{"name": s.name, "parameters": s.parameters,
                                        "error_after_adding": s.error_after} for s in d.selection.steps],
                           "unexplained_in": [{"variable": v, "share": s, "level": lv}
                                              for v, s, lv in d.unexplained_in],
                           "errors_by_test": {k: {"before": b, "after": a}
                                              for k, (b, a) in d.errors_by_test.items()}}
        return {"campaign": self.campaign.describe(), "loops": loops,
                "models": {k: m.to_dict() for k, m in self.models.items()},
                "building_models": {k: (b if isinstance(b, str) else type(b).__name__)
                                    for k, b in self.building.items()},
                "heldout_errors": self.heldout_errors, "timings": self.timings}


def _say_stderr(kind: str, msg: str) -> None:
    """The loop's progress line from a pool worker (stderr is shared with the study)."""
    print(f"sbib identify: closed loop, {kind} base: {msg.strip()}", file=sys.stderr, flush=True)


def _diagnose_task(train, heldout, kind: str, max_nfev: int, verbose: bool = False):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return diagnose(list(train), model=kind, validate=list(heldout), max_nfev=max_nfev,
                        progress=partial(_say_stderr, kind) if verbose else None)


def _counterpart_task(found, train, heldout, max_nfev: int):
    """The normalized base with the effects ``found`` (an extended loop's model), refitted jointly.

    Starts from the extended model's parameters without :math:`\\kappa_x`; the base laws keep the
    loop's voltage nodes.
    """

    data = DiagnosisData.from_tests(list(train), validate=list(heldout))
    params = found.base_parameters()
    base = make_base("normalized", params, found.base.voltage_range)
    start = AugmentedModel(base, tuple(e for e in found.effects if e.name != "stiffness"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fit = refit(start, data.motions, data.forces, data.train, nodes=data.nodes(), max_nfev=max_nfev)
    return fit.model


def _heldout_error(model, tests) -> float:
    num = den = 0.0
    for t in tests:
        f = np.asarray(t.force, dtype=float)
        g = model.simulate(t.time, t.displacement, t.velocity, v=t.voltage).force
        num += float(np.sum((f - g) ** 2))
        den += float(np.sum(f ** 2))
    return float(np.sqrt(num / den))


def start_loops(device, executor=None, campaign=None, campaign_scale: float = 0.5, max_nfev: int = 200,
                progress: Callable[[str], None] | None = None) -> dict:
    """Run the campaign and submit the two loops to ``executor`` (first half of :func:`close_the_loop`).

    Returns the job description :func:`finish_loops` completes. Without an executor the loops
    run in :func:`finish_loops`.

    Parameters
    ----------
    device
        The virtual damper (model instance or name).
    executor : concurrent.futures.Executor, optional
        Process pool to run on (:func:`benchmark.foundation.pools.make_executor`); None: run inline.
    campaign : Campaign, optional
        The test campaign; None: the default campaign.
    campaign_scale : float, optional
        Scale of the campaign's amplitudes (1: as designed).
    max_nfev : int, optional
        Most function evaluations of each fit.
    progress : Callable[[str], None] | None, optional
        Called with one line of text per finished step; None: silent.
    """

    say = progress or (lambda msg: None)
    t0 = time.perf_counter()
    if campaign is None:
        campaign = laboratory_campaign(device, scale=campaign_scale)
    timings = {"campaign_s": time.perf_counter() - t0}
    n = sum(t.time.size for t in campaign.train + campaign.heldout)
    say(f"closed loop: campaign of {len(campaign.train)} training and {len(campaign.heldout)} held-out "
        f"tests ({n} samples); residual loop from the normalized and the extended base started")
    tasks = [(campaign.train, campaign.heldout, k, max_nfev, progress is not None) for k in _KINDS]
    futures = None if executor is None else [executor.submit(_diagnose_task, *t) for t in tasks]
    return {"campaign": campaign, "tasks": tasks, "futures": futures, "timings": timings,
            "max_nfev": max_nfev, "say": say, "t0": time.perf_counter()}


_KINDS = ("extended", "normalized")


def finish_loops(job: dict, executor=None) -> ClosedLoopResult:
    """Gather the loops of :func:`start_loops`, build the claim's normalized counterpart and the
    building models (second half of :func:`close_the_loop`).

    Parameters
    ----------
    job : dict
        What :func:`start_loops` returned.
    executor : concurrent.futures.Executor, optional
        The pool the loops were submitted to; None: they ran inline.
    """

    say, campaign, timings = job["say"], job["campaign"], dict(job["timings"])
    if job["futures"] is None:
        results = run_tasks(_diagnose_task, job["tasks"])
    else:
        results = [f.result() for f in job["futures"]]
    diagnoses = dict(zip(_KINDS, results))
    for d in results:
        say(f"closed loop: {d.model_kind} base, held-out error {d.error_before:.4f} -> {d.error_after:.4f}, "
            f"added {', '.join(d.effects) or 'nothing'}")
    timings["loops_s"] = time.perf_counter() - job["t0"]
    t0 = time.perf_counter()
    found = diagnoses["extended"].final_model
    say("closed loop: refitting the normalized base with the effects found from the extended base")
    counterpart = _counterpart_task(found, campaign.train, campaign.heldout, job["max_nfev"])
    timings["counterpart_s"] = time.perf_counter() - t0
    models = {CLOSED_LOOP_EXTENDED: found, CLOSED_LOOP_NORMALIZED: counterpart,
              LOOP_FROM_NORMALIZED: diagnoses["normalized"].final_model}
    building = {}
    for name, m in models.items():
        try:
            building[name] = building_model(m)
        except (InputError, ParameterError) as exc:
            building[name] = str(exc)
    errors = {name: _heldout_error(m, campaign.heldout) for name, m in models.items()}
    return ClosedLoopResult(campaign, diagnoses, models, building, errors, timings)


def close_the_loop(device, campaign=None, executor=None, progress: Callable[[str], None] | None = None,
                   max_nfev: int = 200, campaign_scale: float = 0.5) -> ClosedLoopResult:
    """Run the laboratory campaign and the residual loop; build the claim's pair (module docstring).

    Parameters
    ----------
    device : damper model or str
        The device under test (through :mod:`damper.lab.laboratory` only).
    campaign : Campaign, optional
        Tests to use (default :func:`~benchmark.applications.identification_campaign.laboratory_campaign`).
    executor : concurrent.futures.Executor, optional
        A pool: the two loops run at once.
    progress : callable, optional
        Receives a one-line message at each stage.
    max_nfev : int
        Residual evaluations per joint refit of the loop.
    campaign_scale : float
        Duration factor of the default campaign's tests.

    Returns
    -------
    ClosedLoopResult
    """
    job = start_loops(device, executor, campaign, campaign_scale, max_nfev, progress)
    return finish_loops(job, executor)


def claim_object(names: dict | None = None) -> dict:
    """The ``claim`` object of ``validation.json``: the model keys of the seed's comparison.

    ``{"original": ..., "proposed": ..., "closed_loop": {"normalized": ..., "extended": ...}}``.

    Parameters
    ----------
    names : dict | None, optional
        Model keys of the two models compared; None: the seed's.
    """
    names = names or {}
    return {"original": names.get("original", ORIGINAL), "proposed": names.get("proposed", PROPOSED),
            "closed_loop": {"normalized": names.get("normalized", CLOSED_LOOP_NORMALIZED),
                            "extended": names.get("extended", CLOSED_LOOP_EXTENDED)}}


def claim_summary(validation_json: dict, claim: dict, mean_target: float = 1.0 / 3.0) -> dict:
    """The seed's claim measured on a validation document: per-run extended/normalized error ratios.

    For the seed's pair (``proposed``/``original``) and the closed loop's pair: the ratio of the
    relative RMS force errors on every run, its mean and maximum, whether it is below 1 on every
    run and at most ``mean_target`` on average.

    Parameters
    ----------
    validation_json : dict
        A validation document (``validation.json``) as a dict.
    claim : dict
        The claim object (:func:`claim_object`).
    mean_target : float, optional
        The mean ratio the seed claims.
    """
    errors = validation_json["errors"]
    out = {}
    pairs = {"seed": (claim["proposed"], claim["original"]),
             "closed_loop": (claim["closed_loop"]["extended"], claim["closed_loop"]["normalized"])}
    for label, (ext, nor) in pairs.items():
        ratios = {}
        for rec, by_o in errors.items():
            for o, e in by_o.items():
                if ext in e and nor in e and e[nor]["rel_rms_error"] > 0:
                    ratios[f"{rec} {o}"] = e[ext]["rel_rms_error"] / e[nor]["rel_rms_error"]
        if not ratios:
            continue
        r = np.array(list(ratios.values()))
        out[label] = {"extended": ext, "normalized": nor, "ratio_by_run": ratios,
                      "ratio_mean": float(r.mean()), "ratio_max": float(r.max()),
                      "below_one_every_run": bool(r.max() < 1.0),
                      "mean_at_most_target": bool(r.mean() <= mean_target), "mean_target": mean_target}
    return out
