"""The building as the model-based controllers see it: linear plant, device geometry, device capacity.

Everything here reads the building through the :class:`~controllers.base.DesignModel` the
simulator hands over in the run's :class:`~controllers.base.ControlContext`, so the controllers
never import the simulator (the layers of ``docs/ARCHITECTURE.md``).
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any

import numpy as np

from benchmark.foundation.errors import InputError
from controllers.base import DesignModel
from controllers.lqg import LinearPlant
import damper

__all__ = ["building_plant", "device_geometry", "device_models", "device_force_capacity"]


def building_plant(design_model: DesignModel | None, isolation: str = "equivalent") -> LinearPlant:
    """Continuous linear plant of the run's building with linearised isolation.

    ``x' = A x + B f + E ü_g``, ``y = C x + D f``: ``f`` the device forces [N] (resisting force,
    as measured), ``ü_g`` the ground acceleration (x, y) [m/s²], ``y`` the measurement vector.
    ``isolation`` selects the bearings' linearisation (``"equivalent"``: harmonic, at 0.1 m and
    3 s; ``"linear-part"``). The simulator supplies it through the context's
    :class:`~controllers.base.DesignModel` (built by :mod:`benchmark.simulator.control`).

    Parameters
    ----------
    design_model : DesignModel | None
        The building's design model from the control context (devices, positions, linear plant); None: no
        devices.
    isolation : str, optional
        Linearisation of the bearings: ``"equivalent"`` (harmonic, at 0.1 m and 3 s) or ``"linear-part"``.
    """
    if design_model is None:
        raise InputError("model-based controller: the run's ControlContext carries no design model; "
                         "run it through benchmark.simulator.simulate or give the controller a LinearPlant")
    return design_model.linear_plant(isolation)


def device_models(design_model: DesignModel | None) -> list:
    """Damper model of every device, in device order.

    Parameters
    ----------
    design_model : DesignModel | None
        The building's design model from the control context (devices, positions, linear plant); None: no
        devices.
    """
    if design_model is None:
        raise InputError("the run's ControlContext carries no design model (device models)")
    return list(design_model.device_models)


def device_geometry(design_model: DesignModel | None) -> tuple[np.ndarray, np.ndarray]:
    """Plan positions (n_dev, 2) [m] relative to the base centre of mass, and directions (0 = x, 1 = y).

    Parameters
    ----------
    design_model : DesignModel | None
        The building's design model from the control context (devices, positions, linear plant); None: no
        devices.
    """
    if design_model is None:
        raise InputError("the run's ControlContext carries no design model (device positions)")
    return (np.asarray(design_model.device_positions, dtype=float),
            np.asarray(design_model.device_directions, dtype=int))


def device_force_capacity(model: Any, voltage: float | None = None, amplitude: float = 0.05,
                          frequency: float = 0.5) -> float:
    """Peak force [N] of a damper model at ``voltage`` (default its maximum) under a sinusoidal
    stroke of ``amplitude`` [m] at ``frequency`` [Hz] (peak velocity 0.16 m/s by default), read
    from the second cycle. It sets the force scale of the designs and the modulated law.

    Parameters
    ----------
    model : Any
        A damper model (:class:`damper.models.base.DamperModel`).
    voltage : float, optional
        Voltage [V]; default: the model's maximum.
    amplitude : float, optional
        Stroke amplitude [m].
    frequency : float, optional
        Stroke frequency [Hz].
    """
    v = float(model.voltage_range[1]) if voltage is None else float(voltage)
    try:
        return _capacity_cached(model, v, float(amplitude), float(frequency))
    except TypeError:  # an unhashable model: compute without the cache
        return _capacity(model, v, float(amplitude), float(frequency))


def _capacity(model: Any, v: float, amplitude: float, frequency: float) -> float:
    t = np.linspace(0.0, 2.0 / frequency, 801)
    response = damper.simulate(model, t, amplitude * np.sin(2 * np.pi * frequency * t), v=v)
    second_cycle = response.force[t >= 1.0 / frequency]
    return float(np.max(np.abs(second_cycle)))


_capacity_cached = lru_cache(maxsize=64)(_capacity)
