"""``sbib run``: one record, one orientation, one isolation, one controller — with its reference run.

::

    sbib run --record NAME|PATH --orientation FN-x|FP-x|FP-y|FN-y --isolation NAME --controller NAME
             [--records-dir DIR] [--format F] [--dt S] [--units U] [--baseline-correct]
             [--out FILE.h5] [--plot DIR] [--json]
             [--n-modes N] [--control-step S] [--integration-step S] [--substep-tolerance TOL]
             [--damper FILE.json|NAME] [--devices N|LAYOUT.json] [--damper-scale F|FORCE]

The evaluation criteria need the uncontrolled run (same building and isolation, no devices,
same record and orientation), so every call computes it too (``--controller none`` *is* that
run, and is computed once). ``--record`` takes a benchmark record name (``kobe``, ...) or a
record file (any format :func:`records.readers.load_record` reads); for a file with two
components ``FN-x`` puts column 1 on x and ``FP-x`` swaps them; a one-component file goes on x
(``FN-x``) or y (``FP-x``); the seed paper's ``FP-y`` / ``FN-y`` are ``FN-x`` / ``FP-x``. The record
options are those of every command that takes a record (:mod:`records.options`). The record's
implausibility flaws (:mod:`records.plausibility`: wrong units, wrong dt) are warned about on
stderr. The record's own step does not decide the integration step: the ground motion is
interpolated onto the building's step (the benchmark's 0.005 s, ``--integration-step``; finer
for a finer record), which divides the control step (default 0.005 s); a step whose nonlinear
forces do not converge makes the run start again at half the step, said on stderr
(:func:`benchmark.simulator.simulation.simulate`). Other notes of the run (a controller that
cannot act on the devices) are printed on stderr too.

``--json`` prints exactly one JSON object on stdout::

    {"record", "orientation" (FN-x or FP-x), "isolation", "structure": {"source", "n_floors", "total_mass_kg",
     "n_bearings"} (the structure file read: the benchmark's or --structure), "controller",
     "control_step_s" (null without a controller), "units_assumed", "record_step_s",
     "integration_step_s" (the step of the results' time grid), "notes": [lines],
     "record_flaws": [messages],
     "peaks": {peak_base_shear [N], peak_structure_shear [N], peak_base_displacement [m],
               peak_drift_ratio [-], peak_floor_acceleration [m/s²], rms_base_displacement [m],
               rms_floor_acceleration [m/s², largest floor], peak_device_force [N]},
     "peak_units": {the same keys: their units},
     "J": {J1..J9, only those defined}, "elapsed_s",
     "reference_peaks": {same keys, uncontrolled run}, "corners": {...}, "out": path or null,
     "plots": [paths], "damper": {"layout", "n_devices", "dampers": [{"damper", "model", "input",
     "scale", "scale_basis", "input_mapping", "effects", "notes", ...}]}}

``--controller`` also takes a user's class, ``package.module:Class`` or ``file.py:Class``
(:mod:`controllers.user`); ``--damper``/``--devices``/``--damper-scale`` choose the devices
(:mod:`benchmark.applications.damper_choice`); the reference stays the building without devices.

The Python equivalent of the command is :func:`benchmark.simulator.case.run_case`
(:func:`run_command` adds the saving, plotting and printing).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os
import sys
import time
from typing import Any

import numpy as np

from benchmark.simulator.evaluation import corner_responses, plan_corners
from benchmark.simulator.evaluation import J_DESCRIPTIONS, PEAK_UNITS
from benchmark.simulator.isolation.configurations import DEFAULT_NONLINEAR, ISOLATION_NAMES
from benchmark.simulator.results import write_result
from benchmark.simulator.plots import plot_run
from records.options import add_record_options
from records.resolve import is_warning
from benchmark.simulator.case import Case, run_case
from benchmark.simulator.criteria import SOURCE, key_json
from benchmark.simulator.building import Building
from controllers.registry import NO_CONTROLLER
from benchmark.simulator.isolation.configurations import check_substep_tolerance
from benchmark.applications.damper_choice import (add_damper_options, command_unit, device_motion, motion_notes,
                                                  resolve_damper, resolve_layout)
from controllers.registry import controller_names
from benchmark.applications.run_inputs import controller_identity, damper_identities, record_identity
from benchmark.foundation.atomic import output_dir, output_file_of
from benchmark.foundation.provenance import file_identity

__all__ = ["register", "run_command", "main_run"]

def _clean(d: dict[str, Any]) -> dict[str, Any]:
    out = {}
    for k, v in d.items():
        if v is None:
            continue
        if isinstance(v, np.ndarray):
            out[k] = v.tolist()
        elif isinstance(v, (np.floating, float)):
            out[k] = float(v) if math.isfinite(float(v)) else None
        else:
            out[k] = v
    return out


def _input_files(record_source: str | list, controller: str, structure_source: str, damper: dict) -> dict:
    """Each input file of a run by absolute path and SHA-256 (:mod:`benchmark.applications.run_inputs`):
    the record (both files of a pair, under ``record["files"]``), a user's controller file, the
    structure file and the damper model files; a name that is not a file (a benchmark record, a
    registered controller) by its name."""
    return {"record": record_identity(record_source), "controller": controller_identity(controller),
            "structure": file_identity(structure_source) if structure_source else {},
            "dampers": damper_identities(damper)}


def run_command(record: str, orientation: str = "FN-x", isolation: str | None = None,
             controller: str = "none", records_dir: str | None = None, out: str | None = None,
             plot_dir: str | None = None, n_modes: int | None = None, control_step: float | None = None,
             substep_tolerance: float | None = None, baseline_correct: bool = False,
             progress: bool = False, format: str = "auto", dt: float | None = None,
             units: str | None = None, warn: bool = True, full_histories: bool = False,
             integration_step: float | None = None, damper: str | None = None, devices: str | None = None,
             damper_scale: Any = None) -> dict[str, Any]:
    """``sbib run``: run one case and its reference (:func:`benchmark.simulator.case.run_case`),
    evaluate, and optionally save and plot.

    Parameters
    ----------
    record : str
        Benchmark record name or record file path (see :func:`records.resolve.resolve_record`).
    orientation : {"FN-x", "FP-x"}
    isolation : str, optional
        Named isolation layer or JSON file (default: the default nonlinear one, ``friction-lrb``).
    controller : str
        Controller name (:func:`controllers.registry.get_controller`); ``"none"``: no devices.
    records_dir : str, optional
    out : str, optional
        HDF5 file to write (run, reference, J1–J9; :func:`benchmark.simulator.results.write_result`).
    plot_dir : str, optional
        Directory for the figures (:func:`benchmark.simulator.plots.plot_run`).
    n_modes : int, optional
        Reduced superstructure (first ``n_modes`` modes); default all (24 in the benchmark: 3 per floor).
    control_step : float, optional
        Controller sample time [s]; ``None``: the benchmark's 0.005 s. Without a controller it
        sets only the time grid.
    substep_tolerance : float, optional
        Sub-step tolerance of every nonlinear bearing.
    baseline_correct : bool
    progress : bool
        Print progress lines on stderr.
    format, dt, units : optional
        How to read a record file (:func:`records.resolve.resolve_record`).
    warn : bool
        Print the record's implausibility flaws and a chosen control step on stderr.
    integration_step : float, optional
        Longest integration step [s] (default the benchmark's 0.005 s; halved automatically while
        the nonlinear forces do not converge, :func:`benchmark.simulator.simulation.simulate`).
    full_histories : bool
        Write ``out`` in double precision, with the per-bearing force and state histories (92
        bearings x 2 components per sample: about 30 MB more for a 30-s record), the kernel's
        state history (every stored history is derived from it; 2.3 MB per run) and the
        measurement vectors the controller saw. Without it the file is single precision
        (:func:`benchmark.simulator.results.write_result`, about 4.5 MB). The figures of
        ``plot_dir`` get the bearing histories either way (the bearing loops need them).
    damper, devices, damper_scale : optional
        ``--damper FILE.json|NAME``, ``--devices N|LAYOUT.json``, ``--damper-scale F|FORCE``
        (:mod:`benchmark.applications.damper_choice`); the summary's ``damper`` says what ran
        (model, scale and its basis, input mapping, notes), and so do the HDF5 attributes.

    Returns
    -------
    dict
        The ``--json`` object (module docstring), plus ``result`` and ``reference`` (the
        :class:`benchmark.simulator.simulation.SimulationResult` objects, not JSON).
    """

    start = time.perf_counter()

    def say(msg: str) -> None:
        if progress:
            print(f"sbib run: {msg}", file=sys.stderr, flush=True)

    record_options = {"records_dir": records_dir, "baseline_correct": baseline_correct, "format": format,
                      "dt": dt, "units": units}
    choice = resolve_damper(damper, damper_scale)
    building_given = None
    layout, used = resolve_layout(devices, choice, damper_scale)
    if damper is not None or devices is not None or damper_scale is not None:
        building_given = Building.default(isolation=isolation or DEFAULT_NONLINEAR, devices=layout, n_modes=n_modes)
        if substep_tolerance is not None:
            building_given = building_given.with_isolation(
                building_given.isolation.with_substep_tolerance(check_substep_tolerance(substep_tolerance)))
    uncontrolled = controller is None or (isinstance(controller, str) and controller.strip().lower() == NO_CONTROLLER)
    if warn and uncontrolled and building_given is not None:
        # the uncontrolled run has no devices: the damper's notes would describe nothing that ran
        given = [o for o, v in (("--damper", damper), ("--devices", devices), ("--damper-scale", damper_scale))
                 if v is not None]
        print(f"sbib run: note: --controller none runs the building without devices; {', '.join(given)} "
              "not used (name a controller, e.g. passive-on, to run them)", file=sys.stderr, flush=True)
    elif warn:
        for note in dict.fromkeys(n for c in used for n in c.notes):
            print(f"sbib run: {note if note.startswith('warning: ') else 'note: ' + note}", file=sys.stderr,
                  flush=True)
    case = Case(record=record, orientation=orientation, controller=controller, isolation=isolation,
                building=building_given,
                n_modes=n_modes, control_step=control_step, record_options=record_options,
                options={"bearing_histories": bool(full_histories or plot_dir),
                         **({} if substep_tolerance is None else {"substep_tolerance": substep_tolerance}),
                         **({} if integration_step is None else {"integration_step": integration_step})})
    run = run_case(case)  # the one way to run a case (benchmark.simulator.case)
    say(f"ran {run.record.name} ({orientation}) and its uncontrolled reference in "
        f"{time.perf_counter() - start:.1f} s")
    if warn and os.environ.get("SBIB_STRUCTURE"):
        sup = run.building.superstructure
        print(f"sbib run: note: structure {sup.source} ({sup.n_floors} floors, {sup.total_mass / 1e3:.6g} t on {sup.n_bearings} "
              f"bearings; isolation '{run.building.isolation.name}': {run.building.isolation.description})",
              file=sys.stderr, flush=True)
    rec, building, result, reference, J = run.record, run.building, run.result, run.reference, run.J
    moved = motion_notes(used, *device_motion(result)) if result is not reference else []
    if warn:
        for note in [*run.notes, *moved]:
            flag = "warning: " if is_warning(note) and not note.startswith("warning: ") else ""
            print(f"sbib run: {flag}{note}", file=sys.stderr, flush=True)
    orientation = rec.metadata.get("orientation", orientation)
    layer = building.isolation
    ctrl_used = result is not reference
    control_step = run.control_step
    sup = building.superstructure
    corners = corner_responses(result, plan_corners(sup.bearing_xy), sup.storey_heights)
    summary: dict[str, Any] = {
        "record": rec.name,
        "orientation": orientation,
        "isolation": layer.name,
        # the structure file read (a variant given by --structure / SBIB_STRUCTURE shows here)
        "structure": {"source": sup.source, "n_floors": sup.n_floors, "total_mass_kg": sup.total_mass,
                      "n_bearings": sup.n_bearings},
        "controller": controller,
        "control_step_s": float(control_step) if ctrl_used else None,
        "units_assumed": rec.metadata.get("units_assumed", ""),
        "record_columns": rec.metadata.get("columns"),
        "record_step_s": float(result.info.get("record_step", rec.dt)),
        "integration_step_s": float(result.info.get("integration_step", rec.dt)),
        "notes": [*run.notes, *moved],
        "record_flaws": list(rec.metadata.get("flaws", [])),
        "peaks": _clean(run.peaks.as_record()),
        "peak_units": {k: PEAK_UNITS[k] for k in run.peaks.as_record() if k in PEAK_UNITS},
        "J": {k: v for k, v in _clean(J).items()},
        "criteria": key_json(),
        "reference_peaks": _clean(reference.peaks.as_record()),
        "corners": {"corners_m": corners["corners"].tolist(),
                    "peak_corner_base_displacement": corners["peak_corner_base_displacement"].tolist(),
                    "peak_corner_drift_ratio": corners["peak_corner_drift_ratio"].tolist()},
        "out": None,
        "plots": [],
        "damper": {"layout": layout.name, "n_devices": layout.n_devices,
                   "dampers": [c.describe() for c in used]},
    }
    if out:
        say(f"writing {out}")
        stored, stored_ref = result, reference
        if not full_histories:
            # the per-bearing histories, if any, were for the figures only; the kernel state and
            # the (noisy, incompressible) measurement vectors are kept with --full-histories
            lean = {"bearing_force": None, "bearing_state": None, "state": None, "measurements": None}
            stored = dataclasses.replace(result, **lean)
            stored_ref = stored if reference is result else dataclasses.replace(reference, **lean)
        files = rec.metadata.get("source_files")
        inputs = _input_files(list(files) if files else getattr(rec, "source", ""), controller, sup.source,
                              summary["damper"])
        write_result(stored, out, reference=None if stored is stored_ref else stored_ref, evaluation=J,
                     isolation=layer, record_source=inputs["record"].get("path", ""),
                     record_units=summary["units_assumed"], inputs=json.dumps(inputs),
                     record_synthetic=getattr(rec, "synthetic", False), control_step=control_step,
                     n_modes="all" if n_modes is None else n_modes, building=json.dumps(building.describe(),
                                                                                         default=str),
                     precision="double" if full_histories else "single",
                     command_unit=command_unit(summary.get("damper")),
                     damper=json.dumps(summary["damper"], default=str))
        summary["out"] = str(out)
    if plot_dir:
        say(f"plotting into {plot_dir}")
        paths = plot_run(result, plot_dir, reference=None if result is reference else reference,
                         bearing_xy=sup.bearing_xy, corners=plan_corners(sup.bearing_xy),
                         command_unit=command_unit(summary["damper"]))
        summary["plots"] = [str(p) for p in paths]
    summary["elapsed_s"] = time.perf_counter() - start
    summary["result"] = result
    summary["reference"] = reference
    return summary


def _print_table(summary: dict[str, Any]) -> None:
    print(f"{summary['record']} ({summary['orientation']}), isolation {summary['isolation']}, "
          f"controller {summary['controller']}: {summary['elapsed_s']:.1f} s")
    print(f"  record values read as {summary['units_assumed']}"
          + (f"; control step {summary['control_step_s']:g} s" if summary.get("control_step_s") else "")
          + f"; record step {summary['record_step_s']:g} s, integrated and reported every "
            f"{summary['integration_step_s']:g} s")
    if summary.get("record_columns"):
        print(f"  record columns: {summary['record_columns']}")
    for flaw in summary.get("record_flaws", []):
        print(f"  record flaw: {flaw}")
    print(f"  {'response':<26s} {'run':>12s} {'uncontrolled':>13s}  units")
    for key, value in summary["peaks"].items():
        ref = summary["reference_peaks"].get(key)
        ref_s = f"{ref:13.5g}" if ref is not None else f"{'-':>13s}"
        print(f"  {key:<26s} {value:12.5g} {ref_s}  {PEAK_UNITS[key]}")
    for c in summary["damper"]["dampers"]:
        print(f"  damper {c['damper']} ({c['model']}, {summary['damper']['n_devices']} devices, "
              f"{summary['damper']['layout']}): {c['scale_basis']}")
        print(f"    {c['input_mapping']}")
    for key, desc in J_DESCRIPTIONS.items():
        value = summary["J"].get(key)
        print(f"  {key:<3s} {'—' if value is None else f'{value:.4f}':>8s}  {desc}")
    print(f"  J's: {SOURCE}; formulas and the project's own choices in docs/criteria.md")
    if summary["out"]:
        print(f"  results: {summary['out']}")
    for p in summary["plots"]:
        print(f"  figure: {p}")


def main_run(args: argparse.Namespace) -> int:
    """Entry point of ``sbib run``: run :func:`run_command` with the parsed ``args``; return the exit status.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed command-line options of the sub-command.
    """
    summary = run_command(args.record, orientation=args.orientation, isolation=args.isolation,
                       controller=args.controller, records_dir=args.records_dir, out=args.out,
                       plot_dir=args.plot, n_modes=args.n_modes, control_step=args.control_step,
                       substep_tolerance=args.substep_tolerance,
                       baseline_correct=args.baseline_correct, progress=not args.json,
                       format=args.format, dt=args.dt, units=args.units, full_histories=args.full_histories,
                       integration_step=args.integration_step, damper=args.damper, devices=args.devices,
                       damper_scale=args.damper_scale)
    summary.pop("result", None)
    summary.pop("reference", None)
    if args.json:
        print(json.dumps(summary))
    else:
        _print_table(summary)
    return 0


def register(subparsers: Any) -> None:
    """Add ``sbib run`` to the ``sbib`` command line (``subparsers`` of :mod:`benchmark.applications.cli`).

    Parameters
    ----------
    subparsers : Any
        The sub-command action of the ``sbib`` parser (``add_subparsers()`` in
        :func:`benchmark.applications.cli.main`) to add the sub-command to.
    """

    p = subparsers.add_parser(
        "run", help="simulate one record with one isolation and controller (and its uncontrolled reference)",
        description="Simulate the benchmark building under one record, with its uncontrolled reference "
                    "run, and report peaks and the evaluation criteria J1-J9.")
    p.add_argument("--record", required=True, metavar="NAME|PATH",
                   help="benchmark record name (e.g. kobe) or a record file")
    p.add_argument("--isolation", default=DEFAULT_NONLINEAR, metavar="NAME|FILE.json",
                   help=f"isolation layer: {', '.join(ISOLATION_NAMES)} or a JSON file "
                        f"(default {DEFAULT_NONLINEAR})")
    p.add_argument("--controller", default="none", metavar="NAME",
                   help="controller name, one of: " + ", ".join(controller_names())
                        + "; or a class of yours as package.module:Class or path/to/file.py:Class "
                        "(controllers/base.py interface); 'none' = no devices (default none)")
    add_damper_options(p)  # --damper, --devices, --damper-scale
    add_record_options(p)  # --orientation, --records-dir, --format, --dt, --units, --baseline-correct
    p.add_argument("--out", default=None, metavar="FILE.h5", type=output_file_of("hdf5"), help="write the time histories (HDF5)")
    p.add_argument("--plot", default=None, metavar="DIR", type=output_dir, help="write figures (PNG) into DIR")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    p.add_argument("--n-modes", type=int, default=None, metavar="N",
                   help="keep the first N superstructure modes (default all: 3 per floor, 24 in the benchmark)")
    p.add_argument("--control-step", type=float, default=None, metavar="S",
                   help="controller sample time [s] (default 0.005, the benchmark's); any record step "
                        "fits")
    p.add_argument("--integration-step", type=float, default=None, metavar="S",
                   help="longest integration step [s] (default 0.005, the benchmark's); the record is "
                        "interpolated onto it, whatever its own step, and the step is halved (up to 3 "
                        "times, said on stderr) where the nonlinear forces do not converge")
    p.add_argument("--substep-tolerance", type=float, default=None, metavar="TOL",
                   help="sub-step tolerance of the nonlinear bearings (default 0.75)")
    p.add_argument("--full-histories", action="store_true",
                   help="write --out in double precision and with the force and state histories of "
                        "every bearing, the kernel's state and the measurement vectors (about 47 MB for "
                        "a 30-s record instead of about 4.5 MB in single precision; off by default)")
    p.set_defaults(func=main_run)
