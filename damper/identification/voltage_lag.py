"""Identification of the coil/field lag from a voltage-switching test.

Constant-voltage tests (the seed paper's procedure) cannot see how fast the damper follows a
change of the commanded voltage. Under a semi-active controller the voltage switches many
times a second, so a model identified at constant voltage is also given a first-order field
filter (Spencer et al. 1997, :math:`\\dot u = -\\eta(u - v)`, :math:`\\tau = 1/\\eta`):

.. math:: \\tau\\dot u = v - u, \\qquad F = F_\\text{model}(x, \\dot x; u).

:math:`\\tau` is fitted by bounded scalar least squares on a test run through
:func:`damper.lab.laboratory.general_test`: a sinusoidal displacement with the voltage switched
between 0 and 1 V as a square wave, the voltage-dependent model fixed. The filter is
:func:`damper.models.field_filter.first_order_filter` (exact for piecewise-linear input).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from benchmark.foundation.errors import InputError
from damper.models.field_filter import first_order_filter
from damper.models.response import simulate
from damper.identification.metrics import relative_rms_error
from damper.lab.laboratory import general_test, resolve_device

__all__ = ["LagFit", "switching_test", "fit_voltage_lag", "filtered_force"]


@dataclass(frozen=True)
class LagFit:
    """Fitted field time constant.

    Attributes
    ----------
    tau : float
        Time constant [s] (0: no lag).
    rel_rms_error, rel_rms_error_without_lag : float
        Force error of the model on the switching test with and without the fitted filter.
    """

    tau: float
    rel_rms_error: float
    rel_rms_error_without_lag: float


def switching_test(device, amplitude: float = 0.1, frequency: float = 0.5, switch_period: float = 0.4,
                   duration: float = 4.0, sample_rate: float = 1000.0, noise: float = 0.0, seed: int = 0):
    """Run the switching test on ``device`` through the virtual laboratory.

    Displacement :math:`X\\sin(2\\pi f t)`; voltage a square wave 0 V / 1 V of period
    ``switch_period`` [s] (the device's own voltage range is used).

    Parameters
    ----------
    device
        The damper tested: a model instance, or the name of a parameterless model
        (:func:`damper.lab.laboratory.resolve_device`).
    amplitude : float, optional
        Displacement amplitude [m].
    frequency : float, optional
        Frequency of the motion [Hz].
    switch_period : float, optional
        Time [s] between voltage switches.
    duration : float, optional
        Length [s].
    sample_rate : float, optional
        Samples per second [Hz].
    noise : float, optional
        Relative RMS measurement noise on the force (0: none).
    seed : int, optional
        Seed of the random generator (the same seed gives the same result).
    """

    model = resolve_device(device)
    lo, hi = model.voltage_range
    t = np.arange(0.0, duration, 1.0 / sample_rate)
    x = amplitude * np.sin(2 * np.pi * frequency * t)
    xdot = amplitude * 2 * np.pi * frequency * np.cos(2 * np.pi * frequency * t)
    v = np.where(np.mod(t, switch_period) < 0.5 * switch_period, lo, hi)
    return general_test(model, t, x, v, noise=noise, seed=seed, xdot=xdot)


def filtered_force(model, t: np.ndarray, x: np.ndarray, xdot: np.ndarray, v: np.ndarray,
                   tau: float) -> np.ndarray:
    """Force of ``model`` driven by the filtered voltage :math:`u` (:math:`\\tau\\dot u = v - u`) [N].

    Parameters
    ----------
    model
        The damper model.
    t : np.ndarray
        Sample times [s], increasing.
    x : np.ndarray
        Displacement [m].
    xdot : np.ndarray
        Velocity [m/s].
    v : np.ndarray
        Coil input: voltage [V] (or current [A] for a model identified on currents).
    tau : float
        Time constant τ [s] of the filter.
    """
    lo, hi = model.voltage_range
    u = np.clip(first_order_filter(t, np.asarray(v, dtype=float), tau), lo, hi)
    return simulate(model, t, x, xdot, u).force


def fit_voltage_lag(model, test, tau_max: float = 0.5) -> LagFit:
    """Fit the field time constant of ``model`` to a voltage-switching ``test`` (a DamperTest).

    Parameters
    ----------
    model : damper model
        Voltage-dependent identified model (fixed).
    test : DamperTest
        With time-varying ``voltage`` (e.g. :func:`switching_test`).
    tau_max : float
        Upper bound of the search [s].
    """
    if test.voltage is None or np.ptp(test.voltage) == 0:
        raise InputError(f"{test.name}: the field lag needs a test whose voltage changes")
    t, x, xd, v, f = test.time, test.displacement, test.velocity, test.voltage, test.force

    def error(tau: float) -> float:
        return relative_rms_error(f, filtered_force(model, t, x, xd, v, tau))

    res = minimize_scalar(error, bounds=(0.0, tau_max), method="bounded", options={"xatol": 1e-5})
    tau = float(res.x)
    return LagFit(tau=tau, rel_rms_error=error(tau), rel_rms_error_without_lag=error(0.0))
