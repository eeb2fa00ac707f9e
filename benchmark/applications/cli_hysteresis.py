"""``sbib hysteresis``: identify and run a hysteretic (Bouc-Wen) oscillator from force/displacement data.

* ``sbib hysteresis fit --data FILE --out model.json [--holdout 0.2] [--json]``: FILE is the
  Bouc-Wen benchmark's HDF5 (group ``multisine``: ``u``, ``y``, ``fs``) or a CSV
  ``time, force, displacement`` (SI). The last ``--holdout`` fraction of the record is left out
  of the fit and the model's RMS displacement error on it is reported (the benchmark's figure of
  merit); the model is simulated over the whole record from rest.
* ``sbib hysteresis predict --model model.json --input FILE.csv --out y.csv [--periodic]``:
  ``time, force`` in, ``time, displacement`` out (SI). With a ``displacement`` column in the input
  the RMS error is printed. ``--periodic``: the input is one period of a periodic force and the
  steady-state period is returned (the benchmark's multisine test set).
* ``sbib hysteresis test-signals --out DIR``: the benchmark's two test sets regenerated with the
  true system (:func:`damper.hysteresis.noel_schoukens.test_sets`), as CSV ``time, force,
  displacement``.

Method: :mod:`damper.hysteresis.identification`; model: :mod:`damper.hysteresis.oscillator`.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from benchmark.foundation.errors import InputError
from benchmark.foundation.arguments import fraction_from_zero, nonnegative, positive_int
from benchmark.foundation.atomic import atomic_write_text, output_dir, output_file_of
from damper.hysteresis import noel_schoukens
from damper.hysteresis.noel_schoukens import FS, rms_error
from damper.hysteresis.files import (data_flaws, load_model, read_data, sampling_rate_flaw, save_model,
                                     write_displacement_csv)
from damper.hysteresis.identification import MIN_SAMPLES, identify_hysteretic

__all__ = ["register", "run_fit", "run_predict", "run_test_signals"]


def _check_out(path) -> None:
    """Fail before the work when the output file's directory does not exist."""
    parent = Path(path).resolve().parent
    if not parent.is_dir():
        raise InputError(f"--out {path}: directory {parent} does not exist")


def run_fit(args: argparse.Namespace) -> int:
    """Identify the model from ``args.data``; write ``args.out``; print a summary.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed command-line options of the sub-command.
    """
    _check_out(args.out)
    data = read_data(args.data, need_displacement=True, group=args.group)
    flaws = data_flaws(data)
    if flaws and not args.keep_flagged:
        raise InputError(f"{args.data}: {'; '.join(flaws)} (--keep-flagged fits anyway)")
    for flaw in flaws:
        print(f"warning: {args.data}: {flaw} (kept: --keep-flagged)", file=sys.stderr)
    n = data.force.size
    n_fit = n - int(round(args.holdout * n))
    if n_fit < MIN_SAMPLES:
        raise InputError(f"{args.data}: {n_fit} samples left to fit after the hold-out; expected at "
                         f"least {MIN_SAMPLES}")
    fit = identify_hysteretic(data.force[:n_fit], data.displacement[:n_fit], data.fs,
                              upsample=args.upsample, skip=args.skip,
                              max_nfev=args.max_iterations)
    summary = fit.to_dict()
    # a fit through flagged data says so in the model file too, not only on stderr
    summary["warnings"] = list(summary.get("warnings", [])) + [f"fitted with --keep-flagged: {f}" for f in flaws]
    summary["data"] = {"source": data.source, "samples": n, "sampling_rate_hz": data.fs,
                       "fit_samples": n_fit, "holdout_samples": n - n_fit}
    if n_fit < n:
        y_all = fit.model.simulate(data.force, data.fs, upsample=args.upsample)
        held = data.displacement[n_fit:]
        summary["holdout"] = {"rms_error": rms_error(y_all[n_fit:], held),
                              "rms_displacement": float(np.sqrt(np.mean(held ** 2))),
                              "first_sample": n_fit, "units": "m"}
    save_model(args.out, fit.model, data.fs, args.upsample, extra={"fit": summary}, inputs=[args.data])
    if args.json:
        print(json.dumps(summary, indent=2, default=_plain))
        return 0
    print(_text_summary(fit, summary, args.out))
    return 0


def _plain(x):
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, (np.floating, np.integer)):
        return x.item()
    raise TypeError(type(x).__name__)


def _text_summary(fit, summary: dict, out) -> str:
    m = fit.model
    se = fit.standard_error
    rows = [("mass", m.mass, se["mass"], "kg"), ("damping", m.damping, se["damping"], "N s/m"),
            ("stiffness", m.stiffness, se["stiffness"], "N/m"),
            ("kappa_w", m.kappa_w, se["kappa_w"], "N"), ("rho", m.rho, se["rho"], "1/m"),
            ("sigma", m.sigma, se["sigma"], ""), ("n", m.n, se["n"], "")]
    std = m.to_standard(beta=1.0)
    data = summary["data"]
    first, last = summary.get("fit_window", (0, data["fit_samples"]))
    lines = [f"hysteretic oscillator from {data['source']} ({last - first} samples fitted, the first {first} "
             f"of {data['fit_samples']} skipped as settling, at {data['sampling_rate_hz']:g} Hz, "
             f"branch {'saturating' if m.branch > 0 else 'hardening'})"]
    lines += [f"  {name:<10s} {v:>14.6g} ± {s:<10.3g} {unit}" for name, v, s, unit in rows]
    lines.append(f"  standard form (beta = 1): alpha {std['alpha']:.6g} N/m, gamma {std['gamma']:.6g}, "
                 f"delta {std['delta']:.6g}, nu {std['nu']:.6g}")
    lines.append(f"  fit: RMS error {fit.rms_error:.3g} m (displacement RMS {fit.rms_displacement:.3g} m), "
                 f"{fit.nfev} simulations, {fit.elapsed:.1f} s wall, {fit.cpu_time:.1f} s CPU")
    if "holdout" in summary:
        h = summary["holdout"]
        lines.append(f"  hold-out (last {summary['data']['holdout_samples']} samples): RMS error "
                     f"{h['rms_error']:.3g} m (displacement RMS {h['rms_displacement']:.3g} m)")
    for w in fit.warnings:
        lines.append(f"  warning: {w}")
    lines.append(f"model -> {out}")
    return "\n".join(lines)


