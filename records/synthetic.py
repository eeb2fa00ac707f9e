"""Built-in ground-motion generator, so that everything runs with no record files at all.

Every generated record has ``synthetic=True``, a name starting with ``synthetic-`` and a
``source`` starting with ``"synthetic:"``; plots and reports say so.

Model
-----
Stationary Gaussian white noise :math:`w(t)` (piecewise constant over each step dt) is
multiplied by a time envelope :math:`e(t)` and passed through the Kanai–Tajimi filter
(ground layer ω_g, ζ_g) followed by the Clough–Penzien high-pass filter (ω_f, ζ_f), which
removes the unbounded low-frequency displacement of Kanai–Tajimi:

.. math::

    \\ddot x_g + 2\\zeta_g\\omega_g\\dot x_g + \\omega_g^2 x_g = -e(t)\\,w(t), \\qquad
    a_1 = -2\\zeta_g\\omega_g\\dot x_g - \\omega_g^2 x_g,

    \\ddot x_f + 2\\zeta_f\\omega_f\\dot x_f + \\omega_f^2 x_f = a_1, \\qquad
    a_{noise} = \\ddot x_f = a_1 - 2\\zeta_f\\omega_f\\dot x_f - \\omega_f^2 x_f.

A second-order Butterworth low-pass at ``f_max`` (default 15 Hz) follows, standing for the
high-frequency decay (f_max, κ) of real records, which Kanai–Tajimi alone lacks. For a
stationary input the power spectral density of the output is

.. math::

    S(\\omega) = S_0\\,
    \\frac{\\omega_g^4 + 4\\zeta_g^2\\omega_g^2\\omega^2}{(\\omega_g^2-\\omega^2)^2 + 4\\zeta_g^2\\omega_g^2\\omega^2}\\;
    \\frac{\\omega^4}{(\\omega_f^2-\\omega^2)^2 + 4\\zeta_f^2\\omega_f^2\\omega^2}\\;
    \\frac{\\omega_c^4}{(\\omega_c^2-\\omega^2)^2 + 2\\omega_c^2\\omega^2},
    \\qquad \\omega_c = 2\\pi f_{max}.

The filters are advanced with their exact zero-order-hold discretisation (a compiled kernel).
The envelope is trapezoidal in the manner of Jennings, Housner & Tsai (1968): a rise
:math:`(t/t_1)^2` for :math:`t < t_1`, a plateau of length :math:`t_s`, then decay
:math:`e^{-c(t - t_1 - t_s)}`. A linear baseline correction brings the noise's final velocity
and displacement to zero (:func:`records.baseline.end_condition_correction`), so it does not drift. An optional Mavroeidis–Papageorgiou velocity pulse
(:mod:`records.pulse`) is added: the noise is scaled to the target PGA on its own, the pulse
added, and the sum scaled by the factor f (usually < 1) that makes the PGA exactly the target (the
pulse's velocity amplitude becomes f·A; ``metadata["pulse_scale"]`` = f). Scaling the noise on
its own keeps its share of the energy, so the significant duration follows the envelope even
on pulse records.

The benchmark-like set (:func:`benchmark_like`) calibrates each column of each benchmark
record to the catalogue (:mod:`records.catalogue`): PGA exactly, length, significant duration
D5–95 (through the envelope, from its expected Husid curve), mean period (through ω_g, from
the filter's spectrum, with ζ_g = 0.6, ω_f = 0.1 ω_g, ζ_f = 0.6) and, on column 1 of the
pulse-like records, a pulse of the catalogue's period T_p with amplitude equal to the column's
PGV (γ = 2, ν = 0; shrunk if its acceleration would exceed 0.8 × PGA); the PGV then follows
only approximately (within about ±40 % on the seven records). On a pulse column the
noise stands for the broadband part only: its ω_g is calibrated to the mean period of the
*other* column (the pulse supplies the long periods) and ω_f = max(0.1 ω_g, 2π/T_p) removes
noise content at periods longer than the pulse, so that the pulse dominates the velocity. These are modelling choices, documented here; the motions are *like* the
benchmark records in these statistics, not copies of them. PGV and PGD are **not** matched:
over the seven records (FN-x, seed 0) the synthetic PGV is 0.36 to 1.6 times the recorded one
and the PGD 0.3 to 8 times (recorded PGD baseline-corrected; El Centro column 1: 107 cm against
13 cm), so each
record's ``metadata["recorded_comparison"]`` states both, and the commands print them.

References
----------
Kanai, K. (1957) Semi-empirical formula for the seismic characteristics of the ground.
Bull. Earthq. Res. Inst. Univ. Tokyo 35, 309–325. Tajimi, H. (1960) A statistical method of
determining the maximum response of a building structure during an earthquake. Proc. 2nd
WCEE, 781–797. Clough, R. W. & Penzien, J. (1975) *Dynamics of Structures*, McGraw-Hill.
Jennings, P. C., Housner, G. W. & Tsai, N. C. (1968) Simulated earthquake motions. EERL, Caltech.
Mavroeidis, G. P. & Papageorgiou, A. S. (2003) Bull. Seism. Soc. Am. 93(3), 1099–1131.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numba
import numpy as np
from scipy.linalg import expm
from scipy.optimize import brentq

from benchmark.foundation.errors import InputError, ParameterError
from records.baseline import end_condition_correction
from records.catalogue import BENCHMARK_RECORDS, ORIENTATIONS, canonical_orientation, get_entry
from records.measures import husid
from records.pulse import PulseParameters
from records.record import STANDARD_GRAVITY, Record

__all__ = [
    "Envelope",
    "GroundMotionModel",
    "generate",
    "envelope_for_duration",
    "omega_g_for_mean_period",
    "benchmark_like_models",
    "benchmark_like",
    "benchmark_like_set",
]


@dataclass(frozen=True)
class Envelope:
    """Trapezoidal time envelope: rise (t/t_rise)² over ``t_rise`` [s], plateau ``t_strong`` [s], decay rate ``decay`` [1/s].

    Parameters
    ----------
    t_rise : float
        Rise time [s]: the envelope grows as (t/t_rise)² from 0 to 1.
    t_strong : float
        Duration [s] of the plateau at 1 (strong motion).
    decay : float
        Exponential decay rate [1/s] after the plateau.
    """

    t_rise: float
    t_strong: float
    decay: float

    def __post_init__(self) -> None:
        if not (self.t_rise >= 0 and self.t_strong >= 0 and self.decay > 0) or not all(
                math.isfinite(x) for x in (self.t_rise, self.t_strong, self.decay)):
            raise ParameterError(f"envelope t_rise={self.t_rise}, t_strong={self.t_strong}, decay={self.decay}; "
                                 "expected t_rise >= 0, t_strong >= 0, decay > 0")

    def __call__(self, t: np.ndarray) -> np.ndarray:
        """Envelope value at times ``t`` [s] (between 0 and 1)."""
        t = np.asarray(t, dtype=float)
        t2 = self.t_rise + self.t_strong
        rise = np.minimum(t / self.t_rise, 1.0) ** 2 if self.t_rise > 0 else np.ones_like(t)
        return np.where(t <= t2, rise, np.exp(-self.decay * (t - t2)))


@dataclass(frozen=True)
class GroundMotionModel:
    """Parameters of one generated component (SI units).

    Parameters
    ----------
    duration : float
        Length n·dt [s].
    pga : float
        Target PGA [m/s²] (met exactly).
    dt : float
        Time step [s].
    omega_g, zeta_g : float
        Kanai–Tajimi ground frequency [rad/s] and damping ratio.
    omega_f, zeta_f : float
        Clough–Penzien high-pass frequency [rad/s] and damping ratio.
    envelope : Envelope or None
        Time envelope; None gives stationary noise.
    pulse : PulseParameters or None
        Optional near-fault velocity pulse.
    f_max : float or None
        Corner [Hz] of the second-order Butterworth low-pass that gives the motion the
        high-frequency decay of real records (default 15 Hz); None leaves Kanai–Tajimi's
        slow :math:`\\omega^{-2}` decay up to the Nyquist frequency.
    """

    duration: float
    pga: float
    dt: float = 0.005
    omega_g: float = 5.0 * math.pi
    zeta_g: float = 0.6
    omega_f: float = 0.5 * math.pi
    zeta_f: float = 0.6
    envelope: Envelope | None = None
    pulse: PulseParameters | None = None
    f_max: float | None = 15.0

    def __post_init__(self) -> None:
        checks = {"duration": self.duration > 0, "pga": self.pga > 0, "dt": self.dt > 0,
                  "omega_g": self.omega_g > 0, "zeta_g": 0 < self.zeta_g < 5, "omega_f": self.omega_f > 0,
                  "zeta_f": 0 < self.zeta_f < 5}
        for name, ok in checks.items():
            value = getattr(self, name)
            if not ok or not math.isfinite(value):
                raise ParameterError(f"ground motion model: {name} = {value}; expected a positive finite value"
                                     + (" below 5" if name.startswith("zeta") else ""))
        if self.duration < 4 * self.dt:
            raise ParameterError(f"ground motion model: duration {self.duration} s is shorter than 4 steps of {self.dt} s")
        if self.omega_g > math.pi / self.dt:
            raise ParameterError(f"ground motion model: omega_g = {self.omega_g} rad/s is above the Nyquist "
                                 f"frequency {math.pi / self.dt:.1f} rad/s of dt = {self.dt} s")
        if self.f_max is not None and not (0 < self.f_max < 0.5 / self.dt and math.isfinite(self.f_max)):
            raise ParameterError(f"ground motion model: f_max = {self.f_max} Hz; expected a frequency between 0 and "
                                 f"the Nyquist frequency {0.5 / self.dt:g} Hz (or None)")
        if self.pulse is not None and self.pulse.period < 4 * self.dt:
            raise ParameterError(f"ground motion model: pulse period {self.pulse.period} s is shorter than 4 steps")

    @property
    def n_samples(self) -> int:
        """Number of samples, round(duration / dt)."""
        return int(round(self.duration / self.dt))

    def psd_shape(self, omega: np.ndarray) -> np.ndarray:
        """Kanai–Tajimi × Clough–Penzien spectral shape S(ω)/S₀ (module docstring).

        Parameters
        ----------
        omega : np.ndarray
            Circular frequencies ω [rad/s].
        """
        return _psd_shape(np.asarray(omega, float), self.omega_g, self.zeta_g, self.omega_f, self.zeta_f, self.f_max)

    def peak_frequency(self) -> float:
        """Frequency [Hz] where the filters' spectral shape peaks (numerically, 0.01–50 Hz)."""
        f = np.logspace(-2, math.log10(min(50.0, 0.5 / self.dt)), 20000)
        return float(f[np.argmax(self.psd_shape(2 * np.pi * f))])


