"""Validation of identified models inside full earthquake simulations (the seed paper's Fig. 11).

For every benchmark record and orientation:

1. the building runs with its own dampers (the device under test, e.g. the virtual benchmark
   damper in the default layout) under a semi-active controller, so the voltages fluctuate;
   each damper's displacement, velocity, commanded voltage and force are recorded, as a
   field measurement would;
2. these inputs are replayed through each identified (voltage-dependent) model with
   :func:`damper.simulate` — as the seed paper does, with the commanded voltage, and also
   through the identified field filter (:mod:`~damper.identification.voltage_lag`; names
   ending in ``+lag``) — and the force histories are compared: relative RMS error,
   peak error over peak force and dissipated-energy error, over all dampers of the run
   (:func:`run_errors`);
3. optionally the building runs again with the identified model in place of its dampers,
   and the evaluation criteria J1–J9 of both runs (against the same uncontrolled run) are
   compared.

The building is handed in by the caller; this module never constructs or inspects the
device under test.

Speed: the runs are independent tasks on a process pool (``jobs``; results in task order, so
they do not depend on the number of workers). Each record and orientation is simulated once
without devices (the J reference) and once with the device under test (:func:`measure_run`);
the replays, the re-run with the identified model and the run's Fig. 11 (when a figure folder
is given) follow in a second task (:func:`compare_run`), which receives the measured run and
a compact copy of the reference instead of recomputing them.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from types import SimpleNamespace
from typing import Callable, Sequence

import numpy as np

from benchmark.foundation.errors import InputError
from benchmark.foundation.pools import stop_pool
from benchmark.simulator.criteria import key_json
from damper.identification.metrics import dissipated_energy
from damper.models.field_filter import first_order_filter
from damper.models.response import simulate as simulate_damper
from records.resolve import resolve_record
from benchmark.simulator.evaluation import evaluate
from benchmark.simulator.case import Case, run_case
from benchmark.foundation.pools import make_executor, run_tasks, worker_count
from records import BENCHMARK_RECORDS, ORIENTATIONS
from damper.identification.plots import plot_force_errors
from records.catalogue import canonical_orientation

#: Suffix of the model names replayed through the identified field filter.
LAG_SUFFIX = "+lag"

__all__ = ["LAG_SUFFIX", "REGIMES", "REGIME_MARGIN", "field_estimate", "regime_masks", "regime_errors",
           "RunValidation", "ValidationResult", "MeasuredRun", "run_errors", "replay",
           "measure_run", "measured_from_runs", "compare_run", "validate_in_building"]


def run_errors(measured: np.ndarray, predicted: np.ndarray, displacement: np.ndarray) -> dict[str, float]:
    """Force errors of one run over all its dampers (arrays of shape (n_samples, n_devices)).

    ``rel_rms_error`` :math:`= \\|F - \\hat F\\|_F / \\|F\\|_F` (all dampers and samples);
    ``peak_error`` :math:`= \\max|F - \\hat F| / \\max|F|`; ``energy_error``
    :math:`= |\\sum_d \\hat E_d - \\sum_d E_d| / \\sum_d |E_d|` with :math:`E_d = \\int F_d\\,dx_d`
    the energy dissipated by damper :math:`d`.

    Parameters
    ----------
    measured : np.ndarray
        Measured (simulated) device forces [N], shape (n_samples, n_devices).
    predicted : np.ndarray
        Forces of the identified model [N], same shape.
    displacement : np.ndarray
        Device displacements [m], same shape.
    """
    f = np.asarray(measured, dtype=float)
    g = np.asarray(predicted, dtype=float)
    x = np.asarray(displacement, dtype=float)
    if f.ndim == 1:
        f, g, x = f[:, None], g[:, None], x[:, None]
    if not (f.shape == g.shape == x.shape):
        raise InputError(f"run_errors: forces and displacement must share a shape, got {f.shape}, "
                         f"{g.shape}, {x.shape}")
    norm = np.linalg.norm(f)
    peak = np.max(np.abs(f))
    e_meas = np.array([dissipated_energy(f[:, d], x[:, d]) for d in range(f.shape[1])])
    e_pred = np.array([dissipated_energy(g[:, d], x[:, d]) for d in range(f.shape[1])])
    denom = np.sum(np.abs(e_meas))
    return {"rel_rms_error": float(np.linalg.norm(f - g) / norm) if norm > 0 else float("nan"),
            "peak_error": float(np.max(np.abs(f - g)) / peak) if peak > 0 else float("nan"),
            "energy_error": float(abs(e_pred.sum() - e_meas.sum()) / denom) if denom > 0 else float("nan")}


def replay(model, t: np.ndarray, displacement: np.ndarray, velocity: np.ndarray,
           voltage: np.ndarray, tau: float = 0.0) -> np.ndarray:
    """Force of ``model`` for each damper's recorded inputs (arrays (n_samples, n_devices)) [N].

    With ``tau > 0`` the commanded voltage first passes the identified field filter
    :math:`\\tau\\dot u = v - u` (:mod:`~damper.identification.voltage_lag`). ``model`` may be a
    registered damper model or an augmented model (:class:`damper.diagnosis.augmented.AugmentedModel`).

    Parameters
    ----------
    model
        The identified damper model.
    t : np.ndarray
        Sample times [s].
    displacement : np.ndarray
        Device displacements [m], same shape.
    velocity : np.ndarray
        Device velocities [m/s], shape (n_samples, n_devices).
    voltage : np.ndarray
        Commanded voltages [V], shape (n_samples, n_devices).
    tau : float, optional
        Time constant τ [s] of the field's first-order lag (0: none).
    """
    x = np.asarray(displacement, dtype=float)
    out = np.empty_like(x)
    if not hasattr(model, "model_id") and hasattr(model, "effects"):
        # An augmented model (damper.diagnosis.augmented) without a registered counterpart: its own simulate.
        lo, hi = model.base.voltage_range
        for d in range(x.shape[1]):
            v = np.asarray(voltage[:, d], dtype=float)
            if tau > 0.0:
                v = first_order_filter(t, v, tau)
            out[:, d] = model.simulate(t, x[:, d], velocity[:, d], v=np.clip(v, lo, hi)).force
        return out
    lo, hi = model.voltage_range
    for d in range(x.shape[1]):
        v = np.asarray(voltage[:, d], dtype=float)
        if tau > 0.0:
            v = first_order_filter(t, v, tau)
        out[:, d] = simulate_damper(model, t, x[:, d], velocity[:, d], np.clip(v, lo, hi)).force
    return out


@dataclass
class RunValidation:
    """One record and orientation.

    Attributes
    ----------
    record, orientation : str
    t : ndarray
        Time [s].
    displacement, velocity, voltage, force : ndarray (n, n_devices)
        The device under test's recorded inputs and force (SI).
    predicted : dict
        ``model name -> force (n, n_devices)`` replayed through the identified model [N].
    errors : dict
        ``model name -> run_errors(...)``.
    J : dict
        ``"device" -> J1..J9`` of the run with the device under test and, where re-run,
        ``model name -> J1..J9`` with the identified model in its place.
    regimes : dict
        ``model name -> regime_errors(...)``: the relative RMS error over the samples where the
        estimated field is low, high, or in transition (empty when not computed).
    """

    record: str
    orientation: str
    t: np.ndarray = field(repr=False)
    displacement: np.ndarray = field(repr=False)
    velocity: np.ndarray = field(repr=False)
    voltage: np.ndarray = field(repr=False)
    force: np.ndarray = field(repr=False)
    predicted: dict = field(repr=False)
    errors: dict
    J: dict
    regimes: dict = field(default_factory=dict)


#: Field regimes: the estimated field within this fraction of the voltage range from its low
#: ("low") or high ("high") end; everything between is "transition".
REGIME_MARGIN = 0.05
REGIMES = ("low", "high", "transition")


def field_estimate(t: np.ndarray, voltage: np.ndarray, tau: float) -> np.ndarray:
    """The field the fluid sees, estimated from the commanded voltage [V]: each column through the
    identified first-order field filter :math:`\\tau\\dot u = v - u` (the commanded voltage
    itself when ``tau`` is 0).

    Parameters
    ----------
    t : np.ndarray
        Sample times [s].
    voltage : np.ndarray
        Commanded voltages [V], shape (n_samples, n_devices).
    tau : float
        Time constant τ [s] of the field's first-order lag (0: none).
    """
    v = np.asarray(voltage, dtype=float)
    if tau <= 0.0:
        return v.copy()
    if v.ndim == 1:
        return first_order_filter(t, v, tau)
    return np.column_stack([first_order_filter(t, v[:, d], tau) for d in range(v.shape[1])])


def regime_masks(field_: np.ndarray, voltage_range: tuple[float, float] = (0.0, 1.0),
                 margin: float = REGIME_MARGIN) -> dict[str, np.ndarray]:
    """Boolean masks of the low-field, high-field and transition samples of ``field_``.

    Parameters
    ----------
    field_ : np.ndarray
        Estimated field (:func:`field_estimate`) [V].
    voltage_range : tuple[float, float], optional
        ``(min, max)`` voltages [V] of the device.
    margin : float, optional
        Fraction of the voltage range that counts as low or high field.
    """
    lo, hi = voltage_range
    span = hi - lo
    low = field_ <= lo + margin * span
    high = field_ >= hi - margin * span
    return {"low": low, "high": high, "transition": ~(low | high)}


def regime_errors(measured: np.ndarray, predicted: np.ndarray, masks: dict[str, np.ndarray]) -> dict:
    """Relative RMS force error over each regime's samples, with the regime's share of the samples
    and of the measured force's energy (so a reader sees which regime dominates the run's error).

    Parameters
    ----------
    measured : np.ndarray
        Measured (simulated) device forces [N], shape (n_samples, n_devices).
    predicted : np.ndarray
        Forces of the identified model [N], same shape.
    masks : dict[str, np.ndarray]
        Boolean masks by regime (:func:`regime_masks`).
    """
    f = np.asarray(measured, dtype=float)
    g = np.asarray(predicted, dtype=float)
    total = float(np.sum(f ** 2))
    out = {}
    for name, mask in masks.items():
        fm = f[mask]
        norm = float(np.linalg.norm(fm))
        out[name] = {"rel_rms_error": float(np.linalg.norm(fm - g[mask]) / norm) if norm > 0 else float("nan"),
                     "sample_share": float(mask.mean()) if mask.size else float("nan"),
                     "force_share": float(np.sum(fm ** 2) / total) if total > 0 else float("nan")}
    return out


@dataclass
class ValidationResult:
    """All runs of :func:`validate_in_building`.

    Parameters
    ----------
    runs : list
        The runs (:class:`MeasuredRun` with the replayed forces and errors).
    controller : str
        Controller of the runs.
    models : tuple
        Keys of the identified models compared.
    """

    runs: list
    controller: str
    models: tuple

    def to_json(self) -> dict:
        """``{record: {orientation: {model: {rel_rms_error, peak_error, energy_error}}}}`` plus J's."""
        errors: dict = {}
        criteria: dict = {}
        regimes: dict = {}
        for run in self.runs:
            errors.setdefault(run.record, {})[run.orientation] = run.errors
            criteria.setdefault(run.record, {})[run.orientation] = run.J
            if run.regimes:
                regimes.setdefault(run.record, {})[run.orientation] = run.regimes
        out = {"controller": self.controller, "models": list(self.models), "errors": errors,
               "J": criteria, "summary": self.summary(), "criteria": key_json()}
        if regimes:
            out["regimes"] = regimes
        return out

    def summary(self) -> dict:
        """Per model: mean and worst of each error over the runs; mean |ΔJ| with the identified model."""
        out: dict = {}
        for m in self.models:
            vals = {k: np.array([r.errors[m][k] for r in self.runs])
                    for k in ("rel_rms_error", "peak_error", "energy_error")}
            entry = {f"mean_{k}": float(np.mean(v)) for k, v in vals.items()}
            entry.update({f"max_{k}": float(np.max(v)) for k, v in vals.items()})
            dj = [abs(r.J[m][j] - r.J["device"][j]) for r in self.runs if m in r.J
                  for j in r.J["device"] if r.J["device"][j] is not None and r.J[m].get(j) is not None]
            if dj:
                entry["mean_abs_delta_J"] = float(np.mean(dj))
                entry["max_abs_delta_J"] = float(np.max(dj))
            out[m] = entry
        for ext in self.models:
            if ext.startswith("normalized"):
                continue
            nor = "normalized" + (LAG_SUFFIX if ext.endswith(LAG_SUFFIX) else "")
            if nor in self.models and self.runs:
                ratios = [r.errors[ext]["rel_rms_error"] / r.errors[nor]["rel_rms_error"] for r in self.runs]
                out[f"{ext}_below_{nor}_every_run"] = bool(max(ratios) < 1.0)
                out[f"{ext}_over_{nor}_rel_rms_ratio_max"] = float(max(ratios))
                out[f"{ext}_over_{nor}_rel_rms_ratio_mean"] = float(np.mean(ratios))
                if all(r.regimes for r in self.runs):
                    by = {}
                    for g in REGIMES:
                        rr = [r.regimes[ext][g]["rel_rms_error"] / r.regimes[nor][g]["rel_rms_error"]
                              for r in self.runs if r.regimes[nor][g]["rel_rms_error"] > 0]
                        if rr:
                            by[g] = {"ratio_mean": float(np.mean(rr)), "ratio_max": float(np.max(rr)),
                                     "below_every_run": bool(max(rr) < 1.0)}
                    out[f"{ext}_over_{nor}_by_field_regime"] = by
        return out


