"""A user's own semi-active controller, run in the building with

    sbib run --record kobe --controller examples/my_controller.py:StrokeProportional
    sbib compare --records kobe --controllers clipped-optimal,examples/my_controller.py:StrokeProportional

It follows the controller interface of ``controllers/base.py``: built with
no arguments; ``reset(context)`` once before the run; ``step(measurements) -> commands`` at
every control step, one command per device in ``[0, context.voltage_max]`` (volts, or amperes
for a damper model fitted on coil currents). The measurement vector's layout is
``controllers/measurements.py``: accelerations of the base and floors (27 on the benchmark's 8
floors, ``3 + 3 n_floors`` on a variant), base displacement (3), device displacements (n), device
forces (n), SI units; ``context.slices`` names its parts (use it rather than fixed offsets).

The law: each device's command grows with its own stroke, ``v = v_max · min(1, |x| / x_ref)``,
so small motions meet a soft device (less floor acceleration) and large ones a stiff device
(less base displacement). Decentralised: no model of the building is needed.
"""

from __future__ import annotations

import numpy as np

from controllers.base import ControlContext, Controller


class StrokeProportional(Controller):
    """``v_j = v_max,j · min(1, |x_j| / x_ref)`` with ``x_j`` the device's displacement [m]."""

    name = "stroke-proportional"

    def __init__(self, x_ref: float = 0.15) -> None:
        super().__init__()
        self.x_ref = float(x_ref)  # stroke at which the device gets its full command [m]

    def reset(self, context: ControlContext) -> None:
        super().reset(context)
        self._stroke = context.slices["device_displacement"]

    def step(self, measurements: np.ndarray) -> np.ndarray:
        x = measurements[self._stroke]
        return self.context.voltage_max * np.minimum(1.0, np.abs(x) / self.x_ref)

    def describe(self) -> dict:
        return {"name": self.name, "x_ref_m": self.x_ref}
