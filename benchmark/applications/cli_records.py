"""``sbib records``: list the benchmark catalogue, show one record, write a synthetic one.

    sbib records list [--records-dir DIR] [--json]
    sbib records show NAME|FILE [--orientation FN-x|FP-x|FP-y|FN-y] [--plot FILE.png] [--json]
                      [--synthetic --seed N] [--baseline-correct]
                      [--format auto|benchmark|at2|single|csv --dt S --units U]
    sbib records generate NAME --out FILE.csv [--orientation] [--seed N] [--plot FILE.png]
    sbib records resample NAME|FILE --step S --out FILE.csv [--out-units U]
                      [--format auto|benchmark|at2|single|csv --dt S --units U] [--baseline-correct]

A thin layer over :mod:`records`: it parses, calls the Python API and prints.
"""

from __future__ import annotations

import argparse
import json
import math
import os
from pathlib import Path
from typing import Any
from records.catalogue import check_catalogue
from benchmark.foundation.errors import InputError
from records.catalogue import canonical_name, load_benchmark_record
from records.readers import load_record
from records.synthetic import benchmark_like
from records.checks import check_record
from records.measures import mean_period, significant_duration
from records.spectra import response_spectrum
from records.readers import write_csv
from records.baseline import baseline_correct
from records.plots import plot_record
from records.catalogue import ORIENTATION_HELP
from records.options import add_record_options, orientation_name
from records.options import record_kwargs
from records.resolve import resolve_record, looks_like_file
from records.resample import resample
from records.readers import unit_factor
from records.plausibility import MAX_DT_S, MIN_DT_S
from benchmark.foundation.errors import DataNotFoundError
from benchmark.foundation.provenance import provenance
from benchmark.foundation.atomic import output_file, output_file_of

