"""Say when a controller cannot act (issue 22): a damper model whose force does not depend on
the command makes every controller give passive-off's response; the run says so, once."""

from __future__ import annotations

import pytest

from benchmark.simulator.authority import command_changes_force, controller_authority_warnings
from benchmark.simulator.building import Building
from benchmark.simulator.case import Case, run_case
from benchmark.simulator.devices import DeviceLayout, DeviceSlot
from benchmark.simulator.simulation import simulate
from damper.models.bingham import Bingham
from damper.models.virtual import VirtualBenchmarkDamper
from damper.models.voltage_laws import Polynomial
from records import load_benchmark_record

# the virtual benchmark damper with its parameters frozen at their 0-V values (no voltage laws)
DEAF = VirtualBenchmarkDamper(yield_force=float(VirtualBenchmarkDamper().yield_force(0.0)), c0=100.0e3, c1=5.0e6)
HEARING = VirtualBenchmarkDamper()


@pytest.fixture(scope="module")
def short_kobe(records_dir):
    rec = load_benchmark_record("kobe", "FN-x", records_dir=records_dir)
    return rec.replace(acceleration=rec.acceleration[:1000])  # 5 s


def test_the_probe_tells_voltage_dependent_models_from_independent_ones():
    assert not command_changes_force(DEAF)
    assert command_changes_force(HEARING)
    assert not command_changes_force(Bingham(f_c=2.0e5, c0=1.0e6))
    assert command_changes_force(Bingham(f_c=Polynomial((2.0e4, 4.0e5)), c0=1.0e6))


def test_a_controller_that_cannot_act_is_warned_about_once(short_kobe):
    building = Building.default(isolation="friction-lrb", damper_model=DEAF)
    clipped = run_case(Case(record=short_kobe, controller="clipped-optimal", building=building), cache=None)
    warnings = [n for n in clipped.notes if "cannot act" in n]
    assert len(warnings) == 1 and warnings[0].startswith("warning: controller 'clipped-optimal' cannot act")
    assert "virtual" in warnings[0] and "passive-off" in warnings[0]
    # why it matters: the J's are passive-off's
    off = run_case(Case(record=short_kobe, controller="passive-off", building=building), cache=None)
    for key, value in off.J.items():
        assert clipped.J[key] == pytest.approx(value, rel=1e-12, abs=1e-15), key


def test_no_warning_when_the_devices_respond_to_the_command(short_kobe):
    building = Building.default(isolation="friction-lrb", damper_model=HEARING)
    r = simulate(building, short_kobe, controller="clipped-optimal")
    assert r.info["notes"] == []


def test_some_devices_that_cannot_act_are_counted():
    slots = DeviceLayout.default(HEARING).slots
    mixed = DeviceLayout(tuple(DeviceSlot(s.x, s.y, s.direction, DEAF if i % 4 == 0 else HEARING, s.label)
                               for i, s in enumerate(slots)))
    (line,) = controller_authority_warnings(mixed, "clipped-optimal")
    assert "cannot act on 4 of 16 devices" in line
    assert controller_authority_warnings(DeviceLayout.default(HEARING), "clipped-optimal") == []
