"""Measurement noise: Gaussian, white at the control step, seeded and precomputed.

The noise of a whole run is drawn at once from a seeded :class:`numpy.random.Generator`
before the run starts and passed to the stepping kernel, so two runs with the same seed are
bit-identical whether the controller is compiled or pure Python. Each group of the
measurement vector (:func:`controllers.base.measurement_slices`) has its own RMS value in SI
units; a sensor's range limit (clipping) can be given per group as well.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from benchmark.foundation.errors import ParameterError
from controllers.base import measurement_layout
from controllers.measurements import N_FLOORS

__all__ = ["MeasurementNoise"]

_GROUPS = {  # field -> measurement groups it applies to
    "acceleration": ("base_acceleration", "floor_acceleration"),
    "displacement": ("base_displacement", "device_displacement"),
    "force": ("device_force",),
}


@dataclass(frozen=True)
class MeasurementNoise:
    """Additive Gaussian measurement noise and sensor range limits.

    Parameters
    ----------
    acceleration_rms : float
        RMS of the noise on absolute accelerations [m/s²] (rotational entries get
        ``acceleration_rms / radius``, see ``rotation_radius``).
    displacement_rms : float
        RMS of the noise on base and device displacements [m].
    force_rms : float
        RMS of the noise on device forces [N].
    rotation_radius : float
        Radius [m] that turns a translational RMS into one for θ entries (rad): the noise of
        a rotation measured by two sensors this far apart.
    acceleration_range, displacement_range, force_range : float
        Sensor range; measurements are clipped to ``±range`` (``inf``: no clipping).
    seed : int, optional
        Seed of the generator (``None``: nondeterministic).
    """

    acceleration_rms: float = 0.0
    displacement_rms: float = 0.0
    force_rms: float = 0.0
    rotation_radius: float = 20.0
    acceleration_range: float = np.inf
    displacement_range: float = np.inf
    force_range: float = np.inf
    seed: int | None = 0

    def __post_init__(self) -> None:
        for name in ("acceleration_rms", "displacement_rms", "force_rms"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value >= 0):
                raise ParameterError(f"MeasurementNoise.{name} must be finite and >= 0, got {value!r}")
        for name in ("acceleration_range", "displacement_range", "force_range", "rotation_radius"):
            value = getattr(self, name)
            if not (value > 0):
                raise ParameterError(f"MeasurementNoise.{name} must be > 0, got {value!r}")

    @property
    def is_zero(self) -> bool:
        """True if the noise adds nothing."""
        return self.acceleration_rms == 0 and self.displacement_rms == 0 and self.force_rms == 0

    def rms_vector(self, n_devices: int, n_floors: int = N_FLOORS) -> np.ndarray:
        """RMS of each entry of the measurement vector (SI).

        Parameters
        ----------
        n_devices : int
            Number of controlled devices (MR dampers) in the building.
        n_floors : int, optional
            Floors above the base (the benchmark's 8 by default; :mod:`controllers.measurements`).
        """
        return self._per_entry(n_devices, n_floors, "rms", 0.0)

    def _per_entry(self, n_devices: int, n_floors: int, kind: str, default: float) -> np.ndarray:
        lay = measurement_layout(n_devices, n_floors)
        out = np.full(lay.n_measurements, default)
        slices = lay.slices()
        for field_name, groups in _GROUPS.items():
            for group in groups:
                out[slices[group]] = getattr(self, f"{field_name}_{kind}")
        # θ entries (every third one of the accelerations and base displacements) are rotations:
        # scale by the radius.
        out[2:lay.base_displacement + 3:3] /= self.rotation_radius
        return out

    def range_vector(self, n_devices: int, n_floors: int = N_FLOORS) -> np.ndarray:
        """Sensor range of each entry (``inf``: unlimited).

        Parameters
        ----------
        n_devices : int
            Number of controlled devices (MR dampers) in the building.
        n_floors : int, optional
            Floors above the base (the benchmark's 8 by default; :mod:`controllers.measurements`).
        """
        return self._per_entry(n_devices, n_floors, "range", np.inf)

    def sample(self, n_steps: int, n_devices: int, rng: np.random.Generator | None = None,
               n_floors: int = N_FLOORS) -> np.ndarray:
        """Draw the noise of a whole run, shape ``(n_steps, n_measurements)`` (``30 + 2 n_devices``
        on the benchmark's 8 floors; SI units).

        The same seed gives the same array; pass ``rng`` to draw from a caller's generator.

        Parameters
        ----------
        n_steps : int
            Number of control steps of the run.
        n_devices : int
            Number of controlled devices (MR dampers) in the building.
        rng : np.random.Generator | None, optional
            Generator to draw from; None: a new one seeded with the noise model's seed.
        n_floors : int, optional
            Floors above the base (the benchmark's 8 by default; :mod:`controllers.measurements`).
        """
        generator = rng if rng is not None else np.random.default_rng(self.seed)
        rms = self.rms_vector(n_devices, n_floors)
        return generator.standard_normal((int(n_steps), rms.size)) * rms

    def apply(self, measurements: np.ndarray, noise: np.ndarray | None, n_devices: int,
              n_floors: int = N_FLOORS) -> np.ndarray:
        """Return ``measurements + noise`` clipped to the sensor ranges.

        Parameters
        ----------
        measurements : np.ndarray
            Clean measurement vector (SI).
        noise : np.ndarray | None
            Noise for this step (a row of :meth:`sample`), or None for none.
        n_devices : int
            Number of controlled devices (MR dampers) in the building.
        n_floors : int, optional
            Floors above the base (the benchmark's 8 by default; :mod:`controllers.measurements`).
        """
        y = measurements if noise is None else measurements + noise
        limits = self.range_vector(n_devices, n_floors)
        if np.all(np.isinf(limits)):
            return y
        return np.clip(y, -limits, limits)
