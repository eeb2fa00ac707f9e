"""The identification study (``sbib identify``): the seed paper's whole procedure on a device.

Steps (each through the public API):

1. identify the normalized and the extended Bouc-Wen models at each voltage of the grid
   0, 0.1, …, 1 V from periodic tests run on the device by the virtual laboratory, and fit the
   voltage laws (:mod:`~damper.identification.voltage_grid`);
2. fit the field lag of each identified model on a voltage-switching test
   (:mod:`~damper.identification.voltage_lag`);
3. validate the voltage-dependent identified models inside full earthquake simulations of the
   benchmark building, every record and orientation, under a semi-active controller
   (:mod:`~damper.identification.validation`), and re-run the building with the identified
   extended model in place of the device;
4. write ``parameters.csv``, ``voltage_laws.json``, ``validation.json``, ``identification.h5``
   (all histories, SI units, provenance) and the figures (seed Fig. 1–3, 6, 8, 11).

The device is injected (default ``"virtual"``, the registered name of the virtual benchmark
damper): the identification sees it only through :mod:`damper.laboratory`, the validation only
through the building's recorded damper histories.
"""

from __future__ import annotations

import csv
import io
import json
import time
import warnings
from pathlib import Path
from typing import Sequence

import numpy as np

from benchmark.atomic import atomic_path, atomic_write_text
from damper.identification.closed_form import PARAMETER_NAMES
from damper.identification.identify import identify
from damper.identification.voltage_grid import DEFAULT_VOLTAGES, TestProtocol, identify_voltage_grid
from damper.identification.voltage_lag import fit_voltage_lag, switching_test

__all__ = ["run_identify_study", "write_parameters_csv", "FIG6_PROTOCOL", "LARGE_LOOP_PROTOCOL"]

#: The seed paper's large loop (Fig. 1-3): ±0.4 m at 0.8 Hz (±2 m/s), at 0 V.
LARGE_LOOP_PROTOCOL = TestProtocol(amplitude=0.4, frequency=0.8, cycles=3.0, sample_rate=1000.0)
#: The seed paper's Fig. 6 test: ±0.03 m over 10 s at 0 V (1 Hz chosen; the seed gives no frequency).
FIG6_PROTOCOL = TestProtocol(amplitude=0.03, frequency=1.0, cycles=10.0, sample_rate=1000.0)


def write_parameters_csv(rows: Sequence[dict], path) -> Path:
    """Write one row per (model, voltage) with parameters [SI], standard errors and fit errors."""
    if not rows:
        raise ValueError("no rows")
    buf = io.StringIO()
    buf.write("# identified parameters per model and voltage; SI units: kappa_x [N/m], kappa_xdot "
              "[N s/m], kappa_w [N], rho [1/m], sigma [-], n [-]; *_std: Jacobian standard errors; "
              "errors over the steady cycles of the identification test\n")
    writer = csv.DictWriter(buf, fieldnames=list(rows[0]), lineterminator="\n")
    writer.writeheader()
    for row in rows:
        writer.writerow({k: (f"{v:.10g}" if isinstance(v, float) else v) for k, v in row.items()})
    return atomic_write_text(path, buf.getvalue())


def _write_hdf5(path: Path, grid, fig6_test, validation, device_name: str) -> Path:
    import h5py

    from benchmark.provenance import provenance

    with atomic_path(path) as tmp:
        with h5py.File(tmp, "w") as h5:
            for k, v in provenance(study="sbib identify", device=device_name).items():
                h5.attrs[k] = v
            h5.attrs["units"] = "SI: s, m, m/s, V, N"
            g = h5.create_group("grid")
            g.attrs["voltages_V"] = grid.voltages
            g.attrs["protocol"] = json.dumps(grid.protocol.__dict__)
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
                        gv.create_dataset(name, data=arr, compression="gzip").attrs["units"] = unit
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
                    for name, arr, unit in (("time", run.t, "s"), ("displacement", run.displacement, "m"),
                                            ("velocity", run.velocity, "m/s"), ("voltage", run.voltage, "V"),
                                            ("force", run.force, "N")):
                        gr.create_dataset(name, data=arr, compression="gzip").attrs["units"] = unit
                    for m, arr in run.predicted.items():
                        gr.create_dataset(f"predicted_force/{m}", data=arr,
                                          compression="gzip").attrs["units"] = "N"
                    gr.attrs["errors"] = json.dumps(run.errors)
                    gr.attrs["J"] = json.dumps(run.J)
    return path


