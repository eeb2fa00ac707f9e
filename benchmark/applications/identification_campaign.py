"""The laboratory campaign of the closed loop: tests a careful experimenter adds to the seed's protocol.

The seed paper identifies its models on periodic tests at constant voltage. Under a semi-active
controller the damper sees what those tests never show: the voltage switching many times a
second, small strokes between reversals, irregular motion. This module designs that campaign
and runs it on the device through :mod:`damper.lab.laboratory` only (never through the earthquake
runs the models are later validated in):

* **voltage steps**: a sine with the voltage held at each level of a staircase in turn;
* **voltage switching**: a sine with the voltage switched between the ends of its range as a
  square wave (a large fast stroke, to about 1.5 m/s, and a moderate one switched every 50 ms);
* **small amplitudes**: strokes of a centimetre or two, with voltage steps;
* **random motion with random voltage**: a band-limited random displacement (a sum of sines
  with random phases over a frequency band) and a voltage that jumps between the levels at
  random times, held from 10 ms (a bang-bang controller) to half a second.

Every signal uses a few voltage levels (:data:`DEFAULT_LEVELS`), as an experimenter sets a coil
supply; the residual loop then reads those levels as the nodes of its voltage laws. The tests
are split into a *training* set (the loop fits on it) and a *held-out* set of different
realizations, amplitudes and switching rates (the loop chooses terms and reports its error on
it). All amplitudes are in metres, frequencies in hertz, voltages in volts (SI throughout). The
signals are the virtual laboratory's (:mod:`damper.lab.protocols`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from benchmark.foundation.errors import InputError
from damper.lab.laboratory import general_test, resolve_device
from damper.lab.protocols import random_motion, random_voltage, square_voltage, staircase_voltage

__all__ = ["Campaign", "DEFAULT_LEVELS", "DEFAULT_SAMPLE_RATE", "laboratory_campaign"]

#: Coil voltage levels of the campaign, as fractions of the device's voltage range.
DEFAULT_LEVELS = (0.0, 0.25, 0.5, 0.75, 1.0)
#: Sample rate of the campaign's tests [Hz]: the benchmark's own sampling and control rate
#: (the field lag of a large damper, tens of milliseconds, is several samples).
DEFAULT_SAMPLE_RATE = 200.0


@dataclass(frozen=True)
class Campaign:
    """The tests of :func:`laboratory_campaign` (each a :class:`damper.io.data.DamperTest`).

    Attributes
    ----------
    train, heldout : tuple of DamperTest
        Tests the loop fits on, and the separate tests it validates on.
    """

    train: tuple
    heldout: tuple

    def describe(self) -> list[dict]:
        """One JSON-ready line per test: set, name, duration [s], samples, stroke [m], voltages [V]."""
        out = []
        for which, tests in (("train", self.train), ("heldout", self.heldout)):
            for t in tests:
                out.append({"set": which, "name": t.name, "duration_s": float(t.time[-1] - t.time[0]),
                            "samples": int(t.time.size),
                            "stroke_m": float(np.ptp(t.displacement)),
                            "voltages_V": sorted({round(float(v), 6) for v in np.unique(t.voltage)})})
        return out


def _time(duration: float, sample_rate: float) -> np.ndarray:
    if not (duration > 0 and sample_rate > 0):
        raise InputError(f"campaign: duration and sample rate must be > 0, got {duration}, {sample_rate}")
    return np.arange(0.0, duration, 1.0 / sample_rate)


def laboratory_campaign(device, sample_rate: float = DEFAULT_SAMPLE_RATE,
                        levels: Sequence[float] = DEFAULT_LEVELS, stroke: float = 0.1,
                        noise: float = 0.0, seed: int = 0, scale: float = 1.0) -> Campaign:
    """Run the campaign on ``device`` through :func:`damper.lab.laboratory.general_test`.

    Parameters
    ----------
    device : damper model or str
        The device under test (``"virtual"``: the virtual benchmark damper).
    sample_rate : float
        Samples per second [Hz].
    levels : sequence of float
        Voltage levels as fractions of the device's voltage range (0: low end, 1: high end).
    stroke : float
        The largest displacement amplitude [m] (the seed protocol's ±0.1 m by default); the
        other tests scale with it.
    noise : float
        Relative RMS measurement noise on the force.
    seed : int
        Seed of the random signals and the noise (the held-out tests use other seeds).
    scale : float
        Duration factor of every test (1: 60 s of training and 44 s of held-out tests).

    Returns
    -------
    Campaign
    """

    model = resolve_device(device)
    lo, hi = model.voltage_range
    fr = np.asarray(levels, dtype=float)
    if fr.size < 2 or np.any(fr < 0) or np.any(fr > 1) or np.any(np.diff(fr) <= 0):
        raise InputError(f"campaign: levels must be at least two increasing fractions in [0, 1], got {levels}")
    if not (stroke > 0 and scale > 0):
        raise InputError(f"campaign: stroke and scale must be > 0, got {stroke}, {scale}")
    volts = lo + fr * (hi - lo)

    def run(name, duration, motion, voltage, k):
        t = _time(duration * scale, sample_rate)
        x, xd = motion(t)
        test = general_test(model, t, x, voltage(t), noise=noise, seed=seed * 100 + k, xdot=xd)
        return _renamed(test, name)

    def sine(amplitude, frequency):
        def motion(t):
            w = 2.0 * np.pi * frequency
            return amplitude * np.sin(w * t), amplitude * w * np.cos(w * t)
        return motion

    def rand(rms, band, s):
        return lambda t: random_motion(t, rms, band, np.random.default_rng(s))

    # Spans of a seismic damper's service (the seed's own large loop: ±0.4 m at 0.8 Hz, 2 m/s):
    # strokes from 0.1 to 3 times ``stroke``, velocities to about 1.5 m/s, voltage held from
    # 10 ms (a bang-bang controller's switching) to seconds (the seed's constant-voltage tests).
    big, small = stroke, 0.1 * stroke
    train = (
        run("steps: sine ±{:g} m 0.5 Hz".format(big), 15.0, sine(big, 0.5),
            lambda t: staircase_voltage(t, volts, 1.5), 1),
        run("switching: sine ±{:g} m 0.8 Hz, 0.2 s".format(3 * stroke), 8.0, sine(3 * stroke, 0.8),
            lambda t: square_voltage(t, lo, hi, 0.2), 2),
        run("small: sine ±{:g} m 2 Hz, steps".format(small), 7.0, sine(small, 2.0),
            lambda t: staircase_voltage(t, volts[::-1], 0.7), 3),
        run("random motion, random voltage (a)", 30.0, rand(0.6 * stroke, (0.3, 4.0), seed + 11),
            lambda t: random_voltage(t, volts, (0.01, 0.3), np.random.default_rng(seed + 12)), 4),
    )
    heldout = (
        run("switching: sine ±{:g} m 0.7 Hz, 0.1 s".format(0.8 * stroke), 8.0, sine(0.8 * stroke, 0.7),
            lambda t: square_voltage(t, lo, hi, 0.1), 5),
        run("small: sine ±{:g} m 1.5 Hz, steps".format(0.2 * stroke), 6.0, sine(0.2 * stroke, 1.5),
            lambda t: staircase_voltage(t, volts, 0.5), 6),
        run("random motion, random voltage (b)", 30.0, rand(0.6 * stroke, (0.1, 4.0), seed + 21),
            lambda t: random_voltage(t, volts, (0.01, 0.5), np.random.default_rng(seed + 22)), 7),
    )
    return Campaign(train=train, heldout=heldout)


def _renamed(test, name: str):
    from dataclasses import replace
    return replace(test, name=name, metadata={**test.metadata, "campaign_test": name})
