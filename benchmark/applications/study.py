"""The main job (``sbib study``, run by ``make run``): everything the project does, end to end.

It writes into one output directory: the record catalogue check, the benchmark suite
under several controllers, the identification report and the diagnosis of measured
data, each step calling the public Python API, and ``report.html``, one page with the
tables and key figures (:mod:`benchmark.applications.report`). Steps whose inputs are absent (e.g. no
record files) fall back to the synthetic benchmark-like records and say so.

The diagnosis (the residual loop) runs on the virtual damper and on the measured UTFSM tests at
1 A; with ``dyke=True`` (``sbib study --dyke``) on the shared Dyke recording too. Each measured
case's folder holds the screening of its files (``diagnosis.json``, ``report.md``) and the
force-window figure the report page shows.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

try:  # CPU time of this process and its ended children (Unix)
    import resource
except ImportError:  # pragma: no cover - Windows: this process only
    resource = None  # type: ignore[assignment]

from benchmark.foundation.atomic import atomic_write_text
from benchmark.foundation.errors import DataNotFoundError
from benchmark.foundation.beside import run_beside
from benchmark.foundation.pools import stop_pool
from records.report import write_records_report
from benchmark.applications.comparison import compare
from benchmark.applications.identification_study import run_identify_study
from benchmark.foundation.pools import make_side_executor
from damper.diagnosis import diagnose
from damper.diagnosis.report import write_report as write_diagnosis_report
from damper.lab.laboratory import periodic_test
from benchmark.foundation.paths import shared_dir
from damper.io.data import read_utfsm, utfsm_files
from damper.io.dyke import read_dyke
from benchmark.foundation.paths import records_dir as _records_dir
from benchmark.foundation.progress import progress_lines
from benchmark.applications.report import REPORT_NAME, write_report

__all__ = ["run_study"]


def run_study(out: str | Path, records_dir: str | None = None, quick: bool = False,
              dyke: bool = False) -> dict:
    """Run the main job and return its summary (also written to ``out/summary.json``).

    Parameters
    ----------
    out : path-like
        Output directory (created).
    records_dir : str, optional
        Directory of the benchmark's record files; synthetic records are used if absent.
    quick : bool
        Fewer records and controllers (for smoke tests).
    dyke : bool
        Also run the residual loop on the shared Dyke recording (``sbib study --dyke``; about
        32 s more of one core, :data:`DYKE_TIME_BUDGET`), written to ``out/diagnosis/dyke``.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    summary: dict = {"steps": {}}
    t0 = time.perf_counter()
    cpu0 = _cpu_s()

    # The residual loop (on the virtual damper and, when present, on the measured UTFSM tests)
    # needs one core and nothing of the steps below: it starts first, in a process of its own,
    # and fills the core the records step leaves idle, then shares the machine with the suite's
    # and the identification's workers (main job 56.0 -> 52.6 s, 2026-11-25: near its CPU bound of
    # about 100 CPU-s on two cores).
    side = make_side_executor()
    diagnosis = side.submit(_timed_diagnosis, out / "diagnosis", quick, dyke) if side is not None else None
    try:
        cpu_mark = _steps(summary, out, records_dir, quick, dyke, diagnosis)
    except BaseException:  # Ctrl-C or a failed step: stop the side worker now
        stop_pool(side)
        raise
    finally:
        if side is not None:
            side.shutdown(cancel_futures=True)
    # the workers' CPU counts once they have ended: the diagnosis's process is in this figure
    summary["steps"]["identification"]["cpu_s_with_diagnosis"] = _cpu_s() - cpu_mark

    summary["elapsed_s"] = time.perf_counter() - t0
    summary["cpu_s"] = _cpu_s() - cpu0
    # one page to open first: tables and key figures, each linking to its data (benchmark/applications/report.py)
    summary["report"] = str(out / REPORT_NAME)
    atomic_write_text(out / "summary.json", json.dumps(summary, indent=2, default=str))
    write_report(out)
    return summary


def _steps(summary: dict, out: Path, records_dir: str | None, quick: bool, dyke: bool, diagnosis) -> float:
    """The main job's steps, the diagnosis started beside them (:func:`run_study`); returns the
    CPU-time mark at the identification's start."""
    cpu = _cpu_s()
    # records: catalogue check and figures (synthetic benchmark-like records if no file is found)

    summary["steps"]["records"] = write_records_report(out / "records", records_dir=records_dir,
                                                       per_record_plots=not quick)
    summary["steps"]["records"].setdefault("output", str(out / "records"))
    summary["steps"]["records"]["cpu_s"], cpu = _cpu_s() - cpu, _cpu_s()

    synthetic = summary["steps"]["records"].get("synthetic", False) if isinstance(
        summary["steps"]["records"], dict) else False
    if records_dir is None and not synthetic:
        try:
            records_dir = str(_records_dir())
        except Exception:  # noqa: BLE001 - any lookup failure means: use the synthetic set
            synthetic = True

    # benchmark suite: every record x orientation under several controllers (J1-J9)
    step = time.perf_counter()
    summary["steps"]["suite"], measured = _suite(out / "suite", records_dir, synthetic, quick)
    summary["steps"]["suite"]["elapsed_s"] = time.perf_counter() - step
    summary["steps"]["suite"]["cpu_s"], cpu = _cpu_s() - cpu, _cpu_s()

    # identification of the virtual benchmark damper (the seed paper's study)
    step = time.perf_counter()
    summary["steps"]["identification"] = _identification(out / "identification", records_dir,
                                                         synthetic, quick, measured)
    summary["steps"]["identification"]["elapsed_s"] = time.perf_counter() - step
    if diagnosis is not None:
        summary["steps"]["diagnosis"] = diagnosis.result()
        summary["steps"]["diagnosis"]["beside"] = "records, suite and identification"
    else:
        summary["steps"]["diagnosis"] = _timed_diagnosis(out / "diagnosis", quick, dyke)
    return cpu


