"""Error measures between a measured (or reference) force history and a model's prediction.

With :math:`e = F - \\hat F` (measured minus predicted):

* relative RMS error :math:`\\|e\\|_2 / \\|F\\|_2` (:func:`relative_rms_error`);
* peak error over peak force :math:`\\max|e| / \\max|F|` (:func:`peak_error`);
* dissipated-energy error :math:`|\\hat E - E| / |E|` with :math:`E = \\int F\\,dx`
  (trapezoidal rule along the displacement history; :func:`energy_error`);
* Spencer et al. (1997) error norms (:func:`spencer_errors`): the squared force error weighted
  by :math:`dt`, :math:`|dx| = |\\dot x| dt` and :math:`|d\\dot x| = |\\ddot x| dt`, each over the
  force variance with the same weight,

  .. math:: E_t = \\frac{\\int e^2 dt}{\\int (F - \\mu_F)^2 dt},\\quad
            E_x = \\frac{\\int e^2 |\\dot x| dt}{\\int (F - \\mu_F)^2 |\\dot x| dt},\\quad
            E_{\\dot x} = \\frac{\\int e^2 |\\ddot x| dt}{\\int (F - \\mu_F)^2 |\\ddot x| dt}

  (the same weight in numerator and denominator makes each norm dimensionless; Spencer et al.
  normalize by the force variance).

All functions take SI arrays of equal length and raise :class:`InputError` otherwise.

References
----------
B.F. Spencer Jr., S.J. Dyke, M.K. Sain, J.D. Carlson, Phenomenological model for
magnetorheological dampers, J. Eng. Mech. 123(3):230–238, 1997.
"""

from __future__ import annotations

import numpy as np

from benchmark.foundation.errors import InputError

__all__ = [
    "relative_rms_error",
    "peak_error",
    "dissipated_energy",
    "energy_error",
    "spencer_errors",
    "force_errors",
]


def _pair(measured, predicted) -> tuple[np.ndarray, np.ndarray]:
    f = np.asarray(measured, dtype=float)
    g = np.asarray(predicted, dtype=float)
    if f.shape != g.shape or f.ndim != 1 or f.size < 2:
        raise InputError(f"force histories: expected two 1-D arrays of equal length >= 2, got shapes "
                         f"{f.shape} and {g.shape}")
    return f, g


def relative_rms_error(measured: np.ndarray, predicted: np.ndarray, mask: np.ndarray | None = None,
                       weights: np.ndarray | None = None) -> float:
    """:math:`\\|w(F - \\hat F)\\|_2 / \\|wF\\|_2` over the usable samples.

    The one relative RMS force error of the package (the identification's and the residual
    loop's).

    Parameters
    ----------
    measured, predicted : ndarray (n,)
        Forces [N].
    mask : ndarray (n,) of bool, optional
        Samples that count (e.g. :attr:`damper.io.data.DamperTest.mask`: the screening leaves
        flagged samples out); default all.
    weights : ndarray (n,), optional
        Non-negative weights :math:`w` (default 1).

    Raises
    ------
    InputError
        Shapes differ, or the measured force is identically zero over the samples that count
        (the relative error is undefined).
    """
    f = np.asarray(measured, dtype=float)
    g = np.asarray(predicted, dtype=float)
    if f.shape != g.shape or f.ndim != 1:
        raise InputError(f"force histories: expected two 1-D arrays of equal length, got shapes "
                         f"{f.shape} and {g.shape}")
    w = np.ones(f.size) if weights is None else np.asarray(weights, dtype=float)
    if mask is not None:
        m = np.asarray(mask, dtype=bool)
        if m.shape != f.shape:
            raise InputError(f"relative RMS error: mask of shape {m.shape}, expected {f.shape}")
        w = np.where(m, w, 0.0)
    if w.shape != f.shape or np.any(w < 0) or not np.all(np.isfinite(w)):
        raise InputError("relative RMS error: weights must be finite, non-negative and as long as "
                         "the force")
    norm = float(np.linalg.norm(w * f))
    if not norm > 0:
        raise InputError("relative RMS error: the measured force is identically zero over the "
                         "samples that count")
    return float(np.linalg.norm(w * (f - g)) / norm)


