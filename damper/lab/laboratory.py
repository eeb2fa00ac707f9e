"""The virtual laboratory: test protocols run on a damper model, returning :class:`DamperTest` data.

Identification reaches the virtual benchmark damper only through these protocols, exactly as
it would reach a real damper in a test rig: it sees time, displacement, velocity, voltage and
the (optionally noisy) force, never the model.

* :func:`periodic_test` -- a periodic displacement (sine or triangle wave) at constant voltage;
* :func:`general_test` -- any displacement and voltage histories.

``device`` is a damper model instance or the registered name of one that needs no parameters
(``"virtual"``, the virtual benchmark damper), so callers need not import its module.
Measurement noise is Gaussian on the force with the given RMS relative to the force's RMS,
drawn from ``numpy.random.default_rng(seed)``: the same seed gives the same data.
"""

from __future__ import annotations


import numpy as np

from benchmark.foundation.errors import InputError
from benchmark.foundation.arguments import positive
from damper.io.data import DamperTest
from damper.models.base import DamperModel
from damper.models.registry import get_model_class
from damper.models.response import simulate

__all__ = ["periodic_test", "general_test", "resolve_device", "WAVEFORMS"]

WAVEFORMS = ("sine", "triangle")


def resolve_device(device):
    """A model instance from ``device`` (an instance, or the name of a parameterless model).

    Parameters
    ----------
    device
        A model instance, or the name of a parameterless model.
    """
    if isinstance(device, str):
        cls = get_model_class(device)
        try:
            return cls()
        except TypeError:
            raise InputError(f"device: model {device!r} needs parameters; pass an instance") from None
    if not isinstance(device, DamperModel):
        raise InputError(f"device: expected a damper model or its name, got {type(device).__name__}")
    return device


#: largest test a protocol generates (a typo such as cycles=1e12 must not exhaust the memory)
_MAX_SAMPLES = 100_000_000


def _check_seed(seed) -> None:
    if seed is not None and (isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0):
        raise InputError(f"seed: expected None or an integer >= 0, got {seed!r}")


def _measure(force: np.ndarray, noise: float, seed) -> np.ndarray:
    if noise == 0.0:
        return force.copy()
    rng = np.random.default_rng(seed)
    scale = noise * float(np.sqrt(np.mean(force ** 2)))
    return force + scale * rng.standard_normal(force.size)


