"""The Bouc-Wen hysteretic benchmark (Noël & Schoukens 2016): true system, signals, data synthesis.

The benchmark's description (its Table 1 and sections 4-5) defines

* the true system: :math:`m = 2` kg, :math:`c = 10` N s/m, :math:`k = 5\\cdot10^4` N/m,
  :math:`\\alpha = 5\\cdot10^4` N/m, :math:`\\beta = 10^3`, :math:`\\gamma = 0.8`,
  :math:`\\delta = -1.1`, :math:`\\nu = 1` (:data:`TRUE_PARAMETERS`, :func:`true_system`);
* the synthesis: Newmark integration at 15 kHz (20 times the 750 Hz sampling rate), from rest,
  of a force generated at the integration rate; then low-pass filtering and downsampling of
  :math:`y` with MATLAB's ``decimate(y, r, 'fir')`` applied for each prime factor 2, 2, 5 of 20
  (:func:`decimate_fir`), one extra period simulated and dropped against the filter's edge
  effects; band-limited (0-375 Hz) Gaussian noise of RMS 8e-3 mm added to :math:`y` for training
  data; the force is noiseless (:func:`synthesize`);
* the two test signals, noiseless: one steady-state period (8192 samples) of a random-phase
  multisine exciting every line in 5-150 Hz with RMS 50 N (:func:`multisine`), and a sine sweep of
  amplitude 40 N from 20 to 50 Hz at 10 Hz/min from rest (:func:`sine_sweep`);
* the figure of merit, the RMS error of :math:`y` in metres over the test record (eq. 6,
  :func:`rms_error`).

The official test files are not redistributed with the benchmark description this project
holds; :func:`test_sets` regenerates signals of the same definitions with the true system and
this project's integrator (:mod:`damper.hysteresis.oscillator_kernel`, the benchmark's Newmark
scheme). The multisine's random phases cannot be the official ones (they come from MATLAB's
``rand``); any seed gives a signal of the same class. The sweep is taken as the linear chirp
:math:`u = 40\\sin(2\\pi(f_0 t + \\tfrac12\\dot f t^2))`, 180 s long.
"""

from __future__ import annotations

import math

import numpy as np

from benchmark.foundation.errors import InputError
from damper.hysteresis.oscillator import HystereticOscillator

__all__ = ["TRUE_PARAMETERS", "FS", "UPSAMPLE", "PERIOD", "true_system", "multisine",
           "sine_sweep", "decimate_fir", "synthesize", "test_sets", "rms_error", "NOISE_RMS"]

#: Table 1 of the description (SI).
TRUE_PARAMETERS = {"mass": 2.0, "damping": 10.0, "stiffness": 5e4, "alpha": 5e4, "beta": 1e3,
                   "gamma": 0.8, "delta": -1.1, "nu": 1.0}
FS = 750.0          #: sampling rate of the benchmark's data [Hz]
UPSAMPLE = 20       #: integration steps per sample (15 kHz integration)
PERIOD = 8192       #: samples per multisine period
NOISE_RMS = 8e-6    #: RMS of the output noise of the training data [m]


def true_system() -> HystereticOscillator:
    """The benchmark's system (Table 1) in the normalized form."""
    return HystereticOscillator.from_standard(**TRUE_PARAMETERS)


