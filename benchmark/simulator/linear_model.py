"""Continuous-time state space of the building with its isolation linearised.

Equations (Narasimhan et al. 2006, Part I) with :math:`u_s = \\Psi q` (Ψ = I for the full superstructure, the
first N modes for a reduced one, see :mod:`benchmark.simulator.structure`), :math:`u_b` the base
displacement (x, y, θ) relative to the ground at the base centre of mass:

.. math::

    M(\\ddot u_s + R\\ddot u_b) + C\\dot u_s + K u_s = -M R \\ddot u_g, \\qquad
    m(\\ddot u_b + \\ddot u_g) = R^T(K u_s + C\\dot u_s) - f_b .

Adding the superstructure's equations to the base's (:math:`R^T(Ku_s + C\\dot u_s) =
-R^T M(\\ddot u_s + R\\ddot u_b + R\\ddot u_g)`) gives the symmetric second-order form used
throughout the package (a Galerkin projection when Ψ is reduced):

.. math::

    \\underbrace{\\begin{bmatrix} \\Psi^T M\\Psi & \\Psi^T M R \\\\ R^T M\\Psi & m + R^T M R
    \\end{bmatrix}}_{M_g}
    \\begin{bmatrix}\\ddot q \\\\ \\ddot u_b\\end{bmatrix}
    + \\begin{bmatrix} \\Psi^T C\\Psi & 0 \\\\ 0 & C_b \\end{bmatrix}\\dot x
    + \\begin{bmatrix} \\Psi^T K\\Psi & 0 \\\\ 0 & K_b \\end{bmatrix} x
    = -M_g \\begin{bmatrix} 0 \\\\ \\ddot u_g \\end{bmatrix}
      - \\begin{bmatrix} 0 \\\\ g \\end{bmatrix}

with :math:`K_b = \\sum_i k_i T_i^T T_i`, :math:`C_b = \\sum_i c_i T_i^T T_i` the linear(ised)
bearings and :math:`g = \\sum_j T_j^T e_{d_j} F_j` the generalised force of the remaining
(nonlinear bearing and device) forces. Note that :math:`M_g^{-1} M_g [0; \\ddot u_g] = [0; \\ddot u_g]`:
the ground acceleration enters only the base's acceleration.

State :math:`z = [q, u_b, \\dot q, \\dot u_b]` (length :math:`2(n_q + 3)`), so

.. math::

    \\dot z = A z + B F + E \\ddot u_g, \\qquad y = C z + D F (+ D_g \\ddot u_g),

with :math:`F` the device forces (device sign convention: a positive force opposes a positive
device displacement, i.e. acts on the base as :math:`-T_j^T e_{d_j} F_j`), :math:`\\ddot u_g`
the ground acceleration (x, y) [m/s²] and :math:`y` the measurement vector of
:mod:`benchmark.simulator.sensors`.

Linearising the isolation (:func:`linear_model`, ``isolation=``)
----------------------------------------------------------------
``"linear-part"``
    Each bearing's linear part only (``params[0:2]`` of :mod:`benchmark.simulator.isolation.registry`):
    k, c for linear bearings (exact), post-yield stiffness α k for lead-rubber, W/R for the
    friction pendulum, no hysteretic damping.
``"equivalent"`` (default)
    Harmonic (describing-function) linearisation: each distinct bearing is driven through the
    bearing kernel along :math:`u = a \\sin \\omega t` (x only, three cycles) and the last cycle's
    total force is fitted by :math:`k_{eq} u + c_{eq} \\dot u` in least squares (its first
    harmonic): the describing-function stiffness (the in-phase part, between the post-yield and
    the secant stiffness for a bilinear loop) and the energy-equivalent viscous damping
    (:math:`\\pi c_{eq} \\omega a^2` = energy dissipated per cycle) at amplitude ``amplitude`` [m]
    and period ``period`` [s]. Exact for linear bearings.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from benchmark.foundation.cache import FunctionCache
from benchmark.foundation.errors import InputError
from controllers.measurements import measurement_layout, measurement_names
from benchmark.simulator.isolation.registry import bearing_step
from benchmark.simulator.structure import location_matrix

__all__ = ["LinearModel", "linear_model", "state_space_matrices", "equivalent_linear_bearing",
           "state_names"]


def state_names(n_q: int, reduced: bool) -> list[str]:
    """Names of the state vector entries ``[q, u_b, q̇, u̇_b]``.

    Parameters
    ----------
    n_q : int
        Number of superstructure coordinates.
    reduced : bool
        Whether they are modal coordinates (reduced superstructure).
    """
    if reduced:
        q = [f"q{i + 1}" for i in range(n_q)]
    else:
        q = [f"u_f{f + 1}_{d}" for f in range(n_q // 3) for d in ("x", "y", "theta")]
    b = ["u_b_x", "u_b_y", "u_b_theta"]
    return q + b + ["d_" + s for s in q + b]


def state_space_matrices(superstructure, Kb: np.ndarray, Cb: np.ndarray) -> dict[str, np.ndarray]:
    """First-order matrices of the building for base stiffness ``Kb`` and damping ``Cb`` (3×3).

    Parameters
    ----------
    superstructure
        The superstructure (:class:`benchmark.simulator.structure.Superstructure`).
    Kb : np.ndarray
        Base stiffness (3×3) [N/m, N·m/rad].
    Cb : np.ndarray
        Base damping (3×3) [N·s/m, N·m·s/rad].

    Returns
    -------
    dict with
        ``Mg, Kg, Cg`` (n_v × n_v, n_v = n_q + 3) second-order matrices;
        ``A`` (n_z × n_z); ``B_g`` (n_z × 3) generalised base force g (enters as −g);
        ``B_ag`` (n_z × 2) ground acceleration x, y;
        ``C_acc`` (27 × n_z), ``D_acc_g`` (27 × 3), ``D_acc_ag`` (27 × 2): absolute accelerations of
        the base (x, y, θ) and floors 1..8 at their centres of mass;
        ``momentum`` (2 × n_v): x and y momentum of building + base per unit velocity (rows of
        :math:`M_g` for the base's translations), used for the input energy.
    """
    sup = superstructure
    psi = sup.basis
    nq = sup.n_q
    nv = nq + 3
    M, K, C, R = sup.M, sup.K, sup.C, sup.R
    Mg = np.zeros((nv, nv))
    Mg[:nq, :nq] = psi.T @ M @ psi
    Mg[:nq, nq:] = psi.T @ M @ R
    Mg[nq:, :nq] = Mg[:nq, nq:].T
    Mg[nq:, nq:] = sup.m_base + R.T @ M @ R
    Kg = np.zeros((nv, nv))
    Kg[:nq, :nq] = psi.T @ K @ psi
    Kg[nq:, nq:] = Kb
    Cg = np.zeros((nv, nv))
    Cg[:nq, :nq] = psi.T @ C @ psi
    Cg[nq:, nq:] = Cb
    Mg = 0.5 * (Mg + Mg.T)
    Kg = 0.5 * (Kg + Kg.T)
    Cg = 0.5 * (Cg + Cg.T)
    Minv = np.linalg.inv(Mg)
    nz = 2 * nv
    A = np.zeros((nz, nz))
    A[:nv, nv:] = np.eye(nv)
    A[nv:, :nv] = -Minv @ Kg
    A[nv:, nv:] = -Minv @ Cg
    sel = np.zeros((nv, 3))
    sel[nq:, :] = np.eye(3)
    B_g = np.zeros((nz, 3))
    B_g[nv:] = -Minv @ sel
    B_ag = np.zeros((nz, 2))
    B_ag[nv + nq, 0] = -1.0
    B_ag[nv + nq + 1, 1] = -1.0
    # Absolute accelerations: base ü_b + ü_g, floors Ψ q̈ + R(ü_b + ü_g).
    acc_rows = A[nv:, :]
    acc_g = B_g[nv:, :]
    acc_ag = B_ag[nv:, :]
    ag3 = np.zeros((3, 2))
    ag3[0, 0] = ag3[1, 1] = 1.0
    C_acc = np.vstack([acc_rows[nq:], psi @ acc_rows[:nq] + R @ acc_rows[nq:]])
    D_acc_g = np.vstack([acc_g[nq:], psi @ acc_g[:nq] + R @ acc_g[nq:]])
    D_acc_ag = np.vstack([acc_ag[nq:] + ag3, psi @ acc_ag[:nq] + R @ (acc_ag[nq:] + ag3)])
    # Floor absolute accelerations do not depend on ü_g directly: clean round-off.
    D_acc_ag[np.abs(D_acc_ag) < 1e-12] = 0.0
    return dict(Mg=Mg, Kg=Kg, Cg=Cg, A=A, B_g=B_g, B_ag=B_ag, C_acc=C_acc, D_acc_g=D_acc_g,
                D_acc_ag=D_acc_ag, momentum=Mg[nq:nq + 2, :].copy())


@lru_cache(maxsize=64)
def _equivalent_cached(type_id: int, params: tuple, state0: tuple, amplitude: float,
                       period: float, steps_per_cycle: int) -> tuple[float, float]:
    p = np.asarray(params, dtype=np.float64)
    state = np.zeros(max(1, len(state0)))
    state[:len(state0)] = state0
    omega = 2.0 * np.pi / period
    dt = period / steps_per_cycle
    n = 3 * steps_per_cycle
    t = np.arange(n + 1) * dt
    u = amplitude * np.sin(omega * t)
    v = amplitude * omega * np.cos(omega * t)
    f = np.zeros(n + 1)
    out = np.zeros(2)
    k_lin, c_lin = p[0], p[1]
    for i in range(n):
        bearing_step(type_id, p, state, u[i], 0.0, u[i + 1], 0.0, v[i], 0.0, v[i + 1], 0.0, dt, out)
        f[i + 1] = k_lin * u[i + 1] + c_lin * v[i + 1] + out[0]
    last = slice(n - steps_per_cycle + 1, n + 1)
    X = np.column_stack([u[last], v[last]])
    (k_eq, c_eq), *_ = np.linalg.lstsq(X, f[last], rcond=None)
    return float(k_eq), float(c_eq)


#: Equivalent-linear stiffness and damping of a bearing by type, parameters and amplitude.
EQUIVALENT_BEARINGS = FunctionCache("simulator.equivalent_bearings", _equivalent_cached)


def equivalent_linear_bearing(bearing, amplitude: float, period: float,
                              steps_per_cycle: int = 2000) -> tuple[float, float]:
    """Harmonic equivalent stiffness and damping of one bearing [N/m], [N·s/m].

    Parameters
    ----------
    bearing : BearingParameters
        A bearing parameter object (:mod:`benchmark.simulator.isolation`).
    amplitude : float
        Displacement amplitude [m] (> 0).
    period : float
        Period of the harmonic motion [s] (> 0).
    steps_per_cycle : int
        Kernel steps per cycle.

    Returns
    -------
    (k_eq, c_eq)
        Least-squares fit :math:`f \\approx k_{eq} u + c_{eq}\\dot u` over the third cycle of
        :math:`u = a \\sin(2\\pi t/T)`: the first-harmonic (describing-function) stiffness and the
        viscous damping that dissipates the same energy per cycle.
    """
    if not (np.isfinite(amplitude) and amplitude > 0):
        raise InputError(f"amplitude: expected a positive displacement in m, got {amplitude!r}")
    if not (np.isfinite(period) and period > 0):
        raise InputError(f"period: expected a positive period in s, got {period!r}")
    return _equivalent_cached(int(bearing.kernel), tuple(float(x) for x in bearing.to_array()),
                              tuple(float(x) for x in bearing.initial_state()), float(amplitude),
                              float(period), int(steps_per_cycle))


def _isolation_coefficients(isolation, method: str, amplitude: float, period: float):
    n = isolation.n_bearings
    k = np.empty(n)
    c = np.empty(n)
    for group in isolation.groups:
        if method == "linear-part":
            kg, cg = group.bearing.linear_part()
        elif method == "equivalent":
            kg, cg = equivalent_linear_bearing(group.bearing, amplitude, period)
        else:
            raise InputError(f"isolation: {method!r}; expected 'linear-part' or 'equivalent'")
        idx = np.asarray(group.indices)
        k[idx] = kg
        c[idx] = cg
    return k, c


@dataclass(frozen=True, eq=False)
class LinearModel:
    """Continuous state space :math:`\\dot z = A z + B F + E \\ddot u_g`, :math:`y = C z + D F + D_g \\ddot u_g`.

    Parameters
    ----------
    settings : dict, optional
        How the isolation was linearised (``isolation``, ``amplitude`` [m], ``period`` [s]).

    Attributes
    ----------
    A : (n_z, n_z)
    B : (n_z, n_devices)  device forces F [N] (device sign convention, see module docstring)
    E : (n_z, 2)          ground acceleration (x, y) [m/s²]
    C : (n_meas, n_z)     measurement vector of :mod:`benchmark.simulator.sensors`
    D : (n_meas, n_devices)
    D_g : (n_meas, 2)     ground acceleration feedthrough (zero for this measurement set)
    state_names, output_names : list of str
    n_q : int             superstructure coordinates (24 or the reduced N)
    bearing_stiffness, bearing_damping : (n_bearings,) linearised k_i [N/m], c_i [N·s/m]
    device_influence : (n_devices, 3) base displacement → device displacement
    matrices : dict       the second-order and auxiliary matrices of :func:`state_space_matrices`
    """

    A: np.ndarray
    B: np.ndarray
    E: np.ndarray
    C: np.ndarray
    D: np.ndarray
    D_g: np.ndarray
    state_names: list
    output_names: list
    n_q: int
    bearing_stiffness: np.ndarray
    bearing_damping: np.ndarray
    device_influence: np.ndarray
    matrices: dict = field(repr=False)
    settings: dict = field(default_factory=dict)

    @property
    def n_states(self) -> int:
        return self.A.shape[0]

    @property
    def n_devices(self) -> int:
        return self.B.shape[1]

    def base_rows(self) -> dict[str, slice]:
        """Slices of the state for the base displacement and velocity."""
        nv = self.n_q + 3
        return {"displacement": slice(self.n_q, nv), "velocity": slice(nv + self.n_q, 2 * nv)}

    def isolated_periods(self) -> np.ndarray:
        """Periods [s] of the lowest three undamped modes of (K_g, M_g) (the isolated modes)."""
        import scipy.linalg

        w2 = scipy.linalg.eigh(self.matrices["Kg"], self.matrices["Mg"], eigvals_only=True)
        return 2.0 * np.pi / np.sqrt(np.maximum(w2[:3], 1e-300))

    def to_statespace(self):
        """A :class:`control.StateSpace` with inputs ``[F (n_devices), ü_g x, ü_g y]``."""
        import control

        B = np.hstack([self.B, self.E])
        D = np.hstack([self.D, self.D_g])
        return control.ss(self.A, B, self.C, D)


def linear_model(building, isolation: str = "equivalent", amplitude: float = 0.1,
                 period: float = 3.0) -> LinearModel:
    """Continuous state space of ``building`` with its isolation linearised.

    Parameters
    ----------
    building : benchmark.simulator.building.Building
        Full or reduced superstructure; its device layout defines ``B`` and the measurement
        vector (no devices: ``B`` has no columns and the measurement vector has 30 entries).
    isolation : {"equivalent", "linear-part"}
        How the bearings are linearised (module docstring).
    amplitude, period : float
        Amplitude [m] and period [s] of the harmonic linearisation (``"equivalent"`` only).

    Returns
    -------
    LinearModel
    """

    sup = building.superstructure
    k, c = _isolation_coefficients(building.isolation, isolation, amplitude, period)
    Kb = location_matrix(sup.bearing_xy, k)
    Cb = location_matrix(sup.bearing_xy, c)
    mats = state_space_matrices(sup, Kb, Cb)
    nq = sup.n_q
    nv = nq + 3
    nz = 2 * nv
    if building.devices is None:
        G = np.zeros((0, 3))
    else:
        G = building.devices.influence()
    n_dev = G.shape[0]
    B = mats["B_g"] @ G.T
    E = mats["B_ag"].copy()
    lay = measurement_layout(n_dev, sup.n_floors)
    s = lay.slices()
    C = np.zeros((lay.n_measurements, nz))
    D = np.zeros((lay.n_measurements, n_dev))
    D_g = np.zeros((lay.n_measurements, 2))
    C[:lay.n_accelerations] = mats["C_acc"]
    D[:lay.n_accelerations] = mats["D_acc_g"] @ G.T
    D_g[:lay.n_accelerations] = mats["D_acc_ag"]
    C[s["base_displacement"], nq:nv] = np.eye(3)
    C[s["device_displacement"], nq:nv] = G
    D[s["device_force"], :] = np.eye(n_dev)
    return LinearModel(A=mats["A"], B=B, E=E, C=C, D=D, D_g=D_g,
                       state_names=state_names(nq, sup.is_reduced), output_names=measurement_names(n_dev, sup.n_floors),
                       n_q=nq, bearing_stiffness=k, bearing_damping=c, device_influence=G, matrices=mats,
                       settings={"isolation": isolation, "amplitude": amplitude, "period": period})