#: Controllers of the main job's comparison.
STUDY_CONTROLLERS = ("passive-off", "passive-on", "clipped-optimal", "modulated", "skyhook", "lyapunov")
#: The identification study's validation controller: the suite keeps its runs in full and hands
#: them over (the same building, records and controller), so that they are not run twice.
VALIDATION_CONTROLLER = "clipped-optimal"


def _suite(folder: Path, records_dir: str | None, synthetic: bool, quick: bool) -> tuple[dict, list]:
    folder.mkdir(parents=True, exist_ok=True)
    result = compare(records=("kobe", "elcentro") if quick else "all",
                     orientations="FN-x" if quick else "both",
                     controllers=STUDY_CONTROLLERS[:3] if quick else STUDY_CONTROLLERS,
                     records_dir=records_dir, synthetic=synthetic, progress=True,
                     measure=(VALIDATION_CONTROLLER,))
    h5 = result.write_hdf5(folder / "comparison.h5")
    # The figures take ~6 s of one core while the suite's workers are done: a forked child
    # (which inherits the results) draws half of them beside this process.
    other_half = run_beside(_plot_part, result, folder / "plots", (1, 2))
    plots = _plot_part(result, folder / "plots", (0, 2)) + other_half.result()
    atomic_write_text(folder / "comparison.json", json.dumps(result.to_json(), indent=2, default=str))
    atomic_write_text(folder / "table.txt", result.table() + "\n")
    print(result.table())
    return ({"output": str(folder), "hdf5": str(h5), "plots": len(plots), "runs": len(result.runs),
             "synthetic_records": synthetic, "summary": result.summary(), "criteria": result.to_json()["criteria"]},
            list(result.measured.values()))


def _cpu_s() -> float:
    """CPU seconds of this process and of its children that have ended (workers, forked helpers)."""
    if resource is None:
        return time.process_time()
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def _plot_part(result, folder: Path, part: tuple[int, int]) -> list[str]:
    return [str(p) for p in result.plot(folder, part)]


def _identification(folder: Path, records_dir: str | None, synthetic: bool, quick: bool,
                    measured: list) -> dict:
    kwargs = {"records": ("kobe",), "orientations": ("FP-x",)} if quick else {}
    summary = run_identify_study(folder, records_dir=records_dir, synthetic=synthetic, measured=measured,
                                 controller=VALIDATION_CONTROLLER, **kwargs)
    return {"output": str(folder), "summary": summary}


def _timed_diagnosis(folder: Path, quick: bool, dyke: bool = False) -> dict:
    step = time.perf_counter()
    result = _diagnosis(folder, quick, dyke)
    result["elapsed_s"] = time.perf_counter() - step
    return result


#: The shared Dyke recording, under the shared directory (``shared/SOURCES.md``).
DYKE_RECORDING = "hysteresis_data/dyke_mr_damper_random_voltage/ransim_u_converted.csv"
#: ``sbib study --dyke``: no new round of the loop's effect selection after this many seconds
#: (issue 24's target for the whole loop on this recording); the report says when it cut the
#: loop short. The Spencer base fit alone takes about 32 s of one core (measured 2026-11-24):
#: the budget cannot shorten it, hence the option (the default main job stays within its time).
DYKE_TIME_BUDGET = 60.0


def _diagnosis(folder: Path, quick: bool, dyke: bool = False) -> dict:
    result: dict = {"output": str(folder)}
    say = progress_lines("diagnosis")
    # The seed paper's finding, systematically: the normalized model lacks a stiffness term.
    tests = [periodic_test("virtual", amplitude=0.4, frequency=0.8, voltage=0.0, cycles=4,
                           sample_rate=200.0, noise=0.01, seed=1),
             periodic_test("virtual", amplitude=0.1, frequency=1.5, voltage=0.0, cycles=4,
                           sample_rate=200.0, noise=0.01, seed=2)]
    say("virtual damper: residual loop on 2 tests (normalized Bouc-Wen base)")
    virtual = diagnose(tests, model="normalized", progress=say)
    write_diagnosis_report(virtual, folder / "virtual")
    result["virtual"] = virtual.to_json()
    if quick:
        return result
    try:
        shared = shared_dir()
    except Exception as exc:  # noqa: BLE001 - measured data are optional for the main job
        result["utfsm"] = f"skipped: {exc}"
        return result
    try:
        files = [f for f in utfsm_files(shared) if f.name.endswith("Hz1A.txt")]
    except DataNotFoundError as exc:
        files, result["utfsm_1A"] = [], f"skipped: {exc}"
    if files:
        say(f"measured UTFSM tests at 1 A: residual loop on {len(files)} tests")
        measured_tests = [read_utfsm(f) for f in files]
        measured = diagnose(measured_tests, model="normalized", progress=say)
        write_diagnosis_report(measured, folder / "utfsm_1A", tests=measured_tests)
        result["utfsm_1A"] = measured.to_json()
    if not dyke:
        return result
    path = shared / DYKE_RECORDING
    if path.is_file():
        say(f"measured Dyke recording: residual loop (Spencer base, last 30 % held out, "
            f"{DYKE_TIME_BUDGET:g} s budget)")
        recording = read_dyke(path)
        real = diagnose([recording], model="spencer", holdout=0.3, progress=say,
                        time_budget=DYKE_TIME_BUDGET)
        write_diagnosis_report(real, folder / "dyke", tests=[recording])
        result["dyke"] = real.to_json()
    else:
        result["dyke"] = f"skipped: {path} not found"
    return result