def multisine(n: int = PERIOD, fs: float = FS, upsample: int = UPSAMPLE, f_min: float = 5.0,
              f_max: float = 150.0, rms: float = 50.0, seed: int | None = 0) -> np.ndarray:
    """One period of a random-phase multisine at the integration rate (the reference script's).

    Every line :math:`l f_0`, :math:`f_0 = f_s/n`, with :math:`\\lfloor f_{min}/f_0\\rfloor \\le l \\le
    \\lceil f_{max}/f_0\\rceil` gets unit amplitude and a uniform random phase; the signal is
    scaled to RMS ``rms`` [N].

    Parameters
    ----------
    n : int, optional
        Number of samples of one period at ``fs``.
    fs : float, optional
        Sampling rate of the data [Hz] (750 Hz in the benchmark).
    upsample : int, optional
        Integration steps per sample.
    f_min : float, optional
        Lowest excited frequency [Hz].
    f_max : float, optional
        Highest excited frequency [Hz].
    rms : float, optional
        RMS of the force [N].
    seed : int | None, optional
        Seed of the random phases; None: fresh entropy.

    Returns
    -------
    ndarray, shape (n * upsample,)
        Force [N] at the instants ``i / (fs upsample)``; every ``upsample``-th sample is the
        signal at the sampling rate.
    """
    rng = np.random.default_rng(seed)
    n_int = n * upsample
    f0 = fs / n
    lines = np.arange(math.floor(f_min / f0), math.ceil(f_max / f0) + 1)
    lines = lines[lines >= 1]
    spectrum = np.zeros(n_int // 2 + 1, dtype=complex)
    spectrum[lines] = np.exp(2j * np.pi * rng.random(lines.size))
    u = np.fft.irfft(spectrum, n_int)
    return rms * u / np.std(u)


def sine_sweep(duration: float = 180.0, fs: float = FS, upsample: int = UPSAMPLE,
               amplitude: float = 40.0, f_start: float = 20.0, rate: float = 10.0 / 60.0
               ) -> np.ndarray:
    """Linear sine sweep :math:`A\\sin(2\\pi(f_0 t + r t^2/2))` at the integration rate.

    The defaults are the benchmark's test sweep: 40 N, 20 Hz upwards at 10 Hz/min for 180 s
    (to 50 Hz).

    Parameters
    ----------
    duration : float, optional
        Length [s].
    fs : float, optional
        Sampling rate of the data [Hz] (750 Hz in the benchmark).
    upsample : int, optional
        Integration steps per sample.
    amplitude : float, optional
        Force amplitude A [N].
    f_start : float, optional
        Start frequency f₀ [Hz].
    rate : float, optional
        Sweep rate r [Hz/s].

    Returns
    -------
    ndarray, shape (round(duration fs) * upsample,)
        Force [N] at the instants ``i / (fs upsample)``.
    """
    t = np.arange(int(round(duration * fs)) * upsample) / (fs * upsample)
    return amplitude * np.sin(2 * np.pi * (f_start * t + 0.5 * rate * t ** 2))


def _prime_factors(n: int) -> list[int]:
    out, p = [], 2
    while n > 1:
        while n % p == 0:
            out.append(p)
            n //= p
        p += 1
    return out


def decimate_fir(y: np.ndarray, factor: int, order: int = 30) -> np.ndarray:
    """Low-pass filter and downsample as MATLAB's ``decimate(y, r, 'fir')``, once per prime factor.

    Each stage: a linear-phase FIR low-pass of order ``order`` (Hamming window, cutoff at
    ``1/r`` of the Nyquist frequency, :func:`scipy.signal.firwin`, the design of MATLAB's
    ``fir1``), applied with its delay compensated (zero phase) to the signal extended at both
    ends by its odd reflection about the end samples, then every ``r``-th sample from the first.

    Parameters
    ----------
    y : ndarray, shape (n,)
    factor : int
        Total downsampling factor (20 for the benchmark: stages 2, 2, 5).
    order : int
        Filter order (even).

    Returns
    -------
    ndarray, shape (ceil(n / factor),) after all stages
    """
    from scipy import signal  # 0.37 s to import, paid by every `sbib` command that loaded this module

    y = np.asarray(y, dtype=float)
    for r in _prime_factors(int(factor)):
        b = signal.firwin(order + 1, 1.0 / r, window="hamming")
        if y.size <= order:
            raise InputError(f"decimate: expected more than {order} samples, got {y.size}")
        ext = np.concatenate([2 * y[0] - y[order:0:-1], y, 2 * y[-1] - y[-2:-order - 2:-1]])
        filtered = np.convolve(ext, b, mode="same")[order:order + y.size]
        y = filtered[::r]
    return y


def synthesize(system: HystereticOscillator, u_fine: np.ndarray, fs: float = FS,
               upsample: int = UPSAMPLE, noise_rms: float = 0.0, seed: int | None = None,
               decimate: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Sampled input and output of ``system`` under ``u_fine``, as the benchmark synthesizes them.

    Parameters
    ----------
    system : HystereticOscillator
    u_fine : ndarray
        Force at the integration rate ``fs * upsample`` [N], from rest.
    fs : float
        Sampling rate of the data [Hz].
    upsample : int
        Integration steps per sample.
    noise_rms : float
        RMS of white Gaussian noise (band-limited to the Nyquist frequency) added to ``y`` [m].
    seed : int, optional
        Noise seed.
    decimate : bool
        Low-pass filter ``y`` with :func:`decimate_fir` (the benchmark) or take every
        ``upsample``-th sample of the integrated displacement.

    Returns
    -------
    u, y : ndarray
        Force [N] and displacement [m] at ``fs``, ``len(u_fine) // upsample`` samples.
    """
    u_fine = np.asarray(u_fine, dtype=float)
    n = u_fine.size // upsample
    states = system.simulate_fine(u_fine, 1.0 / (fs * upsample))
    y_fine = states[:, 0]
    y = decimate_fir(y_fine, upsample)[:n] if decimate else y_fine[::upsample][:n]
    if noise_rms > 0:
        y = y + noise_rms * np.random.default_rng(seed).standard_normal(n)
    return u_fine[::upsample][:n].copy(), y


def test_sets(system: HystereticOscillator | None = None, seed: int = 2016, fs: float = FS,
              upsample: int = UPSAMPLE, sweep_duration: float = 180.0
              ) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The benchmark's two noiseless test sets, regenerated (see the module docstring).

    Parameters
    ----------
    system : HystereticOscillator | None, optional
        The oscillator; None: the benchmark's true system.
    seed : int, optional
        Seed of the multisine's phases.
    fs : float, optional
        Sampling rate of the data [Hz] (750 Hz in the benchmark).
    upsample : int, optional
        Integration steps per sample.
    sweep_duration : float, optional
        Length of the sine sweep [s].

    Returns
    -------
    dict
        ``"multisine"``: one steady-state period (8192 samples; three periods simulated from rest
        and one more against the filter's edge, the third kept); ``"sweep"``: the sine sweep from
        rest (one extra second simulated and dropped). Each value is (u [N], y [m]) at ``fs``.
    """
    system = system or true_system()
    one = multisine(PERIOD, fs, upsample, seed=seed)
    u, y = synthesize(system, np.tile(one, 4), fs, upsample)
    out = {"multisine": (u[2 * PERIOD:3 * PERIOD], y[2 * PERIOD:3 * PERIOD])}
    extra = int(round(fs))
    sweep = sine_sweep(sweep_duration + extra / fs, fs, upsample)
    u, y = synthesize(system, sweep, fs, upsample)
    n = int(round(sweep_duration * fs))
    out["sweep"] = (u[:n], y[:n])
    return out


def rms_error(y_model: np.ndarray, y_true: np.ndarray) -> float:
    """The benchmark's figure of merit (its eq. 6): :math:`\\sqrt{\\frac1{N}\\sum(y_{mod}-y)^2}` [m].

    Parameters
    ----------
    y_model : np.ndarray
        Model displacement [m].
    y_true : np.ndarray
        Measured displacement [m], same samples.
    """
    y_model = np.asarray(y_model, dtype=float)
    y_true = np.asarray(y_true, dtype=float)
    if y_model.shape != y_true.shape:
        raise InputError(f"rms_error: shapes differ, {y_model.shape} and {y_true.shape}")
    return float(np.sqrt(np.mean((y_model - y_true) ** 2)))
