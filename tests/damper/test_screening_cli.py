"""``sbib diagnose`` reports the screening (issue 24 item 1): findings in the text output and
under ``screening`` in the JSON and report; flagged samples left out of the fit and the error
unless ``--keep-flagged``."""

from __future__ import annotations

import json

import numpy as np

from benchmark.applications.cli import main
from damper.diagnosis.augmented import AugmentedModel
from damper.models.bouc_wen import NormalizedBoucWen
from damper.io.data import write_csv
from damper.diagnosis.synthetic import sinusoidal_tests
from damper.io.screening import screen

BASE = NormalizedBoucWen(2000.0, 800.0, 400.0, 1.0, 1.5)


def _files(tmp_path):
    tests = sinusoidal_tests(AugmentedModel(BASE, ()), noise=0.01, seed=4)
    for t in tests:  # the loop's clean synthetic tests: no finding (false-positive check)
        assert screen(t).clean, screen(t).lines()
    files = [str(write_csv(t, tmp_path / f"t{i}.csv")) for i, t in enumerate(tests)]
    # the last test's load cell saturates near its end, in the held-out part
    last = tests[-1]
    f = last.force.copy()
    n = f.size
    span = slice(int(0.85 * n), int(0.95 * n))
    f[span] = 5.0 * np.abs(f).max()
    bad = tmp_path / "saturated.csv"
    write_csv(type(last)(last.time, last.displacement, last.velocity, f, voltage=last.voltage,
                         name="saturated"), bad)
    return files[:-1] + [str(bad)], span


def test_diagnose_reports_screening_and_excludes_flagged(tmp_path, capsys):
    files, span = _files(tmp_path)
    args = ["diagnose", "--data", *files, "--effects", "offset", "--quiet", "--coarse-samples", "0"]
    assert main(args + ["--json", "--out", str(tmp_path / "rep")]) == 0
    doc = json.loads(capsys.readouterr().out)
    scr = doc["screening"]
    assert set(scr) == {f.rsplit("/", 1)[-1] for f in files}
    assert all(not scr[k]["findings"] for k in scr if k != "saturated.csv")
    kinds = {(f["kind"], f["channel"]) for f in scr["saturated.csv"]["findings"]}
    assert ("stuck", "force") in kinds or ("clipped", "force") in kinds
    assert scr["saturated.csv"]["n_excluded"] >= span.stop - span.start - 1
    assert json.loads((tmp_path / "rep" / "diagnosis.json").read_text())["screening"] == scr
    assert "## Screening of the data" in (tmp_path / "rep" / "report.md").read_text()
    # --keep-flagged: the saturated span is fitted and scored
    assert main(args + ["--json", "--keep-flagged"]) == 0
    kept = json.loads(capsys.readouterr().out)
    assert kept["screening"]["saturated.csv"]["kept_flagged"] is True
    assert kept["error_before"] > 3 * doc["error_before"]
    # the text output prints the findings
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "screening saturated.csv: " in out and "excluded from fit and error" in out
    assert "screening t0.csv: nothing found" in out
    assert "screening saturated.csv: estimated force lags the motion's velocity by" in out
