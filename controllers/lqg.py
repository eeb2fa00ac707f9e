"""H2/LQG design on a linear model: modal reduction, LQR gain, discrete Kalman filter, and the
observer-based controller in the compiled form :math:`(A_c, B_c, C_c, D_c)`.

Plant (continuous, linearised isolation; from :mod:`benchmark.simulator.linear_model` for the
benchmark building, or any model in tests):

.. math::

    \\dot x = A x + B f + E \\ddot u_g, \\qquad y = C x + D f,

with ``f`` the device forces [N], ``ü_g`` the ground acceleration (x, y) [m/s²] and ``y``
the measurement vector. The controller uses the *sensor* rows ``y_s = S y`` (absolute
accelerations and base drift) and takes the measured device forces ``f_m = S_f y`` as a known
input, as in the benchmark's sample controllers (Nagarajaiah & Narasimhan 2006, Part II).

**LQR** (continuous): minimise :math:`\\int z^T W_z z + f^T W_f f\\, dt` with regulated outputs
:math:`z = C_z x + D_z f`, i.e. :math:`Q = C_z^T W_z C_z`, :math:`N = C_z^T W_z D_z`,
:math:`R = D_z^T W_z D_z + W_f`; the gain :math:`K` solves

.. math:: A^T P + P A - (P B + N) R^{-1} (B^T P + N^T) + Q = 0, \\quad K = R^{-1}(B^T P + N^T).

**Kalman filter** (discrete, at the control step Δt, zero-order hold): the ground
acceleration is held over a step, so :math:`x[k+1] = A_d x[k] + B_d f[k] + E_d \\ddot u_g[k]`,
with :math:`\\ddot u_g[k]` modelled as white with covariance :math:`W` and the sensor noise
with covariance :math:`V`. With the a-priori covariance :math:`P_e` of the discrete Riccati
equation, the filter gain :math:`M = P_e C_s^T (C_s P_e C_s^T + V)^{-1}` and the current estimate

.. math::

    \\hat x[k|k] = \\hat x[k|k-1] + M (y_s[k] - C_s \\hat x[k|k-1] - D_s f_m[k]), \\qquad
    \\hat x[k+1|k] = A_d \\hat x[k|k] + B_d f_m[k].

**Compiled form**: with controller state :math:`x_c = \\hat x[k|k-1]` and an output gain
:math:`G` (``-K`` for LQR, :math:`B^T P` for the Lyapunov sign term), :math:`f_c = G \\hat x[k|k]`:

.. math::

    A_c = A_d (I - M C_s), \\quad B_c = A_d M (S - D_s S_f) + B_d S_f, \\quad
    C_c = G (I - M C_s), \\quad D_c = G M (S - D_s S_f).

References
----------
Dyke S.J., Spencer B.F., Sain M.K., Carlson J.D. (1996) Smart Mater. Struct. 5:565–575.
Nagarajaiah S., Narasimhan S. (2006) Smart base-isolated benchmark building. Part II:
phase I sample controllers for linear isolation systems. Struct. Control Health Monit. 13:589–604.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.linalg

from benchmark.foundation.errors import NumericalError, ParameterError

__all__ = [
    "LinearPlant",
    "ReducedPlant",
    "modal_reduction",
    "lqr_design",
    "kalman_design",
    "observer_controller",
    "continuous_riccati_residual",
    "discrete_riccati_residual",
    "simulate_linear",
    "estimator_fit",
]


@dataclass(frozen=True)
class LinearPlant:
    """A continuous linear plant :math:`\\dot x = Ax + Bf + E\\ddot u_g`, :math:`y = Cx + Df` (SI).

    Parameters
    ----------
    A : ndarray (n, n)
        State matrix [1/s, 1/s² per state unit].
    B : ndarray (n, n_dev)
        Input matrix of the device forces f [N].
    E : ndarray (n, n_g)
        Input matrix of the ground accelerations ü_g [m/s²].
    C : ndarray (n_meas, n)
        Output matrix of the measurement vector.
    D : ndarray (n_meas, n_dev)
        Feedthrough of the device forces to the measurements.
    """

    A: np.ndarray
    B: np.ndarray
    E: np.ndarray
    C: np.ndarray
    D: np.ndarray

    def __post_init__(self) -> None:
        n = np.shape(self.A)[0]
        shapes = {"A": (n, n), "B": (n, None), "E": (n, None), "C": (None, n), "D": (None, None)}
        for name, shape in shapes.items():
            value = np.asarray(getattr(self, name), dtype=np.float64)
            if value.ndim != 2 or any(s is not None and s != v for s, v in zip(shape, value.shape)):
                raise ParameterError(f"LinearPlant.{name} has shape {value.shape}, expected {shape} "
                                     f"(None: any)")
            if not np.all(np.isfinite(value)):
                raise ParameterError(f"LinearPlant.{name} contains NaN or inf")
            object.__setattr__(self, name, value)
        if self.D.shape != (self.C.shape[0], self.B.shape[1]):
            raise ParameterError(f"LinearPlant.D has shape {self.D.shape}, expected "
                                 f"{(self.C.shape[0], self.B.shape[1])}")

    @property
    def n_states(self) -> int:
        return self.A.shape[0]

    @property
    def n_inputs(self) -> int:
        return self.B.shape[1]

    def discretise(self, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Zero-order-hold discretisation ``(A_d, B_d, E_d)`` at step ``dt`` [s].

        Parameters
        ----------
        dt : float
            Sampling step [s].
        """
        n, m, g = self.n_states, self.B.shape[1], self.E.shape[1]
        big = np.zeros((n + m + g, n + m + g))
        big[:n, :n] = self.A
        big[:n, n:n + m] = self.B
        big[:n, n + m:] = self.E
        phi = scipy.linalg.expm(big * dt)
        return phi[:n, :n], phi[:n, n:n + m], phi[:n, n + m:]


