"""Linear elastic response spectra (5 %-damped by default) by the exact piecewise-linear recurrence.

For each period T (ω = 2π/T) the single-degree-of-freedom oscillator

.. math:: \\ddot u + 2\\zeta\\omega\\dot u + \\omega^2 u = -a_g(t)

is advanced from rest with the ground acceleration taken as linear between samples. The
step from :math:`t_k` to :math:`t_{k+1}` is then exact (Nigam & Jennings 1969):

.. math::

    x_{k+1} = \\Phi x_k + \\Gamma_1 f_k + \\Gamma_2 (f_{k+1} - f_k), \\qquad x = (u, \\dot u),\\ f = a_g,

with :math:`\\Phi = e^{A\\Delta t}` and :math:`\\Gamma_1, \\Gamma_2` read from the exponential of
the first-order-hold augmented matrix (by its Taylor series; the tests check them against
``scipy.linalg.expm`` and against Nigam and Jennings' closed forms).
For short periods the step is split into ``m = ceil(50 Δt / T)`` sub-steps (≤ 64) of the same linear input, which is exact
and catches peaks between samples.

Reported per period: spectral displacement :math:`S_d = \\max|u|`, pseudo-velocity
:math:`S_{pv} = \\omega S_d`, pseudo-acceleration :math:`S_{pa} = \\omega^2 S_d`, and the peak
absolute acceleration :math:`S_a = \\max|\\ddot u + a_g|`. A period of 0 gives the PGA
(and zero displacement).

Reference
---------
Nigam, N. C. & Jennings, P. C. (1969) Calculation of response spectra from strong-motion
earthquake records. *Bull. Seism. Soc. Am.* 59(2), 909–922.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numba
import numpy as np
from scipy.linalg import expm

from benchmark.foundation.errors import InputError
from records.record import Record

__all__ = ["ResponseSpectrum", "response_spectrum", "default_periods", "sdof_response"]

_MAX_SUBSTEPS = 64


def default_periods(n: int = 120, t_min: float = 0.02, t_max: float = 10.0) -> np.ndarray:
    """``n`` periods [s] spaced logarithmically from ``t_min`` to ``t_max``.

    Parameters
    ----------
    n : int, optional
        Number of periods.
    t_min : float, optional
        Shortest period [s] (> 0).
    t_max : float, optional
        Longest period [s].
    """
    if not (0 < t_min < t_max) or n < 2:
        raise InputError(f"periods: need 0 < t_min < t_max and n >= 2, got t_min={t_min}, t_max={t_max}, n={n}")
    return np.logspace(math.log10(t_min), math.log10(t_max), int(n))


@dataclass(frozen=True)
class ResponseSpectrum:
    """Response spectra of one record; arrays have shape (n_periods, n_components).

    Attributes
    ----------
    periods : ndarray (n_periods,)
        Periods [s].
    damping : float
        Damping ratio ζ.
    sd : ndarray
        Spectral displacement [m].
    psv : ndarray
        Pseudo-velocity ω·S_d [m/s].
    psa : ndarray
        Pseudo-acceleration ω²·S_d [m/s²].
    sa : ndarray
        Peak absolute acceleration [m/s²].
    labels : tuple of str
        Component labels.
    """

    periods: np.ndarray
    damping: float
    sd: np.ndarray
    psv: np.ndarray
    psa: np.ndarray
    sa: np.ndarray
    labels: tuple[str, ...] = ()

    def peak_period(self, component: int = 0) -> float:
        """Period [s] of the largest pseudo-acceleration of a component.

        Parameters
        ----------
        component : int, optional
            0-based component index.
        """
        return float(self.periods[int(np.argmax(self.psa[:, component]))])


def _augmented(omega: float, zeta: float, h: float) -> np.ndarray:
    """[[A h, B h, 0], [0, 0, 1], [0, 0, 0]]: its exponential holds Φ, Γ1, Γ2 (first-order hold)."""
    big = np.zeros((4, 4))
    big[0, 1] = h
    big[1, 0], big[1, 1] = -omega * omega * h, -2.0 * zeta * omega * h
    big[1, 2] = -h                 # B = (0, -1): the oscillator is driven by -a_g
    big[2, 3] = 1.0                # the input's increment over the unit-normalised step
    return big


@lru_cache(maxsize=4096)
def _discretise(omega: float, zeta: float, h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Φ, Γ1, Γ2 of the first-order-hold discretisation of ü + 2ζωu̇ + ω²u = −f over step h.

    The exponential of :func:`_augmented` by its Taylor series when ωh ≤ 1 (always the case
    with the sub-stepping of :func:`response_spectrum`; the terms shrink fast and carry no
    cancellation, so even the tiny Γ entries of very long periods keep full relative precision),
    else by ``scipy.linalg.expm``. Cached: every record with the same dt reuses them.
    """
    big = _augmented(omega, zeta, h)
    if omega * h <= 1.0 and 2.0 * zeta * omega * h <= 1.0:
        e = np.eye(4)
        term = np.eye(4)
        for k in range(1, 40):
            term = term @ big / k
            e += term
            if np.max(np.abs(term)) < 1e-30:
                break
    else:
        e = expm(big)
    phi, gamma1, gamma2 = e[:2, :2].copy(), e[:2, 2].copy(), e[:2, 3].copy()
    for arr in (phi, gamma1, gamma2):
        arr.setflags(write=False)
    return phi, gamma1, gamma2


