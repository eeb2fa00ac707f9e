"""The one layout of the measurement vector, shared by sensors, plant, controllers and kernel.

A controller sees, at every control step, the vector (docs/ARCHITECTURE.md, "Measurements";
all SI)

====================  ======  =====================================================================
entries               count   quantity
====================  ======  =====================================================================
0–2                   3       absolute acceleration of the base (x, y [m/s²], θ [rad/s²])
3–26                  24      absolute accelerations of floors 1..8 (x, y, θ each)
27–29                 3       base displacement relative to the ground (x, y [m], θ [rad])
30 … 30+n−1           n       device displacements [m] (along each device's direction)
30+n … 30+2n−1        n       device forces [N] (device sign convention)
====================  ======  =====================================================================

:func:`measurement_layout` returns these offsets as a :class:`MeasurementLayout` (a named
tuple of ints, so the numba stepping kernel reads the same object as the Python code).
Every other module (:mod:`benchmark.sensors`, :mod:`benchmark.linear_model`,
:mod:`controllers.base`, :mod:`benchmark.stepping`) takes its offsets from here; the numbers
27 and 30 are written nowhere else. This module imports only :mod:`benchmark.errors` from the project.
"""

from __future__ import annotations

from typing import NamedTuple

from benchmark.errors import InputError

__all__ = ["MeasurementLayout", "measurement_layout", "N_ACCELERATIONS", "N_BASE_DISPLACEMENTS"]

#: Absolute accelerations: base (x, y, θ) and floors 1..8 (x, y, θ each).
N_ACCELERATIONS = 27
#: Base displacements relative to the ground (x, y, θ).
N_BASE_DISPLACEMENTS = 3


class MeasurementLayout(NamedTuple):
    """Offsets of the measurement vector's blocks (see the module docstring).

    Attributes
    ----------
    n_accelerations : int
        Number of absolute accelerations (27), at ``0:n_accelerations``.
    base_displacement : int
        Offset of the 3 base displacements.
    device_displacement : int
        Offset of the ``n_devices`` device displacements.
    device_force : int
        Offset of the ``n_devices`` device forces.
    n_devices : int
    n_measurements : int
        Length of the vector (``30 + 2 n_devices``).
    """

    n_accelerations: int
    base_displacement: int
    device_displacement: int
    device_force: int
    n_devices: int
    n_measurements: int

    def slices(self) -> dict[str, slice]:
        """Slices of the vector by quantity: ``base_acceleration``, ``floor_acceleration``,
        ``base_displacement``, ``device_displacement``, ``device_force``."""
        return {"base_acceleration": slice(0, 3), "floor_acceleration": slice(3, self.n_accelerations),
                "base_displacement": slice(self.base_displacement, self.base_displacement + N_BASE_DISPLACEMENTS),
                "device_displacement": slice(self.device_displacement, self.device_displacement + self.n_devices),
                "device_force": slice(self.device_force, self.device_force + self.n_devices)}


def measurement_layout(n_devices: int) -> MeasurementLayout:
    """The layout for ``n_devices`` devices (``n_devices >= 0``)."""
    n = int(n_devices)
    if n < 0:
        raise InputError(f"measurement layout: n_devices must be >= 0, got {n_devices!r}")
    base = N_ACCELERATIONS
    dev = base + N_BASE_DISPLACEMENTS
    return MeasurementLayout(n_accelerations=N_ACCELERATIONS, base_displacement=base,
                             device_displacement=dev, device_force=dev + n, n_devices=n,
                             n_measurements=dev + 2 * n)