@dataclass
class MeasuredRun:
    """One record and orientation run with the device under test (output of :func:`measure_run`).

    Attributes
    ----------
    record_name, orientation : str
    record : records.Record
    t : ndarray
        Time [s].
    displacement, velocity, voltage, force : ndarray (n, n_devices)
        The device under test's recorded inputs and force (SI).
    J_device : dict
        J1–J9 of the run against the uncontrolled reference.
    reference : SimpleNamespace
        The fields of the uncontrolled run that :func:`benchmark.simulator.evaluation.evaluate` reads
        (``t``, ``info`` and the response histories), for the re-runs.
    """

    record_name: str
    orientation: str
    record: object = field(repr=False)
    t: np.ndarray = field(repr=False)
    displacement: np.ndarray = field(repr=False)
    velocity: np.ndarray = field(repr=False)
    voltage: np.ndarray = field(repr=False)
    force: np.ndarray = field(repr=False)
    J_device: dict = field(default_factory=dict)
    reference: object = field(default=None, repr=False)


_REFERENCE_FIELDS = ("t", "base_shear", "structure_shear", "base_displacement", "drift_ratio",
                     "floor_acceleration_absolute")


def measure_run(building, record_name: str, orientation: str, controller: str = "clipped-optimal",
                records_dir: str | None = None, synthetic: bool = False) -> MeasuredRun:
    """Run the building without devices (reference) and with its own dampers under ``controller``.

    Returns the dampers' recorded histories, the run's J1–J9 and a compact copy of the
    reference (see :class:`MeasuredRun`).

    Parameters
    ----------
    building
        The building with its dampers (the "true" devices).
    record_name : str
        Record name.
    orientation : str
        ``FN-x`` or ``FP-x``.
    controller : str, optional
        Controller name.
    records_dir : str | None, optional
        Directory of the record files; None: the default.
    synthetic : bool, optional
        Use a synthetic stand-in for the record.
    """

    record = resolve_record(record_name, orientation, records_dir=records_dir, synthetic=synthetic)
    run = run_case(Case(record=record, orientation=orientation, controller=controller, building=building,
                        options={"bearing_histories": False}), cache=None)
    return measured_from_runs(record_name, orientation, record, run.result, run.reference)