def _discretise_closed_form(omega: float, zeta: float, h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The same Φ, Γ1, Γ2 in closed form (Nigam & Jennings in matrix notation; reference for tests, 0 ≤ ζ < 1).

    With :math:`A = [[0, 1], [-\\omega^2, -2\\zeta\\omega]]`, :math:`B = (0, -1)^T`,
    :math:`\\omega_d = \\omega\\sqrt{1-\\zeta^2}` and :math:`(A + \\zeta\\omega I)^2 = -\\omega_d^2 I`:
    :math:`\\Phi = e^{-\\zeta\\omega h}[\\cos(\\omega_d h) I + \\sin(\\omega_d h)/\\omega_d\\,(A + \\zeta\\omega I)]`,
    :math:`\\Gamma_1 = A^{-1}(\\Phi - I)B`, :math:`\\Gamma_2 = A^{-1}(\\Gamma_1/h - B)`. (These lose
    relative precision to cancellation when ωh is small, hence the series in :func:`_discretise`.)
    """
    a = np.array([[0.0, 1.0], [-omega * omega, -2.0 * zeta * omega]])
    b = np.array([0.0, -1.0])
    wd = omega * math.sqrt(1.0 - zeta * zeta)
    phi = math.exp(-zeta * omega * h) * (math.cos(wd * h) * np.eye(2)
                                         + math.sin(wd * h) / wd * (a + zeta * omega * np.eye(2)))
    a_inv = np.array([[-2.0 * zeta / omega, -1.0 / (omega * omega)], [1.0, 0.0]])
    gamma1 = a_inv @ ((phi - np.eye(2)) @ b)
    return phi, gamma1, a_inv @ (gamma1 / h - b)


@numba.njit(cache=True)
def _sdof_peaks(acc, phi, g1, g2, substeps, omega, zeta):  # pragma: no cover - compiled
    """Peak |u|, |u̇| and |ü + a_g| over a record, with ``substeps`` exact sub-steps per sample."""
    u = 0.0
    v = 0.0
    umax = 0.0
    vmax = 0.0
    amax = 0.0  # at rest u = u̇ = 0, so the absolute acceleration starts at 0
    c = 2.0 * zeta * omega
    k = omega * omega
    n = acc.shape[0]
    for i in range(n - 1):
        f0 = acc[i]
        df = (acc[i + 1] - acc[i]) / substeps
        for j in range(substeps):
            fa = f0 + j * df
            un = phi[0, 0] * u + phi[0, 1] * v + g1[0] * fa + g2[0] * df
            vn = phi[1, 0] * u + phi[1, 1] * v + g1[1] * fa + g2[1] * df
            u = un
            v = vn
            au = abs(u)
            if au > umax:
                umax = au
            av = abs(v)
            if av > vmax:
                vmax = av
            aa = abs(c * v + k * u)  # |ü + a_g|
            if aa > amax:
                amax = aa
    return umax, vmax, amax


@numba.njit(cache=True)
def _sdof_history(acc, phi, g1, g2):  # pragma: no cover - compiled
    n = acc.shape[0]
    out = np.zeros((n, 2))
    for i in range(n - 1):
        df = acc[i + 1] - acc[i]
        out[i + 1, 0] = phi[0, 0] * out[i, 0] + phi[0, 1] * out[i, 1] + g1[0] * acc[i] + g2[0] * df
        out[i + 1, 1] = phi[1, 0] * out[i, 0] + phi[1, 1] * out[i, 1] + g1[1] * acc[i] + g2[1] * df
    return out


def sdof_response(acceleration: np.ndarray, dt: float, period: float, damping: float = 0.05) -> np.ndarray:
    """Relative displacement and velocity histories ``(n, 2)`` [m, m/s] of one oscillator (exact recurrence).

    Parameters
    ----------
    acceleration : ndarray, shape (n,)
        Ground acceleration [m/s²], linear between samples.
    dt : float
        Time step [s].
    period : float
        Oscillator period [s], > 0.
    damping : float
        Damping ratio ζ.
    """
    acc = np.ascontiguousarray(acceleration, dtype=float)
    if acc.ndim != 1:
        raise InputError(f"sdof_response: expected one component, got shape {acc.shape}")
    _check(dt, damping)
    if not period > 0:
        raise InputError(f"sdof_response: period = {period}; expected > 0")
    phi, g1, g2 = _discretise(float(2 * np.pi / period), float(damping), float(dt))
    return _sdof_history(acc, phi, g1, g2)


def _check(dt: float, damping: float) -> None:
    if not (math.isfinite(dt) and dt > 0):
        raise InputError(f"response spectrum: dt = {dt}; expected a positive time step")
    if not (0.0 <= damping < 1.0):
        raise InputError(f"response spectrum: damping ratio = {damping}; expected 0 <= zeta < 1")


def response_spectrum(record: Record | np.ndarray, dt: float | None = None, periods: np.ndarray | None = None,
                      damping: float = 0.05) -> ResponseSpectrum:
    """Compute response spectra of every component.

    Parameters
    ----------
    record : Record or ndarray (n,) or (n, m)
        The record, or ground acceleration [m/s²] with ``dt``.
    dt : float, optional
        Time step [s] (taken from the record if one is given).
    periods : array_like, optional
        Periods [s] ≥ 0 (default :func:`default_periods`).
    damping : float
        Damping ratio ζ (default 0.05).

    Returns
    -------
    ResponseSpectrum
    """
    if isinstance(record, Record):
        acc, dt, labels = record.acceleration, record.dt, record.labels
    else:
        if dt is None:
            raise InputError("response_spectrum: give dt with a bare acceleration array")
        acc = np.asarray(record, dtype=float)
        acc = acc[:, None] if acc.ndim == 1 else acc
        labels = tuple(f"component {i + 1}" for i in range(acc.shape[1]))
    dt = float(dt)
    _check(dt, damping)
    periods = default_periods() if periods is None else np.atleast_1d(np.asarray(periods, dtype=float))
    if np.any(~np.isfinite(periods)) or np.any(periods < 0):
        raise InputError("response spectrum: periods must be finite and >= 0")
    n_p, n_c = periods.size, acc.shape[1]
    sd = np.zeros((n_p, n_c))
    sv = np.zeros((n_p, n_c))
    sa = np.zeros((n_p, n_c))
    pga = np.max(np.abs(acc), axis=0)
    for i, period in enumerate(periods):
        if period == 0.0:
            sa[i] = pga
            continue
        omega = 2 * np.pi / period
        substeps = int(min(_MAX_SUBSTEPS, max(1, math.ceil(50 * dt / period))))
        phi, g1, g2 = _discretise(float(omega), float(damping), float(dt / substeps))
        for c in range(n_c):
            sd[i, c], sv[i, c], sa[i, c] = _sdof_peaks(np.ascontiguousarray(acc[:, c]), phi, g1, g2,
                                                       substeps, omega, damping)
    omega = np.where(periods > 0, 2 * np.pi / np.where(periods > 0, periods, 1.0), 0.0)[:, None]
    psa = np.where(periods[:, None] > 0, omega ** 2 * sd, pga[None, :])
    return ResponseSpectrum(periods=periods, damping=float(damping), sd=sd, psv=omega * sd, psa=psa, sa=sa,
                            labels=tuple(labels))
