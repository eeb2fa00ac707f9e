"""The benchmark harness (benchmark.applications.speed): table, fits, helpers and the report files.
Correctness only; no timing is ever asserted."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from benchmark.applications import speed
from benchmark.foundation.errors import InputError
from benchmark.applications.speed import BenchCase, format_table, run_bench, time_call


def test_time_call_counts_calls_and_returns_minimum():
    calls = []
    best, times, result, cpu_best, cpu_times = time_call(lambda: calls.append(1) or len(calls), repeat=4, warmup=2)
    assert len(calls) == 6 and result == 6 and len(times) == 4 and len(cpu_times) == 4
    assert best == min(times) and best >= 0 and cpu_best == min(cpu_times)


def test_linear_fit_is_exact_on_linear_data():
    x = np.array([1.0, 2.0, 4.0, 8.0])
    fit = speed._fit_linear(x, 0.01 + 0.002 * x)
    assert fit["intercept_s"] == pytest.approx(0.01) and fit["slope"] == pytest.approx(0.002)
    assert fit["max_relative_deviation"] < 1e-12
    bent = speed._fit_linear(x, 0.01 + 0.002 * x ** 2)
    assert bent["max_relative_deviation"] > 0.05


def test_table_shows_every_column_and_misses():
    cases = [BenchCase("single-run", project_s=0.042, target="<= 0.050 s", met=True, note="n"),
             BenchCase("vs-solve_ivp", project_s=0.042, reference_s=8.4, ratio=200.0,
                       max_relative_difference=0.0012, target=">= 100x", met=True),
             BenchCase("suite-warm", project_s=7.5, target="<= 5 s", met=False),
             BenchCase("identify-warm", note="not measured: missing")]
    text = format_table(cases)
    assert "42.0 ms" in text and "8.40 s" in text and "200x" in text and "0.120 %" in text
    assert "7.50 s" in text and " NO" in text and "not measured: missing" in text
    assert len(text.splitlines()) == 2 + 4 + 2  # header, rule, 4 rows, 2 notes


def test_run_bench_without_sections_writes_machine_and_rejects_unknown(tmp_path):
    report = run_bench(tmp_path, sections=(), echo=None)
    data = json.loads((tmp_path / "bench.json").read_text())
    assert data["machine"]["cores"] >= 1 and data["cases"] == [] and "git_commit" in data["provenance"]
    assert report["machine"] == data["machine"]
    with pytest.raises(InputError, match="sections"):
        run_bench(tmp_path, sections=("warp",), echo=None)


def test_failing_case_is_reported_not_raised(tmp_path, monkeypatch):
    def broken(**_):
        raise RuntimeError("kernel exploded")

    monkeypatch.setattr(speed, "bench_single_run", broken)
    report = run_bench(tmp_path, sections=("single",), echo=None)
    assert report["cases"][0]["note"].startswith("not measured: RuntimeError: kernel exploded")
    assert report["cases"][0]["met"] is None


def test_scaling_plot_is_written(tmp_path):
    tables = {name: {"x": [1, 2, 4], "time_s": [0.01, 0.02, 0.04], "x_label": name,
                     "fit": speed._fit_linear(np.array([1.0, 2, 4]), np.array([0.01, 0.02, 0.04]))}
              for name in ("record_length", "devices", "modes", "ensemble_size")}
    path = speed.plot_scaling(tables, tmp_path / "s.png")
    assert path.is_file() and path.stat().st_size > 10_000


def test_cli_bench_registered(capsys):
    from benchmark.applications.cli import main

    with pytest.raises(SystemExit):
        main(["bench", "--help"])
    assert "--quick" in capsys.readouterr().out
    assert main(["bench", "--only", "nothing", "--out", "/tmp/unused-bench"]) == 2


def test_building_with_n_devices_and_lengthened_record(shared_dir):
    b5 = speed._building(n_devices=5)
    assert b5.n_devices == 5
    assert list(b5.devices.directions) == [0, 1, 0, 1, 0]
    b40 = speed._building(n_devices=40)
    assert b40.n_devices == 40 and len({s.label for s in b40.devices.slots}) == 40
    r = speed._record(100.0)
    assert r.acceleration.shape[0] == int(round(100.0 / r.dt))
    s = speed._stationary_record(12.0, window=5.0)
    n_window = int(round(5.0 / s.dt))
    assert s.acceleration.shape[0] == int(round(12.0 / s.dt))
    assert np.array_equal(s.acceleration[:n_window], s.acceleration[n_window:2 * n_window])
    whole = speed._record(None).acceleration
    assert np.abs(s.acceleration).max() == np.abs(whole).max()  # the window holds the peak


@pytest.mark.slow
def test_second_process_does_not_recompile():
    script = ("import json; from benchmark.applications import speed; "
              "speed._simulate(speed._building(), speed._record(0.5)); "
              "print('COUNTS', json.dumps(speed.compile_counts()))")
    counts = []
    for _ in range(2):
        out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=900)
        assert out.returncode == 0, out.stderr[-2000:]
        line = [l for l in out.stdout.splitlines() if l.startswith("COUNTS")][0]
        counts.append(json.loads(line.split(" ", 1)[1]))
    assert counts[1]["compilations"] == 0, counts[1]["compiled"]
    assert counts[1]["cache_loads"] > 0


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="VmHWM is Linux's")
def test_a_script_reports_its_own_peak_memory_not_its_launchers():
    """ru_maxrss survives exec: a bench script launched by a large process would report the
    launcher's peak. The bench reads VmHWM instead."""
    ballast = np.ones(450 * 2**20 // 8)  # 450 MB resident in this (launching) process
    code = ("import resource\n"
            "from benchmark.applications.speed import own_peak_rss_kb\n"
            "print(own_peak_rss_kb() / 1024, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    own, inherited = (float(v) for v in out.stdout.split())
    assert ballast.sum() > 0
    assert own < 400.0  # the script's own imports, well below the launcher's 450 MB
    assert own <= inherited
