"""``sbib run``: one record, one orientation, one isolation, one controller — with its reference run.

::

    sbib run --record NAME|PATH --orientation FN-x|FP-x --isolation NAME --controller NAME
             [--records-dir DIR] [--out FILE.h5] [--plot DIR] [--json]
             [--n-modes N] [--control-step S] [--substep-tolerance TOL] [--baseline-correct]

The evaluation criteria need the uncontrolled run (same building and isolation, no devices,
same record and orientation), so every call computes it too (``--controller none`` *is* that
run, and is computed once). ``--record`` takes a benchmark record name (``kobe``, ...) or a
record file (any format :func:`records.readers.load_record` reads); for a file with two
components ``FN-x`` puts column 1 on x and ``FP-x`` swaps them; a one-component file goes on x
(``FN-x``) or y (``FP-x``).

``--json`` prints exactly one JSON object on stdout::

    {"record", "orientation", "isolation", "controller",
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
import dataclasses
import json
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from benchmark.errors import DataNotFoundError, InputError

__all__ = ["register", "run_case", "resolve_record", "main_run"]

_RECORD_SUFFIXES = {".txt", ".at2", ".csv", ".dat", ".acc", ".tsv"}


def _records_api():
    """The records package's loaders (contract names, with their module paths as fallback)."""
    try:
        from records import ORIENTATIONS, load_benchmark_record
    except ImportError:
        from records.catalogue import ORIENTATIONS, load_benchmark_record
    try:
        from records import load_record
    except ImportError:
        from records.readers import load_record
    return ORIENTATIONS, load_benchmark_record, load_record


