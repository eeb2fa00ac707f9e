"""Laboratory signals and protocols with changing voltage (random motion, random voltage, steps).

The one home of the test signals a rig is driven with: :func:`random_motion` (band-limited
random displacement with its exact velocity), :func:`random_voltage` (held random levels),
:func:`staircase_voltage` and :func:`square_voltage`. The residual loop's protocol
(:func:`random_voltage_test`) and the closed loop's laboratory campaign
(:mod:`benchmark.applications.identification_campaign`) are built from them.

A careful experimenter who wants the field dynamics and the voltage dependence of a damper in
one record drives it with a band-limited random displacement while the command voltage jumps
between random levels at random instants (Dyke's characterization tests of the prototype damper
of Spencer et al. 1997 were run this way). :func:`random_voltage_test` builds that protocol and
runs it through :func:`damper.lab.laboratory.general_test`, so the device is reached only as a test
rig would reach it.

* displacement: a sum of ``components`` sines with frequencies drawn log-uniformly in
  ``band`` [Hz] and random phases, scaled to the RMS ``amplitude`` [m] and started from rest by
  a half-second smooth ramp (so that the record has no jump);
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
from benchmark.foundation.arguments import positive
from damper.io.data import DamperTest
from damper.lab.laboratory import general_test
from damper.lab.laboratory import resolve_device

__all__ = ["random_voltage_test", "random_motion", "random_voltage", "staircase_voltage", "square_voltage",
           "smooth_ramp"]


def smooth_ramp(t: np.ndarray, ramp: float) -> tuple[np.ndarray, np.ndarray]:
    """A smooth 0 -> 1 window over the first ``ramp`` seconds and its exact time derivative.

    The cubic smoothstep :math:`w = s^2 (3 - 2 s)`, :math:`s = t/T` clipped to [0, 1], has zero
    slope at both ends, so a signal multiplied by it starts from rest without a jump in velocity.

    Parameters
    ----------
    t : np.ndarray
        Sample times [s], from 0.
    ramp : float
        Ramp duration T [s]; 0 gives no ramp.

    Returns
    -------
    w, dw : np.ndarray
        The window and its derivative [1/s].
    """
    if ramp <= 0:
        return np.ones_like(t), np.zeros_like(t)
    s = np.clip(t / ramp, 0.0, 1.0)
    inside = (t > 0.0) & (t < ramp)
    return s * s * (3.0 - 2.0 * s), np.where(inside, 6.0 * s * (1.0 - s) / ramp, 0.0)


def random_motion(t: np.ndarray, rms: float, band: tuple[float, float], rng: np.random.Generator,
                  components: int = 24, spacing: str = "stratified",
                  ramp: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Band-limited random displacement [m] and its exact velocity [m/s].

    A sum of ``components`` sines with random phases and amplitudes falling as 1/f (equal
    velocity per component, so the fast ones do not dominate the stroke), started from rest by
    :func:`smooth_ramp` and scaled to the RMS displacement ``rms``.

    Parameters
    ----------
    t : np.ndarray
        Sample times [s], from 0, increasing.
    rms : float
        RMS displacement [m].
    band : tuple[float, float]
        Frequency band ``(low, high)`` [Hz], ``0 < low <= high``.
    rng : np.random.Generator
        The random generator (frequencies, then phases are drawn from it).
    components : int, optional
        Number of sines.
    spacing : {"stratified", "log-uniform"}, optional
        ``stratified``: one frequency drawn uniformly in each of ``components`` log-spaced
        sub-bands (the band is covered evenly); ``log-uniform``: independent log-uniform draws.
    ramp : float, optional
        Duration of the ramp from rest [s].
    """
    lo, hi = float(band[0]), float(band[1])
    if not (0.0 < lo <= hi):
        raise InputError(f"random motion: band must satisfy 0 < low <= high, got {band!r}")
    if isinstance(components, bool) or int(components) != components or components < 1:
        raise InputError(f"components: expected an integer >= 1, got {components!r}")
    n = int(components)
    if spacing == "stratified":
        edges = np.geomspace(lo, hi, n + 1)
        f = edges[:-1] + rng.random(n) * np.diff(edges)
    elif spacing == "log-uniform":
        f = np.exp(rng.uniform(math.log(lo), math.log(hi), n))
    else:
        raise InputError(f"random motion: spacing {spacing!r}; expected 'stratified' or 'log-uniform'")
    phase = rng.uniform(0.0, 2.0 * math.pi, n)
    w = 2.0 * math.pi * f
    x = np.sin(np.outer(t, w) + phase) @ (1.0 / f)
    xd = (np.cos(np.outer(t, w) + phase) * w) @ (1.0 / f)
    win, dwin = smooth_ramp(t, ramp)
    x, xd = win * x, win * xd + dwin * x
    scale = float(rms) / float(np.sqrt(np.mean(x ** 2)))
    return scale * x, scale * xd