_LOWPASS_ZETA = math.sqrt(0.5)  # Butterworth


def _psd_shape(omega: np.ndarray, wg: float, zg: float, wf: float, zf: float,
               f_max: float | None = None) -> np.ndarray:
    w2 = omega ** 2
    kt = (wg ** 4 + 4 * zg ** 2 * wg ** 2 * w2) / ((wg ** 2 - w2) ** 2 + 4 * zg ** 2 * wg ** 2 * w2)
    cp = w2 ** 2 / ((wf ** 2 - w2) ** 2 + 4 * zf ** 2 * wf ** 2 * w2)
    if f_max is None:
        return kt * cp
    wc = 2 * np.pi * f_max
    lp = wc ** 4 / ((wc ** 2 - w2) ** 2 + 4 * _LOWPASS_ZETA ** 2 * wc ** 2 * w2)
    return kt * cp * lp


def _filter_matrices(model: GroundMotionModel) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Exact zero-order-hold matrices (Ad, Bd) and output row c of the filter chain."""
    wg, zg, wf, zf = model.omega_g, model.zeta_g, model.omega_f, model.zeta_f
    n = 4 if model.f_max is None else 6
    # states (x_g, xd_g, x_f, xd_f[, y, yd]); input w; a_cp = xdd_f
    a = np.zeros((n, n))
    a[0, 1] = 1.0
    a[1, 0], a[1, 1] = -wg ** 2, -2 * zg * wg
    a[2, 3] = 1.0
    a_cp = np.zeros(n)
    a_cp[:4] = [-wg ** 2, -2 * zg * wg, -wf ** 2, -2 * zf * wf]
    a[3] = a_cp
    c = a_cp.copy()
    if n == 6:  # y'' + 2 zeta_c wc y' + wc^2 y = wc^2 a_cp; output y
        wc = 2 * np.pi * model.f_max
        a[4, 5] = 1.0
        a[5] = wc ** 2 * a_cp
        a[5, 4] += -wc ** 2
        a[5, 5] += -2 * _LOWPASS_ZETA * wc
        c = np.zeros(n)
        c[4] = 1.0
    b = np.zeros(n)
    b[1] = -1.0
    big = np.zeros((n + 1, n + 1))
    big[:n, :n] = a * model.dt
    big[:n, n] = b * model.dt
    e = expm(big)
    return e[:n, :n].copy(), e[:n, n].copy(), c


@numba.njit(cache=True)
def _filter_noise(ad, bd, c, u):  # pragma: no cover - compiled
    """y_k = c·x_k,  x_{k+1} = Ad x_k + Bd u_k (zero-order hold), from rest."""
    n = u.shape[0]
    m = bd.shape[0]
    x = np.zeros(m)
    xn = np.zeros(m)
    y = np.empty(n)
    for k in range(n):
        acc = 0.0
        for i in range(m):
            acc += c[i] * x[i]
        y[k] = acc
        for i in range(m):
            s = bd[i] * u[k]
            for j in range(m):
                s += ad[i, j] * x[j]
            xn[i] = s
        for i in range(m):
            x[i] = xn[i]
    return y


def _rng(seed: Any) -> np.random.Generator:
    if isinstance(seed, np.random.Generator):
        return seed
    try:
        return np.random.default_rng(seed)
    except (TypeError, ValueError) as exc:
        raise InputError(f"seed {seed!r} is not usable as a random seed ({exc})") from None


def _combine(noise: np.ndarray, pulse_acc: np.ndarray, pga: float) -> tuple[np.ndarray, float, float]:
    """Noise scaled to the PGA on its own, plus the pulse, then both scaled so the PGA is exact.

    Returns the acceleration, the noise's factor and the common factor f (usually < 1) that the pulse
    ended up multiplied by. Scaling the noise on its own keeps its share of the energy (so the
    significant duration follows the envelope even on pulse records).
    """
    peak_pulse = float(np.max(np.abs(pulse_acc)))
    if peak_pulse >= pga:
        raise ParameterError(f"pulse peak acceleration {peak_pulse:.3g} m/s² reaches the target PGA {pga:.3g} m/s²")
    peak_noise = float(np.max(np.abs(noise)))
    if peak_noise == 0:
        raise ParameterError("generated noise is identically zero")
    acc = noise * (pga / peak_noise) + pulse_acc
    common = pga / float(np.max(np.abs(acc)))
    acc = acc * common
    acc *= pga / np.max(np.abs(acc))  # remove the last rounding so the PGA is exact
    return acc, pga / peak_noise * common, common


def generate(model: GroundMotionModel, seed: Any = 0, name: str = "synthetic", label: str = "synthetic",
             metadata: dict[str, Any] | None = None) -> Record:
    """Generate one component of ground acceleration from ``model``.

    Parameters
    ----------
    model : GroundMotionModel
        Filter, envelope, pulse and PGA target.
    seed : int, sequence of int, SeedSequence or Generator
        Seed of ``numpy.random.default_rng``; the same seed gives bit-identical output.
    name, label : str
        Record name (``synthetic-`` is prefixed if missing) and component label.
    metadata : dict, optional
        Extra metadata.

    Returns
    -------
    Record
        One component in m/s², ``synthetic=True``.
    """
    rng = _rng(seed)
    n = model.n_samples
    t = np.arange(n) * model.dt
    white = rng.standard_normal(n)
    if model.envelope is not None:
        white = white * model.envelope(t)
    ad, bd, c = _filter_matrices(model)
    noise = _filter_noise(ad, bd, c, np.ascontiguousarray(white))
    noise = noise - end_condition_correction(noise, model.dt)
    pulse_acc = model.pulse.acceleration(t) if model.pulse is not None else np.zeros(n)
    acc, noise_scale, pulse_scale = _combine(noise, pulse_acc, model.pga)
    name = name if name.startswith("synthetic") else f"synthetic-{name}"
    meta = {"model": _model_dict(model), "noise_scale": noise_scale, "pulse_scale": pulse_scale}
    meta.update(metadata or {})
    parts = ["Kanai-Tajimi/Clough-Penzien filtered noise"]
    if model.pulse is not None:
        parts.append(f"Mavroeidis-Papageorgiou pulse Tp={model.pulse.period:.2f} s")
    return Record(name=name, dt=model.dt, acceleration=acc, labels=(label,),
                  source="synthetic: " + " + ".join(parts), synthetic=True, metadata=meta)


def _model_dict(model: GroundMotionModel) -> dict[str, Any]:
    out: dict[str, Any] = {k: getattr(model, k) for k in ("duration", "pga", "dt", "omega_g", "zeta_g",
                                                           "omega_f", "zeta_f", "f_max")}
    out["envelope"] = None if model.envelope is None else vars(model.envelope).copy()
    out["pulse"] = None if model.pulse is None else vars(model.pulse).copy()
    return out


# --------------------------------------------------------------------------- calibration
def envelope_for_duration(duration: float, significant_duration: float, dt: float = 0.005) -> Envelope:
    """Envelope whose expected D5–95 (from the Husid curve of e(t)²) equals ``significant_duration``.

    Parameters
    ----------
    duration : float
        Record length [s].
    significant_duration : float
        Target D5–95 [s], shorter than ``duration``.
    dt : float
        Time step of the grid the Husid curve is evaluated on [s].

    Notes
    -----
    Choices: rise t_1 = min(0.2 D, 0.15 T), decay c = 2 / D (energy e-folds over D / 4); the
    plateau t_s ≥ 0 is solved for. If even t_s = 0 gives more than D, the decay is made faster.
    """
    T, D = float(duration), float(significant_duration)
    if not (T > 0 and 0 < D < T):
        raise ParameterError(f"envelope: significant duration {D} s must be positive and shorter than the "
                             f"record length {T} s")
    t = np.arange(int(round(T / dt))) * dt
    t_rise = min(0.2 * D, 0.15 * T)

    def d595(t_strong: float, decay: float) -> float:
        h = husid(Envelope(t_rise, t_strong, decay)(t), dt)
        return float(np.interp(0.95, h, t) - np.interp(0.05, h, t))

    decay = 2.0 / D
    if d595(0.0, decay) > D:
        decay = brentq(lambda c: d595(0.0, c) - D, decay, 1e3 / D)
        return Envelope(t_rise, 0.0, decay)
    t_max = max(T - t_rise, 0.0)
    if d595(t_max, decay) < D:
        return Envelope(t_rise, t_max, decay)
    return Envelope(t_rise, brentq(lambda s: d595(s, decay) - D, 0.0, t_max, xtol=1e-4), decay)


def _mean_period_of_shape(wg: float, zg: float, wf: float, zf: float, corner: float | None,
                          f_min: float = 0.25, f_max: float = 20.0) -> float:
    f = np.linspace(f_min, f_max, 4000)
    s = _psd_shape(2 * np.pi * f, wg, zg, wf, zf, corner)
    return float(np.trapezoid(s / f, f) / np.trapezoid(s, f))


def omega_g_for_mean_period(mean_period: float, zeta_g: float = 0.6, omega_f_ratio: float = 0.1,
                            zeta_f: float = 0.6, f_max: float | None = 15.0) -> float:
    """Kanai–Tajimi ω_g [rad/s] whose filtered-noise spectrum has the mean period ``mean_period`` [s].

    The mean period is that of Rathje et al. (2004) over 0.25–20 Hz, computed from the filters'
    spectral shape. ω_g is kept within 2π·[0.3, 10] Hz.

    Parameters
    ----------
    mean_period : float
        Target mean period [s].
    zeta_g : float
        Kanai–Tajimi damping ratio.
    omega_f_ratio : float
        Clough–Penzien frequency as a fraction of ω_g.
    zeta_f : float
        Clough–Penzien damping ratio.
    f_max : float or None
        Low-pass corner [Hz] (see :class:`GroundMotionModel`).
    """
    if not mean_period > 0:
        raise ParameterError(f"mean period = {mean_period} s; expected > 0")
    lo, hi = 2 * np.pi * 0.3, 2 * np.pi * 10.0
    g = lambda w: _mean_period_of_shape(w, zeta_g, omega_f_ratio * w, zeta_f, f_max) - mean_period  # noqa: E731
    if g(lo) <= 0:
        return lo
    if g(hi) >= 0:
        return hi
    return float(brentq(g, lo, hi, xtol=1e-6))


# --------------------------------------------------------------------------- benchmark-like set
def benchmark_like_models(name: str, dt: float = 0.005) -> tuple[GroundMotionModel, GroundMotionModel]:
    """The two component models (file columns 1 and 2) calibrated to a benchmark record's catalogue entry.

    Parameters
    ----------
    name : str
        Benchmark record name.
    dt : float
        Time step [s].
    """
    entry = get_entry(name)
    models = []
    for c in range(2):
        envelope = envelope_for_duration(entry.duration_s, entry.significant_duration_s[c], dt)
        tp = entry.pulse_period_s[c]
        wg = omega_g_for_mean_period(entry.mean_period_s[c] if tp is None else entry.mean_period_s[1 - c])
        wf = 0.1 * wg if tp is None else max(0.1 * wg, 2 * np.pi / tp)
        pulse = None
        if tp is not None:
            gamma = 2.0
            half = 0.5 * gamma * tp
            t_peak = max(envelope.t_rise + 0.3 * envelope.t_strong, half + 0.5)
            t_peak = min(t_peak, entry.duration_s - half - 0.5)
            pulse = PulseParameters(amplitude=entry.pgv_m_s[c], period=tp, gamma=gamma, phase=0.0,
                                    t_peak=t_peak)
            peak = float(np.max(np.abs(pulse.acceleration(np.arange(0, entry.duration_s, dt)))))
            pga = entry.pga_g[c] * STANDARD_GRAVITY
            if peak > 0.8 * pga:  # leave room for the noise: shrink the pulse, keep its period
                pulse = PulseParameters(pulse.amplitude * 0.8 * pga / peak, tp, gamma, 0.0, t_peak)
        models.append(GroundMotionModel(duration=entry.duration_s, pga=entry.pga_g[c] * STANDARD_GRAVITY, dt=dt,
                                        omega_g=wg, zeta_g=0.6, omega_f=wf, zeta_f=0.6,
                                        envelope=envelope, pulse=pulse))
    return models[0], models[1]


#: What :func:`benchmark_like` matches and what it does not, printed beside its PGV and PGD.
RECORDED_COMPARISON_NOTE = ("the generator matches PGA, length, D5-95 and mean period; PGV and PGD are not "
                            "calibrated and can differ several-fold from the recorded motion's")


def benchmark_like(name: str, orientation: str = "FN-x", seed: int = 0, dt: float = 0.005) -> Record:
    """A synthetic two-component record calibrated to one benchmark record (see the module docstring).

    Parameters
    ----------
    name : str
        Benchmark record name (``erzincan`` accepted).
    orientation : {"FN-x", "FP-x", "FP-y", "FN-y"}
        As for :func:`records.load_benchmark_record`: ``"FN-x"`` puts the column-1-like component on x.
    seed : int
        Seed; each record name and column draws its own stream from it, so the same seed gives
        the same motion bit for bit, and FN-x / FP-x are the same pair swapped.
    dt : float
        Time step [s].

    Returns
    -------
    Record
        ``name = "synthetic-<name>"``, ``synthetic=True``, labels ``"synthetic <column label>"``.
        ``metadata["recorded_comparison"]`` holds its PGV [m/s] and PGD [m] beside the recorded
        motion's (:attr:`records.catalogue.CatalogueEntry.pgv_m_s`, ``pgd_m``): they are not
        calibrated, and ``sbib records show --synthetic`` and ``records generate`` print them.
    """
    entry = get_entry(name)
    orientation = canonical_orientation(orientation)  # the seed paper's FP-y / FN-y accepted
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InputError(f"seed = {seed!r}; expected a non-negative integer")
    index = BENCHMARK_RECORDS.index(entry.name)
    models = benchmark_like_models(entry.name, dt)
    columns = [generate(m, seed=np.random.SeedSequence([int(seed), index, c]), name=entry.name)
               for c, m in enumerate(models)]
    order = [0, 1] if orientation == "FN-x" else [1, 0]
    acc = np.column_stack([columns[i].acceleration[:, 0] for i in order])
    labels = tuple(f"synthetic {entry.column_labels[i]}" for i in order)
    pulse = models[0].pulse
    source = (f"synthetic: benchmark_like({entry.name!r}, {orientation!r}, seed={int(seed)}): Kanai-Tajimi/"
              "Clough-Penzien filtered noise" + (f" + Mavroeidis-Papageorgiou pulse Tp={pulse.period:.2f} s on "
                                                 f"column 1" if pulse is not None else ""))
    meta = {"orientation": orientation, "x_file_column": order[0] + 1, "y_file_column": order[1] + 1,
            "seed": int(seed), "like": entry.name, "event": f"synthetic, like {entry.event}",
            "models": [columns[i].metadata["model"] for i in order],
            "targets": {"pga_g": [entry.pga_g[i] for i in order], "duration_s": entry.duration_s,
                        "significant_duration_s": [entry.significant_duration_s[i] for i in order],
                        "mean_period_s": [entry.mean_period_s[i] for i in order],
                        "pulse_period_s": [entry.pulse_period_s[i] for i in order]}}
    record = Record(name=f"synthetic-{entry.name}", dt=dt, acceleration=acc, labels=labels, source=source,
                    synthetic=True, metadata=meta)
    # PGV and PGD are not calibrated (module docstring): say how far they are from the recording's
    meta["recorded_comparison"] = {
        "like": entry.name, "pgv_m_s": [float(v) for v in record.pgv], "pgd_m": [float(v) for v in record.pgd],
        "recorded_pgv_m_s": [entry.pgv_m_s[i] for i in order], "recorded_pgd_m": [entry.pgd_m[i] for i in order],
        "note": RECORDED_COMPARISON_NOTE}
    return record.replace(metadata=meta)


def benchmark_like_set(orientation: str = "FN-x", seed: int = 0) -> dict[str, Record]:
    """:func:`benchmark_like` for all seven benchmark records, by catalogue name.

    Parameters
    ----------
    orientation : {"FN-x", "FP-x"}
        Orientation of every record.
    seed : int
        Seed (each record draws its own stream from it).
    """
    return {name: benchmark_like(name, orientation, seed) for name in BENCHMARK_RECORDS}