def resolve_record(spec: str, orientation: str = "FN-x", records_dir: str | None = None,
                   baseline_correct: bool = False):
    """Load a record by benchmark name or file path, oriented as asked (x, y components).

    Parameters
    ----------
    spec : str
        A benchmark record name (``records.BENCHMARK_RECORDS``) or a file path.
    orientation : {"FN-x", "FP-x"}
    records_dir : str, optional
        Directory of the benchmark's files (names only).
    baseline_correct : bool
        Apply the records module's baseline correction.

    Returns
    -------
    records.Record
        Two components [m/s²], column 0 on x, column 1 on y.
    """
    orientations, load_benchmark_record, load_record = _records_api()
    if orientation not in orientations:
        raise InputError(f"--orientation {orientation!r}; expected one of {', '.join(orientations)}")
    path = Path(spec).expanduser()
    looks_like_path = path.exists() or "/" in spec or "\\" in spec or path.suffix.lower() in _RECORD_SUFFIXES
    if not looks_like_path:
        return load_benchmark_record(spec, orientation=orientation, records_dir=records_dir,
                                     baseline_correct=baseline_correct)
    if not path.is_file():
        raise DataNotFoundError(f"--record {spec}: file not found")
    record = load_record(path)
    acc = np.asarray(record.acceleration, dtype=float)
    if acc.ndim == 1:
        acc = acc[:, None]
    if acc.shape[1] == 1:
        zeros = np.zeros_like(acc)
        both = np.hstack([acc, zeros]) if orientation == "FN-x" else np.hstack([zeros, acc])
        label = tuple(record.labels)[0] if record.labels else "component"
        labels = (label, "zero") if orientation == "FN-x" else ("zero", label)
        record = record.replace(acceleration=both, labels=labels)
    elif acc.shape[1] >= 2:
        record = record.select([0, 1] if orientation == "FN-x" else [1, 0])
    meta = dict(record.metadata)
    meta["orientation"] = orientation
    record = record.replace(metadata=meta)
    if baseline_correct:
        from records.baseline import baseline_correct as _correct

        record = _correct(record)
    return record


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
             plot_dir: str | None = None, n_modes: int | None = None, control_step: float = 0.005,
             substep_tolerance: float | None = None, baseline_correct: bool = False,
             progress: bool = False, full_histories: bool = False) -> dict[str, Any]:
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
        HDF5 file to write (run, reference, J1–J9; :func:`benchmark.results.write_result`).
    plot_dir : str, optional
        Directory for the figures (:func:`benchmark.plots.plot_run`).
    n_modes : int, optional
        Reduced superstructure (first ``n_modes`` modes); default all 24.
    control_step : float
        Controller sample time [s].
    substep_tolerance : float, optional
        Sub-step tolerance of every nonlinear bearing.
    baseline_correct : bool
    progress : bool
        Print progress lines on stderr.
    full_histories : bool
        Also write the per-bearing force and state histories (92 bearings x 2 components per
        sample: about 30 MB more for a 30-s record) and the kernel's state history (every
        stored history is derived from it; 2.3 MB per run) into ``out``. The figures of
        ``plot_dir`` get the bearing histories either way (the bearing loops need them).

    Returns
    -------
    dict
        The ``--json`` object (module docstring), plus ``result`` and ``reference`` (the
        :class:`benchmark.simulation.SimulationResult` objects, not JSON).
    """
    from benchmark.building import Building
    from benchmark.evaluation import corner_responses, evaluate, peaks, plan_corners
    from benchmark.isolation.configurations import DEFAULT_NONLINEAR, get_isolation
    from benchmark.simulation import simulate
    from controllers.registry import get_controller

    start = time.perf_counter()
    if control_step is None or not (math.isfinite(control_step) and control_step > 0):
        raise InputError(f"--control-step {control_step!r}: expected a positive number of seconds")
    rec = resolve_record(record, orientation, records_dir, baseline_correct)
    layer = get_isolation(isolation or DEFAULT_NONLINEAR, substep_tolerance=substep_tolerance)
    ctrl = get_controller(controller)
    devices = None if ctrl is None else "default"
    building = Building.default(isolation=layer, devices=devices, n_modes=n_modes)

    def say(msg: str) -> None:
        if progress:
            print(f"sbib run: {msg}", file=sys.stderr, flush=True)

    say(f"reference run (no devices): {rec.name}, {orientation}, {layer.name}")
    info = {"record": rec.name, "orientation": orientation, "isolation": layer.name}
    keep_bearings = bool(full_histories or plot_dir)
    reference = simulate(building.without_devices(), rec, controller=None, control_step=control_step,
                         info=info, bearing_histories=keep_bearings)
    if ctrl is None:
        result = reference
    else:
        say(f"controlled run: {controller}")
        result = simulate(building, rec, controller=ctrl, control_step=control_step, info=info,
                          bearing_histories=keep_bearings)
    J = evaluate(result, reference)
    sup = building.superstructure
    corners = corner_responses(result, plan_corners(sup.bearing_xy), sup.storey_heights)
    summary: dict[str, Any] = {
        "record": rec.name,
        "orientation": orientation,
        "isolation": layer.name,
        "controller": controller,
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
        from benchmark.results import write_result

        say(f"writing {out}")
        stored, stored_ref = result, reference
        if not full_histories:  # the per-bearing histories, if any, were for the figures only
            lean = {"bearing_force": None, "bearing_state": None, "state": None}
            stored = dataclasses.replace(result, **lean)
            stored_ref = stored if reference is result else dataclasses.replace(reference, **lean)
        write_result(stored, out, reference=None if stored is stored_ref else stored_ref, evaluation=J,
                     isolation=layer, record_source=getattr(rec, "source", ""),
                     record_synthetic=getattr(rec, "synthetic", False), control_step=control_step,
                     n_modes="all" if n_modes is None else n_modes, building=json.dumps(building.describe(),
                                                                                         default=str))
        summary["out"] = str(out)
    if plot_dir:
        from benchmark.plots import plot_run

        say(f"plotting into {plot_dir}")
        paths = plot_run(result, plot_dir, reference=None if result is reference else reference,
                         bearing_xy=sup.bearing_xy, corners=plan_corners(sup.bearing_xy))
        summary["plots"] = [str(p) for p in paths]
    summary["elapsed_s"] = time.perf_counter() - start
    summary["result"] = result
    summary["reference"] = reference
    return summary


def _print_table(summary: dict[str, Any]) -> None:
    from benchmark.evaluation import J_DESCRIPTIONS, PEAK_UNITS

    print(f"{summary['record']} ({summary['orientation']}), isolation {summary['isolation']}, "
          f"controller {summary['controller']}: {summary['elapsed_s']:.1f} s")
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
                       full_histories=args.full_histories)
    summary.pop("result", None)
    summary.pop("reference", None)
    if args.json:
        print(json.dumps(summary))
    else:
        _print_table(summary)
    return 0


def register(subparsers: Any) -> None:
    """Add ``sbib run`` to the ``sbib`` command line (``subparsers`` of :mod:`benchmark.cli`)."""
    from benchmark.isolation.configurations import DEFAULT_NONLINEAR, ISOLATION_NAMES

    p = subparsers.add_parser(
        "run", help="simulate one record with one isolation and controller (and its uncontrolled reference)",
        description="Simulate the benchmark building under one record, with its uncontrolled reference "
                    "run, and report peaks and the evaluation criteria J1-J9.")
    p.add_argument("--record", required=True, metavar="NAME|PATH",
                   help="benchmark record name (e.g. kobe) or a record file")
    p.add_argument("--orientation", default="FN-x", choices=("FN-x", "FP-x"),
                   help="FN-x: first component on x; FP-x: swapped (default FN-x)")
    p.add_argument("--isolation", default=DEFAULT_NONLINEAR, metavar="NAME|FILE.json",
                   help=f"isolation layer: {', '.join(ISOLATION_NAMES)} or a JSON file "
                        f"(default {DEFAULT_NONLINEAR})")
    p.add_argument("--controller", default="none", metavar="NAME",
                   help="controller name; 'none' = no devices (default none)")
    p.add_argument("--records-dir", default=None, metavar="DIR", help="directory of the benchmark records")
    p.add_argument("--out", default=None, metavar="FILE.h5", help="write the time histories (HDF5)")
    p.add_argument("--plot", default=None, metavar="DIR", help="write figures (PNG) into DIR")
    p.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    p.add_argument("--n-modes", type=int, default=None, metavar="N",
                   help="keep the first N superstructure modes (default all 24)")
    p.add_argument("--control-step", type=float, default=0.005, metavar="S",
                   help="controller sample time [s] (default 0.005)")
    p.add_argument("--substep-tolerance", type=float, default=None, metavar="TOL",
                   help="sub-step tolerance of the nonlinear bearings (default 0.75)")
    p.add_argument("--baseline-correct", action="store_true",
                   help="baseline-correct the record (off by default, as the benchmark distributes it)")
    p.add_argument("--full-histories", action="store_true",
                   help="also write the force and state histories of every bearing and the kernel's "
                        "state history into --out (about 35 MB more for a 30-s record; off by default)")
    p.set_defaults(func=main_run)
