"""Single-degree-of-freedom oscillator with a Bouc-Wen restoring force, driven by a force.

The model of the Bouc-Wen hysteretic benchmark (Noël & Schoukens 2016, eqs. 1-3), of an isolation
bearing or of any hysteretic test specimen loaded through a mass:

.. math::

   m\\ddot y + c\\dot y + k y + z = u(t), \\qquad
   \\dot z = \\alpha\\dot y - \\beta\\left(\\gamma|\\dot y||z|^{\\nu-1}z + \\delta\\dot y|z|^{\\nu}\\right),

input the force :math:`u` [N], output the displacement :math:`y` [m].

Unique (normalized) parametrization
-----------------------------------
Only :math:`\\alpha`, :math:`\\beta\\gamma`, :math:`\\beta\\delta` and :math:`\\nu` enter the equations,
so :math:`(\\alpha, \\beta, \\gamma, \\delta, \\nu)` is not unique (any :math:`\\beta` with
:math:`\\gamma/\\beta`, :math:`\\delta/\\beta` gives the same system). As in
:mod:`damper.models.bouc_wen` (Ikhouane & Rodellar 2007) the model is stored normalized,
:math:`z = \\kappa_w w` with

.. math::

   \\dot w = \\rho\\left(\\dot y - s\\,\\sigma|\\dot y||w|^{n-1}w - s\\,(1-\\sigma)\\dot y|w|^{n}\\right),

:math:`\\kappa_w > 0` [N], :math:`\\rho > 0` [1/m], :math:`n = \\nu \\ge 1`, :math:`\\sigma` [-] and the
branch sign :math:`s = \\operatorname{sgn}\\beta(\\gamma+\\delta) = \\pm 1`:

.. math::

   \\kappa_w = \\left(\\frac{\\alpha}{|\\beta(\\gamma+\\delta)|}\\right)^{1/\\nu}, \\quad
   \\rho = \\frac{\\alpha}{\\kappa_w}, \\quad \\sigma = \\frac{\\gamma}{\\gamma+\\delta}, \\quad
   s = \\operatorname{sgn}\\beta(\\gamma+\\delta) .

With :math:`s = +1` this is exactly :class:`damper.models.bouc_wen.NormalizedBoucWen`'s hysteresis
(:math:`|w| \\le 1`, :math:`\\kappa_w` is the force the hysteretic part saturates at). With
:math:`s = -1` (the benchmark: :math:`\\gamma + \\delta = -0.3`) the hysteretic force hardens on
loading instead of saturating and :math:`\\kappa_w` is the force at which its loading stiffness
has doubled. The map is one-to-one for :math:`\\alpha > 0` and :math:`\\beta(\\gamma+\\delta) \\ne 0`;
the reverse map :meth:`HystereticOscillator.to_standard` picks :math:`\\beta` (default 1).
:math:`\\alpha` [N/m] is the initial stiffness of the hysteretic force, so the small-amplitude
stiffness of the oscillator is :math:`k + \\alpha`.

Integration
-----------
The benchmark integrates with a Newmark (trapezoidal) scheme at 20 times the sampling rate
(its section 4); :mod:`damper.hysteresis.oscillator_kernel` implements that scheme. A force sampled
at ``fs`` is first interpolated to the integration rate: band-limited interpolation
(:func:`upsample_force`: exact Fourier interpolation for one period of a periodic input, a long
Kaiser-windowed polyphase filter otherwise), since a sampled force is the sampling of a
band-limited signal and linear interpolation would attenuate it by 0.7 % already at the
benchmark's 35.6 Hz resonance.

References
----------
Noël J.P., Schoukens M. (2016) *Hysteretic benchmark with a dynamic nonlinearity*, Workshop on
Nonlinear System Identification Benchmarks, Brussels.
Ikhouane F., Rodellar J. (2007) *Systems with Hysteresis*, Wiley.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from benchmark.foundation.errors import InputError, NumericalError, ParameterError
from damper.hysteresis.oscillator_kernel import newmark_bouc_wen

__all__ = ["HystereticOscillator", "upsample_force", "DEFAULT_UPSAMPLE", "PARAMETER_NAMES",
           "PARAMETER_UNITS"]

#: Integration steps per sample (the benchmark's factor 20: 750 Hz data, 15 kHz integration).
DEFAULT_UPSAMPLE = 20
#: The stored (normalized) parameters, in order.
PARAMETER_NAMES = ("mass", "damping", "stiffness", "kappa_w", "rho", "sigma", "n", "branch")
PARAMETER_UNITS = {"mass": "kg", "damping": "N s/m", "stiffness": "N/m", "kappa_w": "N",
                   "rho": "1/m", "sigma": "1", "n": "1", "branch": "1"}
# Half-length (in input samples) of the polyphase interpolation filter for non-periodic inputs.
_INTERP_HALF = 32
_INTERP_BETA = 10.0


def _finite(name: str, value) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name}: expected a number, got {value!r}") from None
    if not math.isfinite(v):
        raise ParameterError(f"{name}: expected a finite number, got {v}")
    return v


@dataclass(frozen=True)
class HystereticOscillator:
    """Mass, viscous damper, linear spring and normalized Bouc-Wen element (see module docstring).

    Parameters
    ----------
    mass : float
        :math:`m` > 0 [kg].
    damping : float
        :math:`c` >= 0 [N s/m].
    stiffness : float
        :math:`k` [N/m] (finite; the small-amplitude stiffness is :math:`k + \\kappa_w\\rho`).
    kappa_w : float
        :math:`\\kappa_w` > 0 [N].
    rho : float
        :math:`\\rho` > 0 [1/m].
    sigma : float
        :math:`\\sigma` [-] (finite).
    n : float
        :math:`n = \\nu` >= 1 [-].
    branch : int
        :math:`s` = +1 (saturating) or -1 (hardening).

    Raises
    ------
    ParameterError
        A parameter outside the class above.
    """

    mass: float
    damping: float
    stiffness: float
    kappa_w: float
    rho: float
    sigma: float
    n: float
    branch: int = 1

    def __post_init__(self) -> None:
        for name in PARAMETER_NAMES[:-1]:
            object.__setattr__(self, name, _finite(name, getattr(self, name)))
        if not self.mass > 0:
            raise ParameterError(f"mass: expected > 0 kg, got {self.mass}")
        if not self.damping >= 0:
            raise ParameterError(f"damping: expected >= 0 N s/m, got {self.damping}")
        if not self.kappa_w > 0:
            raise ParameterError(f"kappa_w: expected > 0 N, got {self.kappa_w}")
        if not self.rho > 0:
            raise ParameterError(f"rho: expected > 0 1/m, got {self.rho}")
        if not self.n >= 1:
            raise ParameterError(f"n: expected >= 1, got {self.n}")
        if self.branch not in (1, -1):
            raise ParameterError(f"branch: expected +1 or -1, got {self.branch!r}")
        object.__setattr__(self, "branch", int(self.branch))

    # ------------------------------------------------------------------ conversions
    @property
    def alpha(self) -> float:
        """:math:`\\alpha = \\kappa_w\\rho`, initial stiffness of the hysteretic force [N/m]."""
        return self.kappa_w * self.rho

    def kernel_coefficients(self) -> tuple[float, float, float, float]:
        """(:math:`\\alpha`, :math:`\\beta\\gamma`, :math:`\\beta\\delta`, :math:`\\nu`) in SI units."""
        scale = self.branch * self.rho * self.kappa_w ** (1.0 - self.n)   # beta (gamma + delta)
        return self.alpha, scale * self.sigma, scale * (1.0 - self.sigma), self.n

    @classmethod
    def from_kernel(cls, mass: float, damping: float, stiffness: float, alpha: float, bg: float,
                    bd: float, nu: float) -> "HystereticOscillator":
        """The model with :math:`\\alpha`, :math:`\\beta\\gamma`, :math:`\\beta\\delta`, :math:`\\nu` (SI).

        Parameters
        ----------
        bg : float
            Product βγ [1/m^ν].
        bd : float
            Product βδ [1/m^ν].
        mass : float
            Mass m [kg].
        damping : float
            Viscous damping c [N·s/m].
        stiffness : float
            Stiffness k [N/m].
        alpha : float
            Hysteretic stiffness α [N/m].
        nu : float
            Exponent ν (≥ 1).
        """
        alpha, bg, bd, nu = (_finite(k, v) for k, v in
                             (("alpha", alpha), ("beta*gamma", bg), ("beta*delta", bd), ("nu", nu)))
        if not alpha > 0:
            raise ParameterError(f"alpha: expected > 0 N/m, got {alpha}")
        total = bg + bd
        if total == 0.0 or not math.isfinite(total):
            raise ParameterError("beta*(gamma + delta): expected a nonzero value (the normalized "
                                 "form needs it), got 0")
        if not nu >= 1:
            raise ParameterError(f"nu: expected >= 1, got {nu}")
        kappa_w = (alpha / abs(total)) ** (1.0 / nu)
        return cls(mass, damping, stiffness, kappa_w, alpha / kappa_w, bg / total, nu,
                   1 if total > 0 else -1)

    @classmethod
    def from_standard(cls, mass: float, damping: float, stiffness: float, alpha: float,
                      beta: float, gamma: float, delta: float, nu: float) -> "HystereticOscillator":
        """The model with the benchmark's parameters (:math:`\\alpha, \\beta, \\gamma, \\delta, \\nu`), SI.

        Parameters
        ----------
        beta : float
            Scale β of the hysteretic variable.
        gamma : float
            Coefficient γ [1/m^ν].
        delta : float
            Coefficient δ [1/m^ν].
        mass : float
            Mass m [kg].
        damping : float
            Viscous damping c [N·s/m].
        stiffness : float
            Stiffness k [N/m].
        alpha : float
            Hysteretic stiffness α [N/m].
        nu : float
            Exponent ν (≥ 1).

        Examples
        --------
        >>> bw = HystereticOscillator.from_standard(2.0, 10.0, 5e4, 5e4, 1e3, 0.8, -1.1, 1.0)
        >>> round(bw.kappa_w, 3), round(bw.rho, 3), round(bw.sigma, 4), bw.branch
        (166.667, 300.0, -2.6667, -1)
        """
        beta, gamma, delta = (_finite(k, v) for k, v in
                              (("beta", beta), ("gamma", gamma), ("delta", delta)))
        return cls.from_kernel(mass, damping, stiffness, alpha, beta * gamma, beta * delta, nu)

    def to_standard(self, beta: float = 1.0) -> dict[str, float]:
        """The benchmark's form with the chosen free scale :math:`\\beta` (> 0 or < 0, SI).

        Parameters
        ----------
        beta : float, optional
            The free scale β (≠ 0).

        Returns
        -------
        dict
            ``mass, damping, stiffness, alpha, beta, gamma, delta, nu``.
        """
        beta = _finite("beta", beta)
        if beta == 0.0:
            raise ParameterError("beta: expected a nonzero value")
        alpha, bg, bd, nu = self.kernel_coefficients()
        return {"mass": self.mass, "damping": self.damping, "stiffness": self.stiffness,
                "alpha": alpha, "beta": beta, "gamma": bg / beta, "delta": bd / beta, "nu": nu}

    def parameters(self) -> dict[str, float]:
        """The stored parameters (SI) as a dict; ``HystereticOscillator(**p)`` rebuilds the model."""
        return asdict(self)

    def natural_frequency(self) -> float:
        """Small-amplitude natural frequency :math:`\\sqrt{(k+\\alpha)/m}/2\\pi` [Hz]."""
        k0 = self.stiffness + self.alpha
        return math.sqrt(k0 / self.mass) / (2 * math.pi) if k0 > 0 else float("nan")

    # ------------------------------------------------------------------ simulation
    def simulate_fine(self, u_fine: np.ndarray, h: float, every: int = 1,
                      initial: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> np.ndarray:
        """Integrate under forces given at the integration instants.

        Parameters
        ----------
        u_fine : ndarray, shape (n,)
            Force at instants ``i h`` [N].
        h : float
            Integration step [s].
        every : int
            Return every ``every``-th instant.
        initial : (y0, ydot0, z0)
            Initial state [m, m/s, N].

        Returns
        -------
        ndarray, shape ((n - 1) // every + 1, 3)
            Displacement [m], velocity [m/s] and hysteretic force [N].

        Raises
        ------
        NumericalError
            The Newton-Raphson iteration failed or the state diverged.
        """
        u_fine = np.ascontiguousarray(u_fine, dtype=float)
        if u_fine.ndim != 1 or u_fine.size < 1:
            raise InputError("force: expected a non-empty 1-D array")
        if not (h > 0 and math.isfinite(h)):
            raise InputError(f"integration step: expected > 0 s, got {h}")
        out = np.empty(((u_fine.size - 1) // every + 1, 3))
        alpha, bg, bd, nu = self.kernel_coefficients()
        y0, v0, z0 = (float(x) for x in initial)
        bad = newmark_bouc_wen(u_fine, float(h), self.mass, self.damping, self.stiffness, alpha,
                               bg, bd, nu, y0, v0, z0, int(every), out)
        if bad >= 0:
            raise NumericalError("hysteretic oscillator: the Newmark iteration diverged",
                                 time=bad * h, hint="the parameters may make the oscillator "
                                 "unstable under this force")
        return out

    def simulate(self, force: np.ndarray, fs: float, upsample: int = DEFAULT_UPSAMPLE,
                 periodic: bool = False, initial: tuple[float, float, float] = (0.0, 0.0, 0.0),
                 max_periods: int = 50, states: bool = False) -> np.ndarray:
        """Displacement response to a force sampled at ``fs``.

        Parameters
        ----------
        force : ndarray, shape (n,)
            Force samples [N] at instants ``j / fs``.
        fs : float
            Sampling rate [Hz].
        upsample : int
            Integration steps per sample (the benchmark uses 20).
        periodic : bool
            ``force`` is one period of a periodic force: return the steady-state period (the
            period is repeated from ``initial`` until two consecutive periods differ by less than
            1e-10 of the response RMS, at most ``max_periods`` times).
        initial : (y0, ydot0, z0)
            Initial state [m, m/s, N] (with ``periodic``: the state the repetitions start from).
        max_periods : int
            Cap on the repetitions of a periodic force.
        states : bool
            Return the (n, 3) states (y, ydot, z) instead of y alone.

        Returns
        -------
        ndarray
            Displacement [m], shape (n,); or the states, shape (n, 3).
        """
        force = np.asarray(force, dtype=float)
        if force.ndim != 1 or force.size < 2:
            raise InputError("force: expected a 1-D array of at least 2 samples")
        if not (fs > 0 and math.isfinite(fs)):
            raise InputError(f"sampling rate: expected > 0 Hz, got {fs}")
        upsample = int(upsample)
        if upsample < 1:
            raise InputError(f"upsample: expected >= 1, got {upsample}")
        h = 1.0 / (fs * upsample)
        u_fine = upsample_force(force, upsample, periodic)
        if not periodic:
            out = self.simulate_fine(u_fine[:(force.size - 1) * upsample + 1], h, upsample, initial)
            return out if states else out[:, 0]
        chain = np.concatenate([u_fine, u_fine[:1]])
        state = tuple(float(x) for x in initial)
        previous = None
        for _ in range(max(int(max_periods), 1)):
            out = self.simulate_fine(chain, h, upsample, state)
            state = tuple(out[-1])
            period = out[:-1]
            if previous is not None:
                change = np.sqrt(np.mean((period[:, 0] - previous[:, 0]) ** 2))
                size = np.sqrt(np.mean(period[:, 0] ** 2))
                if change <= 1e-10 * size or size == 0.0:
                    break
            previous = period
        return period if states else period[:, 0]


def upsample_force(force: np.ndarray, factor: int, periodic: bool = False) -> np.ndarray:
    """Band-limited interpolation of a sampled force to ``factor`` times its rate.

    Parameters
    ----------
    force : ndarray, shape (n,)
        Force samples [N].
    factor : int
        Upsampling factor (>= 1).
    periodic : bool
        ``force`` is one period of a periodic signal: exact Fourier interpolation
        (:func:`scipy.signal.resample`). Otherwise a polyphase filter
        (:func:`scipy.signal.resample_poly`) with a Kaiser window (beta 10, 64 input samples long),
        flat to 1e-5 up to 0.4 times the sampling rate; the force is taken as zero before the
        first sample and held at its last value after the end.

    Returns
    -------
    ndarray, shape (n * factor,)
        Force at instants ``i / (fs factor)``; sample ``j * factor`` equals ``force[j]`` for the
        periodic case and to filter precision otherwise.
    """
    force = np.asarray(force, dtype=float)
    factor = int(factor)
    if factor == 1:
        return force.copy()
    # scipy.signal only here: the building's processes import this module (through the model
    # files) and never resample; at import it cost them 0.3 s and ~30 MB
    from scipy import signal

    if periodic:
        return signal.resample(force, force.size * factor)
    taps = signal.firwin(2 * _INTERP_HALF * factor + 1, 1.0 / factor,
                         window=("kaiser", _INTERP_BETA))
    padded = np.concatenate([force, np.full(_INTERP_HALF, force[-1])])
    fine = signal.resample_poly(padded, factor, 1, window=taps)
    return fine[:force.size * factor]