@dataclass(frozen=True)
class ReducedPlant:
    """A plant reduced by modal truncation and the map back to the full state.

    ``plant`` is the reduced plant; full states are approximately ``T_r @ x_r`` and
    ``x_r = W_r @ x`` projects a full state onto the retained modes. ``eigenvalues`` are the
    retained continuous eigenvalues.

    Parameters
    ----------
    plant : LinearPlant
        The reduced plant (real modal coordinates).
    T_r : np.ndarray
        Map from reduced to full states, ``x ≈ T_r x_r`` (n, n_r).
    W_r : np.ndarray
        Projection of a full state onto the retained modes, ``x_r = W_r x`` (n_r, n).
    eigenvalues : np.ndarray, optional
        Retained continuous eigenvalues [rad/s] (complex pairs count once).
    """

    plant: LinearPlant
    T_r: np.ndarray
    W_r: np.ndarray
    eigenvalues: np.ndarray = field(default_factory=lambda: np.zeros(0))


def modal_reduction(plant: LinearPlant, n_modes: int, static_correction: bool = True,
                    at_most: bool = False) -> ReducedPlant:
    """Keep the ``n_modes`` slowest modes (complex pairs count once) of ``plant``.

    The state is transformed to real modal coordinates (a complex pair ``v, v̄`` becomes the
    columns ``Re v, Im v``); the retained block is kept and, with ``static_correction``, the
    truncated modes' static contribution :math:`-C_t A_t^{-1} B_t` is added to ``D`` (so that
    absolute accelerations keep their instantaneous response to device forces).

    Parameters
    ----------
    plant : LinearPlant
        Full linear plant.
    n_modes : int
        Number of modes kept (1 to the number of modes of ``plant``).
    static_correction : bool, optional
        Add the truncated modes' static contribution to ``D``.
    at_most : bool, optional
        Keep every mode when ``plant`` has fewer than ``n_modes`` (a controller's design order on
        a building already reduced by ``--n-modes``) instead of refusing.

    Raises
    ------
    ParameterError
        If ``n_modes`` is not between 1 and the number of modes.
    """
    A = plant.A
    lam, V = scipy.linalg.eig(A)
    order = np.argsort(np.abs(lam) + 1e-9 * np.abs(lam.imag))
    columns, kept_lambdas, groups = [], [], []
    used = np.zeros(lam.size, dtype=bool)
    for i in order:
        if used[i]:
            continue
        used[i] = True
        if abs(lam[i].imag) > 1e-9 * max(1.0, abs(lam[i])):
            # find the conjugate partner
            partner = np.argmin(np.abs(lam - np.conj(lam[i])) + used * 1e300)
            used[partner] = True
            v = V[:, i] if lam[i].imag > 0 else V[:, partner]
            groups.append([len(columns), len(columns) + 1])
            columns += [v.real, v.imag]
            kept_lambdas.append(lam[i] if lam[i].imag > 0 else lam[partner])
        else:
            groups.append([len(columns)])
            columns.append(V[:, i].real)
            kept_lambdas.append(lam[i].real)
    n_total = len(groups)
    if at_most:
        n_modes = min(n_modes, n_total)
    if not 1 <= n_modes <= n_total:
        raise ParameterError(f"modal_reduction: n_modes must lie in [1, {n_total}], got {n_modes}")
    T = np.column_stack(columns)
    T_inv = np.linalg.inv(T)
    keep = np.concatenate([groups[j] for j in range(n_modes)]).astype(int)
    drop = np.setdiff1d(np.arange(A.shape[0]), keep)
    Am, Bm, Em, Cm = T_inv @ A @ T, T_inv @ plant.B, T_inv @ plant.E, plant.C @ T
    D = plant.D.copy()
    if static_correction and drop.size:
        D = D - Cm[:, drop] @ np.linalg.solve(Am[np.ix_(drop, drop)], Bm[drop])
    reduced = LinearPlant(A=Am[np.ix_(keep, keep)], B=Bm[keep], E=Em[keep], C=Cm[:, keep], D=D)
    return ReducedPlant(plant=reduced, T_r=T[:, keep], W_r=T_inv[keep], eigenvalues=np.array(kept_lambdas[:n_modes]))


