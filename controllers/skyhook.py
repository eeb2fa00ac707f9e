"""Skyhook control from measured base accelerations (clipped to what an MR damper can do).

The ideal skyhook damper pushes the base against its *absolute* velocity,
:math:`f_{sky} = c_{sky} \\dot u^a`. No sensor measures that velocity, so each device
estimates the absolute velocity at its own location by a leaky integration of the measured
absolute base accelerations (a first-order high-pass integrator that forgets offsets and
low-frequency drift):

.. math::

    \\ddot u^a_i = \\ddot u^a_{b,x} - y_i\\, \\ddot\\theta^a_b \\ (\\text{x devices}), \\quad
    \\ddot u^a_{b,y} + x_i\\, \\ddot\\theta^a_b \\ (\\text{y devices}),

    \\hat v_i[k+1] = \\alpha \\hat v_i[k] + \\Delta t\\, \\ddot u^a_i[k], \\quad
    \\alpha = e^{-2\\pi f_{hp} \\Delta t},

and the desired (resisting) device force :math:`f_{c,i} = c_{sky} \\hat v_i[k+1]` is followed by
the clipped-optimal rule :math:`v_i = V_{max} H((f_{c,i} - f_i) f_i)` (law 1 of
:mod:`controllers.compiled`): the damper is switched on when its force has the skyhook sign
and is smaller than the skyhook force.

References
----------
Karnopp D., Crosby M.J., Harwood R.A. (1974) Vibration control using semi-active force
generators. J. Eng. Ind. 96(2):619–626.
Nagarajaiah S., Narasimhan S. (2006) Smart base-isolated benchmark building, Part II.
"""

from __future__ import annotations

import numpy as np

from benchmark.foundation.errors import ParameterError
from controllers.base import CompiledBackedController, ControlContext, register_controller
from controllers.compiled import DEFAULT_DEAD_BAND, LAW_CLIPPED_OPTIMAL, CompiledController
from controllers.plant import device_force_capacity, device_geometry, device_models

__all__ = ["Skyhook"]


@register_controller
class Skyhook(CompiledBackedController):
    """Skyhook controller (``skyhook``).

    Parameters
    ----------
    damping : float, optional
        Skyhook coefficient per device [N·s/m]; default: the device's force capacity at
        maximum voltage divided by ``velocity_scale`` (so that the damper is asked for its
        full force at that absolute velocity).
    velocity_scale : float
        [m/s] (default 0.3 m/s).
    highpass_frequency : float
        Corner frequency of the leaky integrator [Hz] (default 0.05 Hz, well below the
        isolated building's ~0.3 Hz).
    positions, directions : array-like, optional
        Device plan positions (n_dev, 2) [m] and directions (0 = x, 1 = y); default: the
        building's device layout.
    dead_band : float, optional
        Dead band on the desired force as a fraction of ``damping * velocity_scale`` (the
        device's capacity by default): as for :class:`controllers.clipped_optimal.ClippedOptimal`
        (default :data:`controllers.compiled.DEFAULT_DEAD_BAND`; 0: none).
    """

    name = "skyhook"

    def __init__(self, damping: float | None = None, velocity_scale: float = 0.3,
                 highpass_frequency: float = 0.05, positions=None, directions=None,
                 dead_band: float | None = None) -> None:
        super().__init__()
        self.dead_band = DEFAULT_DEAD_BAND if dead_band is None else float(dead_band)
        if not (np.isfinite(self.dead_band) and 0.0 <= self.dead_band < 1.0):
            raise ParameterError(f"skyhook: dead_band must be a fraction in [0, 1), got {dead_band!r}")
        for label, value in (("velocity_scale", velocity_scale), ("highpass_frequency", highpass_frequency)):
            if not (np.isfinite(value) and value > 0):
                raise ParameterError(f"skyhook: {label} must be > 0, got {value!r}")
        if damping is not None and not (np.isfinite(damping) and damping > 0):
            raise ParameterError(f"skyhook: damping must be > 0 N·s/m, got {damping!r}")
        self.damping = damping
        self.velocity_scale = float(velocity_scale)
        self.highpass_frequency = float(highpass_frequency)
        self.positions = positions
        self.directions = directions

    def build(self, context: ControlContext) -> CompiledController:
        n_dev, dt = context.n_devices, context.control_step
        if self.positions is None:
            positions, directions = device_geometry(context.design_model)
        else:
            positions = np.asarray(self.positions, dtype=float)
            directions = np.asarray(self.directions, dtype=int)
        if positions.shape != (n_dev, 2) or directions.shape != (n_dev,) or not np.all(np.isin(directions, (0, 1))):
            raise ParameterError(f"skyhook: need positions ({n_dev}, 2) and directions ({n_dev},) in {{0, 1}}, "
                                 f"got {positions.shape} and {directions.shape}")
        if self.damping is not None:
            c_sky = np.full(n_dev, self.damping)
        else:
            models = device_models(context.design_model)
            c_sky = np.array([device_force_capacity(m, v) for m, v in zip(models, context.voltage_max)]) \
                / self.velocity_scale
        self.c_sky = c_sky
        s = context.slices
        base = s["base_acceleration"].start
        # Acceleration at each device location as a row map of the measurement vector.
        accel_map = np.zeros((n_dev, context.n_measurements))
        for i, ((x, y), d) in enumerate(zip(positions, directions)):
            if d == 0:
                accel_map[i, base + 0] = 1.0
                accel_map[i, base + 2] = -y
            else:
                accel_map[i, base + 1] = 1.0
                accel_map[i, base + 2] = x
        alpha = np.exp(-2 * np.pi * self.highpass_frequency * dt)
        Ac = alpha * np.eye(n_dev)
        Bc = dt * accel_map
        # f_c[k] = c (alpha v[k] + dt a[k]) = c v[k+1]
        Cc = np.diag(c_sky * alpha)
        Dc = c_sky[:, None] * Bc
        return CompiledController(name=self.name, n_meas=context.n_measurements, n_devices=n_dev,
                                  control_step=dt, law_id=LAW_CLIPPED_OPTIMAL,
                                  law_params=self.dead_band * c_sky * self.velocity_scale,
                                  v_max=context.voltage_max, slew_rate=context.slew_rate,
                                  Ac=Ac, Bc=Bc, Cc=Cc, Dc=Dc)

    def describe(self) -> dict:
        return {"name": self.name, "damping": self.damping, "velocity_scale": self.velocity_scale,
                "highpass_frequency": self.highpass_frequency, "dead_band": self.dead_band}
