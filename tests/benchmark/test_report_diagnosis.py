"""The report page's diagnosis section (issue 24: "the report page shows the real-data diagnosis"):
per case the force window and the residual trace, the screening findings of each measured file,
and a loop cut short by its time budget said so."""

from __future__ import annotations

import json

from benchmark.applications.report import build_report_html

_PNG = bytes.fromhex("89504e470d0a1a0a0000000d49484452000000010000000108060000001f15c489"
                     "0000000d49444154789c63000100000500010d0a2db40000000049454e44ae426082")


def _case(root, name, doc):
    folder = root / "diagnosis" / name
    folder.mkdir(parents=True)
    (folder / "diagnosis.json").write_text(json.dumps(doc))
    for image in ("force_window.png", "residual_trace.png", "loops.png"):
        (folder / image).write_bytes(_PNG)


def test_measured_cases_show_window_trace_and_screening(tmp_path):
    base = {"model": "spencer", "error_before": 0.111, "error_after": 0.099,
            "effects": [{"name": "shear_thinning"}, {"name": "inertia"}], "unexplained_in": []}
    finding = {"kind": "clipped", "channel": "force", "t_start": 19.85, "t_end": 19.88, "n_samples": 87,
               "message": "force at its clipping level 4545.45", "excluded": True}
    second = {**finding, "t_start": 19.59, "t_end": 19.62, "n_samples": 102}
    idle = {"kind": "idle", "channel": "displacement", "t_start": 2.0, "t_end": 4.0, "n_samples": 400,
            "message": "no motion", "excluded": False}
    _case(tmp_path, "dyke", {**base, "settings": {"seconds": 41.5, "stopped_by_budget": True, "time_budget": 20,
                                                   "decimation": 14},
                             "screening": {"ransim_u_converted.csv": {
                                 "n_samples": 60096, "n_excluded": 1469, "findings": [finding, idle, second],
                                 "estimates": {"force_velocity_lag_s": 0.0021}, "kept_flagged": False}}})
    _case(tmp_path, "utfsm_1A", {**base, "model": "normalized", "settings": {"seconds": 20.0},
                                 "screening": {"10mm1Hz1A.txt": {"n_samples": 3000, "n_excluded": 0,
                                                                 "findings": [], "estimates": {}}}})
    _case(tmp_path, "virtual", {**base, "model": "normalized", "settings": {"seconds": 1.0}})
    page = build_report_html(tmp_path)
    section = page[page.index('id="diagnosis"'):page.index('id="records"')]
    # the virtual damper first, then the measured ones
    assert section.index("diagnosis/virtual/") < section.index("diagnosis/utfsm_1A/") < section.index("diagnosis/dyke/")
    for case in ("virtual", "utfsm_1A", "dyke"):
        for image in ("force_window.png", "residual_trace.png"):
            assert f'src="diagnosis/{case}/{image}"' in section
    # the screening: what, where, how many, excluded; a clean file says so; the estimated lag
    # one line per kind and channel: how many spans, where, how many samples in all
    assert "<b>clipped</b> (force) 2 spans in 19.590–19.880 s, 189 samples [excluded]" in section
    assert "<b>idle</b> (displacement) at 2.000–4.000 s, 400 samples [reported only]" in section
    assert section.index("<b>idle</b>") < section.index("<b>clipped</b>")      # in time order
    assert "1469" in section and "2.1 ms" in section
    assert "10mm1Hz1A.txt" in section and "nothing found" in section
    # the budget that cut the Dyke loop short is said, the others are not
    assert section.count("cut short") == 1 and "ended the effect selection" in section
    assert "one sample in 14" in section


def test_without_the_dyke_case_the_page_says_how_to_add_it(tmp_path):
    _case(tmp_path, "virtual", {"model": "normalized", "error_before": 0.12, "error_after": 0.01,
                                "effects": [{"name": "stiffness"}], "settings": {"seconds": 1.0}})
    section = build_report_html(tmp_path)
    assert "sbib study --dyke" in section and "cut short" not in section


def test_a_mains_line_and_a_dropped_effect_are_said_on_the_page(tmp_path):
    """The fitted-model checks of diagnosis.json (damper/diagnosis/interference.py and the loop's
    full-rate rescoring) reach the page as notes; a case without them shows none."""
    base = {"model": "normalized", "error_before": 0.145, "error_after": 0.078,
            "effects": [{"name": "roll_off"}], "unexplained_in": []}
    line = {"test": "10mm1Hz1A", "frequency_hz": 50.001, "amplitude_n": 40.06, "share": 0.2, "ratio": 1100.0,
            "in_motion": False}
    _case(tmp_path, "utfsm_1A", {**base, "settings": {"seconds": 9.0, "dropped_at_full_rate": ["fade"]},
                                 "interference": {"lines": [line], "searched": ["10mm1Hz1A", "5mm3Hz1A"], "tests": 2,
                                                  "error": 0.078, "error_without": 0.0742,
                                                  "error_without_by_frequency": {"50": 0.0741}}})
    _case(tmp_path, "virtual", {**base, "settings": {"seconds": 1.0},
                                "interference": {"lines": [], "searched": ["a"], "tests": 1, "error": 0.01,
                                                 "error_without": 0.01, "error_without_by_frequency": {}}})
    page = build_report_html(tmp_path)
    section = page[page.index('id="diagnosis"'):page.index('id="records"')]
    utfsm = section[section.index('id="diagnosis-utfsm_1A"'):]
    assert "50-Hz line in 1 of 2 test(s) searched (10mm1Hz1A)" in utfsm
    assert "0.0780 -&gt; 0.0741 without it" in utfsm       # the frequency's own figure, read back from JSON
    assert "Left out: fade" in utfsm
    virtual = section[section.index('id="diagnosis-virtual"'):section.index('id="diagnosis-utfsm_1A"')]
    assert "Hz line" not in virtual and "Left out" not in virtual