__all__ = ["register"]


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``records`` command and its sub-commands to the ``sbib`` parser.

    Parameters
    ----------
    subparsers : argparse._SubParsersAction
        The sub-command action of the ``sbib`` parser (``add_subparsers()`` in
        :func:`benchmark.applications.cli.main`) to add the sub-command to.
    """

    parser = subparsers.add_parser(
        "records", help="ground-motion records: catalogue, show, synthetic",
        description="The benchmark's seven records (newhall, sylmar, elcentro, rinaldi, kobe, jiji, erzikan), "
                    "your own record files and the built-in synthetic generator.")
    sub = parser.add_subparsers(dest="records_command", metavar="SUBCOMMAND")
    parser.set_defaults(func=lambda args: (parser.print_help(), 2)[1])

    p = sub.add_parser("list", help="the catalogue: found or missing, PGA, duration, flaws",
                       description="Check a records directory against the benchmark catalogue.")
    p.add_argument("--records-dir", default=None,
                   help="directory of the benchmark files (default: SBIB_RECORDS_DIR, then <shared>/records/raw/FDZ)")
    p.add_argument("--json", action="store_true", help="print the check as JSON")
    p.set_defaults(func=_list)

    p = sub.add_parser("show", help="PGA, PGV, duration, dt of one record; optional plot",
                       description="Show a benchmark record by name, a synthetic benchmark-like record "
                                   "(--synthetic), or any record file (PEER .AT2, benchmark two-column, "
                                   "single-column with --dt, CSV).")
    p.add_argument("name", metavar="NAME|FILE", help="benchmark record name (erzincan accepted) or a file path")
    add_record_options(p)  # the same record options as sbib run and sbib compare
    p.add_argument("--synthetic", action="store_true", help="show the synthetic benchmark-like record instead")
    p.add_argument("--seed", type=int, default=0, help="seed of the synthetic record (default 0)")
    p.add_argument("--damping", type=float, default=0.05, help="damping ratio of the spectra (default 0.05)")
    p.add_argument("--plot", default=None, metavar="FILE.png", type=output_file,
                   help="write time histories (acc, vel, disp) and response spectra to this file")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(func=_show)

    p = sub.add_parser("generate", help="write a synthetic benchmark-like record as CSV",
                       description="Generate the synthetic record like a benchmark record (PGA, duration, "
                                   "D5-95, mean period, pulse period) and write it as CSV in m/s2.")
    p.add_argument("name", help="benchmark record to imitate")
    p.add_argument("--out", required=True, type=output_file_of("csv"), help="output CSV file")
    p.add_argument("--orientation", default="FN-x", type=orientation_name, help=ORIENTATION_HELP + " (default FN-x)")
    p.add_argument("--seed", type=int, default=0, help="seed (default 0)")
    p.add_argument("--plot", default=None, metavar="FILE.png", type=output_file, help="also plot it")
    p.set_defaults(func=_generate)

    p = sub.add_parser(
        "resample", help="write a record resampled onto another time step (CSV with units and provenance)",
        description="Resample a benchmark record or a record file onto a uniform time step and write it as "
                    "CSV: time [s] and one column per component, with the units in the header and comment "
                    "lines saying where the record came from, how it was resampled and by which sbib. A "
                    "finer step interpolates linearly between the samples (the motion the simulator "
                    "integrates anyway); a coarser one low-passes first (zero-phase Butterworth at 80 % of "
                    "the new Nyquist frequency) so that nothing aliases. sbib run does not need it: it "
                    "interpolates any record onto its own step. Example: sbib records resample "
                    "KJM-000 --dt 0.02 --units g --step 0.005 --out KJM-000_0.005.csv")
    p.add_argument("name", metavar="NAME|FILE", help="benchmark record name (erzincan accepted) or a file path")
    p.add_argument("--step", type=float, required=True, metavar="S", help="new time step [s], e.g. 0.005")
    p.add_argument("--out", required=True, metavar="FILE.csv", type=output_file_of("csv"), help="output CSV file (written atomically)")
    p.add_argument("--out-units", default=None, metavar="U",
                   help="units of the written values: g, m/s2, cm/s2 (gal), mm/s2 (default: those the "
                        "record was read in)")
    add_record_options(p, orientation=False)  # --records-dir, --format, --dt (of the input), --units, ...
    p.set_defaults(func=_resample)


# --------------------------------------------------------------------------- list
def _list(args: argparse.Namespace) -> int:
    report = check_catalogue(args.records_dir)
    if args.json:
        print(json.dumps(report, indent=2))
    else:
        print(_format_catalogue(report))
    if args.records_dir and report["error"]:  # the table says what is missing; stderr says why (exit 2)

        raise InputError(f"--records-dir {args.records_dir}: {report['error']}")
    if report["error"] and (os.environ.get("SBIB_RECORDS_DIR") or os.environ.get("SBIB_SHARED")):
        raise DataNotFoundError(report["error"])  # a directory the user set is missing: say which
    return 0


def _format_catalogue(report: dict[str, Any]) -> str:
    lines = []
    if report["error"]:
        lines.append(f"records directory: unavailable ({report['error']})")
    else:
        lines.append(f"records directory: {report['records_dir']} ({report['n_found']} of "
                     f"{len(report['records'])} found)")
    lines.append(f"{'name':<9} {'file':<13} {'found':<7} {'PGA col 1 / col 2 [g]':<22} {'catalogue [g]':<15} "
                 f"{'duration':>9}  flaws")
    units = sorted({item["units_assumed"] for item in report["records"] if item.get("units_assumed")})
    if units:
        lines.insert(1, f"values read as: {'; '.join(units)}")
    for item in report["records"]:
        expected = " / ".join(f"{x:.3f}" for x in item["expected_pga_g"])
        if not item["found"]:
            lines.append(f"{item['name']:<9} {item['file']:<13} {'MISSING':<7} {'-':<22} {expected:<15} "
                         f"{item['expected_duration_s']:>7.2f} s  -")
            continue
        if "error" in item:
            lines.append(f"{item['name']:<9} {item['file']:<13} {'yes':<7} unreadable: {item['error']}")
            continue
        pga = " / ".join(f"{x:.3f}" for x in item["pga_g"])
        flaws = item["flaws"]
        lines.append(f"{item['name']:<9} {item['file']:<13} {'yes':<7} {pga:<22} {expected:<15} "
                     f"{item['duration_s']:>7.2f} s  {len(flaws) if flaws else '-'}")
        for flaw in flaws:
            lines.append(f"{'':<11}flaw ({flaw['kind'].replace('_', ' ')}{', known' if flaw['known'] else ''}): "
                         f"{flaw['message']}")
    return "\n".join(lines)


# --------------------------------------------------------------------------- show
def _load(args: argparse.Namespace):
    """The record to show: :func:`records.resolve.resolve_record`, as for ``sbib run``, so a
    file honours ``--orientation`` too (column 1 on x for FN-x, swapped for FP-x)."""

    return resolve_record(args.name, args.orientation, synthetic=args.synthetic, seed=args.seed,
                          **record_kwargs(args))


def _show(args: argparse.Namespace) -> int:
    if not 0 <= args.damping < 1:
        raise InputError(f"--damping {args.damping}; expected 0 <= damping < 1")
    record = _load(args)
    spectrum = response_spectrum(record, damping=args.damping)
    summary = record.summary()
    summary["significant_duration_s"] = [significant_duration(record.acceleration[:, c], record.dt)
                                         for c in range(record.n_components)]
    summary["mean_period_s"] = [_mean_period_or_none(record.acceleration[:, c], record.dt)
                                for c in range(record.n_components)]
    summary["spectral_peak_period_s"] = [spectrum.peak_period(c) for c in range(record.n_components)]
    summary["peak_psa_g"] = [float(x) for x in spectrum.psa.max(axis=0) / 9.80665]
    flaws = record.metadata.get("flaws")
    if flaws is None:
        flaws = [f.message for f in check_record(record)]
    summary["flaws"] = list(flaws)
    for key in ("event", "station", "orientation", "x_file_column", "baseline_correction", "units_in_file",
                "recorded_comparison", "columns", "source_files"):
        if key in record.metadata:
            summary[key] = record.metadata[key]
    if args.plot:
        summary["plot"] = str(plot_record(record, args.plot, spectrum=spectrum))
    if args.json:
        print(json.dumps(summary, indent=2))
        return 0
    print(_format_summary(summary))
    return 0


def _or_dash(value: float | None, width: int, digits: int) -> str:
    return f"{'-':>{width}}" if value is None else f"{value:>{width}.{digits}f}"


def _mean_period_or_none(acceleration, dt: float) -> float | None:
    """The mean period, or None for a record without content in its band (zero, or very short)."""

    try:
        return mean_period(acceleration, dt)
    except InputError:
        return None


def _format_summary(s: dict[str, Any]) -> str:
    head = ("SYNTHETIC " if s["synthetic"] else "") + s["name"]
    extra = [str(s[k]) for k in ("event", "station") if s.get(k)]
    if s.get("orientation"):
        column = s.get("x_file_column", 1)
        where = f"x = file column {column}" if column is not None else "its one component on y"
        if s.get("source_files"):  # a pair of one-component files: x is a file, not a column
            where = f"x = {Path(s['source_files'][column - 1]).name}"
        extra.append(f"orientation {s['orientation']} ({where})")
    lines = [head + (" — " + "; ".join(extra) if extra else ""), f"source: {s['source']}"]
    lines.append(f"dt {s['dt_s']:g} s, {s['n_samples']} samples, duration {s['duration_s']:.3f} s"
                 + (f"; {s['baseline_correction']}" if s.get("baseline_correction") else ""))
    lines.append(f"units: values read as {s['units_assumed']}; shown below in g, m/s², cm/s and cm")
    if s.get("columns"):
        lines.append(f"columns: {s['columns']}")
    axis = ["x: ", "y: "] if s["n_samples"] and len(s["labels"]) == 2 else [""] * len(s["labels"])
    lines.append(f"{'component':<28} {'PGA [g]':>8} {'PGA [m/s²]':>11} {'PGV [cm/s]':>11} {'PGD [cm]':>9} "
                 f"{'D5-95 [s]':>10} {'Tm [s]':>7} {'PSA peak [g] at T [s]':>22}")
    for c, label in enumerate(s["labels"]):
        prefix = axis[c] if c < len(axis) else ""
        lines.append(f"{(prefix + label)[:28]:<28} {s['pga_g'][c]:>8.3f} {s['pga_m_s2'][c]:>11.3f} "
                     f"{100 * s['pgv_m_s'][c]:>11.1f} {100 * s['pgd_m'][c]:>9.1f} "
                     f"{s['significant_duration_s'][c]:>10.2f} {_or_dash(s['mean_period_s'][c], 7, 3)} "
                     f"{s['peak_psa_g'][c]:>13.3f} at {s['spectral_peak_period_s'][c]:.2f}")
    if s.get("recorded_comparison"):
        lines.append(_format_recorded_comparison(s["recorded_comparison"]))
    if s["flaws"]:
        lines.extend(f"flaw: {f}" for f in s["flaws"])
    else:
        lines.append("flaws: none found")
    if s.get("plot"):
        lines.append(f"plot written: {s['plot']}")
    return "\n".join(lines)


def _format_recorded_comparison(c: dict[str, Any]) -> str:
    """One line: the synthetic record's PGV and PGD against the recorded motion it imitates."""
    def pair(values, scale, digits=0):
        return " / ".join(f"{scale * v:.{digits}f}" for v in values)
    return (f"against the recorded {c['like']} (x / y): PGA matched; PGV {pair(c['pgv_m_s'], 100)} cm/s vs "
            f"{pair(c['recorded_pgv_m_s'], 100)} cm/s, PGD {pair(c['pgd_m'], 100)} cm vs "
            f"{pair(c['recorded_pgd_m'], 100)} cm (recorded PGD after baseline correction); {c['note']}")


