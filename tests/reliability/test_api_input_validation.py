"""The Python API validates its input: records, damper models and tests, the laboratory,
identification, diagnosis, the building and :func:`benchmark.simulator.simulation.simulate`.

Each bad call must raise an :class:`InputError` (or :class:`ParameterError`) with a one-line
message that names the argument or field at fault; never a ``TypeError``/``ValueError`` from
deep inside numpy, and never a silently wrong result.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from benchmark.foundation.errors import DataNotFoundError, InputError, ParameterError

T = np.linspace(0.0, 1.0, 101)
X = 0.01 * np.sin(2 * np.pi * 3 * T)


def _raises(func, match: str, kind=InputError):
    with pytest.raises(kind) as info:
        func()
    message = str(info.value)
    assert "\n" not in message, message
    assert match in message, f"{message!r} does not mention {match!r}"
    return message


# ---------------------------------------------------------------------------------------------
# records
# ---------------------------------------------------------------------------------------------
RECORD_CASES = {
    "dt zero": (dict(dt=0.0), "dt"),
    "dt NaN": (dict(dt=math.nan), "dt"),
    "dt negative": (dict(dt=-0.01), "dt"),
    "NaN sample": (dict(acceleration=np.array([[0.0], [np.nan], [1.0]])), "non-finite"),
    "inf sample": (dict(acceleration=np.array([0.0, np.inf, 1.0])), "non-finite"),
    "one sample": (dict(acceleration=np.array([[1.0, 2.0]])), "n_samples >= 2"),
    "3-D array": (dict(acceleration=np.zeros((3, 2, 2))), "shape"),
    "labels": (dict(labels=("x",), acceleration=np.zeros((3, 2))), "labels"),
}


@pytest.mark.parametrize("case", sorted(RECORD_CASES))
def test_record_rejects(case):
    from records import Record

    fields = dict(name="r", dt=0.01, acceleration=np.zeros((5, 1)))
    changes, match = RECORD_CASES[case]
    fields.update(changes)
    _raises(lambda: Record(**fields), match)


def test_record_loaders_reject_unknown_names_formats_and_directories(tmp_path):
    from records import load_benchmark_record, load_record

    _raises(lambda: load_benchmark_record("atlantis"), "atlantis")
    _raises(lambda: load_benchmark_record("kobe", orientation="NS-x"), "NS-x")
    _raises(lambda: load_benchmark_record("kobe", records_dir=tmp_path / "none"), "none", DataNotFoundError)
    path = tmp_path / "r.csv"
    path.write_text("time,ax\n0,1\n0.01,2\n")
    _raises(lambda: load_record(path, format="xlsx"), "xlsx")
    _raises(lambda: load_record(path, dt=0.02), "dt")          # contradicts the time column
    _raises(lambda: load_record(tmp_path / "none.csv"), "none.csv", DataNotFoundError)
    _raises(lambda: load_record(tmp_path), str(tmp_path))       # a directory, not a file


# ---------------------------------------------------------------------------------------------
# damper models, damper.simulate, DamperTest, laboratory
# ---------------------------------------------------------------------------------------------
GOOD_EBW = dict(kappa_x=207e3, kappa_xdot=100e3, kappa_w=50e3, rho=40.0, sigma=1.0, n=1.5)
PARAMETER_CASES = {
    "rho <= 0": (dict(rho=0.0), "rho"),
    "sigma < 1/2": (dict(sigma=0.4), "sigma"),
    "n < 1": (dict(n=0.9), "n"),
    "kappa_xdot < 0": (dict(kappa_xdot=-1.0), "kappa_xdot"),
    "kappa_w NaN": (dict(kappa_w=math.nan), "kappa_w"),
    "kappa_x inf": (dict(kappa_x=math.inf), "kappa_x"),
    "rho text": (dict(rho="fast"), "rho"),
}


@pytest.mark.parametrize("case", sorted(PARAMETER_CASES))
def test_extended_bouc_wen_rejects_inadmissible_parameters(case):
    from damper import ExtendedBoucWen

    changes, match = PARAMETER_CASES[case]
    _raises(lambda: ExtendedBoucWen(**{**GOOD_EBW, **changes}), match, ParameterError)


def test_virtual_damper_rejects_inadmissible_override():
    from damper.models.virtual import VirtualBenchmarkDamper

    _raises(lambda: VirtualBenchmarkDamper(rho=-1.0), "rho", ParameterError)


SIMULATE_CASES = {
    "voltage above range": (dict(v=2.0), "v"),
    "voltage below range": (dict(v=-0.1), "v"),
    "voltage history out of range": (dict(v=np.where(T > 0.5, 1.5, 0.0)), "sample 51"),
    "voltage text": (dict(v="high"), "v"),
    "time backwards": (dict(t=T[::-1]), "t"),
    "time repeated": (dict(t=np.r_[T[:50], T[49:-1]]), "t"),
    "length mismatch": (dict(x=X[:-1]), "x"),
    "NaN displacement": (dict(x=np.where(T > 0.5, np.nan, X)), "x"),
    "inf velocity": (dict(xdot=np.full(T.size, np.inf)), "xdot"),
    "2-D displacement": (dict(x=np.column_stack([X, X])), "x"),
    "one sample": (dict(t=T[:1], x=X[:1]), "t"),
    "wrong state size": (dict(state0=[0.0, 0.0, 0.0]), "state0"),
}


@pytest.mark.parametrize("case", sorted(SIMULATE_CASES))
def test_damper_simulate_rejects(case):
    from damper import ExtendedBoucWen, simulate

    model = ExtendedBoucWen(**GOOD_EBW)
    kwargs = dict(t=T, x=X)
    changes, match = SIMULATE_CASES[case]
    kwargs.update(changes)
    _raises(lambda: simulate(model, **kwargs), match)


def test_damper_simulate_rejects_non_models():
    from damper import simulate

    _raises(lambda: simulate("virtual-ish", T, X), "damper model")
    _raises(lambda: simulate(object(), T, X), "damper model")


LAB_CASES = {
    "negative amplitude": (dict(amplitude=-0.1), "amplitude"),
    "NaN frequency": (dict(frequency=math.nan), "frequency"),
    "voltage above the device range": (dict(voltage=1.5), "voltage"),
    "voltage text": (dict(voltage="max"), "voltage"),
    "zero cycles": (dict(cycles=0), "cycles"),
    "too few samples per period": (dict(sample_rate=5.0), "sample_rate"),
    "negative noise": (dict(noise=-0.1), "noise"),
    "waveform": (dict(waveform="square"), "waveform"),
    "seed text": (dict(noise=0.01, seed="lucky"), "seed"),
    "absurd length": (dict(cycles=1e12), "samples"),
    "unknown device": (dict(device="flux-capacitor"), "flux-capacitor"),
}


@pytest.mark.parametrize("case", sorted(LAB_CASES))
def test_laboratory_periodic_test_rejects(case):
    from damper.lab.laboratory import periodic_test

    kwargs = dict(device="virtual", amplitude=0.05, frequency=1.0, voltage=0.0, cycles=2)
    changes, match = LAB_CASES[case]
    kwargs.update(changes)
    _raises(lambda: periodic_test(**kwargs), match)


def test_laboratory_general_test_rejects_voltage_outside_the_device_range():
    from damper.lab.laboratory import general_test

    _raises(lambda: general_test("virtual", T, X, v=np.full(T.size, 3.0)), "v")
    _raises(lambda: general_test("virtual", T, X, v=0.0, noise=math.inf), "noise")


def test_damper_test_record_rejects():
    from damper import DamperTest

    _raises(lambda: DamperTest(T, X[:-1], X, X), "displacement")
    _raises(lambda: DamperTest(T[::-1], X, X, X), "time")
    _raises(lambda: DamperTest(T, X, X, np.where(T > 0.5, np.nan, X)), "force")
    _raises(lambda: DamperTest(T, X, X, X, voltage=0.0, current=0.1), "voltage or a current")
    _raises(lambda: DamperTest(T[:1], X[:1], X[:1], X[:1]), "at least 2")


# ---------------------------------------------------------------------------------------------
# identification and diagnosis
# ---------------------------------------------------------------------------------------------
def test_identification_rejects_unusable_tests():
    from damper.identification.identify import identify_arrays

    t = np.linspace(0.0, 4.0, 801)
    x = 0.02 * np.sin(2 * np.pi * t)
    _raises(lambda: identify_arrays(t, x, x[:-1]), "equal length")
    _raises(lambda: identify_arrays(t, np.where(t > 1, np.nan, x), x), "non-finite")
    _raises(lambda: identify_arrays(t[::-1], x, x), "time")
    _raises(lambda: identify_arrays(t, np.zeros_like(t), x), "stroke")
    _raises(lambda: identify_arrays(t[:200], x[:200], x[:200]), "cycle")
    _raises(lambda: identify_arrays(t, x, x, model="spencer"), "model")


def test_identification_rejects_too_short_a_test():
    from damper.identification.identify import identify_arrays

    _raises(lambda: identify_arrays(T[:2], X[:2], X[:2]), "")


def test_diagnosis_rejects_bad_arguments():
    from damper.diagnosis import diagnose
    from damper.lab.laboratory import periodic_test

    test = periodic_test("virtual", 0.05, 1.0, 0.0, cycles=2)
    _raises(lambda: diagnose([]), "at least one test")
    _raises(lambda: diagnose(["not a test"]), "DamperTest")
    _raises(lambda: diagnose([test], holdout=1.5), "holdout")
    _raises(lambda: diagnose([test], model="magic"), "magic")
    _raises(lambda: diagnose([test], candidates=["telepathy"]), "telepathy")


# ---------------------------------------------------------------------------------------------
# bearings, isolation layers, devices, the building
# ---------------------------------------------------------------------------------------------
def test_bearing_parameters_are_validated():
    from benchmark.simulator.isolation.friction_pendulum import FrictionPendulumBearing
    from benchmark.simulator.isolation.lead_rubber import LeadRubberBearing
    from benchmark.simulator.isolation.linear import LinearBearing

    _raises(lambda: LinearBearing(-1.0, 1.0), "", ParameterError)
    _raises(lambda: LinearBearing(1.0, math.nan), "", ParameterError)
    _raises(lambda: LeadRubberBearing(k_initial=1e7, alpha=1.5, yield_force=1e5), "alpha", ParameterError)
    _raises(lambda: LeadRubberBearing(k_initial=-1e7, alpha=0.1, yield_force=1e5), "k_initial", ParameterError)
    _raises(lambda: FrictionPendulumBearing(weight=2e6, radius=2.0, mu_max=0.03, mu_min=0.06,
                                            rate_parameter=20.0), "mu", ParameterError)
    _raises(lambda: FrictionPendulumBearing(weight=2e6, radius=0.0, mu_max=0.06, mu_min=0.03,
                                            rate_parameter=20.0), "radius", ParameterError)


def test_isolation_layers_are_validated():
    from benchmark.simulator.isolation.configurations import (BearingGroup, IsolationLayer, get_isolation,
                                                    isolation_from_dict)
    from benchmark.simulator.isolation.linear import LinearBearing

    b = LinearBearing(1e6, 1e4)
    _raises(lambda: IsolationLayer("gap", (BearingGroup(b, range(90)),)), "91-92", ParameterError)
    _raises(lambda: IsolationLayer("twice", (BearingGroup(b, range(92)), BearingGroup(b, [0]))), "bearing 1",
            ParameterError)
    _raises(lambda: IsolationLayer("out", (BearingGroup(b, range(93)),)), "92", ParameterError)
    _raises(lambda: get_isolation("granite"), "granite")
    _raises(lambda: get_isolation("linear", substep_tolerance=-1.0), "substep_tolerance", ParameterError)
    _raises(lambda: isolation_from_dict({"groups": [{"type": "rubber-duck", "bearings": "1-92"}]}, "f.json"),
            "rubber-duck")
    _raises(lambda: isolation_from_dict({"groups": [{"type": "linear", "bearings": "1-93",
                                                     "parameters": {"k": 1e6, "c": 1e4}}]}, "f.json"),
            "93")
    _raises(lambda: isolation_from_dict({"groups": [{"type": "linear", "bearings": "a-b"}]}, "f.json"),
            "f.json")


def test_devices_are_validated():
    from benchmark.simulator.devices import DeviceLayout, DeviceSlot
    from damper.models.virtual import VirtualBenchmarkDamper

    model = VirtualBenchmarkDamper()
    _raises(lambda: DeviceSlot(0.0, 0.0, "z", model), "direction")
    _raises(lambda: DeviceSlot(math.nan, 0.0, 0, model), "x")
    _raises(lambda: DeviceSlot(0.0, 0.0, 0, "a damper"), "not a damper model")
    _raises(lambda: DeviceLayout(()), "at least one")
    _raises(lambda: DeviceLayout.from_positions([[0.0, 0.0]], [0, 1], model), "positions")


@pytest.fixture(scope="module")
def linear_building():
    from benchmark.simulator.building import Building

    return Building.default(isolation="linear", devices="default")


@pytest.fixture(scope="module")
def short_record():
    from records import Record

    rng = np.random.default_rng(1)
    return Record("noise", 0.005, 0.5 * rng.standard_normal((41, 2)))


def test_building_rejects_a_layer_of_the_wrong_size(linear_building):
    from benchmark.simulator.building import Building
    from benchmark.simulator.isolation.configurations import BearingGroup, IsolationLayer
    from benchmark.simulator.isolation.linear import LinearBearing

    small = IsolationLayer("small", (BearingGroup(LinearBearing(1e6, 1e4), range(10)),), n_bearings=10)
    _raises(lambda: Building(linear_building.superstructure, small), "10 bearings")
    _raises(lambda: Building.default(devices="many"), "devices")
    _raises(lambda: Building.default(n_modes=0), "n_modes")


SIM_CASES = {
    # any positive control step fits: the integration step divides it (issue 22)
    "integration step negative": (dict(integration_step=-0.005), "integration_step"),
    "integration step NaN": (dict(integration_step=math.nan), "integration_step"),
    "halvings negative": (dict(max_halvings=-1), "max_halvings"),
    "control step NaN": (dict(control_step=math.nan), "control_step"),
    "control step negative": (dict(control_step=-0.005), "control_step"),
    "record shorter than one control step": (dict(control_step=0.5), "shorter than one control step"),
    # the bounds of a semi-active control step (a 1e-5 s step ran out of memory, 5 s was taken)
    "control step too short": (dict(control_step=1e-5), "updates every 0.0001-1 s"),
    "control step too long": (dict(control_step=5.0), "updates every 0.0001-1 s"),
    "too many integration steps": (dict(integration_step=1e-7), "more than the 1e+06 a run holds"),
    "fixed-point tolerance": (dict(fixed_point_tolerance=0.0), "fixed_point_tolerance"),
    "max iterations": (dict(max_iterations=0), "max_iterations"),
    "substep tolerance": (dict(substep_tolerance=-1.0), "substep_tolerance"),
    "unknown controller": (dict(controller="psychic"), "psychic"),
}


@pytest.mark.parametrize("case", sorted(SIM_CASES))
def test_simulate_rejects(case, linear_building, short_record):
    from benchmark.simulator.simulation import simulate

    changes, match = SIM_CASES[case]
    _raises(lambda: simulate(linear_building.without_devices(), short_record, **changes), match)


def test_simulate_rejects_bad_records_and_controllers(linear_building, short_record):
    from benchmark.simulator.simulation import simulate

    three = dataclasses.replace(short_record, acceleration=np.zeros((41, 3)), labels=("a", "b", "c"))
    _raises(lambda: simulate(linear_building, three), "(n, 2)")
    _raises(lambda: simulate(linear_building, np.zeros((10, 2))), "records.Record")
    _raises(lambda: simulate(linear_building.without_devices(), short_record, controller="passive-on"),
            "no devices")


class _BadController:
    """A pure-Python controller that returns what it is told to."""

    def __init__(self, voltages):
        self.voltages = voltages
        self.name = "bad"

    def step(self, measurements):
        return self.voltages


@pytest.mark.parametrize("voltages, match", [(np.zeros(3), "shape (3,)"), ("high", "str")])
def test_simulate_rejects_malformed_controller_output(linear_building, short_record, voltages, match):
    from benchmark.simulator.simulation import simulate

    message = _raises(lambda: simulate(linear_building, short_record, controller=_BadController(voltages)),
                      match)
    assert "'bad'" in message


def test_simulate_stops_on_non_finite_controller_output(linear_building, short_record):
    """A NaN voltage is a numerical failure of the controller: NumericalError with time and hint."""
    from benchmark.foundation.errors import NumericalError
    from benchmark.simulator.simulation import simulate

    with pytest.raises(NumericalError) as info:
        simulate(linear_building, short_record, controller=_BadController(np.full(16, np.nan)))
    assert info.value.time == 0.0 and info.value.hint and "'bad'" in str(info.value)


def test_simulate_saturates_voltages_above_the_device_range(linear_building, short_record):
    """Voltages above the device's maximum are saturated (the actuator's limit), never passed on."""
    from benchmark.simulator.simulation import simulate

    result = simulate(linear_building, short_record, controller=_BadController(np.full(16, 5.0)))
    assert np.all(result.voltage <= linear_building.devices.voltage_max) and result.voltage.max() > 0