def continuous_riccati_residual(A, B, Q, R, N, P) -> float:
    """Relative residual ‖AᵀP + PA − (PB+N)R⁻¹(BᵀP+Nᵀ) + Q‖ / ‖Q‖ (Frobenius) of the LQR equation.

    Parameters
    ----------
    A : ndarray (n, n)
        State matrix.
    B : ndarray (n, m)
        Input matrix.
    Q : ndarray (n, n)
        State weight.
    R : ndarray (m, m)
        Input weight.
    N : ndarray (n, m)
        Cross weight.
    P : ndarray (n, n)
        Candidate Riccati solution.
    """
    res = A.T @ P + P @ A - (P @ B + N) @ np.linalg.solve(R, B.T @ P + N.T) + Q
    return float(np.linalg.norm(res) / max(np.linalg.norm(Q), np.finfo(float).tiny))


def discrete_riccati_residual(A, C, Qd, V, P) -> float:
    """Relative residual of the filter Riccati equation
    ‖A P Aᵀ − A P Cᵀ(C P Cᵀ + V)⁻¹ C P Aᵀ + Q_d − P‖ / ‖P‖.

    Parameters
    ----------
    A : ndarray (n, n)
        Discrete state matrix.
    C : ndarray (n_s, n)
        Sensor output matrix.
    Qd : ndarray (n, n)
        Process-noise covariance E_d W E_dᵀ.
    V : ndarray (n_s, n_s)
        Sensor-noise covariance.
    P : ndarray (n, n)
        Candidate a-priori covariance.
    """
    S = C @ P @ C.T + V
    res = A @ P @ A.T - A @ P @ C.T @ np.linalg.solve(S, C @ P @ A.T) + Qd - P
    return float(np.linalg.norm(res) / max(np.linalg.norm(P), np.finfo(float).tiny))


def lqr_design(A, B, Cz, Dz, Wz, Wf) -> dict:
    """Continuous LQR on regulated outputs (see the module docstring).

    Parameters
    ----------
    A : ndarray (n, n)
        Continuous state matrix.
    B : ndarray (n, n_dev)
        Input matrix of the device forces.
    Cz : ndarray (n_z, n)
        Regulated outputs' state matrix C_z.
    Dz : ndarray (n_z, n_dev)
        Regulated outputs' feedthrough D_z.
    Wz : ndarray (n_z, n_z)
        Weight of the regulated outputs W_z.
    Wf : ndarray (n_dev, n_dev)
        Weight of the device forces W_f [1/N²].

    Returns
    -------
    dict
        ``K`` (gain, f = −K x), ``P`` (Riccati solution), ``Q``, ``R``, ``N``,
        ``closed_loop_poles`` (eig(A − BK)), ``riccati_residual`` (relative).

    Raises
    ------
    NumericalError
        If the Riccati equation has no stabilising solution.
    """
    Wz = np.atleast_2d(Wz)
    Wf = np.atleast_2d(Wf)
    Q = Cz.T @ Wz @ Cz
    N = Cz.T @ Wz @ Dz
    R = Dz.T @ Wz @ Dz + Wf
    Q = 0.5 * (Q + Q.T)
    R = 0.5 * (R + R.T)
    try:
        K, P, poles = _lqr(A, B, Q, R, N)
    except Exception as exc:  # scipy raises several types for a failed ARE
        raise NumericalError(f"LQR design failed: {exc}",
                             hint="check that the weights are positive and the model stabilisable") from None
    K, P = np.asarray(K), np.asarray(P)
    return {"K": K, "P": P, "Q": Q, "R": R, "N": N, "closed_loop_poles": np.asarray(poles),
            "riccati_residual": continuous_riccati_residual(A, B, Q, R, N, P)}


