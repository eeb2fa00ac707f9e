"""``results/report.html`` (issue #16, item 15): tables, captioned figures linking to their data,
offline, and rendered by a real headless browser (Debian's ``chromium``)."""

from __future__ import annotations

import html

import json
import re
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import pytest

from benchmark.foundation.errors import InputError
from benchmark.applications.report import REPORT_NAME, build_report_html, write_report


@pytest.fixture(scope="module")
def small_results(tmp_path_factory, shared_dir, records_dir):
    """A small results directory written by the study's own steps, in seconds, not the full study:
    one record and two controllers, a three-voltage identification without validation, the
    virtual damper's residual loop and the record catalogue."""
    from benchmark.applications.study import _diagnosis
    from benchmark.applications.comparison import compare
    from benchmark.applications.identification_study import run_identify_study
    from damper.identification.voltage_grid import TestProtocol
    from records.report import write_records_report

    out = tmp_path_factory.mktemp("results")
    suite = out / "suite"
    suite.mkdir()
    result = compare(records=("kobe",), orientations="FN-x", controllers=("passive-off", "clipped-optimal"),
                     records_dir=str(records_dir), jobs=1, progress=False)
    result.write_hdf5(suite / "comparison.h5")
    result.plot(suite / "plots")
    (suite / "comparison.json").write_text(json.dumps(result.to_json(), default=str))
    (suite / "table.txt").write_text(result.table() + "\n")
    run_identify_study(out / "identification", voltages=(0.0, 0.5, 1.0),
                       protocol=TestProtocol(amplitude=0.1, frequency=0.5, cycles=3.0, sample_rate=200.0),
                       validate=False, compare_free_kappa_x=False, ceiling=False, progress=False, jobs=1)
    _diagnosis(out / "diagnosis", quick=True)
    write_records_report(out / "records", records_dir=records_dir, per_record_plots=False)
    write_report(out)
    return out


class _Collector(HTMLParser):
    def __init__(self):
        super().__init__()
        self.links, self.images, self.scripts, self.styles_external, self.tables = [], [], 0, [], 0
        self.captions, self._in_caption = [], False

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "a" and a.get("href") and not a["href"].startswith("#"):
            self.links.append(a["href"])
        elif tag == "img":
            self.images.append(a.get("src", ""))
        elif tag == "script":
            self.scripts += 1
        elif tag == "link":
            self.styles_external.append(a.get("href", ""))
        elif tag == "table":
            self.tables += 1
        elif tag == "figcaption":
            self._in_caption = True
            self.captions.append("")

    def handle_endtag(self, tag):
        if tag == "figcaption":
            self._in_caption = False

    def handle_data(self, data):
        if self._in_caption:
            self.captions[-1] += data


def _parse(path: Path) -> _Collector:
    c = _Collector()
    c.feed(path.read_text(encoding="utf-8"))
    return c


def test_report_has_the_tables_and_captioned_figures_linking_to_data(small_results):
    page = small_results / REPORT_NAME
    text = page.read_text(encoding="utf-8")
    c = _parse(page)
    # the J's per controller, with the key to J1-J9
    assert "passive-off" in text and "clipped-optimal" in text
    from benchmark.simulator.criteria import CRITERIA

    assert "J6" in text and html.escape(CRITERIA["J6"].description) in text
    # identification errors and the diagnosis before/after
    assert "Identification errors" in text and "fit error" in text
    assert "error before" in text and "error after" in text and "stiffness" in text
    assert c.tables >= 4
    # every figure has a caption that links to a data file (not only to the image)
    assert len(c.images) >= 5 and len(c.captions) == len(c.images)
    assert all("data:" in cap for cap in c.captions)
    for target in ("suite/comparison.json", "identification/parameters.csv", "diagnosis/virtual/diagnosis.json",
                   "records/catalogue.json"):
        assert target in c.links