def run_predict(args: argparse.Namespace) -> int:
    """Simulate the model of ``args.model`` under the force of ``args.input``; write ``args.out``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed command-line options of the sub-command.
    """
    _check_out(args.out)
    model, doc = load_model(args.model)
    data = read_data(args.input, need_displacement=False)
    rate = sampling_rate_flaw(data.fs)
    if rate:  # the check `fit` applies: a time column in ms read as s (0.75 Hz)
        raise InputError(f"{args.input}: {rate}")
    upsample = args.upsample or int(doc.get("upsample", 20))
    y = model.simulate(data.force, data.fs, upsample=upsample, periodic=args.periodic)
    write_displacement_csv(args.out, data.time, y)
    msg = f"{data.force.size} samples at {data.fs:g} Hz -> {args.out}"
    if data.displacement is not None:
        msg += (f"; RMS error against the file's displacement {rms_error(y, data.displacement):.3g} m "
                f"(its RMS {float(np.sqrt(np.mean(data.displacement ** 2))):.3g} m)")
    print(msg)
    return 0


def run_test_signals(args: argparse.Namespace) -> int:
    """Write the regenerated benchmark test sets as CSV files in ``args.out``.

    Parameters
    ----------
    args : argparse.Namespace
        Parsed command-line options of the sub-command.
    """
    if args.seed < 0:
        raise InputError(f"--seed {args.seed}: expected a non-negative integer")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    for name, (u, y) in noel_schoukens.test_sets(seed=args.seed).items():
        t = np.arange(u.size) / FS
        text = "time [s],force [N],displacement [m]\n" + "".join(
            f"{a:.17g},{b:.17g},{c:.17g}\n" for a, b, c in zip(t, u, y))
        atomic_write_text(out / f"{name}.csv", text)
        print(f"{name}: {u.size} samples -> {out / f'{name}.csv'}")
    return 0


def register(subparsers) -> None:
    """Add ``sbib hysteresis fit|predict|test-signals``.

    Parameters
    ----------
    subparsers
        The sub-command action of the ``sbib`` parser (``add_subparsers()`` in
        :func:`benchmark.applications.cli.main`) to add the sub-command to.
    """
    parser = subparsers.add_parser("hysteresis", help="identify/run a hysteretic (Bouc-Wen) oscillator "
                                   "from force/displacement data (Bouc-Wen benchmark)",
                                   description=__doc__,
                                   formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="hysteresis_command", metavar="SUBCOMMAND")
    parser.set_defaults(func=lambda args: (parser.print_help(), 2)[1])

    p = sub.add_parser("fit", help="identify the model from force/displacement data")
    p.add_argument("--data", required=True, help="benchmark HDF5 or CSV time,force,displacement (SI)")
    p.add_argument("--out", required=True, type=output_file_of("json"), help="output model JSON")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.add_argument("--holdout", type=fraction_from_zero, default=0.2,
                   help="fraction of the record, at its end, left out of the fit and reported "
                        "(default 0.2)")
    p.add_argument("--group", default=None, help="HDF5 group (default: multisine)")
    p.add_argument("--upsample", type=positive_int, default=20,
                   help="integration steps per sample (default 20, the benchmark's)")
    p.add_argument("--skip", type=nonnegative, default=None,
                   help="seconds at the start left out of the fit window (default: the start "
                        "model's settling time)")
    p.add_argument("--max-iterations", type=positive_int, default=40,
                   help="cap on the output-error iterations (default 40)")
    p.add_argument("--keep-flagged", action="store_true",
                   help="fit data with a clipped or stuck channel or an implausible sampling rate "
                        "(refused by default)")
    p.set_defaults(func=run_fit)

    p = sub.add_parser("predict", help="displacement response of a fitted model to a force")
    p.add_argument("--model", required=True, help="model JSON written by 'sbib hysteresis fit'")
    p.add_argument("--input", required=True, help="CSV time,force[,displacement] (SI) or HDF5")
    p.add_argument("--out", required=True, type=output_file_of("csv"), help="output CSV time,displacement")
    p.add_argument("--periodic", action="store_true",
                   help="the input is one period of a periodic force: return the steady state")
    p.add_argument("--upsample", type=positive_int, default=None,
                   help="integration steps per sample (default: the model file's)")
    p.set_defaults(func=run_predict)

    p = sub.add_parser("test-signals", help="write the benchmark's test sets, regenerated, as CSV")
    p.add_argument("--out", required=True, type=output_dir, help="output directory")
    p.add_argument("--seed", type=int, default=2016, help="multisine phase seed (default 2016)")
    p.set_defaults(func=run_test_signals)