def kalman_design(Ad, Ed, Cs, W, V) -> dict:
    """Stationary discrete Kalman filter for :math:`x[k+1] = A_d x + E_d w`, :math:`y_s = C_s x + v`.

    Parameters
    ----------
    Ad : ndarray (n, n)
        Discrete state matrix A_d.
    Ed : ndarray (n, n_g)
        Discrete ground-acceleration input matrix E_d.
    Cs : ndarray (n_s, n)
        Rows of the output matrix read by the sensors, C_s.
    W : ndarray (n_g, n_g)
        Covariance of the ground acceleration modelled as white noise [(m/s²)²].
    V : ndarray (n_s, n_s)
        Covariance of the sensor noise (SI units squared).

    Returns
    -------
    dict
        ``M`` (filter gain, current estimate), ``L`` (predictor gain, ``A_d M``), ``P``
        (a-priori covariance), ``Qd`` (= E_d W E_dᵀ), ``poles`` (eig(A_d − L C_s)),
        ``riccati_residual`` (relative).
    """
    W = np.atleast_2d(W)
    V = np.atleast_2d(V)
    # Pass the process noise as Qd = E W Eᵀ, symmetrised, with G = I: python-control forms
    # G QN Gᵀ itself and rejects its round-off asymmetry ("QN must be a symmetric matrix",
    # seen with reduced models, e.g. --n-modes 6).
    Qd_sym = Ed @ W @ Ed.T
    Qd_sym = 0.5 * (Qd_sym + Qd_sym.T)
    try:
        L, P, poles = _dlqe(Ad, np.eye(Ad.shape[0]), Cs, Qd_sym, 0.5 * (V + V.T))
    except Exception as exc:
        raise NumericalError(f"Kalman filter design failed: {exc}",
                             hint="check the sensor set (observability) and noise intensities") from None
    P = np.asarray(P)
    P = 0.5 * (P + P.T)
    M = P @ Cs.T @ np.linalg.inv(Cs @ P @ Cs.T + V)
    Qd = Ed @ W @ Ed.T
    return {"M": M, "L": Ad @ M, "P": P, "Qd": Qd, "poles": np.linalg.eigvals(Ad - Ad @ M @ Cs),
            "riccati_residual": discrete_riccati_residual(Ad, Cs, Qd, V, P)}


def observer_controller(Ad, Bd, Cs, Ds, M, G, sensor_rows, force_rows, n_meas) -> tuple:
    """Assemble ``(Ac, Bc, Cc, Dc)`` of the observer-based controller (module docstring).

    Parameters
    ----------
    Ad, Bd : discrete plant matrices (force input)
    Cs, Ds : sensor rows of the plant output (``y_s = C_s x + D_s f``)
    M : filter gain
    G : output gain (``f_c = G x̂[k|k]``)
    sensor_rows, force_rows : index arrays into the measurement vector (``S``, ``S_f``)
    n_meas : int
        Length of the measurement vector.
    """
    n = Ad.shape[0]
    S = np.zeros((len(sensor_rows), n_meas))
    S[np.arange(len(sensor_rows)), sensor_rows] = 1.0
    Sf = np.zeros((len(force_rows), n_meas))
    Sf[np.arange(len(force_rows)), force_rows] = 1.0
    innovation_input = S - Ds @ Sf          # y_s - D_s f_m as a map of y
    I_MC = np.eye(n) - M @ Cs
    Ac = Ad @ I_MC
    Bc = Ad @ M @ innovation_input + Bd @ Sf
    Cc = G @ I_MC
    Dc = G @ M @ innovation_input
    return Ac, Bc, Cc, Dc


