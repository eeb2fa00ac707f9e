"""The identification study (``sbib identify``): the seed paper's whole procedure on a device.

Steps (each through the public API):

1. read the extended model's :math:`\\kappa_x` once from the large 0 V loop (seed step a),
   identify the normalized and the extended Bouc-Wen models at each voltage of the grid
   0, 0.1, …, 1 V from periodic tests run on the device by the virtual laboratory, with that
   :math:`\\kappa_x` held fixed, and fit the voltage laws
   (:mod:`~damper.identification.voltage_grid`); for comparison, also the extended model with
   :math:`\\kappa_x` free at each voltage (``extended-free-kx``: seed laws, i.e. :math:`\\kappa_x`
   the mean of the per-voltage values; ``extended-free-kx-pchip``: the generic laws, i.e. a
   voltage-dependent :math:`\\kappa_x(v)`);
2. fit the field lag of each identified model on a voltage-switching test
   (:mod:`~damper.identification.voltage_lag`);
3. validate the voltage-dependent identified models inside full earthquake simulations of the
   benchmark building, every record and orientation, under a semi-active controller
   (:mod:`~benchmark.applications.identification_validation`), split the errors by field regime (low, high,
   transition), and re-run the building with the identified extended model in place of the
   device;
4. measure the structural ceiling on each run's most-moving damper at 0 V and 1 V
   (:mod:`~benchmark.applications.identification_ceiling`): the identified models' error against the best
   each model form reaches fitted to that very motion;
5. close the loop (:mod:`~benchmark.applications.identification_closed_loop`, unless ``close_loop=False``):
   a laboratory campaign with changing voltage (:mod:`~benchmark.applications.identification_campaign`), the
   residual loop from both bases, the augmented models validated in the same runs (replayed
   with the commanded voltage and re-run in the building), and the seed's claim measured:
   the Fig. 11 pair ("original", "proposed") and the closed loop's pair, named by the
   ``claim`` object of ``validation.json`` with their per-run ratios in ``claim_test``;
6. write ``parameters.csv``, ``voltage_laws.json``, ``validation.json``, ``ceiling.json``,
   ``closed_loop.json``, ``identification.h5`` (all histories, SI units, provenance) and the
   figures (seed Fig. 1–3, 6, 8, 11, the seed's Fig. 11 pair, the claim's ratios, and the
   error anatomy).

The device is injected (default ``"virtual"``, the registered name of the virtual benchmark
damper): the identification sees it only through :mod:`damper.lab.laboratory`, the validation only
through the building's recorded damper histories.

Everything runs on one process pool (``jobs``, default all cores): the earthquake runs with the
device under test (and their uncontrolled references, once per record and orientation) start
at once, while the voltage grid is identified; then the replays, the re-runs with the
identified model and the figures (one Fig. 11 per run) run as further tasks. Results are
gathered in task order and do not depend on the number of workers.

Test protocol
-------------
The grid's test (:class:`~damper.identification.voltage_grid.TestProtocol`, ±0.1 m at 0.5 Hz)
satisfies the plastic assumption with margin (:math:`\\rho(X_{max}-X_{min}) \\approx 20` at every
voltage) and spans the dampers' displacements and velocities in the earthquake runs (RMS
0.01–0.11 m and 0.05–0.25 m/s). The seed's Fig. 6 test (±0.03 m) gives
:math:`\\rho(X_{max}-X_{min}) \\approx 6`, below :data:`~damper.identification.cycles.RECOMMENDED_RHO_STROKE`,
so its closed-form start is biased; it is run and plotted (Fig. 6), not used to identify.
"""

from __future__ import annotations

import csv
import io
import json
import sys
import time
import warnings
from pathlib import Path
from typing import Sequence

import numpy as np

from benchmark.foundation.atomic import atomic_path, atomic_write_text
from benchmark.foundation.progress import progress_bar
from benchmark.applications.identification_ceiling import DEFAULT_CEILING_VOLTAGES
from damper.identification.closed_form import PARAMETER_NAMES
from damper.identification.identify import identify
from benchmark.foundation.pools import make_executor, run_tasks, worker_count
from damper.identification.voltage_grid import (DEFAULT_VOLTAGES, KAPPA_X_MODES, LARGE_LOOP_PROTOCOL,
                                                TestProtocol, identify_voltage_grid)
