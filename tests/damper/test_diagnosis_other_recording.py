"""Issue 24's rows on another recording of the Dyke damper (opt-in: the file is not in shared/).

``shared/`` holds one recording of the Dyke damper (``ransim_u_converted.csv``). Another
recording of the same device in the same format (for example ``ranran_50_converted.csv`` of
the data set NEES-2012-1158, published beside the shared file; docs/diagnosis.md, "Another
recording of the Dyke damper") is checked against the issue's targets when
``SBIB_DYKE_OTHER`` names it: fitted on its first 70 %, the held-out rest within 0.15, and
scored across recordings (``--validate``) within 0.20. The thresholds are the issue's, not
values measured on one file; the loop's time (60 s on one core) is measured by hand
(docs/diagnosis.md), never asserted.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from benchmark.applications.cli import main

DYKE = "hysteresis_data/dyke_mr_damper_random_voltage/ransim_u_converted.csv"


@pytest.fixture
def other_recording() -> Path:
    value = os.environ.get("SBIB_DYKE_OTHER")
    if not value:
        pytest.skip("set SBIB_DYKE_OTHER to another recording of the Dyke damper (docs/diagnosis.md) "
                    "to run this test")
    path = Path(value)
    if not path.is_file():
        pytest.fail(f"SBIB_DYKE_OTHER = {value}: no such file")
    return path


def _diagnose(data: Path, validate: Path, capsys) -> dict:
    """``sbib diagnose --data DATA --validate VALIDATE`` on the Spencer base, its JSON."""
    for path in (data, validate):
        if not path.is_file():
            pytest.skip(f"{path} not found")
    assert main(["diagnose", "--data", str(data), "--validate", str(validate),
                 "--model", "spencer", "--holdout", "0.3", "--json", "--quiet"]) == 0
    return json.loads(capsys.readouterr().out)


@pytest.mark.slow
def test_another_recording_meets_the_targets(other_recording, shared_dir, capsys):
    out = _diagnose(other_recording, shared_dir / DYKE, capsys)
    assert out["error_after"] <= 0.15
    assert out["error_after"] < out["error_before"]
    assert out["validation"]["error_after"] <= 0.20
    # the screening leaves most of a recording usable, and names what it leaves out
    for name, scr in out["screening"].items():
        assert scr["n_excluded"] < 0.5 * scr["n_samples"], name
        if scr["n_excluded"]:
            assert any(f["excluded"] and f["n_samples"] > 0 for f in scr["findings"]), name


@pytest.mark.slow
def test_a_model_of_the_shared_recording_predicts_the_other(other_recording, shared_dir, capsys):
    out = _diagnose(shared_dir / DYKE, other_recording, capsys)
    assert out["error_after"] <= 0.13
    assert out["validation"]["error_after"] <= 0.20
