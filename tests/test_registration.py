"""One registration pattern (issue #23): a new damper model or controller is exactly one class.

Each test defines one class, decorated with its family's decorator, and nothing else, then uses it
by name through the public entry points (the building, ``simulate(controller=NAME)``).
"""

from __future__ import annotations

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