from damper.identification.voltage_lag import fit_voltage_lag, switching_test
from benchmark.foundation.provenance import provenance
from damper.lab.laboratory import resolve_device
from records import BENCHMARK_RECORDS, ORIENTATIONS
from damper.identification import plots
from benchmark.foundation.errors import InputError
from benchmark.foundation.pools import stop_pool
from damper.identification.plots import plot_error_anatomy
from benchmark.simulator.building import Building
from benchmark.applications.identification_validation import MeasuredRun, measure_run
from benchmark.applications.identification_validation import validate_in_building
from benchmark.applications.identification_ceiling import pick_damper, structural_ceiling, summarize_ceiling
from records.catalogue import canonical_orientation
from benchmark.applications.identification_claim_plots import plot_claim_ratios, plot_seed_fig11
from benchmark.applications.identification_closed_loop import start_loops
from benchmark.applications.identification_closed_loop import CLOSED_LOOP_EXTENDED, CLOSED_LOOP_NORMALIZED, claim_object, closed_form_models, finish_loops
from benchmark.applications.identification_closed_loop import claim_summary

__all__ = ["run_identify_study", "write_parameters_csv", "FIG6_PROTOCOL", "LARGE_LOOP_PROTOCOL",
           "FREE_KX", "FREE_KX_PCHIP"]

#: Validation names of the comparison variant with kappa_x free at each voltage (seed laws:
#: kappa_x constant at the mean of the per-voltage values; generic laws: kappa_x(v) by PCHIP).
FREE_KX = "extended-free-kx"
FREE_KX_PCHIP = "extended-free-kx-pchip"
#: The seed paper's Fig. 6 test: ±0.03 m over 10 s at 0 V (1 Hz chosen; the seed gives no frequency).
FIG6_PROTOCOL = TestProtocol(amplitude=0.03, frequency=1.0, cycles=10.0, sample_rate=1000.0)


#: SI unit of each numeric column of parameters.csv (a ``_std`` column has its parameter's unit)
_CSV_UNITS = {"voltage": "V", "kappa_x": "N/m", "kappa_xdot": "N s/m", "kappa_w": "N", "rho": "1/m",
              "sigma": "-", "n": "-", "rel_rms_error": "-", "peak_error": "-", "energy_error": "-",
              "rho_stroke": "-"}


def _with_unit(name: str) -> str:
    unit = _CSV_UNITS.get(name[:-4] if name.endswith("_std") else name)
    return name if unit is None else f"{name} [{unit}]"


def write_parameters_csv(rows: Sequence[dict], path) -> Path:
    """Write one row per (model, voltage) with parameters [SI], standard errors and fit errors.

    Parameters
    ----------
    rows : Sequence[dict]
        One dict per (model, voltage): parameters [SI], standard errors, fit errors.
    path
        CSV file to write (replaced atomically).
    """
    if not rows:
        raise ValueError("no rows")
    buf = io.StringIO()
    buf.write("# identified parameters per model and voltage; SI units: kappa_x [N/m], kappa_xdot "
              "[N s/m], kappa_w [N], rho [1/m], sigma [-], n [-]; *_std: Jacobian standard errors; "
              "errors over the steady cycles of the identification test; at_bounds: the parameters the "
              "data left at a bound of the search (not identified)\n")
    names = list(rows[0])
    buf.write(",".join(_with_unit(k) for k in names) + "\n")
    writer = csv.DictWriter(buf, fieldnames=names, lineterminator="\n")
    for row in rows:
        writer.writerow({k: (f"{v:.10g}" if isinstance(v, float) else v) for k, v in row.items()})
    return atomic_write_text(path, buf.getvalue())


_GZ = {"compression": "gzip", "compression_opts": 1}  # fastest here, and smaller than with shuffle


