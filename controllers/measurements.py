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

The offsets are those of the benchmark's eight floors. A variant structure file with another
number of floors (``n_floors``, :mod:`benchmark.simulator.structure`) has ``3 + 3 n_floors``
accelerations and every later block moves with them; every function here takes ``n_floors``, and
:func:`layout_of` reads it back from a vector's length.

:func:`measurement_layout` returns these offsets as a :class:`MeasurementLayout` (a named
tuple of ints, so the numba stepping kernel reads the same object as the Python code).
Every other module (:mod:`benchmark.simulator.sensors`, :mod:`benchmark.simulator.linear_model`,
:mod:`controllers.base`, :mod:`benchmark.simulator.stepping`) takes its offsets from here; the
numbers 27 and 30 are written nowhere else. This module imports only the foundation.
"""

from __future__ import annotations

from typing import NamedTuple

from benchmark.foundation.errors import InputError

__all__ = ["MeasurementLayout", "measurement_layout", "layout_of", "N_FLOORS", "N_ACCELERATIONS",
           "N_BASE_DISPLACEMENTS", "measurement_slices", "n_measurements", "measurement_names"]

#: Floors above the base in the benchmark (a variant structure file may have others).
N_FLOORS = 8
#: Absolute accelerations of the benchmark: base (x, y, θ) and floors 1..8 (x, y, θ each).
N_ACCELERATIONS = 3 + 3 * N_FLOORS
#: Base displacements relative to the ground (x, y, θ).
N_BASE_DISPLACEMENTS = 3


class MeasurementLayout(NamedTuple):
    """Offsets of the measurement vector's blocks (see the module docstring).

    Attributes
    ----------
    n_accelerations : int
        Number of absolute accelerations (``3 + 3 n_floors``: 27 in the benchmark), at
        ``0:n_accelerations``.
    base_displacement : int
        Offset of the 3 base displacements.
    device_displacement : int
        Offset of the ``n_devices`` device displacements.
    device_force : int
        Offset of the ``n_devices`` device forces.
    n_devices : int
    n_measurements : int
        Length of the vector (``n_accelerations + 3 + 2 n_devices``).
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


def measurement_layout(n_devices: int, n_floors: int = N_FLOORS) -> MeasurementLayout:
    """The layout for ``n_devices`` devices (``n_devices >= 0``) on ``n_floors`` floors.

    Parameters
    ----------
    n_devices : int
        Number of controlled devices (MR dampers) in the building.
    n_floors : int, optional
        Floors above the base (the benchmark's 8 by default).
    """
    n = int(n_devices)
    if n < 0:
        raise InputError(f"measurement layout: n_devices must be >= 0, got {n_devices!r}")
    floors = int(n_floors)
    if floors < 1:
        raise InputError(f"measurement layout: n_floors must be >= 1, got {n_floors!r}")
    base = 3 + 3 * floors
    dev = base + N_BASE_DISPLACEMENTS
    return MeasurementLayout(n_accelerations=base, base_displacement=base,
                             device_displacement=dev, device_force=dev + n, n_devices=n,
                             n_measurements=dev + 2 * n)


def layout_of(n_measurements: int, n_devices: int) -> MeasurementLayout:
    """The layout whose vector has ``n_measurements`` entries for ``n_devices`` devices.

    A design that holds a plant whose outputs are the measurement vector reads the number of
    floors from it this way, so that no design needs to be told the building's height.

    Parameters
    ----------
    n_measurements : int
        Length of the measurement vector (rows of the plant's output matrix).
    n_devices : int
        Number of controlled devices (MR dampers) in the building.

    Raises
    ------
    InputError
        If no whole number of floors gives that length.
    """
    floors, rest = divmod(int(n_measurements) - 6 - 2 * int(n_devices), 3)
    if rest or floors < 1:
        raise InputError(f"measurement layout: {n_measurements} measurements for {n_devices} devices is no "
                         "whole number of floors (expected 6 + 3 n_floors + 2 n_devices)")
    return measurement_layout(n_devices, floors)


def measurement_slices(n_devices: int, n_floors: int = N_FLOORS) -> dict[str, slice]:
    """Slices of the measurement vector by quantity (:meth:`MeasurementLayout.slices`).

    Parameters
    ----------
    n_devices : int
        Number of controlled devices (MR dampers) in the building.
    n_floors : int, optional
        Floors above the base (the benchmark's 8 by default).
    """
    return measurement_layout(n_devices, n_floors).slices()


def n_measurements(n_devices: int, n_floors: int = N_FLOORS) -> int:
    """Length of the measurement vector (``30 + 2 n_devices`` on the benchmark's 8 floors).

    Parameters
    ----------
    n_devices : int
        Number of controlled devices (MR dampers) in the building.
    n_floors : int, optional
        Floors above the base (the benchmark's 8 by default).
    """
    return measurement_layout(n_devices, n_floors).n_measurements


def measurement_names(n_devices: int, n_floors: int = N_FLOORS) -> list[str]:
    """Names of the measurement vector entries (units in brackets).

    Parameters
    ----------
    n_devices : int
        Number of controlled devices (MR dampers) in the building.
    n_floors : int, optional
        Floors above the base (the benchmark's 8 by default).
    """
    dofs = (("x", "m/s2"), ("y", "m/s2"), ("theta", "rad/s2"))
    names = [f"a_base_{d} [{u}]" for d, u in dofs]
    names += [f"a_floor{f}_{d} [{u}]" for f in range(1, int(n_floors) + 1) for d, u in dofs]
    names += ["u_base_x [m]", "u_base_y [m]", "u_base_theta [rad]"]
    names += [f"x_device{j + 1} [m]" for j in range(n_devices)]
    names += [f"f_device{j + 1} [N]" for j in range(n_devices)]
    return names
