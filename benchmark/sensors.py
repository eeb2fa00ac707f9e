"""The measurement vector a controller sees at each control step, and its noise.

Order (docs/ARCHITECTURE.md, "Measurements"), all SI:

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

The state-space rows that produce it are built in :mod:`benchmark.linear_model`
(``C``, ``D``) and, for the nonlinear simulation, inside the stepping kernel from the same
matrices.

Noise (:func:`noise_samples`) is precomputed in Python from a seeded
:class:`numpy.random.Generator` and added inside the kernel, so runs are bit-identical for the
same seed.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from benchmark.errors import InputError
from benchmark.measurement_layout import N_ACCELERATIONS, measurement_layout

__all__ = ["measurement_names", "measurement_slices", "n_measurements", "noise_samples",
           "N_ACCELERATIONS"]


def n_measurements(n_devices: int) -> int:
    """Length of the measurement vector: ``30 + 2 n_devices`` (:mod:`benchmark.measurement_layout`)."""
    return measurement_layout(n_devices).n_measurements


def measurement_slices(n_devices: int) -> dict[str, slice]:
    """Slices of the measurement vector by quantity (:mod:`benchmark.measurement_layout`)."""
    return measurement_layout(n_devices).slices()


def measurement_names(n_devices: int) -> list[str]:
    """Names of the measurement vector entries (units in brackets)."""
    dofs = (("x", "m/s2"), ("y", "m/s2"), ("theta", "rad/s2"))
    names = [f"a_base_{d} [{u}]" for d, u in dofs]
    names += [f"a_floor{f}_{d} [{u}]" for f in range(1, 9) for d, u in dofs]
    names += ["u_base_x [m]", "u_base_y [m]", "u_base_theta [rad]"]
    names += [f"x_device{j + 1} [m]" for j in range(n_devices)]
    names += [f"f_device{j + 1} [N]" for j in range(n_devices)]
    return names


def noise_samples(noise: Any, n_control: int, n_devices: int,
                  seed: int | None = None) -> tuple[np.ndarray, np.ndarray]:
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

    Returns
    -------
    samples : (n_control, n_meas) array
        Added to the measurements inside the kernel.
    ranges : (n_meas,) array
        Sensor ranges: noisy measurements are clipped to ``±range`` (``inf``: none).
    """
    n_meas = n_measurements(n_devices)
    ranges = np.full(n_meas, np.inf)
    if noise is None or (np.isscalar(noise) and float(noise) == 0.0):
        return np.zeros((n_control, n_meas)), ranges
    if hasattr(noise, "sample") and callable(noise.sample):
        rng = None if seed is None else np.random.default_rng(seed)
        out = np.asarray(noise.sample(n_control, n_devices, rng=rng), dtype=float)
        if hasattr(noise, "range_vector"):
            ranges = np.asarray(noise.range_vector(n_devices), dtype=float)
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
