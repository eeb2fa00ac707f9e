"""``sbib run``: one record, one orientation, one isolation, one controller — with its reference run.

::

    sbib run --record NAME|PATH --orientation FN-x|FP-x|FP-y|FN-y --isolation NAME --controller NAME
             [--records-dir DIR] [--format F] [--dt S] [--units U] [--baseline-correct]
             [--out FILE.h5] [--plot DIR] [--json]
             [--n-modes N] [--control-step S] [--substep-tolerance TOL]

The evaluation criteria need the uncontrolled run (same building and isolation, no devices,
same record and orientation), so every call computes it too (``--controller none`` *is* that
run, and is computed once). ``--record`` takes a benchmark record name (``kobe``, ...) or a
record file (any format :func:`records.readers.load_record` reads); for a file with two
components ``FN-x`` puts column 1 on x and ``FP-x`` swaps them; a one-component file goes on x
(``FN-x``) or y (``FP-x``); the seed paper's ``FP-y`` / ``FN-y`` are ``FN-x`` / ``FP-x``. The record
options are those of every command that takes a record (:mod:`records.options`). The record's
implausibility flaws (:mod:`records.plausibility`: wrong units, wrong dt) are warned about on
stderr. Without a controller the control step does not matter; with one, the default is the
benchmark's 0.005 s when it is a whole multiple of the record step, else the nearest whole
multiple, said on stderr (:func:`choose_control_step`).

``--json`` prints exactly one JSON object on stdout::

    {"record", "orientation" (FN-x or FP-x), "isolation", "controller",
     "control_step_s" (null without a controller), "units_assumed", "record_flaws": [messages],
     "peaks": {peak_base_shear [N], peak_structure_shear [N], peak_base_displacement [m],
               peak_drift_ratio [-], peak_floor_acceleration [m/s²], rms_base_displacement [m],
               rms_floor_acceleration [m/s², largest floor], peak_device_force [N]},
     "J": {J1..J9, only those defined}, "elapsed_s",
     "reference_peaks": {same keys, uncontrolled run}, "corners": {...}, "out": path or null,
     "plots": [paths]}

The Python equivalent of the command is :func:`run_case`.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from benchmark.foundation.errors import DataNotFoundError, InputError
from benchmark.simulator.building import Building
from benchmark.simulator.evaluation import corner_responses, evaluate, peaks, plan_corners
from benchmark.simulator.isolation.configurations import DEFAULT_NONLINEAR, get_isolation
from benchmark.simulator.simulation import simulate
from controllers.registry import get_controller
from records import ORIENTATIONS, load_benchmark_record, load_record
from benchmark.simulator.evaluation import J_DESCRIPTIONS, PEAK_UNITS
from benchmark.simulator.isolation.configurations import ISOLATION_NAMES
from records.baseline import baseline_correct as _correct
from benchmark.simulator.results import write_result
from benchmark.simulator.plots import plot_run
from records.resolve import resolve_record as _resolve
from records.options import add_record_options

__all__ = ["register", "run_case", "resolve_record", "choose_control_step", "main_run", "DEFAULT_CONTROL_STEP"]

def resolve_record(spec: str, orientation: str = "FN-x", records_dir: str | None = None,
                   baseline_correct: bool = False, format: str = "auto", dt: float | None = None,
                   units: str | None = None):
    """Load a record by benchmark name or file path, oriented as asked (x, y components).

    The one resolver every command uses, :func:`records.resolve.resolve_record` (see there for
    the orientation of files, the seed paper's ``FP-y`` / ``FN-y`` and the options).

    Returns
    -------
    records.Record
        Two components [m/s²], column 0 on x, column 1 on y; ``metadata`` holds the canonical
        orientation, ``units_assumed`` and ``flaws``.
    """

    return _resolve(spec, orientation, records_dir=records_dir, baseline_correct=baseline_correct,
                    format=format, dt=dt, units=units)


#: The benchmark's control sample time [s] (Narasimhan et al. 2006), used when it fits the record.
DEFAULT_CONTROL_STEP = 0.005


def choose_control_step(record_dt: float, requested: float | None = None) -> tuple[float, str]:
    """Return the control step [s] for a record step and why it was chosen.

    Parameters
    ----------
    record_dt : float
        The record's time step [s]; the structure steps at it, so the control step must be a
        whole multiple of it.
    requested : float, optional
        ``--control-step`` as given; ``None`` picks one.

    Returns
    -------
    (float, str)
        The control step and a note ("" when it is the benchmark's 0.005 s or the requested one).
        Without a request: 0.005 s when it is a whole multiple of the record step, else the
        whole multiple of the record step nearest to 0.005 s (at least one step), e.g. 0.01 s for
        a PEER record at dt = 0.01 s.

    Raises
    ------
    InputError
        A requested step that is not positive or not a whole multiple of ``record_dt``; the
        message names ``--control-step`` and a step that would work.
    """
    if requested is not None:
        if not (math.isfinite(requested) and requested > 0):
            raise InputError(f"--control-step {requested!r}: expected a positive number of seconds")
        ratio = requested / record_dt
        if abs(ratio - round(ratio)) > 1e-6 * max(1.0, ratio) or round(ratio) < 1:
            k = max(1, round(ratio))
            raise InputError(f"--control-step {requested:g} s is not a whole multiple of the record step "
                             f"{record_dt:g} s; give --control-step {k * record_dt:g} (or another multiple of "
                             f"{record_dt:g} s), or leave it out to pick one")
        return float(requested), ""
    ratio = DEFAULT_CONTROL_STEP / record_dt
    k = max(1, round(ratio))
    if abs(ratio - k) <= 1e-6 * max(1.0, ratio):
        return DEFAULT_CONTROL_STEP, ""
    step = k * record_dt
    return step, (f"control step {step:g} s: the benchmark's {DEFAULT_CONTROL_STEP:g} s is not a whole multiple "
                  f"of the record step {record_dt:g} s (give --control-step to choose another multiple)")


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


def run_case(record: str, orientation: str = "FN-x", isolation: str | None = None,
             controller: str = "none", records_dir: str | None = None, out: str | None = None,
             plot_dir: str | None = None, n_modes: int | None = None, control_step: float | None = None,
             substep_tolerance: float | None = None, baseline_correct: bool = False,
             progress: bool = False, format: str = "auto", dt: float | None = None,
             units: str | None = None, warn: bool = True) -> dict[str, Any]:
    """Run one case and its uncontrolled reference; evaluate, and optionally save and plot.

    Parameters
    ----------
    record : str
        Benchmark record name or record file path (see :func:`resolve_record`).
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
        Reduced superstructure (first ``n_modes`` modes); default all 24.
    control_step : float, optional
        Controller sample time [s]; ``None`` picks one (:func:`choose_control_step`: the
        benchmark's 0.005 s when it fits the record step). Without a controller it does not matter.
    substep_tolerance : float, optional
        Sub-step tolerance of every nonlinear bearing.
    baseline_correct : bool
    progress : bool
        Print progress lines on stderr.
    format, dt, units : optional
        How to read a record file (:func:`records.resolve.resolve_record`).
    warn : bool
        Print the record's implausibility flaws and a chosen control step on stderr.

    Returns
    -------
    dict
        The ``--json`` object (module docstring), plus ``result`` and ``reference`` (the
        :class:`benchmark.simulator.simulation.SimulationResult` objects, not JSON).
    """

    start = time.perf_counter()
    if control_step is not None and not (math.isfinite(control_step) and control_step > 0):
        raise InputError(f"--control-step {control_step!r}: expected a positive number of seconds")
    rec = resolve_record(record, orientation, records_dir, baseline_correct, format=format, dt=dt, units=units)
    orientation = rec.metadata.get("orientation", orientation)
    layer = get_isolation(isolation or DEFAULT_NONLINEAR, substep_tolerance=substep_tolerance)
    ctrl = get_controller(controller)
    implausible = [f for f in rec.metadata.get("flaws", []) if "implausible" in f]
    if warn:
        for flaw in implausible:
            print(f"sbib run: warning: {flaw}", file=sys.stderr, flush=True)
    if ctrl is None:  # no devices, no controller: the control step does not matter
        control_step = control_step if control_step is not None else rec.dt
    else:
        control_step, note = choose_control_step(rec.dt, control_step)
        if note and warn:
            print(f"sbib run: {note}", file=sys.stderr, flush=True)
    devices = None if ctrl is None else "default"
    building = Building.default(isolation=layer, devices=devices, n_modes=n_modes)

    def say(msg: str) -> None:
        if progress:
            print(f"sbib run: {msg}", file=sys.stderr, flush=True)

    say(f"reference run (no devices): {rec.name}, {orientation}, {layer.name}")
    info = {"record": rec.name, "orientation": orientation, "isolation": layer.name}
    reference = simulate(building.without_devices(), rec, controller=None, control_step=control_step,
                         info=info)
    if ctrl is None:
        result = reference
    else:
        say(f"controlled run: {controller}")
        result = simulate(building, rec, controller=ctrl, control_step=control_step, info=info)
    J = evaluate(result, reference)
    sup = building.superstructure
    corners = corner_responses(result, plan_corners(sup.bearing_xy), sup.storey_heights)
    summary: dict[str, Any] = {
        "record": rec.name,
        "orientation": orientation,
        "isolation": layer.name,
        "controller": controller,
        "control_step_s": float(control_step) if ctrl is not None else None,
        "units_assumed": rec.metadata.get("units_assumed", ""),
        "record_flaws": list(rec.metadata.get("flaws", [])),
        "peaks": _clean(peaks(result)),
        "J": {k: v for k, v in _clean(J).items()},
        "reference_peaks": _clean(peaks(reference)),
        "corners": {"corners_m": corners["corners"].tolist(),
                    "peak_corner_base_displacement": corners["peak_corner_base_displacement"].tolist(),
                    "peak_corner_drift_ratio": corners["peak_corner_drift_ratio"].tolist()},
        "out": None,
        "plots": [],
    }
    if out:
        say(f"writing {out}")
        write_result(result, out, reference=None if result is reference else reference, evaluation=J,
                     isolation=layer, record_source=getattr(rec, "source", ""),
                     record_synthetic=getattr(rec, "synthetic", False), control_step=control_step,
                     n_modes="all" if n_modes is None else n_modes, building=json.dumps(building.describe(),
                                                                                         default=str))
        summary["out"] = str(out)
    if plot_dir:
        say(f"plotting into {plot_dir}")
        paths = plot_run(result, plot_dir, reference=None if result is reference else reference,
                         bearing_xy=sup.bearing_xy, corners=plan_corners(sup.bearing_xy))
        summary["plots"] = [str(p) for p in paths]
    summary["elapsed_s"] = time.perf_counter() - start
    summary["result"] = result
    summary["reference"] = reference
    return summary


def _print_table(summary: dict[str, Any]) -> None:
    print(f"{summary['record']} ({summary['orientation']}), isolation {summary['isolation']}, "
          f"controller {summary['controller']}: {summary['elapsed_s']:.1f} s")
    print(f"  record values read as {summary['units_assumed']}"
          + (f"; control step {summary['control_step_s']:g} s" if summary.get("control_step_s") else ""))
    for flaw in summary.get("record_flaws", []):
        print(f"  record flaw: {flaw}")
    print(f"  {'response':<26s} {'run':>12s} {'uncontrolled':>13s}  units")
    for key, value in summary["peaks"].items():
        ref = summary["reference_peaks"].get(key)
        ref_s = f"{ref:13.5g}" if ref is not None else f"{'-':>13s}"
        print(f"  {key:<26s} {value:12.5g} {ref_s}  {PEAK_UNITS[key]}")
    for key, desc in J_DESCRIPTIONS.items():
        value = summary["J"].get(key)
        print(f"  {key:<3s} {'—' if value is None else f'{value:.4f}':>8s}  {desc}")
    if summary["out"]:
        print(f"  results: {summary['out']}")
    for p in summary["plots"]:
        print(f"  figure: {p}")


def main_run(args: argparse.Namespace) -> int:
    """Entry point of ``sbib run``: run :func:`run_case` with the parsed ``args``; return the exit status."""
    summary = run_case(args.record, orientation=args.orientation, isolation=args.isolation,
                       controller=args.controller, records_dir=args.records_dir, out=args.out,
                       plot_dir=args.plot, n_modes=args.n_modes, control_step=args.control_step,
                       substep_tolerance=args.substep_tolerance,
                       baseline_correct=args.baseline_correct, progress=not args.json,
                       format=args.format, dt=args.dt, units=args.units)
    summary.pop("result", None)
    summary.pop("reference", None)
    if args.json:
        print(json.dumps(summary))
    else:
        _print_table(summary)
    return 0


def register(subparsers: Any) -> None:
    """Add ``sbib run`` to the ``sbib`` command line (``subparsers`` of :mod:`benchmark.applications.cli`)."""

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
                   help="controller name; 'none' = no devices (default none)")
    add_record_options(p)  # --orientation, --records-dir, --format, --dt, --units, --baseline-correct
    p.add_argument("--out", default=None, metavar="FILE.h5", help="write the time histories (HDF5)")
    p.add_argument("--plot", default=None, metavar="DIR", help="write figures (PNG) into DIR")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    p.add_argument("--n-modes", type=int, default=None, metavar="N",
                   help="keep the first N superstructure modes (default all 24)")
    p.add_argument("--control-step", type=float, default=None, metavar="S",
                   help="controller sample time [s], a whole multiple of the record step (default: the "
                        "benchmark's 0.005 s when it is one, else the multiple nearest to it, said on stderr; "
                        "without a controller it does not matter)")
    p.add_argument("--substep-tolerance", type=float, default=None, metavar="TOL",
                   help="sub-step tolerance of the nonlinear bearings (default 0.75)")
    p.set_defaults(func=main_run)
