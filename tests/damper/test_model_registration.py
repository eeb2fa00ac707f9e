"""A new damper model is one class decorated with ``register_model`` (docs/ARCHITECTURE.md).

This module *is* the new module: it defines a toy model (a linear viscous damper whose
coefficient grows with the coil voltage, c(v) = c0 + c1 v), registers it (the decorator, applied
in a fixture so that the last test can see an unregistered one), and runs it alone and inside
the building.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pytest

from benchmark.foundation.errors import InputError
from damper.models.base import KERNEL_BINGHAM, DamperModel
from damper.models.voltage_laws import Constant, Polynomial


@dataclass(frozen=True)
class ToyViscousDamper(DamperModel):
    """F = (c0 + c1 v) xdot [N]; c0, c1 [N·s/m, N·s/(m·V)]. Packs into the Bingham family's
    layout ``[law(f_c), law(c0), f0]`` with no friction, so it needs no kernel of its own."""

    c0: float
    c1: float
    voltage_range: tuple[float, float] = (0.0, 1.0)

    name: ClassVar[str] = "toy_viscous"
    kernel: ClassVar[int] = KERNEL_BINGHAM
    n_states: ClassVar[int] = 0

    def to_array(self) -> np.ndarray:
        return np.concatenate((Constant(0.0).to_array(), Polynomial((self.c0, self.c1)).to_array(), [0.0]))

    def initial_state(self) -> np.ndarray:
        return np.zeros(0)

    def rates(self, state, x, xdot, v):
        return np.zeros(0)

    def force(self, state, x, xdot, v):
        return (self.c0 + self.c1 * v) * xdot


@pytest.fixture
def registered():
    from damper.models import registry

    cls = registry.register_model(ToyViscousDamper)  # the decorator, applied here
    yield cls
    registry.MODELS.unregister(cls.name)


def test_the_toy_model_is_found_by_name_and_simulated(registered):
    import damper

    assert damper.get_model_class("toy_viscous") is ToyViscousDamper
    t = np.linspace(0.0, 2.0, 2001)
    x = 0.01 * np.sin(2 * np.pi * t)
    response = damper.simulate(ToyViscousDamper(c0=1e3, c1=4e3), t, x, v=0.5)
    xdot = 0.01 * 2 * np.pi * np.cos(2 * np.pi * t)
    # damper.simulate differentiates x numerically when xdot is not given
    np.testing.assert_allclose(response.force, 3e3 * xdot, atol=1e-4 * 3e3 * 0.063)


def test_the_toy_model_runs_in_the_building(registered, records_dir):
    from benchmark.simulator.building import Building
    from benchmark.simulator.simulation import simulate
    from records import load_benchmark_record

    record = load_benchmark_record("kobe", "FN-x")
    model = ToyViscousDamper(c0=1e5, c1=5e5)
    building = Building.default(isolation="linear", damper_model=model)
    result = simulate(building, record, controller="passive-on")
    # passive-on holds every device at its largest voltage: F = (c0 + c1) xdot for each device
    # (to the fixed-point tolerance with which the step's end velocity is converged)
    np.testing.assert_allclose(result.device_force, 6e5 * result.device_velocity,
                               atol=1e-3 * 6e5 * np.abs(result.device_velocity).max())
    reference = simulate(building.without_devices(), record)
    assert np.abs(result.base_displacement[:, :2]).max() < np.abs(reference.base_displacement[:, :2]).max()


def test_registration_refuses_what_breaks_the_contract(registered):
    from damper.models import registry

    class NotAModel:
        name = "nope"

    with pytest.raises(InputError, match="not a subclass of damper.models.base.DamperModel"):
        registry.register_model(NotAModel)

    @dataclass(frozen=True)
    class Clash(ToyViscousDamper):
        name: ClassVar[str] = "virtual"

    with pytest.raises(InputError, match="already registered"):
        registry.register_model(Clash)

    @dataclass(frozen=True)
    class BadKernel(ToyViscousDamper):
        name: ClassVar[str] = "bad_kernel"
        kernel: ClassVar[int] = 99

    with pytest.raises(InputError, match="not a kernel family"):
        registry.register_model(BadKernel)


def test_an_unregistered_model_is_refused_by_the_building():
    from benchmark.simulator.building import Building

    with pytest.raises(InputError, match="not a registered damper model"):
        Building.default(isolation="linear", damper_model=ToyViscousDamper(c0=1.0, c1=1.0))