def run_identify_study(out, device="virtual", voltages: Sequence[float] = DEFAULT_VOLTAGES,
                       protocol: TestProtocol = TestProtocol(), records: Sequence[str] | None = None,
                       orientations: Sequence[str] | None = None, controller: str = "clipped-optimal",
                       rerun: Sequence[str] = ("extended",), validate: bool = True,
                       records_dir: str | None = None, synthetic: bool = False,
                       progress: bool = True, plots: bool = True) -> dict:
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
        Show a progress bar (tqdm, on stderr).
    plots : bool
        Write the figures.

    Returns
    -------
    dict
        Summary: files written, identified parameters at 0 and 1 V, law errors, validation
        numbers, timings.
    """
    from damper.laboratory import resolve_device

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    timings: dict[str, float] = {}
    t_all = time.perf_counter()
    model = resolve_device(device)
    from records import BENCHMARK_RECORDS, ORIENTATIONS
    n_runs = len(records or BENCHMARK_RECORDS) * len(orientations or ORIENTATIONS) if validate else 0
    bar = None
    if progress:
        from tqdm import tqdm
        bar = tqdm(total=2 * len(voltages) + n_runs, desc="sbib identify", unit="step", leave=False)

    def tick(label: str) -> None:
        if bar is not None:
            bar.set_postfix_str(label)
            bar.update(1)

    t0 = time.perf_counter()
    grid = identify_voltage_grid(model, voltages=voltages, protocol=protocol, progress=tick)
    fig6_test = FIG6_PROTOCOL.run(model, 0.0)
    large_test = LARGE_LOOP_PROTOCOL.run(model, 0.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        large = {m: identify(large_test, model=m) for m in grid.models}
    switching = switching_test(model)
    lag_fits = {m: fit_voltage_lag(grid.models[m]["seed"], switching) for m in grid.models}
    timings["identification_s"] = time.perf_counter() - t0

    files = {"parameters": str(write_parameters_csv(grid.rows(), out / "parameters.csv")),
             "voltage_laws": str(atomic_write_text(out / "voltage_laws.json", json.dumps(
                 grid.laws_json() | {"field_lag": {m: lf.__dict__ for m, lf in lag_fits.items()}},
                 indent=2)))}
    validation = None
    if validate:
        from benchmark.building import Building
        from damper.identification.validation import validate_in_building

        t0 = time.perf_counter()
        building = Building.default(damper_model=model)
        identified = {m: grid.models[m]["seed"] for m in grid.models}
        lags = {m: lf.tau for m, lf in lag_fits.items()}
        validation = validate_in_building(building, identified, lags=lags, records=records,
                                          orientations=orientations,
                                          controller=controller, rerun=rerun, records_dir=records_dir,
                                          synthetic=synthetic, progress=tick)
        timings["validation_s"] = time.perf_counter() - t0
        files["validation"] = str(atomic_write_text(out / "validation.json",
                                                    json.dumps(validation.to_json(), indent=2)))
    if bar is not None:
        bar.close()
    t0 = time.perf_counter()
    files["hdf5"] = str(_write_hdf5(out / "identification.h5", grid, fig6_test, validation, model.name))
    timings["hdf5_s"] = time.perf_counter() - t0
    if plots:
        t0 = time.perf_counter()
        files["figures"] = _figures(out / "figures", grid, fig6_test, large, validation)
        timings["plots_s"] = time.perf_counter() - t0
    timings["total_s"] = time.perf_counter() - t_all

    summary = {
        "device": model.name,
        "voltages": [float(v) for v in grid.voltages],
        "protocol": grid.protocol.__dict__,
        "parameters": {m: {f"{v:.2f} V": ident.parameters for v, ident in zip(grid.voltages, idents)}
                       for m, idents in grid.identifications.items()},
        "identification_errors": {m: {f"{v:.2f} V": ident.errors["rel_rms_error"]
                                      for v, ident in zip(grid.voltages, idents)}
                                  for m, idents in grid.identifications.items()},
        "law_errors": {m: {fam: {p: fit.rms_error for p, fit in fits.items()}
                           for fam, fits in fams.items()} for m, fams in grid.laws.items()},
        "law_notes": grid.notes,
        "large_loop_0V": {m: {"parameters": i.parameters, "rel_rms_error": i.errors["rel_rms_error"]}
                          for m, i in large.items()},
        "field_lag": {m: lf.__dict__ for m, lf in lag_fits.items()},
        "validation": validation.to_json() if validation is not None else None,
        "files": files,
        "timings": timings,
    }
    atomic_write_text(out / "summary.json", json.dumps(summary, indent=2, default=float))
    return summary


def _figures(folder: Path, grid, fig6_test, large: dict, validation) -> list[str]:
    from damper.identification import plots

    folder.mkdir(parents=True, exist_ok=True)
    written = []
    for k, label in ((0, "0V"), (len(grid.voltages) - 1, f"{grid.voltages[-1]:g}V")):
        idents = {m: grid.identifications[m][k] for m in grid.identifications}
        written.append(plots.plot_loops(idents, folder / f"fig01_loops_{label}.png"))
    written.append(plots.plot_loops(large, folder / "fig01_loops_large_0V.png",
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
    written.append(plots.plot_parameters_vs_voltage(grid, folder / "fig08_parameters_vs_voltage.png"))
    if validation is not None:
        for run in validation.runs:
            written.append(plots.plot_force_errors(run, folder / f"fig11_force_errors_{run.record}_{run.orientation}.png"))
    return [str(p) for p in written]