def random_voltage(t: np.ndarray, levels, hold, rng: np.random.Generator) -> np.ndarray:
    """Piecewise-constant voltage [V] on ``t``: a random level held for a random time, again and again.

    Two switching processes, as the two kinds of rig command:

    * ``levels = (low, high)`` and ``hold`` a number: levels drawn uniformly in [low, high], held
      for exponentially distributed times of mean ``hold`` (a Poisson switching process: a
      continuously adjustable supply);
    * ``levels`` a sequence of voltages and ``hold = (shortest, longest)``: each hold drawn
      uniformly in that range, then a jump to another of the levels (a supply set to a few
      levels, as the seed's constant-voltage tests).

    Parameters
    ----------
    t : np.ndarray
        Sample times [s], increasing.
    levels : (float, float) or sequence of float
        The voltage range, or the voltages to choose from (see above).
    hold : float or (float, float)
        Mean holding time [s], or the shortest and longest holding times [s].
    rng : np.random.Generator
        The random generator.
    """
    v = np.empty(t.size)
    if np.ndim(hold) == 0:
        hold = positive("hold", hold)
        lo, hi = (float(levels[0]), float(levels[1]))
        if len(levels) != 2 or not hi >= lo:
            raise InputError(f"levels: expected (low, high) with high >= low, got {levels!r}")
        k, now = 0, float(t[0])
        while k < t.size:
            end = now + rng.exponential(hold)
            stop = max(int(np.searchsorted(t, end, side="left")), k + 1)
            v[k:stop] = rng.uniform(lo, hi)
            k, now = stop, end
        return v
    shortest, longest = (positive("hold", hold[0]), positive("hold", hold[1]))
    if longest < shortest:
        raise InputError(f"hold: expected (shortest, longest) with longest >= shortest, got {hold!r}")
    choices = np.asarray(levels, dtype=float)
    if choices.size < 1:
        raise InputError("levels: expected at least one voltage")
    start, current = 0, rng.choice(choices)
    while start < t.size:
        end = max(int(np.searchsorted(t, t[start] + rng.uniform(shortest, longest))), start + 1)
        v[start:end] = current
        start = end
        current = rng.choice(choices[choices != current]) if choices.size > 1 else current
    return v


def staircase_voltage(t: np.ndarray, levels, hold: float) -> np.ndarray:
    """The voltage held at each of ``levels`` for ``hold`` seconds in turn (cycling).

    Parameters
    ----------
    t : np.ndarray
        Sample times [s], increasing.
    levels : sequence of float
        Voltages [V] in turn.
    hold : float
        Holding time [s] of each level.
    """
    k = (np.floor(t / positive("hold", hold)).astype(int)) % len(levels)
    return np.asarray(levels, dtype=float)[k]


def square_voltage(t: np.ndarray, low: float, high: float, period: float) -> np.ndarray:
    """A square wave between ``low`` and ``high`` [V] of ``period`` [s], starting low.

    Parameters
    ----------
    t : np.ndarray
        Sample times [s], increasing.
    low : float
        Low voltage [V].
    high : float
        High voltage [V].
    period : float
        Period [s].
    """
    period = positive("period", period)
    return np.where(np.mod(t, period) < 0.5 * period, low, high)


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
    duration = positive("duration", duration)
    sample_rate = positive("sample_rate", sample_rate)
    amplitude = positive("amplitude", amplitude)
    f_lo, f_hi = (positive("band", band[0]), positive("band", band[1]))
    if f_hi < f_lo or sample_rate < 20.0 * f_hi:
        raise InputError(f"band: expected 0 < low <= high <= sample_rate/20, got {band!r} at "
                         f"{sample_rate:g} Hz")
    rng = np.random.default_rng(seed)
    n = int(round(duration * sample_rate)) + 1
    t = np.arange(n) / sample_rate
    x, xd = random_motion(t, amplitude, (f_lo, f_hi), rng, components=components, spacing="log-uniform",
                          ramp=min(0.5, 0.25 * duration))
    lo, hi = model.voltage_range if levels is None else levels
    v = random_voltage(t, (lo, hi), hold, rng)
    test = general_test(model, t, x, v, noise=noise, seed=int(rng.integers(2 ** 31)), xdot=xd)
    return DamperTest(time=test.time, displacement=test.displacement, velocity=test.velocity,
                      force=test.force, voltage=test.voltage,
                      name=f"{model.name} random motion, random voltage ({duration:g} s, "
                           f"{sample_rate:g} Hz)",
                      source=f"damper.lab.protocols.random_voltage_test({model.name})",
                      metadata={**test.metadata, "protocol": "random voltage", "hold": hold,
                                "band": list(band), "amplitude": amplitude, "seed": seed})
