"""Compiled Newmark integration of the Bouc-Wen oscillator (kernel of :mod:`damper.hysteresis.oscillator`).

Equations (Noël & Schoukens 2016, eqs. 1-3, with :math:`B = \\beta\\gamma`, :math:`D = \\beta\\delta`):

.. math::

   m\\ddot y + c\\dot y + k y + z = u(t), \\qquad
   \\dot z = f(\\dot y, z) = \\alpha\\dot y - B|\\dot y||z|^{\\nu-1}z - D\\dot y|z|^{\\nu} .

Scheme (the benchmark's own, its eqs. 4-5, with :math:`a = 1/2`, :math:`b = 1/4`, :math:`c = 1/2`,
i.e. the trapezoidal rule for :math:`\\dot y`, :math:`y` and :math:`z`): with step :math:`h`,

.. math::

   \\dot y_{+} = \\dot y + \\tfrac h2(\\ddot y + \\ddot y_{+}), \\quad
   y_{+} = y + h\\dot y + \\tfrac{h^2}{4}(\\ddot y + \\ddot y_{+}), \\quad
   z_{+} = z + \\tfrac h2(\\dot z + \\dot z_{+}),

and the two unknowns :math:`(\\ddot y_{+}, \\dot z_{+})` solve the equilibrium
:math:`m\\ddot y_+ + c\\dot y_+ + k y_+ + z_+ = u_+` and :math:`\\dot z_+ = f(\\dot y_+, z_+)` by
Newton-Raphson (the benchmark starts it from :math:`\\ddot y_+ = \\dot z_+ = 0`; here from the
previous instant's rates, which reaches the same root in fewer iterations), iterated until the
corrections are below 1e-13 of the size of each equation's terms. The scheme is second order;
its error at the benchmark's 15 kHz integration rate is about 1e-4 of the response (see
``tests/damper/hysteresis/test_hysteretic_oscillator.py``).
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = ["newmark_bouc_wen"]

_MAX_NEWTON = 50


@numba.njit(cache=True, inline="always")
def _rate(v, z, alpha, bg, bd, nu):
    """f(v, z) and its partial derivatives with respect to v and z."""
    az = abs(z)
    if nu == 1.0:
        p = az                 # |z|^nu
        q = 1.0                # |z|^(nu-1)
    elif az == 0.0:
        p = 0.0
        q = 0.0
    else:
        p = az ** nu
        q = p / az
    sv = 1.0 if v > 0.0 else (-1.0 if v < 0.0 else 0.0)
    sz = 1.0 if z > 0.0 else (-1.0 if z < 0.0 else 0.0)
    f = alpha * v - bg * abs(v) * q * z - bd * v * p
    f_v = alpha - bg * sv * q * z - bd * p
    f_z = -nu * q * (bg * abs(v) + bd * v * sz)
    return f, f_v, f_z


@numba.njit(cache=True)
def _fail(out, i, every):
    """NaN in every output row from the one of instant ``i`` on."""
    for r in range((i + every - 1) // every, out.shape[0]):
        out[r, 0] = np.nan
        out[r, 1] = np.nan
        out[r, 2] = np.nan


@numba.njit(cache=True)
def newmark_bouc_wen(u, h, m, c, k, alpha, bg, bd, nu, y0, v0, z0, every, out):
    """Integrate the oscillator under the force samples ``u`` (step ``h``) from (y0, v0, z0).

    Parameters
    ----------
    u : ndarray, shape (n,)
        Force at the integration instants ``i h`` [N].
    h : float
        Integration step [s].
    m, c, k, alpha, bg, bd, nu : float
        Mass [kg], damping [N s/m], stiffness [N/m], :math:`\\alpha` [N/m], :math:`\\beta\\gamma`
        and :math:`\\beta\\delta` [N^(1-nu)/m], :math:`\\nu` [-].
    y0, v0, z0 : float
        Initial displacement [m], velocity [m/s] and hysteretic force [N].
    every : int
        Output decimation: row ``j`` of ``out`` is the state at instant ``j * every``.
    out : ndarray, shape (>= (n - 1) // every + 1, 3)
        Filled with (y, ydot, z); rows after a failure are NaN.

    Returns
    -------
    int
        -1 on success, else the integration index at which Newton-Raphson failed or the state
        became non-finite.
    """
    y, v, z = y0, v0, z0
    zd, _, _ = _rate(v, z, alpha, bg, bd, nu)
    a = (u[0] - c * v - k * y - z) / m
    out[0, 0] = y
    out[0, 1] = v
    out[0, 2] = z
    hh = 0.5 * h
    h2 = 0.25 * h * h
    j11 = m + c * hh + k * h2
    for i in range(1, u.shape[0]):
        # Predictor: the previous instant's rates. (The benchmark starts from zero; both converge
        # to the same root of the implicit equations, this one in fewer iterations.)
        a1 = a
        zd1 = zd
        ok = False
        for _ in range(_MAX_NEWTON):
            v1 = v + hh * (a + a1)
            y1 = y + h * v + h2 * (a + a1)
            z1 = z + hh * (zd + zd1)
            f, f_v, f_z = _rate(v1, z1, alpha, bg, bd, nu)
            r1 = m * a1 + c * v1 + k * y1 + z1 - u[i]
            r2 = zd1 - f
            # Jacobian of (r1, r2) with respect to (a1, zd1)
            j12 = hh
            j21 = -f_v * hh
            j22 = 1.0 - f_z * hh
            det = j11 * j22 - j12 * j21
            if det == 0.0 or not np.isfinite(det):
                break
            da = (r1 * j22 - j12 * r2) / det
            dz = (j11 * r2 - j21 * r1) / det
            a1 -= da
            zd1 -= dz
            # Converged when the corrections are round-off against the size of the terms of
            # each equation (the rates themselves vanish at reversals and at saturation).
            size_a = abs(a1) + abs(a) + (abs(u[i]) + abs(z1) + abs(k * y1)) / m
            size_z = abs(zd1) + abs(zd) + abs(alpha * v1) + abs(alpha * v)
            if abs(da) <= 1e-13 * size_a and abs(dz) <= 1e-13 * size_z:
                ok = True
                break
        v1 = v + hh * (a + a1)
        y1 = y + h * v + h2 * (a + a1)
        z1 = z + hh * (zd + zd1)
        if not ok:
            # Newton may stall at round-off level: accept when the residual is negligible.
            f, _, _ = _rate(v1, z1, alpha, bg, bd, nu)
            r1 = m * a1 + c * v1 + k * y1 + z1 - u[i]
            scale = abs(u[i]) + abs(m * a1) + abs(k * y1) + abs(z1) + 1e-300
            size_z = abs(f) + abs(zd1) + abs(alpha * v1) + 1e-300
            if not (abs(r1) <= 1e-9 * scale and abs(zd1 - f) <= 1e-9 * size_z):
                _fail(out, i, every)
                return i
        a = a1
        zd = zd1
        v = v1
        y = y1
        z = z1
        if not (np.isfinite(y) and np.isfinite(v) and np.isfinite(z)):
            _fail(out, i, every)
            return i
        if i % every == 0:
            r = i // every
            out[r, 0] = y
            out[r, 1] = v
            out[r, 2] = z
    return -1
