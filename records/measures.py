"""Scalar intensity measures of a ground-motion component: Arias intensity, significant duration, mean period.

These are what the synthetic generator is calibrated to and what its tests compare.

References
----------
Arias, A. (1970) A measure of earthquake intensity. In *Seismic Design for Nuclear Power
Plants*, MIT Press, 438–483.
Trifunac, M. D. & Brady, A. G. (1975) A study on the duration of strong earthquake ground
motion. *Bull. Seism. Soc. Am.* 65(3), 581–626.
Rathje, E. M., Faraj, F., Russell, S. & Bray, J. D. (2004) Empirical relationships for
frequency content parameters of earthquake ground motions. *Earthquake Spectra* 20(1), 119–144.
"""

from __future__ import annotations

import numpy as np

from benchmark.foundation.errors import InputError

__all__ = ["arias_intensity", "husid", "significant_duration", "mean_period"]


def _component(acceleration: np.ndarray) -> np.ndarray:
    a = np.asarray(acceleration, dtype=float)
    if a.ndim != 1 or a.size < 2:
        raise InputError(f"expected one acceleration component of at least 2 samples, got shape {a.shape}")
    return a


def _cumulative_square(acceleration: np.ndarray, dt: float) -> np.ndarray:
    """:math:`\\int_0^{t_k} a^2\\,dt` at every sample (trapezoidal rule)."""
    a2 = _component(acceleration) ** 2
    return np.concatenate(([0.0], np.cumsum(0.5 * dt * (a2[1:] + a2[:-1]))))


def husid(acceleration: np.ndarray, dt: float) -> np.ndarray:
    """Normalised cumulative Arias intensity (Husid plot), from 0 to 1 over the samples.

    .. math:: H(t_k) = \\int_0^{t_k} a^2\\,dt \\Big/ \\int_0^{T} a^2\\,dt

    (trapezoidal rule). An all-zero component gives all zeros.

    Parameters
    ----------
    acceleration : ndarray, shape (n,)
        One component [m/s²].
    dt : float
        Time step [s].
    """
    cum = _cumulative_square(acceleration, dt)
    return cum / cum[-1] if cum[-1] > 0 else cum


def arias_intensity(acceleration: np.ndarray, dt: float) -> float:
    """Arias intensity :math:`I_a = \\frac{\\pi}{2g}\\int_0^T a(t)^2\\,dt` [m/s].

    Parameters
    ----------
    acceleration : ndarray, shape (n,)
        One component [m/s²].
    dt : float
        Time step [s].
    """
    return float(np.pi / (2 * 9.80665) * _cumulative_square(acceleration, dt)[-1])


def significant_duration(acceleration: np.ndarray, dt: float, start: float = 0.05,
                         end: float = 0.95) -> float:
    """Significant duration [s]: time between ``start`` and ``end`` fractions of the Arias intensity.

    Default D5–95 (Trifunac & Brady 1975). Crossing times are interpolated linearly between
    samples.

    Parameters
    ----------
    acceleration : ndarray, shape (n,)
        One component [m/s²].
    dt : float
        Time step [s].
    start, end : float
        Fractions of the Arias intensity (0 ≤ start < end ≤ 1).
    """
    if not 0.0 <= start < end <= 1.0:
        raise InputError(f"significant duration fractions start={start}, end={end}; expected 0 <= start < end <= 1")
    h = husid(acceleration, dt)
    if h[-1] == 0:
        return 0.0
    t = np.arange(h.size) * dt
    return float(np.interp(end, h, t) - np.interp(start, h, t))


def mean_period(acceleration: np.ndarray, dt: float, f_min: float = 0.25, f_max: float = 20.0) -> float:
    """Mean period T_m [s] (Rathje et al. 2004) from the Fourier amplitudes C_i between f_min and f_max [Hz].

    .. math:: T_m = \\frac{\\sum_i C_i^2 / f_i}{\\sum_i C_i^2}, \\quad f_{min} \\le f_i \\le f_{max}

    Parameters
    ----------
    acceleration : ndarray, shape (n,)
        One component [m/s²].
    dt : float
        Time step [s].
    f_min, f_max : float
        Frequency band [Hz] (f_max is capped at the Nyquist frequency).
    """
    a = _component(acceleration)
    freq = np.fft.rfftfreq(a.size, dt)
    amp2 = np.abs(np.fft.rfft(a)) ** 2
    band = (freq >= f_min) & (freq <= min(f_max, 0.5 / dt))
    if not band.any() or amp2[band].sum() == 0:
        raise InputError(f"mean period: no spectral content between {f_min} and {f_max} Hz")
    return float(np.sum(amp2[band] / freq[band]) / np.sum(amp2[band]))
