"""Passive controllers: every device held at a constant voltage.

``passive-off`` holds 0 V (the damper's minimum force), ``passive-on`` the maximum voltage
of each device (its ``voltage_range[1]``, or a chosen voltage). They are the benchmark's
reference cases for semi-active control (Narasimhan et al. 2006, Part II).
"""

from __future__ import annotations

import numpy as np

from benchmark.foundation.errors import ParameterError
from controllers.base import CompiledBackedController, ControlContext, register_controller
from controllers.compiled import CompiledController, constant_voltage

__all__ = ["ConstantVoltage", "PassiveOff", "PassiveOn"]


class ConstantVoltage(CompiledBackedController):
    """Hold every device at a constant voltage.

    Parameters
    ----------
    voltage : float or None
        Voltage [V]; ``None`` means each device's maximum voltage. Values above a device's
        maximum raise :class:`~benchmark.foundation.errors.ParameterError` at :meth:`reset`.
    name : str, optional
    """

    def __init__(self, voltage: float | None = 0.0, name: str | None = None) -> None:
        super().__init__()
        if voltage is not None and not (np.isfinite(voltage) and voltage >= 0):
            raise ParameterError(f"constant-voltage controller: voltage must be >= 0 V, got {voltage!r}")
        self.voltage = voltage
        self.name = name or ("passive-on" if voltage is None else f"constant-{voltage:g}V")

    def build(self, context: ControlContext) -> CompiledController:
        v = context.voltage_max if self.voltage is None else np.full(context.n_devices, float(self.voltage))
        if np.any(v > context.voltage_max):
            raise ParameterError(f"controller {self.name!r}: voltage {self.voltage:g} V exceeds the devices' "
                                 f"maximum {context.voltage_max.min():g} V")
        return constant_voltage(context.n_devices, v, n_meas=context.n_measurements,
                                control_step=context.control_step, v_max=context.voltage_max,
                                slew_rate=context.slew_rate, name=self.name)

    def describe(self) -> dict:
        return {"name": self.name, "voltage": "max" if self.voltage is None else self.voltage}


@register_controller
class PassiveOff(ConstantVoltage):
    """0 V on every device (``passive-off``)."""

    name = "passive-off"

    def __init__(self) -> None:
        super().__init__(0.0, name="passive-off")


@register_controller
class PassiveOn(ConstantVoltage):
    """Maximum voltage on every device (``passive-on``).

    Parameters
    ----------
    voltage : float, optional
        Voltage [V] applied to every device; default: each device's maximum.
    """

    name = "passive-on"

    def __init__(self, voltage: float | None = None) -> None:
        super().__init__(voltage, name="passive-on")