def simulate_linear(plant: LinearPlant, dt: float, ground: np.ndarray, forces: np.ndarray | None = None,
                    x0: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Exact ZOH simulation of ``plant`` with inputs held over each step.

    Returns ``(x, y)`` with ``x[k]``, ``y[k] = C x[k] + D f[k]`` for ``k = 0..n-1``.

    Parameters
    ----------
    plant : LinearPlant
        The plant to simulate.
    dt : float
        Time step [s].
    ground : np.ndarray
        Ground acceleration, shape (n, n_g) [m/s²].
    forces : np.ndarray | None, optional
        Device forces, shape (n, n_dev) [N]; None: zero.
    x0 : np.ndarray | None, optional
        Initial state; None: at rest.
    """
    Ad, Bd, Ed = plant.discretise(dt)
    n = ground.shape[0]
    f = np.zeros((n, plant.n_inputs)) if forces is None else forces
    x = np.zeros((n, plant.n_states))
    xk = np.zeros(plant.n_states) if x0 is None else x0.copy()
    for k in range(n):
        x[k] = xk
        xk = Ad @ xk + Bd @ f[k] + Ed @ ground[k]
    y = x @ plant.C.T + f @ plant.D.T
    return x, y


def estimator_fit(true: np.ndarray, estimate: np.ndarray) -> np.ndarray:
    """Fit per column, 100·(1 − ‖x − x̂‖/‖x − mean x‖) [%] (100 % = perfect).

    Parameters
    ----------
    true : np.ndarray
        True states, shape (n_steps, n_states).
    estimate : np.ndarray
        Estimated states, same shape.
    """
    err = np.linalg.norm(true - estimate, axis=0)
    spread = np.linalg.norm(true - true.mean(axis=0), axis=0)
    return 100.0 * (1.0 - err / np.where(spread > 0, spread, np.inf))


# python-control's lqr and dlqe (0.10, scipy back end, no slycot), operation for operation, so the
# gains are bit-identical to those python-control computes (tests/controllers/test_lqg_design.py
# checks it), without importing python-control in every process that designs an LQG:
# python-control loads matplotlib.pyplot and scipy.signal at import (~60-120 MB per process).

def _symmetric_or_raise(M: np.ndarray, name: str) -> None:
    if not ((M - M.T) < np.finfo(M.dtype).eps).all():  # python-control's _is_symmetric
        raise ValueError(f"{name} must be a symmetric matrix")


def _lqr(A, B, Q, R, N):
    """``control.lqr(A, B, Q, R, N)``: ``(K, X, closed-loop poles)`` of the continuous LQR with
    cross weight ``N`` (``care`` with ``S = N``, ``E = I``, scipy's generalized ARE solver)."""
    A = np.array(A, ndmin=2, dtype=float)
    B = np.array(B, ndmin=2, dtype=float)
    Q = np.array(Q, ndmin=2, dtype=float)
    R = np.array(R, ndmin=2, dtype=float)
    S = np.array(N, ndmin=2, dtype=float)
    _symmetric_or_raise(Q, "Q")
    _symmetric_or_raise(R, "R")
    E = np.eye(A.shape[0])
    X = scipy.linalg.solve_continuous_are(A, B, Q, R, s=S, e=E)
    K = np.linalg.solve(R, B.T @ X @ E + S.T)
    poles, _ = scipy.linalg.eig(A - B @ K, E)
    return K, X, poles


def _dlqe(A, G, C, QN, RN):
    """``control.dlqe(A, G, C, QN, RN)``: ``(L, P, estimator poles)`` of the stationary discrete
    Kalman predictor (``dare`` of the dual problem, scipy's discrete ARE solver)."""
    A = np.array(A, ndmin=2, dtype=float)
    G = np.array(G, ndmin=2, dtype=float)
    C = np.array(C, ndmin=2, dtype=float)
    QN = np.array(QN, ndmin=2, dtype=float)
    RN = np.array(RN, ndmin=2, dtype=float)
    Ad, Bd, Qd, Rd = (np.array(M, ndmin=2) for M in (A.T, C.T, G @ QN @ G.T, RN))
    _symmetric_or_raise(Qd, "QN")
    _symmetric_or_raise(Rd, "RN")
    X = scipy.linalg.solve_discrete_are(Ad, Bd, Qd, Rd, e=None, s=None)
    LT = scipy.linalg.solve(Bd.T @ X @ Bd + Rd, Bd.T @ X @ Ad)
    poles = scipy.linalg.eigvals(Ad - Bd @ LT)
    return LT.T, X, poles
