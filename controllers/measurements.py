"""The measurement vector a controller sees: its layout, defined once for the whole project.

Order (all SI), as produced by the simulator's sensors (:mod:`benchmark.simulator.sensors`) and
the stepping kernel, and as read by every controller, the plant's output matrices and the noise
models:

====================  ======  =====================================================================
entries               count   quantity
====================  ======  =====================================================================
0–2                   3       absolute acceleration of the base (x, y [m/s²], θ [rad/s²]) at its
                              centre of mass: :math:`\\ddot u_b + \\ddot u_g`
3–26                  24      absolute accelerations of floors 1..8 (x, y, θ each):
                              :math:`\\ddot u_s + R(\\ddot u_b + \\ddot u_g)`
27–29                 3       base displacement relative to the ground (x, y [m], θ [rad])
30 … 30+n−1           n       device displacements [m] (along each device's direction)
30+n … 30+2n−1        n       device forces [N] (device sign convention)
====================  ======  =====================================================================

The layout belongs to the controller interface (what a controller is told), so it lives in the
controllers library; the simulator, which sits above, builds its output rows from it
(Narasimhan et al. 2006, Sec. 4, list the same sensors: accelerations at the base and floors,
base displacement, device displacements and forces).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["N_ACCELERATIONS", "MeasurementLayout", "measurement_layout", "measurement_slices",
           "n_measurements", "measurement_names"]

#: Absolute accelerations of the base (x, y, θ) and of floors 1..8 (x, y, θ each).
N_ACCELERATIONS = 27
#: Entries before the device channels: 27 accelerations and 3 base displacements.
_N_FIXED = N_ACCELERATIONS + 3


@dataclass(frozen=True)
class MeasurementLayout:
    """Layout of the measurement vector for ``n_devices`` devices (module docstring).

    Attributes
    ----------
    n_devices : int
        Number of devices (one displacement and one force channel each).
    """

    n_devices: int

    @property
    def size(self) -> int:
        """Length of the measurement vector, ``30 + 2 n_devices``."""
        return _N_FIXED + 2 * self.n_devices

    @property
    def base_acceleration(self) -> slice:
        """Absolute base accelerations (x, y [m/s²], θ [rad/s²])."""
        return slice(0, 3)

    @property
    def floor_acceleration(self) -> slice:
        """Absolute floor accelerations, floor 1 → 8, (x, y, θ) each."""
        return slice(3, N_ACCELERATIONS)

    @property
    def accelerations(self) -> slice:
        """All 27 absolute accelerations (base, then floors)."""
        return slice(0, N_ACCELERATIONS)

    @property
    def base_displacement(self) -> slice:
        """Base displacement relative to the ground (x, y [m], θ [rad])."""
        return slice(N_ACCELERATIONS, _N_FIXED)

    @property
    def device_displacement(self) -> slice:
        """Device displacements [m]."""
        return slice(_N_FIXED, _N_FIXED + self.n_devices)

    @property
    def device_force(self) -> slice:
        """Device forces [N]."""
        return slice(_N_FIXED + self.n_devices, _N_FIXED + 2 * self.n_devices)

    def slices(self) -> dict[str, slice]:
        """Slices by quantity: ``base_acceleration``, ``floor_acceleration``,
        ``base_displacement``, ``device_displacement``, ``device_force``."""
        return {"base_acceleration": self.base_acceleration,
                "floor_acceleration": self.floor_acceleration,
                "base_displacement": self.base_displacement,
                "device_displacement": self.device_displacement,
                "device_force": self.device_force}

    def names(self) -> list[str]:
        """Names of the entries, units in brackets."""
        dofs = (("x", "m/s2"), ("y", "m/s2"), ("theta", "rad/s2"))
        names = [f"a_base_{d} [{u}]" for d, u in dofs]
        names += [f"a_floor{f}_{d} [{u}]" for f in range(1, 9) for d, u in dofs]
        names += ["u_base_x [m]", "u_base_y [m]", "u_base_theta [rad]"]
        names += [f"x_device{j + 1} [m]" for j in range(self.n_devices)]
        names += [f"f_device{j + 1} [N]" for j in range(self.n_devices)]
        return names


def measurement_layout(n_devices: int) -> MeasurementLayout:
    """The :class:`MeasurementLayout` for ``n_devices`` devices."""
    return MeasurementLayout(int(n_devices))


def measurement_slices(n_devices: int) -> dict[str, slice]:
    """Slices of the measurement vector by quantity (:meth:`MeasurementLayout.slices`)."""
    return measurement_layout(n_devices).slices()


def n_measurements(n_devices: int) -> int:
    """Length of the measurement vector for ``n_devices`` devices (``30 + 2 n_devices``)."""
    return measurement_layout(n_devices).size


def measurement_names(n_devices: int) -> list[str]:
    """Names of the measurement vector entries (units in brackets)."""
    return measurement_layout(n_devices).names()