def _write_hdf5(path: Path, grids: dict, fig6_test, validation, device_name: str,
                full_histories: bool = False) -> Path:
    """Write identification.h5.

    By default the file stays small (about 8 MB for the 14 validation runs instead of 120 MB):
    histories in single precision (7 significant digits, beyond any measurement's) and, in each
    validation run, only the device with the largest peak force (its index in the attribute
    ``device_index``; the errors of every device are in ``validation.json``). ``full_histories``
    keeps every device in double precision.
    """
    import h5py

    dtype = np.float64 if full_histories else np.float32

    def stored(arr, device=None):
        arr = np.asarray(arr)
        if device is not None and arr.ndim == 2:
            arr = arr[:, device]
        return arr.astype(dtype) if arr.dtype.kind == "f" else arr

    with atomic_path(path) as tmp:
        with h5py.File(tmp, "w") as h5:
            for k, v in provenance(study="sbib identify", device=device_name).items():
                h5.attrs[k] = v
            h5.attrs["units"] = "SI: s, m, m/s, V, N"
            h5.attrs["histories"] = ("full: every device, double precision" if full_histories else
                                     "compact: single precision; validation runs keep the device with "
                                     "the largest peak force (device_index); full: sbib identify "
                                     "--full-histories")
            for gname, grid in grids.items():
                g = h5.create_group(gname)
                g.attrs["voltages_V"] = grid.voltages
                g.attrs["protocol"] = json.dumps(grid.protocol.__dict__)
                if grid.kappa_x is not None:
                    g.attrs["kappa_x"] = json.dumps(grid.kappa_x.to_dict())
                for model, idents in grid.identifications.items():
                    gm = g.create_group(model)
                    gm.attrs["parameter_names"] = list(PARAMETER_NAMES)
                    gm.create_dataset("parameters", data=grid.table(model)).attrs["units"] = \
                        "N/m, N s/m, N, 1/m, -, -"
                    gm.create_dataset("standard_errors", data=grid.standard_errors(model))
                    for v, ident in zip(grid.voltages, idents):
                        gv = gm.create_group(f"{v:.2f}V")
                        for name, arr, unit in (("time", ident.t, "s"), ("displacement", ident.x, "m"),
                                                ("velocity", ident.xdot, "m/s"), ("force", ident.force, "N"),
                                                ("model_force", ident.fit.force, "N")):
                            gv.create_dataset(name, data=stored(arr), **_GZ).attrs["units"] = unit
                        gv.attrs["summary"] = json.dumps(ident.summary())
            f6 = h5.create_group("fig6_test")
            for name, arr, unit in (("time", fig6_test.time, "s"), ("displacement", fig6_test.displacement, "m"),
                                    ("force", fig6_test.force, "N")):
                f6.create_dataset(name, data=arr).attrs["units"] = unit
            if validation is not None:
                gval = h5.create_group("validation")
                gval.attrs["controller"] = validation.controller
                for run in validation.runs:
                    gr = gval.create_group(f"{run.record}/{run.orientation}")
                    force = np.asarray(run.force)
                    device = (None if full_histories or force.ndim != 2 else
                              int(np.argmax(np.max(np.abs(force), axis=0))))
                    if device is not None:
                        gr.attrs["device_index"] = device
                    for name, arr, unit in (("time", run.t, "s"), ("displacement", run.displacement, "m"),
                                            ("velocity", run.velocity, "m/s"), ("voltage", run.voltage, "V"),
                                            ("force", run.force, "N")):
                        gr.create_dataset(name, data=stored(arr, device), **_GZ).attrs["units"] = unit
                    for m, arr in run.predicted.items():
                        gr.create_dataset(f"predicted_force/{m}", data=stored(arr, device),
                                          **_GZ).attrs["units"] = "N"
                    gr.attrs["errors"] = json.dumps(run.errors)
                    gr.attrs["J"] = json.dumps(run.J)
    return path