def measured_from_runs(record_name: str, orientation: str, record, measured, reference) -> MeasuredRun:
    """The :class:`MeasuredRun` of a controlled run and its uncontrolled reference.

    What :func:`measure_run` returns, from runs made elsewhere (the main job's suite runs the
    same building, records and controller and hands its runs over instead of repeating them).

    Parameters
    ----------
    record_name : str
        Record name.
    orientation : str
        ``FN-x`` or ``FP-x``.
    record
        The record of the runs.
    measured : benchmark.simulator.results.SimulationResult
        The run with the dampers under the controller.
    reference : benchmark.simulator.results.SimulationResult
        The uncontrolled run (no devices) of the same record.
    """
    ref = SimpleNamespace(info=dict(getattr(reference, "info", {}) or {}), device_force=None,
                          **{k: np.asarray(getattr(reference, k)) for k in _REFERENCE_FIELDS})
    return MeasuredRun(record_name, orientation, record, np.asarray(measured.t),
                       np.asarray(measured.device_displacement), np.asarray(measured.device_velocity),
                       np.asarray(measured.voltage), np.asarray(measured.device_force),
                       evaluate(measured, reference), ref)


def compare_run(building, measured: MeasuredRun, identified: dict, lags: dict | None = None,
                rerun: Sequence[str] = (), controller: str = "clipped-optimal",
                figure: str | None = None) -> RunValidation:
    """Replay one measured run through the identified models; re-run the building with some of them.

    Parameters
    ----------
    building : benchmark.simulator.building.Building
        The building of :func:`measure_run` (its device slots receive the identified model).
    measured : MeasuredRun
    identified : dict
        ``model name -> voltage-dependent damper model``.
    lags : dict, optional
        ``model name -> tau`` [s]: also replay through the field filter (name ``+lag``).
    rerun : sequence of str
        Identified models put in the building in place of its dampers (J comparison).
    controller : str
    figure : str, optional
        Write this run's Fig. 11 (:func:`damper.identification.plots.plot_force_errors`) there.
    """

    t, x, xd, v, f = measured.t, measured.displacement, measured.velocity, measured.voltage, measured.force
    predicted, errors, regimes = {}, {}, {}
    # One field estimate for every model, so all are split on the same samples: the commanded
    # voltage through the median identified lag (the identified lags differ by a few percent).
    tau_ref = float(np.median(list(lags.values()))) if lags else 0.0
    vrange = next(iter(identified.values())).voltage_range if identified else (0.0, 1.0)
    masks = regime_masks(field_estimate(t, v, tau_ref), vrange)
    for m, model in identified.items():
        predicted[m] = replay(model, t, x, xd, v)
        errors[m] = run_errors(f, predicted[m], x)
        regimes[m] = regime_errors(f, predicted[m], masks)
        if lags and m in lags:
            predicted[m + LAG_SUFFIX] = replay(model, t, x, xd, v, tau=lags[m])
            errors[m + LAG_SUFFIX] = run_errors(f, predicted[m + LAG_SUFFIX], x)
            regimes[m + LAG_SUFFIX] = regime_errors(f, predicted[m + LAG_SUFFIX], masks)
    J = {"device": measured.J_device}
    for m in rerun:
        swapped = building.with_devices(building.devices.with_model(identified[m]))
        rerun_case = Case(record=measured.record, orientation=measured.orientation, controller=controller,
                          building=swapped, options={"bearing_histories": False})
        J[m] = evaluate(run_case(rerun_case, reference=False).result, measured.reference)
    run = RunValidation(measured.record_name, measured.orientation, t, x, xd, v, f, predicted, errors, J,
                        regimes)
    if figure is not None:
        plot_force_errors(run, figure)
    return run


