"""The linear floor: the cost below which no run of the building can go (``sbib bench``).

A bare compiled loop of the exact linear step of :mod:`benchmark.simulator.stepping`,

.. math::

    z_{k+1} = \\Phi z_k + G_0 w_k + G_1 w_{k+1},

over the same states (54 for the full superstructure) and the same record samples as a run,
with the inputs :math:`w = [\\ddot u_{g,x}, \\ddot u_{g,y}, 0, 0, 0]` (no nonlinear force), writing
the state history. Every run does at least this work, so the benchmark states its targets as
multiples of this time measured in the same process (the ratio is what a shared machine's load
does not distort; absolute times it does).
"""

from __future__ import annotations

import numba
import numpy as np

__all__ = ["linear_floor_steps", "linear_floor_inputs"]


@numba.njit(cache=True, fastmath={"reassoc", "contract"})  # the flags of benchmark.simulator.stepping
def linear_floor_steps(Phi, G0, G1, w, z_out):
    """Run ``z_out[k+1] = Phi z_out[k] + G0 w[k] + G1 w[k+1]`` for every sample; return the last state's sum.

    Parameters
    ----------
    Phi, G0, G1 : ndarray
        ``(nz, nz)``, ``(nz, m)``, ``(nz, m)`` (:func:`benchmark.simulator.stepping.discretize_foh`).
    w : ndarray, shape (n, m)
        Inputs at the samples.
    z_out : ndarray, shape (n, nz)
        State history; ``z_out[0]`` is the initial state, the rest is overwritten.
    """
    nz = Phi.shape[0]
    m = w.shape[1]
    for k in range(w.shape[0] - 1):
        z0 = z_out[k]
        z1 = z_out[k + 1]
        for r in range(nz):
            s = 0.0
            for c in range(nz):
                s += Phi[r, c] * z0[c]
            for c in range(m):
                s += G0[r, c] * w[k, c] + G1[r, c] * w[k + 1, c]
            z1[r] = s
    total = 0.0
    for r in range(nz):
        total += z_out[-1, r]
    return total


def linear_floor_inputs(ground_acceleration: np.ndarray) -> np.ndarray:
    """Inputs ``(n, 5)`` of the floor loop: the ground acceleration ``(n, 2)`` [m/s²] and zero forces.

    Parameters
    ----------
    ground_acceleration : np.ndarray
        Ground acceleration (x, y) [m/s²], shape (n, 2).
    """
    ag = np.asarray(ground_acceleration, dtype=np.float64)
    w = np.zeros((ag.shape[0], 5))
    w[:, :ag.shape[1]] = ag
    return w