def _identify_task(test, model: str, kappa_x: float | None):
    """Pool task: identify one test (warnings kept in the result)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return identify(test, model=model, kappa_x=kappa_x if model == "extended" else None)


def run_identify_study(out, device="virtual", voltages: Sequence[float] = DEFAULT_VOLTAGES,
                       protocol: TestProtocol = TestProtocol(), records: Sequence[str] | None = None,
                       orientations: Sequence[str] | None = None, controller: str = "clipped-optimal",
                       rerun: Sequence[str] = ("extended",), validate: bool = True,
                       records_dir: str | None = None, synthetic: bool = False,
                       progress: bool = True, plots: bool = True, kappa_x: str | float = "large-loop",
                       compare_free_kappa_x: bool = True, ceiling: bool = True,
                       jobs: int | None = None, close_loop: bool = True,
                       campaign_scale: float = 0.5, full_histories: bool = False,
                       measured: Sequence[MeasuredRun] = ()) -> dict:
    """Run the identification study and write its outputs to ``out``; return the summary.

    Parameters
    ----------
    out : path-like
        Output directory (created).
    device : damper model or str
        The device under test (default the registered ``"virtual"`` benchmark damper).
    voltages : sequence of float
        Identification grid [V].
    protocol : TestProtocol
        Periodic test at each voltage.
    records, orientations : sequence of str, optional
        Validation runs (default: all seven records, both orientations).
    controller : str
        Semi-active controller of the validation runs.
    rerun : sequence of str
        Identified models put in the building in place of the device (J comparison).
    validate : bool
        Run the earthquake validation at all.
    records_dir : str, optional
        Record files directory.
    synthetic : bool
        Use synthetic benchmark-like records.
    progress : bool
        Show progress on stderr (:func:`benchmark.foundation.progress.progress_bar`: a bar on a terminal,
        one line per step otherwise).
    plots : bool
        Write the figures.
    kappa_x : {"large-loop", "joint", "per-voltage"} or float
        The extended model's :math:`\\kappa_x` (see
        :func:`~damper.identification.voltage_grid.identify_voltage_grid`; default the seed's
        step a, read once from the large 0 V loop).
    compare_free_kappa_x : bool
        Also identify the extended model with :math:`\\kappa_x` free at each voltage and validate
        it (names :data:`FREE_KX`, :data:`FREE_KX_PCHIP`).
    ceiling : bool
        With the validation: measure the structural ceiling of the normalized and extended forms
        on each run's most-moving damper (:func:`~benchmark.applications.identification_ceiling.structural_ceiling`).
    jobs : int, optional
        Worker processes (default all cores; 1: everything in this process).
    close_loop : bool
        Close the loop (:mod:`~benchmark.applications.identification_closed_loop`): run the laboratory campaign
        and the residual loop, validate the augmented models with the others, and measure the
        seed's claim (the ``claim`` object of ``validation.json``, the seed's Fig. 11 pair).
    campaign_scale : float
        Duration factor of the closed loop's laboratory campaign.
    full_histories : bool
        Keep every device's histories in double precision in ``identification.h5`` (default:
        single precision and one device per validation run, about 8 MB instead of 120 MB).
    measured : sequence of MeasuredRun, optional
        Validation runs of this device under ``controller`` already made elsewhere, with their
        references (:func:`~benchmark.applications.identification_validation.measured_from_runs`;
        the main job's suite runs the same building, records and controller): the records and
        orientations found there are not run again.

    Returns
    -------
    dict
        Summary: files written, identified parameters at each voltage, law errors, the
        :math:`\\kappa_x` estimate, validation numbers, timings.
    """

    if isinstance(kappa_x, str) and kappa_x not in KAPPA_X_MODES:
        raise InputError(f"kappa_x: expected one of {KAPPA_X_MODES} or a number [N/m], got {kappa_x!r}")
    if close_loop and not (isinstance(campaign_scale, (int, float)) and np.isfinite(campaign_scale)
                           and campaign_scale > 0):
        raise InputError(f"campaign_scale: expected a number > 0, got {campaign_scale!r}")
    n_jobs = worker_count(jobs)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    timings: dict[str, float] = {}
    t_all = time.perf_counter()
    model = resolve_device(device)

    pairs = [(r, canonical_orientation(o)) for r in (records or BENCHMARK_RECORDS)
             for o in (orientations or ORIENTATIONS)] if validate else []
    with_free = compare_free_kappa_x and kappa_x != "per-voltage"
    bar = None
    say = (lambda msg: print(f"sbib identify: {msg}", file=sys.stderr, flush=True)) if progress else None
    if progress:
        bar = progress_bar((3 if with_free else 2) * len(voltages) + (2 if ceiling else 1) * len(pairs),
                           desc="sbib identify", unit="step", leave=False)

    def tick(label: str) -> None:
        if bar is not None:
            bar.set_postfix_str(label)
            bar.update(1)

    pool = make_executor(n_jobs)
    validation = validation_json = None
    closed = claim_names = None
    figure_folder = out / "figures"
    try:
        loop_job = None
        t_loop = time.perf_counter()
        if close_loop:
            # The campaign needs only the device, and the loops are the longest tasks: they start
            # first, and the building runs and the grid fill the other workers.
            loop_job = start_loops(model, pool, campaign_scale=campaign_scale, progress=say)
        building = None
        measuring: list = []
        given = {(m.record_name, canonical_orientation(m.orientation)): m for m in measured}
        if validate:
            building = Building.default(damper_model=model)
            # The runs with the device under test need no identified model: start them now
            # (those handed over are not run again).
            if pool is not None:
                measuring = [given[(r, o)] if (r, o) in given else
                             pool.submit(measure_run, building, r, o, controller, records_dir, synthetic)
                             for r, o in pairs]
            elif all(p in given for p in pairs):
                measuring = [given[p] for p in pairs]
        t0 = time.perf_counter()
        grid = identify_voltage_grid(model, voltages=voltages, protocol=protocol, progress=tick,
                                     kappa_x=kappa_x, executor=pool, jobs=1)
        grids = {"grid": grid}
        if with_free:
            grids["grid_free_kappa_x"] = identify_voltage_grid(
                model, voltages=voltages, models=("extended",), protocol=protocol, progress=tick,
                kappa_x="per-voltage", executor=pool, jobs=1)
        fig6_test = FIG6_PROTOCOL.run(model, 0.0)
        large_test = LARGE_LOOP_PROTOCOL.run(model, 0.0)
        fixed_kx = grid.kappa_x.value if grid.kappa_x is not None and grid.kappa_x.mode != "per-voltage" else None
        identified = {m: grid.models[m]["seed"] for m in grid.models}
        if with_free:
            free = grids["grid_free_kappa_x"].models["extended"]
            identified[FREE_KX] = free["seed"]
            identified[FREE_KX_PCHIP] = free["generic"]
        switching = switching_test(model)
        names = list(identified)
        results = run_tasks(_identify_task, [(large_test, m, fixed_kx) for m in grid.models], pool) + \
            run_tasks(fit_voltage_lag, [(identified[m], switching) for m in names], pool)
        large = dict(zip(grid.models, results[:len(grid.models)]))
        lag_fits = dict(zip(names, results[len(grid.models):]))
        timings["identification_s"] = time.perf_counter() - t0
        runs_measured = None
        ceiling_jobs: list = []
        t_ceiling = time.perf_counter()
        if validate and measuring:
            runs_measured = [m if isinstance(m, MeasuredRun) else m.result() for m in measuring]
            if ceiling and pool is not None:
                # The ceiling needs only the measured runs and the grid's models: its tasks fill
                # the workers now instead of waiting for the validation (same tasks, same order).
                ceiling_jobs = [pool.submit(structural_ceiling, *task)
                                for task in _ceiling_tasks(model, runs_measured, identified)]
        closed = None
        claim_names = None
        if close_loop:
            closed = finish_loops(loop_job, pool)
            timings["closed_loop_s"] = time.perf_counter() - t_loop
            seed_notes: list = []
            identified.update(closed_form_models(grid, model.voltage_range, seed_notes))
            grid.notes.extend(seed_notes)
            for name, bm in closed.building.items():
                identified[name] = bm if not isinstance(bm, str) else closed.models[name]
            claim_names = claim_object()
            rerun = tuple(rerun) + tuple(m for m in (CLOSED_LOOP_EXTENDED, CLOSED_LOOP_NORMALIZED)
                                         if not isinstance(closed.building.get(m, ""), str))

        files = {"parameters": str(write_parameters_csv(
                     [row for g in grids.values() for row in g.rows()], out / "parameters.csv")),
                 "voltage_laws": str(atomic_write_text(out / "voltage_laws.json", json.dumps(
                     {name: g.laws_json() for name, g in grids.items()}
                     | {"field_lag": {m: lf.__dict__ for m, lf in lag_fits.items()}}, indent=2)))}
        if closed is not None:
            files["closed_loop"] = str(atomic_write_text(out / "closed_loop.json", json.dumps(
                closed.to_json(), indent=2, default=float)))
        figure_job = None
        ceiling_entries: list = []
        ceiling_summary = None
        if plots:
            figure_folder.mkdir(parents=True, exist_ok=True)
            args = (figure_folder, grid, fig6_test, large, grids.get("grid_free_kappa_x"))
            figure_job = pool.submit(_figures, *args) if pool is not None else None
            if pool is None:
                files["figures"] = _figures(*args)
        if validate:
            t0 = time.perf_counter()
            lags = {m: lf.tau for m, lf in lag_fits.items()}
            validation = validate_in_building(building, identified, lags=lags, records=records,
                                              orientations=orientations, controller=controller,
                                              rerun=rerun, records_dir=records_dir, synthetic=synthetic,
                                              progress=tick, executor=pool, jobs=1, measured=runs_measured,
                                              figures=figure_folder if plots else None)
            timings["validation_s"] = time.perf_counter() - t0
            validation_json = validation.to_json()
            if claim_names is not None:
                validation_json["claim"] = claim_names
                validation_json["claim_test"] = claim_summary(validation_json, claim_names)
            files["validation"] = str(atomic_write_text(out / "validation.json",
                                                        json.dumps(validation_json, indent=2)))

            if ceiling and validation.runs:
                if ceiling_jobs:
                    found = []
                    for job in ceiling_jobs:
                        found.append(job.result())
                        tick("ceiling")
                else:
                    t_ceiling = time.perf_counter()
                    found = run_tasks(structural_ceiling, _ceiling_tasks(model, validation.runs, identified),
                                      pool, progress=lambda _: tick("ceiling"))
                ceiling_entries = [e for run_entries in found for e in run_entries]
                ceiling_summary = summarize_ceiling(ceiling_entries)
                timings["ceiling_s"] = time.perf_counter() - t_ceiling
                files["ceiling"] = str(atomic_write_text(out / "ceiling.json", json.dumps(
                    {"voltages_V": list(DEFAULT_CEILING_VOLTAGES), "summary": ceiling_summary,
                     "entries": [e.to_dict() for e in ceiling_entries]}, indent=2)))
        if figure_job is not None:
            files["figures"] = figure_job.result()
    except BaseException:  # Ctrl-C or a failed task: stop the workers now, wait for nothing
        stop_pool(pool)
        raise
    finally:
        if pool is not None:
            pool.shutdown(cancel_futures=True)
        if bar is not None:
            bar.close()
    if plots and validation is not None:
        files["figures"] = files.get("figures", []) + [
            str(figure_folder / f"fig11_force_errors_{r.record}_{r.orientation}.png") for r in validation.runs]
        if any(r.regimes for r in validation.runs):
            files["figures"].append(str(plot_error_anatomy(validation_json, ceiling_entries,
                                                           figure_folder / "fig11_error_anatomy.png")))
    if plots and validation is not None and claim_names is not None:
        files["figures"] = files.get("figures", []) + _claim_figures(validation, validation_json, figure_folder)
    t0 = time.perf_counter()
    files["hdf5"] = str(_write_hdf5(out / "identification.h5", grids, fig6_test, validation, model.name,
                                    full_histories))
    timings["hdf5_s"] = time.perf_counter() - t0
    timings["total_s"] = time.perf_counter() - t_all
    timings["jobs"] = n_jobs

    summary = {
        "device": model.name,
        "voltages": [float(v) for v in grid.voltages],
        "protocol": grid.protocol.__dict__,
        "kappa_x": grid.kappa_x.to_dict() if grid.kappa_x is not None else None,
        "parameters": {m: {f"{v:.2f} V": ident.parameters for v, ident in zip(grid.voltages, idents)}
                       for m, idents in grid.identifications.items()},
        "identification_errors": {m: {f"{v:.2f} V": ident.errors["rel_rms_error"]
                                      for v, ident in zip(grid.voltages, idents)}
                                  for m, idents in grid.identifications.items()},
        "law_errors": {m: {fam: {p: fit.rms_error for p, fit in fits.items()}
                           for fam, fits in fams.items()} for m, fams in grid.laws.items()},
        "law_notes": grid.notes,
        # the parameters the data left at a bound, per model and voltage (parameters.csv's at_bounds)
        "at_bounds": {},
        "large_loop_0V": {m: {"parameters": i.parameters, "rel_rms_error": i.errors["rel_rms_error"]}
                          for m, i in large.items()},
        "field_lag": {m: lf.__dict__ for m, lf in lag_fits.items()},
        "validation": validation_json,
        "ceiling": ceiling_summary,
        "closed_loop": None if closed is None else closed.to_json(),
        "claim_test": None if validation_json is None else validation_json.get("claim_test"),
        "files": files,
        "timings": timings,
    }
    summary["at_bounds"] = {}
    for row in grid.rows():
        if row["at_bounds"]:
            summary["at_bounds"].setdefault(row["model"], {})[f"{row['voltage']:.2f} V"] = row["at_bounds"]
    if with_free:
        g = grids["grid_free_kappa_x"]
        summary["parameters"][FREE_KX] = {f"{v:.2f} V": i.parameters
                                          for v, i in zip(g.voltages, g.identifications["extended"])}
        summary["identification_errors"][FREE_KX] = {f"{v:.2f} V": i.errors["rel_rms_error"]
                                                     for v, i in zip(g.voltages, g.identifications["extended"])}
    atomic_write_text(out / "summary.json", json.dumps(summary, indent=2, default=float))
    return summary


def _ceiling_tasks(model, runs, identified: dict) -> list[tuple]:
    """Arguments of :func:`structural_ceiling` for each validation run (measured or validated:
    both carry the record, orientation and the devices' motion); each task gets only the damper
    it measures."""
    forms = {m: identified[m] for m in ("normalized", "extended") if m in identified}
    tasks = []
    for r in runs:
        d = pick_damper(r.displacement)
        tasks.append((model, r.t, r.displacement[:, d], r.velocity[:, d], forms, DEFAULT_CEILING_VOLTAGES,
                      r.record_name if isinstance(r, MeasuredRun) else r.record, r.orientation, d))
    return tasks


def _claim_figures(validation, validation_json: dict, folder: Path) -> list[str]:
    """The seed's Fig. 11 pair on Kobe FP-y (= FN-x) when that run was validated (else the first
    run), and the claim's per-run ratios."""

    claim = validation_json["claim"]
    runs = [r for r in validation.runs if claim["original"] in r.predicted and claim["proposed"] in r.predicted]
    written = []
    if runs:
        run = next((r for r in runs if (r.record, r.orientation) == ("kobe", "FN-x")), runs[0])
        written.append(str(plot_seed_fig11(run, folder / f"fig11_seed_{run.record}_{run.orientation}.png",
                                           claim["proposed"], claim["original"])))
    if validation_json.get("claim_test"):
        written.append(str(plot_claim_ratios(validation_json["claim_test"], folder / "fig11_claim_ratios.png")))
    return written


def _figures(folder: Path, grid, fig6_test, large: dict, comparison=None) -> list[str]:
    """Seed Fig. 1-3, 6 and 8 (Fig. 11 is drawn per run by the validation)."""

    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for k, label in ((0, "0V"), (len(grid.voltages) - 1, f"{grid.voltages[-1]:g}V")):
        idents = {m: grid.identifications[m][k] for m in grid.identifications}
        written.append(plots.plot_identified_loops(idents, folder / f"fig01_loops_{label}.png"))
    written.append(plots.plot_identified_loops(large, folder / "fig01_loops_large_0V.png",
                                    title="±0.4 m, 0.8 Hz loop at 0 V (cf. seed Fig. 1)"))
    if "extended" in large:
        ext0 = large["extended"]
        written.append(plots.plot_inclination(ext0, folder / "fig02_inclination_0V.png"))
        written.append(plots.plot_elastic_removed(ext0, folder / "fig03_elastic_removed_0V.png"))
    id_test = grid.identifications[next(iter(grid.identifications))][0]

    class _Shown:  # the identification test at 0 V in the DamperTest shape the plot reads
        time, displacement, force = id_test.t, id_test.x, id_test.force
        name = f"identification test: ±{grid.protocol.amplitude:g} m, {grid.protocol.frequency:g} Hz, 0 V"

    written.append(plots.plot_test_signals([fig6_test, _Shown], folder / "fig06_test_signals.png"))
    written.append(plots.plot_parameters_vs_voltage(grid, folder / "fig08_parameters_vs_voltage.png",
                                                    comparison=comparison))
    return [str(p) for p in written]
