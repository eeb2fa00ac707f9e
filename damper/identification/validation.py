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
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

from benchmark.errors import InputError
from damper.identification.metrics import dissipated_energy
from damper.effects import first_order_filter
from damper.simulate import simulate as simulate_damper

#: Suffix of the model names replayed through the identified field filter.
LAG_SUFFIX = "+lag"

__all__ = ["LAG_SUFFIX", "RunValidation", "ValidationResult", "run_errors", "replay", "validate_in_building"]


def run_errors(measured: np.ndarray, predicted: np.ndarray, displacement: np.ndarray) -> dict[str, float]:
    """Force errors of one run over all its dampers (arrays of shape (n_samples, n_devices)).

    ``rel_rms_error`` :math:`= \\|F - \\hat F\\|_F / \\|F\\|_F` (all dampers and samples);
    ``peak_error`` :math:`= \\max|F - \\hat F| / \\max|F|`; ``energy_error``
    :math:`= |\\sum_d \\hat E_d - \\sum_d E_d| / \\sum_d |E_d|` with :math:`E_d = \\int F_d\\,dx_d`
    the energy dissipated by damper :math:`d`.
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
    :math:`\\tau\\dot u = v - u` (:mod:`~damper.identification.voltage_lag`).
    """
    x = np.asarray(displacement, dtype=float)
    out = np.empty_like(x)
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


@dataclass
class ValidationResult:
    """All runs of :func:`validate_in_building`."""

    runs: list
    controller: str
    models: tuple

    def to_json(self) -> dict:
        """``{record: {orientation: {model: {rel_rms_error, peak_error, energy_error}}}}`` plus J's."""
        errors: dict = {}
        criteria: dict = {}
        for run in self.runs:
            errors.setdefault(run.record, {})[run.orientation] = run.errors
            criteria.setdefault(run.record, {})[run.orientation] = run.J
        return {"controller": self.controller, "models": list(self.models), "errors": errors,
                "J": criteria, "summary": self.summary()}

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
        for suffix in ("", LAG_SUFFIX):
            ext, nor = f"extended{suffix}", f"normalized{suffix}"
            if ext in self.models and nor in self.models:
                ratios = [r.errors[ext]["rel_rms_error"] / r.errors[nor]["rel_rms_error"] for r in self.runs]
                out[f"{ext}_below_{nor}_every_run"] = bool(max(ratios) < 1.0)
                out[f"{ext}_over_{nor}_rel_rms_ratio_max"] = float(max(ratios))
                out[f"{ext}_over_{nor}_rel_rms_ratio_mean"] = float(np.mean(ratios))
        return out


def validate_in_building(building, identified: dict, lags: dict | None = None,
                         records: Sequence[str] | None = None,
                         orientations: Sequence[str] | None = None,
                         controller: str = "clipped-optimal", rerun: Sequence[str] = ("extended",),
                         records_dir: str | None = None, synthetic: bool = False,
                         progress: Callable[[str], None] | None = None) -> ValidationResult:
    """Replay earthquake runs through identified models and compare (see the module docstring).

    Parameters
    ----------
    building : benchmark.building.Building
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
    """
    from benchmark.evaluation import evaluate
    from benchmark.simulation import simulate
    from records import BENCHMARK_RECORDS, ORIENTATIONS, load_benchmark_record

    if building.devices is None or building.n_devices == 0:
        raise InputError("validation: the building has no dampers to validate against")
    records = tuple(records or BENCHMARK_RECORDS)
    orientations = tuple(orientations or ORIENTATIONS)
    for m in rerun:
        if m not in identified:
            raise InputError(f"rerun: {m!r} is not among the identified models {sorted(identified)}")
    runs = []
    for name in records:
        for orientation in orientations:
            if synthetic:
                from records.synthetic import benchmark_like
                record = benchmark_like(name, orientation)
            else:
                record = load_benchmark_record(name, orientation, records_dir=records_dir)
            info = {"orientation": orientation}
            reference = simulate(building.without_devices(), record, None, info=info)
            measured = simulate(building, record, controller, info=info)
            t = np.asarray(measured.t)
            x = np.asarray(measured.device_displacement)
            xd = np.asarray(measured.device_velocity)
            v = np.asarray(measured.voltage)
            f = np.asarray(measured.device_force)
            predicted, errors = {}, {}
            for m, model in identified.items():
                predicted[m] = replay(model, t, x, xd, v)
                errors[m] = run_errors(f, predicted[m], x)
                if lags and m in lags:
                    predicted[m + LAG_SUFFIX] = replay(model, t, x, xd, v, tau=lags[m])
                    errors[m + LAG_SUFFIX] = run_errors(f, predicted[m + LAG_SUFFIX], x)
            J = {"device": evaluate(measured, reference)}
            for m in rerun:
                swapped = building.with_devices(building.devices.with_model(identified[m]))
                J[m] = evaluate(simulate(swapped, record, controller, info=info), reference)
            runs.append(RunValidation(name, orientation, t, x, xd, v, f, predicted, errors, J))
            if progress is not None:
                progress(f"{name} {orientation}")
    names = tuple(identified) + tuple(m + LAG_SUFFIX for m in identified if lags and m in lags)
    return ValidationResult(runs, controller, names)