def periodic_test(device, amplitude: float, frequency: float, voltage: float, cycles: float = 5.0,
                  sample_rate: float = 200.0, noise: float = 0.0, seed: int | None = None,
                  waveform: str = "sine") -> DamperTest:
    """Drive ``device`` with a periodic displacement at constant voltage.

    The displacement starts at rest at zero and is a sine, :math:`x = X\\sin(2\\pi f t)`, or a
    triangle wave with the same period and amplitude (constant speed :math:`4Xf` between
    reversals, the "wave" input of Ikhouane & Rodellar's identification). The whole record is
    returned, transient included (use :meth:`DamperTest.select` to keep the last cycles).

    Parameters
    ----------
    device : damper model or str
        The device under test (``"virtual"`` for the virtual benchmark damper).
    amplitude : float
        Displacement amplitude X [m].
    frequency : float
        Frequency f [Hz].
    voltage : float
        Constant command voltage [V], within ``device.voltage_range``.
    cycles : float
        Number of periods (default 5).
    sample_rate : float
        Samples per second [Hz] (default 200); at least 10 per period.
    noise : float
        Relative RMS measurement noise on the force (default 0).
    seed : int, optional
        Seed of the noise generator.
    waveform : {"sine", "triangle"}

    Returns
    -------
    DamperTest
        ``time, displacement, velocity, force, voltage`` (SI), metadata with the protocol.
    """
    model = resolve_device(device)
    amplitude = positive("amplitude", amplitude)
    frequency = positive("frequency", frequency)
    cycles = positive("cycles", cycles)
    sample_rate = positive("sample_rate", sample_rate)
    noise = positive("noise", noise, strict=False)
    if waveform not in WAVEFORMS:
        raise InputError(f"waveform: expected one of {', '.join(WAVEFORMS)}, got {waveform!r}")
    if sample_rate < 10.0 * frequency:
        raise InputError(f"sample_rate: expected at least 10 samples per period "
                         f"(>= {10 * frequency:g} Hz), got {sample_rate:g} Hz")
    try:
        voltage = float(voltage)
    except (TypeError, ValueError):
        raise InputError(f"voltage: expected a number of volts, got {voltage!r}") from None
    _check_seed(seed)
    lo, hi = model.voltage_range
    if not (lo <= voltage <= hi):
        raise InputError(f"voltage: expected {lo:g} <= v <= {hi:g} V for {model.name}, got {voltage:g} V")
    n = int(round(cycles * sample_rate / frequency)) + 1
    if n > _MAX_SAMPLES:
        raise InputError(f"cycles * sample_rate / frequency = {n - 1:.3g} samples; expected at most "
                         f"{_MAX_SAMPLES:.0e} (fewer cycles or a lower sample_rate)")
    t = np.arange(n) / sample_rate
    if waveform == "sine":
        omega = 2.0 * np.pi * frequency
        x = amplitude * np.sin(omega * t)
        xdot = amplitude * omega * np.cos(omega * t)
    else:
        phase = np.mod(t * frequency + 0.25, 1.0)  # 0 at the trough, 0.5 at the crest
        x = amplitude * (4.0 * np.abs(phase - 0.5) - 1.0) * -1.0
        speed = 4.0 * amplitude * frequency
        xdot = np.where(phase < 0.5, speed, -speed)
        xdot[np.isclose(phase, 0.0) | np.isclose(phase, 0.5) | np.isclose(phase, 1.0)] = 0.0
    response = simulate(model, t, x, xdot, v=voltage)
    label = f"{model.name} {waveform} {amplitude:g} m {frequency:g} Hz {voltage:g} V"
    return DamperTest(time=t, displacement=x, velocity=xdot, force=_measure(response.force, noise, seed),
                      voltage=np.full(n, voltage), name=label,
                      source=f"damper.lab.laboratory.periodic_test({model.name})",
                      metadata=dict(protocol="periodic", waveform=waveform, amplitude=amplitude,
                                    frequency=frequency, voltage=voltage, cycles=cycles,
                                    sample_rate=sample_rate, noise=noise, seed=seed,
                                    device=model.name))


def general_test(device, t, x, v, noise: float = 0.0, seed: int | None = None,
                 xdot=None) -> DamperTest:
    """Drive ``device`` with any displacement ``x(t)`` [m] and voltage ``v(t)`` [V].

    ``xdot`` defaults to the second-order finite difference of ``x``; ``v`` may be a number.
    Voltage is held from each sample to the next. Noise as in :func:`periodic_test`.

    Parameters
    ----------
    device
        The damper tested: a model instance, or the name of a parameterless model
        (:func:`damper.lab.laboratory.resolve_device`).
    t
        Sample times [s], increasing.
    x
        Displacement history [m] at ``t``.
    v
        Voltage [V]: a number, or a history at ``t`` (held from each sample to the next).
    noise : float, optional
        Relative RMS measurement noise on the force (0: none).
    seed : int | None, optional
        Seed of the noise generator; None: fresh entropy.
    xdot : optional
        Velocity history [m/s]; None: second-order finite difference of ``x``.
    """
    model = resolve_device(device)
    noise = positive("noise", noise, strict=False)
    _check_seed(seed)
    response = simulate(model, t, x, xdot, v=v)
    return DamperTest(time=response.t, displacement=response.displacement,
                      velocity=response.velocity, force=_measure(response.force, noise, seed),
                      voltage=response.voltage, name=f"{model.name} general test",
                      source=f"damper.lab.laboratory.general_test({model.name})",
                      metadata=dict(protocol="general", noise=noise, seed=seed, device=model.name))
