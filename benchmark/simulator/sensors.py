"""The sensors: the measurement vector a controller sees at each control step, and its noise.

The layout of the vector (27 absolute accelerations on the benchmark's 8 floors, ``3 + 3 n_floors``
on a variant; the base displacement, the device
displacements and forces) is defined once, in :mod:`controllers.measurements`, and used here, in
:mod:`benchmark.simulator.linear_model` (the output rows ``C``, ``D``), in the stepping kernel and
by every controller.

Noise (:func:`noise_samples`) is precomputed in Python from a seeded
:class:`numpy.random.Generator` and added inside the kernel, so runs are bit-identical for the
same seed.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from benchmark.foundation.errors import InputError
from controllers.measurements import (N_ACCELERATIONS, N_FLOORS, MeasurementLayout, measurement_layout,
                                      measurement_names, measurement_slices, n_measurements)

__all__ = ["measurement_names", "measurement_slices", "n_measurements", "noise_samples",
           "N_ACCELERATIONS", "MeasurementLayout", "measurement_layout"]


def noise_samples(noise: Any, n_control: int, n_devices: int,
                  seed: int | None = None, n_floors: int = N_FLOORS) -> tuple[np.ndarray, np.ndarray]:
    """Measurement noise for every control step and the sensor ranges.

    Parameters
    ----------
    noise : None, array or noise object
        ``None`` or ``0``: no noise.
        array ``(n_meas,)``: standard deviation of white Gaussian noise per channel (SI units of
        the channel).
        array ``(n_control, n_meas)``: the noise itself (used as given).
        object with ``sample(n_steps, n_devices, rng=None)`` (e.g.
        :class:`controllers.noise.MeasurementNoise`): called with a generator seeded by ``seed``
        when ``seed`` is given (else the object's own seed); its ``range_vector(n_devices)``, if
        any, gives the sensor ranges.
    n_control : int
        Number of control steps.
    n_devices : int
        Number of devices (sets ``n_meas = 30 + 2 n_devices``).
    seed : int, optional
        Seed of the :class:`numpy.random.Generator`.
    n_floors : int, optional
        Floors above the base (the benchmark's 8 by default). A noise object is told it (keyword
        ``n_floors``) only on a building of another height, so objects written for the benchmark's
        signature keep working on it.

    Returns
    -------
    samples : (n_control, n_meas) array
        Added to the measurements inside the kernel.
    ranges : (n_meas,) array
        Sensor ranges: noisy measurements are clipped to ``±range`` (``inf``: none).
    """
    n_meas = n_measurements(n_devices, n_floors)
    ranges = np.full(n_meas, np.inf)
    height = {} if n_floors == N_FLOORS else {"n_floors": n_floors}
    if noise is None or (np.isscalar(noise) and float(noise) == 0.0):
        return np.zeros((n_control, n_meas)), ranges
    if hasattr(noise, "sample") and callable(noise.sample):
        rng = None if seed is None else np.random.default_rng(seed)
        try:
            out = np.asarray(noise.sample(n_control, n_devices, rng=rng, **height), dtype=float)
            if hasattr(noise, "range_vector"):
                ranges = np.asarray(noise.range_vector(n_devices, **height), dtype=float)
        except TypeError as exc:
            if height and "n_floors" in str(exc):
                raise InputError(f"noise: {type(noise).__name__}.sample / range_vector take no n_floors, and the "
                                 f"building has {n_floors} floors ({n_meas} measurements, not the benchmark's "
                                 f"{n_measurements(n_devices)}); accept n_floors=, as "
                                 "controllers.noise.MeasurementNoise does") from None
            raise
    else:
        rng = np.random.default_rng(seed)
        arr = np.asarray(noise, dtype=float)
        if arr.ndim == 0:
            raise InputError("noise: a single number is ambiguous across channels with different units; "
                             f"give {n_meas} standard deviations (one per measurement, SI) or a noise object")
        if arr.shape == (n_meas,):
            if np.any(arr < 0) or not np.all(np.isfinite(arr)):
                raise InputError("noise: standard deviations must be finite and >= 0")
            out = rng.standard_normal((n_control, n_meas)) * arr
        else:
            out = arr
    if out.shape != (n_control, n_meas):
        raise InputError(f"noise: shape {out.shape}; expected ({n_meas},) standard deviations or "
                         f"({n_control}, {n_meas}) samples")
    if not np.all(np.isfinite(out)):
        raise InputError("noise: samples contain NaN or inf")
    if ranges.shape != (n_meas,) or np.any(ranges <= 0):
        raise InputError(f"noise: sensor ranges must be {n_meas} positive values")
    return np.ascontiguousarray(out), np.ascontiguousarray(ranges)
