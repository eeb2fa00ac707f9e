"""Synthetic devices and tests for checking the residual loop on data whose truth is known.

A *device* is anything with ``simulate(t, x, xdot, xddot, v)`` returning an object with a
``force`` array: an :class:`~damper.diagnosis.augmented.AugmentedModel` (a base model with library
effects the fitted model does not declare), or one of the devices here whose effect lies
*outside* the library:

* :class:`PlayDevice` -- a loose joint (backlash, play :math:`2g`): the damper body follows the
  play operator of the displacement and no force is transmitted while the joint crosses its
  gap after each reversal (a dead zone);
* :class:`HeatedDevice` -- the force level depends on a hidden temperature rise :math:`T` [K]
  driven by the dissipated power, :math:`C\\dot T = |F\\dot x| - hT`, as
  :math:`F = (1 - \\beta T) F_0` (a heating *and cooling* law, which the library's linear
  ``fade`` cannot follow when the power changes during a test).

:func:`sinusoidal_tests` drives a device through sinusoids (several amplitudes and frequencies,
so that stiffness and inertia are separable) and adds seeded Gaussian noise to the force.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numba
import numpy as np

from benchmark.foundation.errors import InputError, ParameterError
from damper.diagnosis.augmented import AugmentedModel, AugmentedResponse
from damper.io.data import DamperTest
from damper.diagnosis.effects import Motion

__all__ = ["PlayDevice", "HeatedDevice", "sinusoidal_tests", "play_operator", "step_voltage_tests"]


@numba.njit(cache=True)
def _play(x, gap, out, contact):
    out[0] = x[0]
    contact[0] = True
    for k in range(1, x.size):
        lo = x[k] - gap
        hi = x[k] + gap
        prev = out[k - 1]
        if prev < lo:
            out[k] = lo
            contact[k] = True
        elif prev > hi:
            out[k] = hi
            contact[k] = True
        else:
            out[k] = prev
            contact[k] = False


def play_operator(x: np.ndarray, gap: float) -> tuple[np.ndarray, np.ndarray]:
    """Play (backlash) operator of half-width ``gap`` [m]: the output and the contact flags.

    Parameters
    ----------
    x : np.ndarray
        Input displacement history [m].
    gap : float
        Half-width of the play [m].
    """
    x = np.ascontiguousarray(x, dtype=np.float64)
    if not (math.isfinite(gap) and gap >= 0):
        raise ParameterError(f"play gap: expected a finite value >= 0 m, got {gap!r}")
    out = np.empty_like(x)
    contact = np.empty(x.size, dtype=np.bool_)
    _play(x, float(gap), out, contact)
    return out, contact


@dataclass(frozen=True)
class PlayDevice:
    """A damper behind a loose joint: dead zone of travel ``2 gap`` after each reversal.

    Parameters
    ----------
    inner : AugmentedModel
        The damper itself.
    gap : float
        Half play [m].
    """

    inner: AugmentedModel
    gap: float

    def simulate(self, t, x, xdot, xddot, v=0.0) -> AugmentedResponse:
        """Force history [N]: the inner damper driven by the play output, zero out of contact.

        Parameters
        ----------
        t
            Sample times [s], increasing.
        x
            Displacement [m].
        xdot
            Velocity [m/s].
        xddot
            Acceleration [m/s²].
        v : float or ndarray, optional
            Coil input [V], a number or a history at ``t``.
        """
        xp, contact = play_operator(np.asarray(x, dtype=float), self.gap)
        t = np.asarray(t, dtype=float)
        xpd = np.gradient(xp, t, edge_order=2)
        xpdd = np.gradient(xpd, t, edge_order=2)
        r = self.inner.response(Motion(t, xp, xpd, xpdd, v))
        force = np.where(contact, r.force, 0.0)
        return AugmentedResponse(force=force, base_force=r.base_force, model_input=r.model_input)


@dataclass(frozen=True)
class HeatedDevice:
    """A damper whose force level falls with a hidden temperature rise (see the module docstring).

    Parameters
    ----------
    inner : AugmentedModel
        The damper at the reference temperature.
    beta : float
        Fractional force loss per kelvin [1/K].
    heat_capacity : float
        :math:`C` [J/K].
    conductance : float
        :math:`h` [W/K].
    """

    inner: AugmentedModel
    beta: float
    heat_capacity: float
    conductance: float

    def simulate(self, t, x, xdot, xddot, v=0.0) -> AugmentedResponse:
        """Force history [N] with the temperature integrated alongside (semi-implicit Euler).

        Parameters
        ----------
        t
            Sample times [s], increasing.
        x
            Displacement [m].
        xdot
            Velocity [m/s].
        xddot
            Acceleration [m/s²].
        v : float or ndarray, optional
            Coil input [V], a number or a history at ``t``.
        """
        t = np.asarray(t, dtype=float)
        r = self.inner.response(Motion(t, x, xdot, xddot, v))
        f0 = r.force
        power = np.abs(f0 * np.asarray(xdot, dtype=float))
        temp = np.zeros(t.size)
        for k in range(t.size - 1):
            h = t[k + 1] - t[k]
            level = max(1.0 - self.beta * temp[k], 0.0)
            temp[k + 1] = (temp[k] + h * level * power[k] / self.heat_capacity) / (
                1.0 + h * self.conductance / self.heat_capacity)
        force = np.clip(1.0 - self.beta * temp, 0.0, None) * f0
        return AugmentedResponse(force=force, base_force=r.base_force, model_input=r.model_input,
                                 terms={"temperature": temp})


def _noisy_test(device, t, x, xd, xdd, v, noise, rng, name, input_name) -> DamperTest:
    f = np.asarray(device.simulate(t, x, xd, xdd, v).force, dtype=float)
    if noise > 0:
        f = f + noise * float(np.sqrt(np.mean(f ** 2))) * rng.standard_normal(f.size)
    kw = {input_name: np.broadcast_to(np.asarray(v, dtype=float), t.shape).copy()}
    return DamperTest(time=t, displacement=x, velocity=xd, force=f, name=name,
                      source=f"synthetic: {name}", metadata={"noise": noise}, **kw)


def sinusoidal_tests(device, motions: Sequence[tuple[float, float]] = ((0.01, 1.0), (0.004, 3.0)),
                     voltage: float = 0.0, cycles: float = 5.0, samples_per_cycle: int = 200,
                     noise: float = 0.01, seed: int = 0, input_name: str = "voltage",
                     amplitude_profile=None) -> list[DamperTest]:
    """Drive ``device`` through sinusoids :math:`x = X\\sin 2\\pi f t`; one test per ``(X, f)``.

    Parameters
    ----------
    device : object with ``simulate(t, x, xdot, xddot, v)``
    motions : sequence of (amplitude [m], frequency [Hz])
    voltage : float
        Constant coil input (V, or A with ``input_name="current"``).
    cycles : float
        Cycles per test.
    samples_per_cycle : int
    noise : float
        Standard deviation of the added force noise, as a fraction of the force RMS.
    seed : int
        Seed of the noise.
    input_name : {"voltage", "current"}
    amplitude_profile : callable, optional
        ``g(t/duration)`` multiplying the amplitude (e.g. a step down half-way).

    Returns
    -------
    list of DamperTest
    """
    if input_name not in ("voltage", "current"):
        raise InputError(f"input_name: expected 'voltage' or 'current', got {input_name!r}")
    rng = np.random.default_rng(seed)
    tests = []
    for amp, freq in motions:
        if not (amp > 0 and freq > 0):
            raise InputError(f"motions: expected amplitude > 0 and frequency > 0, got ({amp}, {freq})")
        duration = cycles / freq
        t = np.linspace(0.0, duration, int(round(cycles * samples_per_cycle)) + 1)
        w = 2.0 * math.pi * freq
        if amplitude_profile is None:
            x = amp * np.sin(w * t)
            xd = amp * w * np.cos(w * t)
            xdd = -amp * w * w * np.sin(w * t)
        else:
            g = np.asarray(amplitude_profile(t / duration), dtype=float)
            x = amp * g * np.sin(w * t)
            xd = np.gradient(x, t, edge_order=2)
            xdd = np.gradient(xd, t, edge_order=2)
        name = f"{amp * 1e3:g}mm {freq:g}Hz {voltage:g}{'A' if input_name == 'current' else 'V'}"
        tests.append(_noisy_test(device, t, x, xd, xdd, voltage, noise, rng, name, input_name))
    return tests


def step_voltage_tests(device, amplitude: float = 0.01, frequency: float = 1.0,
                       levels: Sequence[float] = (0.0, 1.0), switch_period: float = 0.35,
                       cycles: float = 6.0, samples_per_cycle: int = 400, noise: float = 0.01,
                       seed: int = 0) -> list[DamperTest]:
    """A sinusoid with the voltage switched between ``levels`` every ``switch_period`` [s]
    (one test; the steps make a voltage lag visible).

    Parameters
    ----------
    device
        The damper tested: a model instance, or the name of a parameterless model
        (:func:`damper.lab.laboratory.resolve_device`).
    amplitude : float, optional
        Displacement amplitude [m].
    frequency : float, optional
        Frequency of the motion [Hz].
    levels : Sequence[float], optional
        Voltages [V] switched between.
    switch_period : float, optional
        Time [s] between switches.
    cycles : float, optional
        Number of periods of the sinusoid.
    samples_per_cycle : int, optional
        Samples per period.
    noise : float, optional
        Relative RMS measurement noise on the force (0: none).
    seed : int, optional
        Seed of the random generator (the same seed gives the same result).
    """
    rng = np.random.default_rng(seed)
    duration = cycles / frequency
    t = np.linspace(0.0, duration, int(round(cycles * samples_per_cycle)) + 1)
    w = 2.0 * math.pi * frequency
    x = amplitude * np.sin(w * t)
    xd = amplitude * w * np.cos(w * t)
    xdd = -amplitude * w * w * np.sin(w * t)
    idx = (np.floor(t / switch_period).astype(int)) % len(levels)
    v = np.asarray(levels, dtype=float)[idx]
    name = f"{amplitude * 1e3:g}mm {frequency:g}Hz voltage steps"
    return [_noisy_test(device, t, x, xd, xdd, v, noise, rng, name, "voltage")]
