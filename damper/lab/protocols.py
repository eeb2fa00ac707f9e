"""Laboratory protocols with changing voltage for the residual loop (random motion, random voltage).

A careful experimenter who wants the field dynamics and the voltage dependence of a damper in
one record drives it with a band-limited random displacement while the command voltage jumps
between random levels at random instants (Dyke's characterization tests of the prototype damper
of Spencer et al. 1997 were run this way). :func:`random_voltage_test` builds that protocol and
runs it through :func:`damper.lab.laboratory.general_test`, so the device is reached only as a test
rig would reach it.

* displacement: a sum of ``components`` sines with frequencies drawn log-uniformly in
  ``band`` [Hz] and random phases, scaled to the RMS ``amplitude`` [m] and started from rest by
  a half-second cosine ramp (so that the record has no jump);
* voltage: held levels drawn uniformly in ``levels`` [V], each held for an exponentially
  distributed time of mean ``hold`` [s] (a Poisson switching process); 0.1-0.5 s is the range
  of the switching in semi-active control and in Dyke's records.

References
----------
Spencer B.F. Jr., Dyke S.J., Sain M.K., Carlson J.D. (1997), *Phenomenological model for
magnetorheological dampers*, J. Eng. Mech. 123(3):230-238.
"""

from __future__ import annotations

import math

import numpy as np

from benchmark.foundation.errors import InputError
from damper.io.data import DamperTest
from damper.lab.laboratory import general_test
from damper.lab.laboratory import resolve_device

__all__ = ["random_voltage_test", "random_voltage_levels"]


def _positive(name: str, value) -> float:
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name}: expected a number, got {value!r}") from None
    if not (math.isfinite(value) and value > 0):
        raise InputError(f"{name}: expected a finite number > 0, got {value}")
    return value


def random_voltage_levels(t: np.ndarray, hold: float, levels: tuple[float, float],
                          rng: np.random.Generator) -> np.ndarray:
    """Piecewise-constant voltage [V] on ``t``: uniform levels, exponential holding times.

    Parameters
    ----------
    t : np.ndarray
        Sample times [s], increasing.
    hold : float
        Mean holding time [s] of a level.
    levels : tuple[float, float]
        ``(low, high)`` voltages [V] the levels are drawn between.
    rng : np.random.Generator
        The random generator.
    """
    hold = _positive("hold", hold)
    lo, hi = (float(levels[0]), float(levels[1]))
    if not hi >= lo:
        raise InputError(f"levels: expected (low, high) with high >= low, got {levels!r}")
    v = np.empty(t.size)
    k, now = 0, float(t[0])
    while k < t.size:
        end = now + rng.exponential(hold)
        stop = int(np.searchsorted(t, end, side="left"))
        stop = max(stop, k + 1)
        v[k:stop] = rng.uniform(lo, hi)
        k, now = stop, end
    return v


def random_voltage_test(device, duration: float = 40.0, sample_rate: float = 1000.0,
                        amplitude: float = 0.01, band: tuple[float, float] = (0.2, 3.0),
                        components: int = 8, hold: float = 0.3,
                        levels: tuple[float, float] | None = None, noise: float = 0.01,
                        seed: int = 0) -> DamperTest:
    """Random displacement with a randomly switching voltage (see the module docstring).

    Parameters
    ----------
    device : damper model or str
        The device under test (``"virtual"``: the virtual benchmark damper).
    duration : float
        Length [s].
    sample_rate : float
        Samples per second [Hz].
    amplitude : float
        RMS displacement [m].
    band : (float, float)
        Frequency band of the displacement [Hz].
    components : int
        Number of sines.
    hold : float
        Mean holding time of a voltage level [s].
    levels : (float, float), optional
        Voltage range [V] (default: the device's ``voltage_range``).
    noise : float
        Relative RMS force noise.
    seed : int
        Seed of the motion, the voltage and the noise.

    Returns
    -------
    DamperTest
    """

    model = resolve_device(device)
    duration = _positive("duration", duration)
    sample_rate = _positive("sample_rate", sample_rate)
    amplitude = _positive("amplitude", amplitude)
    f_lo, f_hi = (_positive("band", band[0]), _positive("band", band[1]))
    if f_hi < f_lo or sample_rate < 20.0 * f_hi:
        raise InputError(f"band: expected 0 < low <= high <= sample_rate/20, got {band!r} at "
                         f"{sample_rate:g} Hz")
    if isinstance(components, bool) or int(components) != components or components < 1:
        raise InputError(f"components: expected an integer >= 1, got {components!r}")
    rng = np.random.default_rng(seed)
    n = int(round(duration * sample_rate)) + 1
    t = np.arange(n) / sample_rate
    freqs = np.exp(rng.uniform(math.log(f_lo), math.log(f_hi), int(components)))
    phases = rng.uniform(0.0, 2.0 * math.pi, int(components))
    weights = 1.0 / freqs  # equal velocity per component: the fast ones do not dominate the stroke
    w = 2.0 * math.pi * freqs
    x = (weights * np.sin(np.outer(t, w) + phases)).sum(axis=1)
    xd = (weights * w * np.cos(np.outer(t, w) + phases)).sum(axis=1)
    ramp_t = min(0.5, 0.25 * duration)
    ramp = np.where(t < ramp_t, 0.5 - 0.5 * np.cos(math.pi * t / ramp_t), 1.0)
    dramp = np.where(t < ramp_t, 0.5 * math.pi / ramp_t * np.sin(math.pi * t / ramp_t), 0.0)
    x, xd = x * ramp, xd * ramp + x * dramp
    scale = amplitude / float(np.sqrt(np.mean(x ** 2)))
    x, xd = x * scale, xd * scale
    lo, hi = model.voltage_range if levels is None else levels
    v = random_voltage_levels(t, hold, (lo, hi), rng)
    test = general_test(model, t, x, v, noise=noise, seed=int(rng.integers(2 ** 31)), xdot=xd)
    return DamperTest(time=test.time, displacement=test.displacement, velocity=test.velocity,
                      force=test.force, voltage=test.voltage,
                      name=f"{model.name} random motion, random voltage ({duration:g} s, "
                           f"{sample_rate:g} Hz)",
                      source=f"damper.lab.protocols.random_voltage_test({model.name})",
                      metadata={**test.metadata, "protocol": "random voltage", "hold": hold,
                                "band": list(band), "amplitude": amplitude, "seed": seed})