def validate_in_building(building, identified: dict, lags: dict | None = None,
                         records: Sequence[str] | None = None,
                         orientations: Sequence[str] | None = None,
                         controller: str = "clipped-optimal", rerun: Sequence[str] = ("extended",),
                         records_dir: str | None = None, synthetic: bool = False,
                         progress: Callable[[str], None] | None = None, jobs: int | None = 1,
                         executor=None, measured: Sequence[MeasuredRun] | None = None,
                         figures: str | Path | None = None) -> ValidationResult:
    """Replay earthquake runs through identified models and compare (see the module docstring).

    Parameters
    ----------
    building : benchmark.simulator.building.Building
        The building with its own dampers (the device under test).
    identified : dict
        ``model name -> voltage-dependent damper model`` (e.g. from
        :func:`~damper.identification.voltage_grid.identify_voltage_grid`).
    lags : dict, optional
        ``model name -> field time constant tau`` [s]: each such model is also replayed with
        the filtered voltage, under the name ``model + "+lag"``.
    records, orientations : sequence of str, optional
        Default: the seven benchmark records and both orientations (14 runs).
    controller : str
        A controller of :mod:`controllers.registry` that makes the voltage fluctuate.
    rerun : sequence of str
        Identified models to put in the building in place of its dampers (J comparison).
    records_dir : str, optional
        Directory of the record files.
    synthetic : bool
        Use the labelled synthetic benchmark-like records instead of the files.
    progress : callable, optional
        Called with a label after each run.
    jobs : int, optional
        Worker processes (``None`` or 0: all cores; 1: this process). Ignored with ``executor``.
    executor : concurrent.futures.Executor, optional
        A pool to run on.
    measured : sequence of MeasuredRun, optional
        Runs already measured (:func:`measure_run`), e.g. while the identification ran; then
        ``records``, ``orientations`` and ``controller``'s runs are not repeated.
    figures : path-like, optional
        Folder for one Fig. 11 per run (``fig11_force_errors_<record>_<orientation>.png``),
        drawn in the workers.
    """

    if building.devices is None or building.n_devices == 0:
        raise InputError("validation: the building has no dampers to validate against")
    for m in rerun:
        if m not in identified:
            raise InputError(f"rerun: {m!r} is not among the identified models {sorted(identified)}")
    if measured is None:
        records = tuple(records or BENCHMARK_RECORDS)

        orientations = tuple(canonical_orientation(o) for o in (orientations or ORIENTATIONS))
        pairs = [(r, o) for r in records for o in orientations]
    else:
        pairs = [(mr.record_name, mr.orientation) for mr in measured]
    own = executor is None and worker_count(jobs, len(pairs)) > 1
    pool = make_executor(min(worker_count(jobs), len(pairs))) if own else executor
    folder = None if figures is None else Path(figures)
    if folder is not None:
        folder.mkdir(parents=True, exist_ok=True)

    def tick(run: RunValidation) -> None:
        if progress is not None:
            progress(f"{run.record} {run.orientation}")

    try:
        if measured is None:
            measured = run_tasks(measure_run, [(building, r, o, controller, records_dir, synthetic)
                                               for r, o in pairs], pool)
        tasks = [(building, mr, identified, lags, tuple(rerun), controller,
                  None if folder is None else
                  str(folder / f"fig11_force_errors_{mr.record_name}_{mr.orientation}.png"))
                 for mr in measured]
        runs = run_tasks(compare_run, tasks, pool, tick)
    except BaseException:  # Ctrl-C or a failed task: stop the workers now, wait for nothing
        if own:
            stop_pool(pool)
        raise
    finally:
        if own and pool is not None:
            pool.shutdown()
    names = tuple(identified) + tuple(m + LAG_SUFFIX for m in identified if lags and m in lags)
    return ValidationResult(runs, controller, names)
