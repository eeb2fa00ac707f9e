"""What the simulator tells a controller before a run: the context and the design model.

The controllers library never imports the simulator (``docs/ARCHITECTURE.md``); it receives
the building as data. :func:`design_model` wraps a building as a
:class:`controllers.base.DesignModel` (its devices and its linearised plant from
:mod:`benchmark.simulator.linear_model`), one object per building so that designs cached on it
(the LQG of :mod:`controllers.clipped_optimal`) are shared by every run on that building.
:func:`control_context` builds a run's :class:`controllers.base.ControlContext`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from benchmark.foundation.cache import WeakKeyCache
from benchmark.foundation.errors import InputError
from benchmark.simulator.building import Building
from benchmark.simulator.linear_model import linear_model
from controllers.base import ControlContext
from controllers.lqg import LinearPlant

__all__ = ["BuildingDesignModel", "design_model", "control_context"]

#: One design model per building, alive while the building is (designs cached on it are shared).
DESIGN_MODELS = WeakKeyCache("simulator.design_models")


@dataclass(eq=False)
class BuildingDesignModel:
    """A building as a model-based design sees it (:class:`controllers.base.DesignModel`).

    Parameters
    ----------
    building : Building
        The building.
    device_models : tuple
        Damper model of every device, in device order.
    device_positions : np.ndarray
        Plan positions of the devices relative to the base centre of mass (n_dev, 2) [m].
    device_directions : np.ndarray
        Direction of each device (0 = x, 1 = y).
    _plants : dict, optional
        Cache of the linear plants by isolation linearisation (filled on use).
    """

    building: Building = field(repr=False)
    device_models: tuple
    device_positions: np.ndarray
    device_directions: np.ndarray
    _plants: dict = field(default_factory=dict, repr=False)

    def linear_plant(self, isolation: str = "equivalent") -> LinearPlant:
        """Continuous linear plant with linearised isolation (:func:`~.linear_model.linear_model`).

        Parameters
        ----------
        isolation : str, optional
            Linearisation of the bearings: ``"equivalent"`` (harmonic, at 0.1 m and 3 s) or ``"linear-part"``.
        """
        if isolation not in self._plants:
            model = linear_model(self.building, isolation=isolation)
            self._plants[isolation] = LinearPlant(A=model.A, B=model.B, E=model.E, C=model.C, D=model.D)
        return self._plants[isolation]


def design_model(building: Building) -> BuildingDesignModel:
    """The (cached) design model of ``building``; it needs a device layout.

    Parameters
    ----------
    building : Building
        The building (with a device layout).
    """
    devices = building.devices
    if devices is None:
        raise InputError("the building has no device layout (building.devices); a controller needs "
                         "devices to command")
    try:
        hit = DESIGN_MODELS.get(building)
    except TypeError:  # a building that cannot be weakly referenced
        hit = None
    if hit is not None:
        return hit
    dm = BuildingDesignModel(building=building, device_models=tuple(devices.models),
                             device_positions=np.asarray(devices.xy, dtype=float),
                             device_directions=np.asarray(devices.directions, dtype=int))
    try:
        DESIGN_MODELS.put(building, dm)
    except TypeError:  # a building that cannot be weakly referenced: no sharing
        pass
    return dm


def control_context(building: Building, control_step: float = 0.005,
                    slew_rate: float | np.ndarray = np.inf, info: dict | None = None) -> ControlContext:
    """The :class:`~controllers.base.ControlContext` of a run on ``building``: device count,
    control step [s], each damper model's largest voltage [V], the slew limit [V/s] and the
    design model.

    Parameters
    ----------
    building : Building
        The building (with a device layout).
    control_step : float, optional
        Control step [s].
    slew_rate : float | np.ndarray, optional
        Largest voltage rate [V/s] per device (a number for all); inf: none.
    info : dict | None, optional
        Extra information handed to the controller; None: none.
    """
    dm = design_model(building)
    vmax = np.array([float(m.voltage_range[1]) for m in dm.device_models])
    return ControlContext(n_devices=len(dm.device_models), control_step=control_step, voltage_max=vmax,
                          design_model=dm, slew_rate=slew_rate, info=dict(info or {}),
                          n_floors=building.superstructure.n_floors)