def peak_error(measured: np.ndarray, predicted: np.ndarray) -> float:
    """:math:`\\max_t |F - \\hat F| / \\max_t |F|`.

    Parameters
    ----------
    measured : np.ndarray
        Measured force [N].
    predicted : np.ndarray
        Model force [N] at the same samples.
    """
    f, g = _pair(measured, predicted)
    peak = np.max(np.abs(f))
    return float(np.max(np.abs(f - g)) / peak) if peak > 0 else float("nan")


def dissipated_energy(force: np.ndarray, displacement: np.ndarray) -> float:
    """:math:`\\int F\\,dx` along the history [J] (trapezoidal rule).

    Parameters
    ----------
    force : np.ndarray
        Force [N].
    displacement : np.ndarray
        Displacement [m] at the same samples.
    """
    f, x = _pair(force, displacement)
    return float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(x)))


def energy_error(measured: np.ndarray, predicted: np.ndarray, displacement: np.ndarray) -> float:
    """Relative error of the dissipated energy :math:`|\\int \\hat F dx - \\int F dx| / |\\int F dx|`.

    Parameters
    ----------
    measured : np.ndarray
        Measured force [N].
    predicted : np.ndarray
        Model force [N] at the same samples.
    displacement : np.ndarray
        Displacement [m] at the same samples.
    """
    e_meas = dissipated_energy(measured, displacement)
    e_pred = dissipated_energy(predicted, displacement)
    return float(abs(e_pred - e_meas) / abs(e_meas)) if e_meas != 0 else float("nan")


def spencer_errors(t: np.ndarray, measured: np.ndarray, predicted: np.ndarray,
                   displacement: np.ndarray, velocity: np.ndarray) -> dict[str, float]:
    """Spencer et al.'s error norms ``E_t``, ``E_x``, ``E_xdot`` (see the module docstring).

    Parameters
    ----------
    t : np.ndarray
        Sample times [s].
    measured : np.ndarray
        Measured force [N].
    predicted : np.ndarray
        Model force [N] at the same samples.
    displacement : np.ndarray
        Displacement [m] at the same samples.
    velocity : np.ndarray
        Velocity [m/s] at the same samples.
    """
    f, g = _pair(measured, predicted)
    t = np.asarray(t, dtype=float)
    x = np.asarray(displacement, dtype=float)
    v = np.asarray(velocity, dtype=float)
    if not (t.shape == x.shape == v.shape == f.shape):
        raise InputError("spencer_errors: t, displacement and velocity must match the force length "
                         f"{f.size}")
    dt = np.gradient(t)
    e2 = (f - g) ** 2
    d2 = (f - f.mean()) ** 2
    out = {}
    for name, weight in (("E_t", dt), ("E_x", np.abs(np.gradient(x))),
                         ("E_xdot", np.abs(np.gradient(v)))):
        den = np.sum(d2 * weight)
        out[name] = float(np.sum(e2 * weight) / den) if den > 0 else float("nan")
    return out


def force_errors(t: np.ndarray, measured: np.ndarray, predicted: np.ndarray,
                 displacement: np.ndarray, velocity: np.ndarray,
                 mask: np.ndarray | None = None) -> dict[str, float]:
    """All measures at once: ``rel_rms_error``, ``peak_error``, ``energy_error``, ``E_t``, ``E_x``, ``E_xdot``.

    With ``mask`` (the usable samples, :mod:`damper.io.screening`) the relative RMS error counts
    only those; the other measures see the flagged samples' measured force replaced by the
    prediction (their error there is zero, their energy the model's).

    Parameters
    ----------
    t : ndarray (n,)
        Sample times [s].
    measured, predicted : ndarray (n,)
        Measured and model forces [N].
    displacement : ndarray (n,)
        Displacement [m] (loop energy, Spencer's E_x).
    velocity : ndarray (n,)
        Velocity [m/s] (Spencer's E_xdot).
    mask : ndarray (n,) of bool, optional
        The usable samples (default all).
    """
    if mask is not None and not np.all(mask):
        m = np.asarray(mask, dtype=bool)
        rel = relative_rms_error(measured, predicted, mask=m)
        measured = np.where(m, np.asarray(measured, dtype=float), np.asarray(predicted, dtype=float))
        out = force_errors(t, measured, predicted, displacement, velocity)
        out["rel_rms_error"] = rel
        return out
    out = {"rel_rms_error": relative_rms_error(measured, predicted),
           "peak_error": peak_error(measured, predicted),
           "energy_error": energy_error(measured, predicted, displacement)}
    out.update(spencer_errors(t, measured, predicted, displacement, velocity))
    return out