# --------------------------------------------------------------------------- generate
def _generate(args: argparse.Namespace) -> int:
    record = benchmark_like(args.name, args.orientation, seed=args.seed)
    path = write_csv(record, args.out)
    print(f"SYNTHETIC record {record.name} ({record.source}) written to {path}")
    print(_format_recorded_comparison(record.metadata["recorded_comparison"]))
    if args.plot:
        print(f"plot written: {plot_record(record, args.plot)}")
    return 0


# --------------------------------------------------------------------------- resample
def _resample(args: argparse.Namespace) -> int:
    if not (math.isfinite(args.step) and args.step > 0):
        raise InputError(f"--step {args.step!r}: expected a positive time step in s, e.g. 0.005")
    if not MIN_DT_S <= args.step <= MAX_DT_S:
        # the plausible steps of a strong-motion record (records.plausibility): 1e-7 s wrote 3e8
        # rows for minutes; 5 s kept 6 samples of kobe
        raise InputError(f"--step {args.step:g}: expected a time step in s between {MIN_DT_S:g} and {MAX_DT_S:g} "
                         "(what accelerographs sample at), e.g. 0.005")
    out = Path(args.out).expanduser()
    if looks_like_file(args.name) and Path(args.name).expanduser().resolve() == out.resolve():
        raise InputError(f"--out {args.out}: is the input record itself; give another file")
    if args.out_units is not None:
        unit_factor(args.out_units, "--out-units")  # an unknown unit: one line before any work
    # the source's own components, in its own order (a file is not oriented)
    record = resolve_record(args.name, "FN-x", **record_kwargs(args))
    if looks_like_file(args.name) and record.metadata.get("y_file_column") is None:
        record = record.select([0])  # a one-component file: its component only, not the zero y
    units = args.out_units or str(record.metadata.get("units_in_file") or "m/s2")
    new = resample(record, args.step)
    how = new.metadata.get("resampled", f"not resampled: the record's step is already {record.dt:g} s")
    prov = provenance()
    comments = [f"resampled by sbib records resample: {how}",
                f"original: {record.n_samples} samples at {record.dt:g} s, values read as "
                f"{record.metadata.get('units_assumed', 'm/s2')}",
                "provenance: " + "; ".join(f"{k}={prov[k]}" for k in ("package", "package_version", "git_commit",
                                                                     "created_utc", "numpy", "scipy"))]
    path = write_csv(new, out, units=units, comments=comments)
    print(f"{record.name}: {record.n_samples} samples at {record.dt:g} s -> {new.n_samples} samples at "
          f"{new.dt:g} s ({how}); written to {path} in {units}")
    return 0
