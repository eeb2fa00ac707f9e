"""The 14 SLAMMER records (single column, g, no time step in the file) run at their own steps
under clipped-optimal (issue 22: "The SLAMMER records all run under clipped-optimal at their own
steps"). The steps are those of the SLAMMER table eq.sql (shared/records/raw/SOURCES.md)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from benchmark.applications.cli import main
from benchmark.simulator.building import Building
from benchmark.simulator.case import Case, run_case
from records.resolve import resolve_record

#: file under records/raw/SLAMMER -> its step [s] (eq.sql's digi_int)
SLAMMER_STEPS = {
    "Imperial_Valley_1940/ELC-180": 0.01, "Imperial_Valley_1940/ELC-270": 0.01,
    "Northridge_1994/NWH-090": 0.02, "Northridge_1994/NWH-360": 0.02,
    "Northridge_1994/SYL-090": 0.02, "Northridge_1994/SYL-360": 0.02,
    "Northridge_1994/RRS-228": 0.01, "Northridge_1994/RRS-318": 0.01,
    "Kobe_Japan_1995/KJM-000": 0.02, "Kobe_Japan_1995/KJM-090": 0.02,
    "Kobe_Japan_1995/TAK-000": 0.01, "Kobe_Japan_1995/TAK-090": 0.01,
    "Chi-Chi_Taiwan_1999/TCU068-000": 0.005, "Chi-Chi_Taiwan_1999/TCU068-090": 0.005,
}


def _slammer(shared_dir, name):
    path = shared_dir / "records" / "raw" / "SLAMMER" / name
    if not path.is_file():
        pytest.skip(f"SLAMMER record not found at {path}")
    return path


def test_kjm000_at_its_own_step_runs_from_the_command_line(shared_dir, tmp_path, capsys):
    # the first 14 s of the file (the fixed point failed at t = 10.96 s at the record's step)
    lines = _slammer(shared_dir, "Kobe_Japan_1995/KJM-000").read_text().splitlines()[:701]
    short = tmp_path / "KJM-000-14s.txt"
    short.write_text("\n".join(lines) + "\n")
    rc = main(["run", "--record", str(short), "--format", "single", "--dt", "0.02", "--units", "g",
               "--controller", "clipped-optimal", "--json"])
    captured = capsys.readouterr()
    assert rc == 0, captured.err
    summary = json.loads(captured.out)
    assert summary["record_step_s"] == 0.02 and summary["integration_step_s"] == 0.005
    assert "interpolated linearly onto the integration step 0.005 s" in captured.err
    assert summary["J"]["J1"] > 0 and summary["notes"]


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(SLAMMER_STEPS))
def test_every_slammer_record_runs_under_clipped_optimal_at_its_own_step(shared_dir, name):
    path = _slammer(shared_dir, name)
    record = resolve_record(str(path), "FN-x", format="single", dt=SLAMMER_STEPS[name], units="g")
    building = Building.default(isolation="friction-lrb", devices="default")
    out = run_case(Case(record=record, controller="clipped-optimal", building=building), cache=None)
    assert out.result.info["record_step"] == SLAMMER_STEPS[name]
    assert out.result.info["integration_step"] <= 0.005
    assert out.result.t[-1] == pytest.approx((record.n_samples - 1) * record.dt, abs=0.005)
    assert np.all(np.isfinite(out.result.base_displacement))
    assert all(np.isfinite(v) for v in out.J.values() if v is not None)
