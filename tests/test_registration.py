"""One registration pattern (issue #23): a new damper model, controller, bearing or effect is exactly one class.

Each test defines one class, decorated with its family's decorator, and nothing else, then uses it
by name through the public entry points (the building, ``simulate(controller=NAME)``).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pytest

from benchmark.foundation.errors import InputError
from benchmark.foundation.registry import Registry


def test_a_new_controller_is_one_decorated_class(records_dir):
    import benchmark as sb
    from controllers import CONTROLLERS, Controller, controller_names, get_controller
    from controllers.base import register_controller

    @register_controller
    class HalfVoltage(Controller):
        """Half the devices' largest voltage, always."""

        name = "test-half-voltage"

        def step(self, measurements):
            return 0.5 * self.context.voltage_max

    try:
        assert "test-half-voltage" in controller_names()
        assert isinstance(get_controller("test-half-voltage"), HalfVoltage)
        record = sb.load_benchmark_record("kobe", "FN-x")
        building = sb.Building.default(isolation="linear")
        result = sb.simulate(building, record, controller="test-half-voltage")
        np.testing.assert_allclose(result.voltage, np.broadcast_to(0.5 * building.devices.voltage_max, result.voltage.shape))
    finally:
        CONTROLLERS.unregister("test-half-voltage")
    assert "test-half-voltage" not in controller_names()


def test_a_new_damper_model_is_one_decorated_class(records_dir):
    import benchmark as sb
    import damper
    from damper.models.base import KERNEL_BINGHAM, MODELS, DamperModel, register_model
    from damper.models.voltage_laws import Constant, Polynomial

    @register_model
    @dataclass(frozen=True)
    class LinearViscous(DamperModel):
        """F = c xdot, packed into the Bingham family's layout (no friction, no offset)."""

        c: float
        voltage_range: tuple[float, float] = (0.0, 1.0)
        name: ClassVar[str] = "test-linear-viscous"
        kernel: ClassVar[int] = KERNEL_BINGHAM
        n_states: ClassVar[int] = 0

        def to_array(self):
            return np.concatenate((Constant(0.0).to_array(), Polynomial((self.c,)).to_array(), [0.0]))

        def initial_state(self):
            return np.zeros(0)

        def rates(self, state, x, xdot, v):
            return np.zeros(0)

        def force(self, state, x, xdot, v):
            return self.c * xdot

    try:
        assert damper.get_model_class("test-linear-viscous") is LinearViscous
        record = sb.load_benchmark_record("kobe", "FN-x")
        building = sb.Building.default(isolation="linear", damper_model=LinearViscous(c=2e5))
        result = sb.simulate(building, record, controller="passive-off")
        np.testing.assert_allclose(result.device_force, 2e5 * result.device_velocity,
                                   atol=1e-3 * 2e5 * np.abs(result.device_velocity).max())
    finally:
        MODELS.unregister("test-linear-viscous")


def test_a_new_bearing_is_one_decorated_class(records_dir, tmp_path):
    """A high-damping rubber bearing given by its rubber (shear modulus, area, height, yield
    strain) is one class packing into the lead-rubber kernel family; an isolation file names it
    and the building runs it exactly as the equivalent lead-rubber bearing."""
    import benchmark as sb
    from benchmark.simulator.isolation import BearingGroup, IsolationLayer, LeadRubberBearing, load_isolation
    from benchmark.simulator.isolation.base import (BEARINGS, KERNEL_LEAD_RUBBER, BearingParameters,
                                                     register_bearing)
    from benchmark.simulator.isolation.registry import bearing_names, bearing_type

    @register_bearing
    @dataclass(frozen=True)
    class HighDampingRubber(BearingParameters):
        """Rubber of shear modulus G [Pa], area [m^2], height [m]; yields at a shear strain."""

        shear_modulus: float
        area: float
        height: float
        yield_strain: float
        alpha: float
        name: ClassVar[str] = "test-high-damping-rubber"
        kernel: ClassVar[int] = KERNEL_LEAD_RUBBER
        n_states: ClassVar[int] = 2

        def equivalent(self) -> LeadRubberBearing:
            k = self.shear_modulus * self.area / self.height
            return LeadRubberBearing(k_initial=k, alpha=self.alpha, yield_force=k * self.yield_strain * self.height)

        def to_array(self):
            return self.equivalent().to_array()

        def rates(self, state, ux, uy, vx, vy):
            return self.equivalent().rates(state, ux, uy, vx, vy)

        def force(self, state, ux, uy, vx, vy):
            return self.equivalent().force(state, ux, uy, vx, vy)

    hdr = dict(shear_modulus=0.8e6, area=1.2, height=0.2, yield_strain=0.05, alpha=0.15)
    layer_file = tmp_path / "hdr.json"
    layer_file.write_text(json.dumps({"name": "fp-hdr", "groups": [
        {"type": "friction-pendulum", "bearings": "1-61",
         "parameters": {"weight": 2.2078e6, "radius": 2.24, "mu_max": 0.06, "mu_min": 0.03,
                        "rate_parameter": 20}},
        {"type": "test-high-damping-rubber", "bearings": "62-92", "parameters": hdr}]}))
    try:
        assert "test-high-damping-rubber" in bearing_names()
        assert bearing_type("test-high-damping-rubber") is HighDampingRubber
        layer = load_isolation(layer_file)
        reference = IsolationLayer("fp-lrb", (layer.groups[0], BearingGroup(HighDampingRubber(**hdr).equivalent(),
                                                                             layer.groups[1].indices)))
        record = sb.load_benchmark_record("kobe", "FN-x")
        run = sb.simulate(sb.Building.default(isolation=layer), record, controller="passive-off")
        same = sb.simulate(sb.Building.default(isolation=reference), record, controller="passive-off")
        # the same packed arrays through the same compiled kernel: equal to the last bit
        np.testing.assert_array_equal(run.base_displacement, same.base_displacement)
        assert np.abs(run.base_displacement).max() > 0.05  # the bearings were loaded into yield
    finally:
        BEARINGS.unregister("test-high-damping-rubber")
    assert "test-high-damping-rubber" not in bearing_names()


