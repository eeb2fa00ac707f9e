"""The records step of the main job: catalogue check and figures of the records found (or of synthetic ones).

Writes into one directory:

* ``catalogue.json``: :func:`records.check_catalogue` (found or missing, PGAs, durations,
  flaws), plus which records the figures show and whether they are synthetic;
* ``<name>.png``: time histories and 5 %-damped spectra of each record (orientation FN-x);
* ``spectra.png``: all records' pseudo-acceleration spectra, x and y.

When no benchmark file is found, the figures show the synthetic benchmark-like records
(:func:`records.synthetic.benchmark_like`, seed 0) and every title and the JSON say so.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path
from typing import Any

from benchmark.foundation.atomic import atomic_write_text
from records.catalogue import BENCHMARK_RECORDS, check_catalogue, load_benchmark_record
from records.plots import plot_record, plot_spectra_overview
from records.synthetic import benchmark_like

__all__ = ["write_records_report"]


def write_records_report(out_dir: str | os.PathLike, records_dir: str | os.PathLike | None = None,
                         per_record_plots: bool = True, seed: int = 0) -> dict[str, Any]:
    """Check the catalogue and draw the records; return a small summary (also in ``catalogue.json``).

    Parameters
    ----------
    out_dir : path-like
        Output directory (created).
    records_dir : path-like, optional
        Directory of the benchmark files (default lookup of :func:`benchmark.foundation.paths.records_dir`).
    per_record_plots : bool
        Draw one figure per record (about half a second each) besides the spectra overview.
    seed : int
        Seed of the synthetic records used when no file is found.

    Returns
    -------
    dict
        ``records_dir``, ``n_found``, ``synthetic`` (bool), ``plotted`` (names), ``flaws`` (count
        per record), ``files`` (paths written), ``elapsed_s``.
    """
    t0 = time.perf_counter()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    report = check_catalogue(records_dir)
    found = [item["name"] for item in report["records"] if item["found"] and "error" not in item]
    synthetic = not found
    if synthetic:
        recs = [benchmark_like(name, "FN-x", seed=seed) for name in BENCHMARK_RECORDS]
    else:
        recs = [load_benchmark_record(name, "FN-x", records_dir=report["records_dir"]) for name in found]
    files = []
    if per_record_plots:
        files += [str(plot_record(rec, out / f"{rec.name}.png")) for rec in recs]
    files.append(str(plot_spectra_overview(
        recs, out / "spectra.png",
        title=("SYNTHETIC benchmark-like records (no record files found), FN-x" if synthetic
               else "benchmark records, FN-x (column 1 on x)"))))
    report["figures"] = {"synthetic": synthetic, "records": [r.name for r in recs], "orientation": "FN-x",
                         "files": files}
    catalogue_json = out / "catalogue.json"
    atomic_write_text(catalogue_json, json.dumps(report, indent=2))
    return {
        "records_dir": report["records_dir"],
        "n_found": report["n_found"],
        "synthetic": synthetic,
        "plotted": [r.name for r in recs],
        "flaws": {item["name"]: len(item.get("flaws", [])) for item in report["records"] if item["found"]},
        "files": [str(catalogue_json)] + files,
        "elapsed_s": time.perf_counter() - t0,
    }
