"""The building as the model-based controllers see it: linear plant, device geometry, device capacity.

Everything here reads the building through its public contracts
(:mod:`benchmark.linear_model`, :mod:`benchmark.devices`, :mod:`damper`), so a controller
design never reaches into the stepping kernel.
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any

import numpy as np

from benchmark.errors import InputError
from controllers.lqg import LinearPlant

__all__ = ["building_plant", "device_geometry", "device_models", "device_force_capacity"]


def building_plant(building: Any, isolation: str = "equivalent") -> LinearPlant:
    """Continuous linear plant of ``building`` with linearised isolation (:mod:`benchmark.linear_model`).

    ``x' = A x + B f + E ü_g``, ``y = C x + D f``: ``f`` the device forces [N] (resisting force,
    as measured), ``ü_g`` the ground acceleration (x, y) [m/s²], ``y`` the measurement vector.
    ``isolation`` selects the bearings' linearisation (``"equivalent"``: harmonic, at 0.1 m and
    3 s; ``"linear-part"``), see :func:`benchmark.linear_model.linear_model`.
    """
    if building is None:
        raise InputError("model-based controller: the run's ControlContext carries no building; "
                         "pass ControlContext(building=...) or give the controller a LinearPlant")
    try:
        from benchmark import linear_model
    except ImportError as exc:  # pragma: no cover - only while the package is being assembled
        raise InputError(f"model-based controller needs benchmark.linear_model ({exc})") from None
    model = linear_model.linear_model(building, isolation=isolation)
    return LinearPlant(A=model.A, B=model.B, E=model.E, C=model.C, D=model.D)


def device_models(building: Any) -> list:
    """Damper model of every device slot, in device order."""
    devices = getattr(building, "devices", None)
    if devices is None:
        raise InputError("the building has no device layout (building.devices)")
    for attr in ("models", "dampers"):
        if hasattr(devices, attr):
            return list(getattr(devices, attr))
    slots = getattr(devices, "slots", devices)
    return [getattr(slot, "model", None) or getattr(slot, "damper") for slot in slots]


def device_geometry(building: Any) -> tuple[np.ndarray, np.ndarray]:
    """Plan positions (n_dev, 2) [m] relative to the base centre of mass, and directions (0 = x, 1 = y)."""
    devices = getattr(building, "devices", None)
    if devices is None:
        raise InputError("the building has no device layout (building.devices)")
    for attr in ("xy", "positions"):
        if hasattr(devices, attr) and hasattr(devices, "directions"):
            return np.asarray(getattr(devices, attr), dtype=float), np.asarray(devices.directions, dtype=int)
    slots = getattr(devices, "slots", devices)
    pos = np.array([[float(getattr(s, "x")), float(getattr(s, "y"))] for s in slots])
    dirs = np.array([int(getattr(s, "direction")) for s in slots])
    return pos, dirs


def device_force_capacity(model: Any, voltage: float | None = None, amplitude: float = 0.05,
                          frequency: float = 0.5) -> float:
    """Peak force [N] of a damper model at ``voltage`` (default its maximum) under a sinusoidal
    stroke of ``amplitude`` [m] at ``frequency`` [Hz] (peak velocity 0.16 m/s by default), read
    from the second cycle. It sets the force scale of the designs and the modulated law."""
    v = float(model.voltage_range[1]) if voltage is None else float(voltage)
    try:
        return _capacity_cached(model, v, float(amplitude), float(frequency))
    except TypeError:  # an unhashable model: compute without the cache
        return _capacity(model, v, float(amplitude), float(frequency))


def _capacity(model: Any, v: float, amplitude: float, frequency: float) -> float:
    import damper

    t = np.linspace(0.0, 2.0 / frequency, 801)
    response = damper.simulate(model, t, amplitude * np.sin(2 * np.pi * frequency * t), v=v)
    second_cycle = response.force[t >= 1.0 / frequency]
    return float(np.max(np.abs(second_cycle)))


_capacity_cached = lru_cache(maxsize=64)(_capacity)