def test_a_new_effect_is_one_decorated_class():
    """A cubic (hardening) spring is one effect class; the residual loop then lists it, finds it in
    a device that has it and halves the held-out error (it is not in the library, so nothing else
    explains the odd-in-displacement residual as well)."""
    import math

    from damper.diagnosis import diagnose
    from damper.diagnosis.augmented import AugmentedModel
    from damper.diagnosis.effects import EFFECTS, Effect, effect_names, get_effect, register_effect
    from damper.diagnosis.synthetic import sinusoidal_tests
    from damper.models.bouc_wen import NormalizedBoucWen

    @register_effect
    @dataclass(frozen=True)
    class CubicStiffness(Effect):
        """Hardening spring k3 x^3 [N]."""

        k3: float
        name: ClassVar[str] = "test-cubic-stiffness"
        role: ClassVar[str] = "additive"
        parameter_name: ClassVar[str] = "k3"
        unit: ClassVar[str] = "N/m^3"
        lower: ClassVar[float] = 0.0
        description: ClassVar[str] = "hardening spring k3*x^3"
        traces: ClassVar[tuple[str, ...]] = ("displacement", "loop")

        def __post_init__(self) -> None:
            self._validate()

        @classmethod
        def scale(cls, motions, force_rms):
            x3 = math.sqrt(sum(float(np.sum(m.x ** 6)) for m in motions) / sum(m.x.size for m in motions))
            return force_rms / max(x3, 1e-30)

        def force(self, motion):
            return self.k3 * motion.x ** 3

    try:
        assert effect_names()[-1] == "test-cubic-stiffness"
        assert get_effect("test-cubic-stiffness") is CubicStiffness
        base = NormalizedBoucWen(2000.0, 800.0, 400.0, 1.0, 1.5)
        device = AugmentedModel(base, (CubicStiffness(4e8),))  # ~0.5 kN at 1.2 cm, about 15 % of the force
        d = diagnose(sinusoidal_tests(device, noise=0.01, seed=3))
        assert "test-cubic-stiffness" in d.effects, (d.effects, d.error_before, d.error_after)
        assert d.error_after <= 0.5 * d.error_before
    finally:
        EFFECTS.unregister("test-cubic-stiffness")
    assert "test-cubic-stiffness" not in effect_names()
    with pytest.raises(InputError, match="role"):
        @register_effect
        @dataclass(frozen=True)
        class Nowhere(Effect):
            value: float
            name: ClassVar[str] = "test-nowhere"
            role: ClassVar[str] = "elsewhere"


def test_a_registry_refuses_a_taken_name_and_a_foreign_class():
    class Base:
        name = "base"

    registry = Registry("thing", Base)

    @registry.register
    class A(Base):
        name = "a"

    class B(Base):
        name = "a"

    with pytest.raises(InputError, match="already registered"):
        registry.register(B)
    with pytest.raises(InputError, match="not a subclass"):
        registry.register(int)
    with pytest.raises(InputError, match="unknown name 'z'; expected one of a"):
        registry.get_class("z")
    assert registry.get_class("a") is A