def test_report_is_offline_and_every_link_resolves_inside_the_folder(small_results):
    page = small_results / REPORT_NAME
    c = _parse(page)
    assert c.scripts == 0 and c.styles_external == []
    text = page.read_text(encoding="utf-8")
    assert not re.search(r"""(src|href)\s*=\s*["'](https?:|//)""", text), "no CDN or remote resource"
    for ref in c.links + c.images:
        assert not Path(ref).is_absolute() and ".." not in Path(ref).parts, ref
        assert (small_results / ref).is_file(), f"report links to a missing file {ref}"


def test_report_survives_a_partial_results_directory(tmp_path, small_results):
    shutil.copytree(small_results / "suite", tmp_path / "suite")
    html = build_report_html(tmp_path)
    assert "clipped-optimal" in html
    assert html.count("not in this results directory") == 3      # identification, diagnosis, records
    with pytest.raises(InputError, match="does not exist"):
        write_report(tmp_path / "nowhere")
    with pytest.raises(InputError, match="directly inside"):
        write_report(tmp_path, tmp_path / "sub" / "report.html")


def test_study_writes_the_report(monkeypatch, tmp_path):
    """``sbib study`` ends by writing report.html (the steps themselves stubbed: they are tested
    elsewhere, and the slow test runs the real quick study)."""
    import benchmark.applications.study as study

    def no_records(folder, **_):
        return {"output": str(folder)}

    monkeypatch.setattr("records.report.write_records_report", no_records)
    monkeypatch.setattr(study, "write_records_report", no_records, raising=False)   # if imported at module level
    monkeypatch.setattr(study, "_suite", lambda folder, *a: ({"output": str(folder)}, []))
    monkeypatch.setattr(study, "_identification", lambda folder, *a: {"output": str(folder)})
    monkeypatch.setattr(study, "_diagnosis", lambda folder, *a: {"output": str(folder)})
    summary = study.run_study(tmp_path / "results", quick=True)
    assert summary["report"] == str(tmp_path / "results" / REPORT_NAME)
    assert (tmp_path / "results" / REPORT_NAME).is_file()
    assert json.loads((tmp_path / "results" / "summary.json").read_text())["report"] == summary["report"]


def _chromium() -> str:
    for name in ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable"):
        path = shutil.which(name)
        if path:
            return path
    pytest.skip("no headless browser: install Debian's chromium (apt-get install -y chromium; "
                ".ci/run does it when apt is available) to render report.html")


def test_report_renders_in_headless_chromium(small_results, tmp_path):
    browser = _chromium()
    url = (small_results / REPORT_NAME).resolve().as_uri()
    flags = ["--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars", "--no-first-run",
             f"--user-data-dir={tmp_path / 'profile'}"]
    dom = subprocess.run([browser, *flags, "--dump-dom", url], capture_output=True, text=True, timeout=180)
    assert dom.returncode == 0, dom.stderr[-2000:]
    assert "Controllers: evaluation criteria J1–J9" in dom.stdout
    assert dom.stdout.count("<img") >= 5 and dom.stdout.count("<table") >= 4
    shot = tmp_path / "report.png"
    run = subprocess.run([browser, *flags, "--window-size=1280,2400", f"--screenshot={shot}", url],
                         capture_output=True, text=True, timeout=180)
    assert run.returncode == 0 and shot.is_file(), run.stderr[-2000:]
    from PIL import Image
    import numpy as np

    pixels = np.asarray(Image.open(shot).convert("L"), dtype=float)
    assert pixels.shape == (2400, 1280)
    # a rendered page, not a blank one: text and figures make the image far from uniform
    assert pixels.std() > 20.0 and (pixels < 128).mean() > 0.01


def test_report_tolerates_malformed_result_files(tmp_path):
    (tmp_path / "suite").mkdir()
    (tmp_path / "suite" / "comparison.json").write_bytes(b"\x89PNG not json")
    (tmp_path / "identification").mkdir()
    (tmp_path / "identification" / "parameters.csv").write_text(
        "model,voltage,kappa_x,kappa_xdot,kappa_w,rho,sigma,n,rel_rms_error\nnormalized,0,abc,1e3,,1,1,1,0.1\n")
    path = write_report(tmp_path)
    text = path.read_text(encoding="utf-8")
    assert "unreadable" in text and "normalized" in text and "–" in text
