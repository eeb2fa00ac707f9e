"""The one layout of the measurement vector, shared by sensors, plant, controllers and kernel.

It belongs to the controller interface (what a controller is told), so it lives in the
controllers library; the simulator, which sits above, builds its output rows and its kernel
from it (Narasimhan et al. 2006, Part I, list the same sensors).

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
Every other module (:mod:`benchmark.simulator.sensors`, :mod:`benchmark.simulator.linear_model`,
:mod:`controllers.base`, :mod:`benchmark.simulator.stepping`) takes its offsets from here; the
numbers 27 and 30 are written nowhere else. This module imports only the foundation.
"""

from __future__ import annotations

from typing import NamedTuple

from benchmark.foundation.errors import InputError

__all__ = ["MeasurementLayout", "measurement_layout", "N_ACCELERATIONS", "N_BASE_DISPLACEMENTS",
           "measurement_slices", "n_measurements", "measurement_names"]

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
    """The layout for ``n_devices`` devices (``n_devices >= 0``).

    Parameters
    ----------
    n_devices : int
        Number of controlled devices (MR dampers) in the building.
    """
    n = int(n_devices)
    if n < 0:
        raise InputError(f"measurement layout: n_devices must be >= 0, got {n_devices!r}")
    base = N_ACCELERATIONS
    dev = base + N_BASE_DISPLACEMENTS
    return MeasurementLayout(n_accelerations=N_ACCELERATIONS, base_displacement=base,
                             device_displacement=dev, device_force=dev + n, n_devices=n,
                             n_measurements=dev + 2 * n)


def measurement_slices(n_devices: int) -> dict[str, slice]:
    """Slices of the measurement vector by quantity (:meth:`MeasurementLayout.slices`).

    Parameters
    ----------
    n_devices : int
        Number of controlled devices (MR dampers) in the building.
    """
    return measurement_layout(n_devices).slices()


def n_measurements(n_devices: int) -> int:
    """Length of the measurement vector for ``n_devices`` devices (``30 + 2 n_devices``).

    Parameters
    ----------
    n_devices : int
        Number of controlled devices (MR dampers) in the building.
    """
    return measurement_layout(n_devices).n_measurements


def measurement_names(n_devices: int) -> list[str]:
    """Names of the measurement vector entries (units in brackets).

    Parameters
    ----------
    n_devices : int
        Number of controlled devices (MR dampers) in the building.
    """
    dofs = (("x", "m/s2"), ("y", "m/s2"), ("theta", "rad/s2"))
    names = [f"a_base_{d} [{u}]" for d, u in dofs]
    names += [f"a_floor{f}_{d} [{u}]" for f in range(1, 9) for d, u in dofs]
    names += ["u_base_x [m]", "u_base_y [m]", "u_base_theta [rad]"]
    names += [f"x_device{j + 1} [m]" for j in range(n_devices)]
    names += [f"f_device{j + 1} [N]" for j in range(n_devices)]
    return names
