"""Spencer et al. (1997) phenomenological MR damper model, with first-order field dynamics.

.. math::

   F &= c_1 \\dot y + k_1 (x - x_0) \\\\
   \\dot y &= \\frac{\\alpha z + c_0 \\dot x + k_0 (x - y)}{c_0 + c_1} \\\\
   \\dot z &= -\\gamma|\\dot x - \\dot y| z |z|^{n-1} - \\beta(\\dot x - \\dot y)|z|^n + A(\\dot x - \\dot y) \\\\
   \\alpha &= \\alpha_a + \\alpha_b u,\\quad c_0 = c_{0a} + c_{0b} u,\\quad c_1 = c_{1a} + c_{1b} u \\\\
   \\dot u &= -\\eta (u - v)

``x`` the device displacement, ``y`` the internal displacement of the Bouc-Wen/dashpot
element, ``v`` the commanded voltage and ``u`` the voltage the fluid "sees". Note that Spencer
attaches ``gamma`` to the :math:`|\\dot x - \\dot y|` term, the reverse of Wen's convention.

The kernel works with the normalized hysteretic variable :math:`w = z/z_0`,
:math:`z_0 = (A/(\\beta+\\gamma))^{1/n}` (Spencer et al. 1997; Bahar et al. 2009), so the element's force is
:math:`\\alpha z = (\\alpha z_0) w` and
:math:`\\dot w = \\rho(\\dot r - \\sigma|\\dot r||w|^{n-1}w + (\\sigma-1)\\dot r|w|^n)` with
:math:`\\dot r = \\dot x - \\dot y`, :math:`\\rho = A/z_0`, :math:`\\sigma = \\gamma/(\\beta+\\gamma)`
(Spencer's γ is Wen's β). Admissible: ``A > 0``, ``beta + gamma > 0``, ``gamma >= beta``
(σ ≥ ½), ``n >= 1``, positive dashpots, non-negative springs, ``eta > 0``.

The same kernel (:func:`spencer_type_step`) serves every "Spencer-type" device, with any
:mod:`~damper.models.voltage_laws` for the hysteretic force scale and the two dashpots: the virtual
benchmark damper (:mod:`damper.models.virtual`) uses it with saturating laws.

Numerics: the filtered voltage is advanced exactly,
:math:`u(\\tau) = v + (u_0 - v)e^{-\\eta\\tau}`; ``(y, w)`` are integrated with classical RK4
in time along the cubic Hermite path of the step, in
:math:`N = \\lceil \\lambda\\,\\Delta t/\\mathrm{tol} \\rceil` sub-steps with
:math:`\\lambda = (\\rho\\,\\alpha z_0 + k_0)/(c_0+c_1) + \\rho n\\max(1, 2\\sigma-1)\\max(1,|w|)^{n-1}
(|\\dot x|_{max} + |\\dot y|)`, the ratios taken at the worse of the
field's values at the start and the end of the step (the field moves monotonically between
them). For :math:`\\sigma > 1` that bound is the unloading branch's, :math:`2\\sigma - 1` times
stiffer than the loading one and met only briefly after each reversal: a step is first taken
with the loading rate (the factor 1 instead) at the packed ``loading_tol``; if any RK4 node finds
:math:`\\dot r\\,w < 0` it is redone in sub-steps sized by the rate where each starts, at the
same tolerance (the unloading branch's rate falls with :math:`|w|^{n-1}`, so a whole return
costs about :math:`n\\ln(2\\sigma)/\\mathrm{tol}` sub-steps instead of growing with σ); and a step
that starts within 1e-9 of :math:`|w| = 1` and keeps loading advances :math:`w` in closed form
(:math:`1 - |w|` decays as :math:`e^{-\\rho n\\int|\\dot r|}`) and :math:`y` alone (σ > 1
only: the σ ≤ 1 devices of the building's lock-step keep the uniform count, bit for bit). The
laws are evaluated once per RK4 node: the end of one sub-step is the start of the next, and the
last node's values give the force at the end of the step.

Parameters of the 1.5 kN prototype (:meth:`Spencer.prototype_1997`, Spencer et al. 1997,
as quoted by Bahar et al. 2009, **unverified against the paper's table**): c0a 21.0 N·s/cm,
c0b 3.50 N·s/(cm·V), k0 46.9 N/cm, c1a 283 N·s/cm, c1b 2.95 N·s/(cm·V), k1 5.00 N/cm,
x0 14.3 cm, αa 140 N/cm, αb 695 N/(cm·V), γ = β = 363 cm⁻², A = 301, n = 2, η = 190 s⁻¹,
voltage 0-2.25 V.

References
----------
Spencer B.F. Jr., Dyke S.J., Sain M.K., Carlson J.D. (1997) *Phenomenological model of a
magnetorheological damper*, J. Eng. Mech. 123(3):230-238.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import ClassVar

import numba
import numpy as np

from damper.models.base import DamperModel, KERNEL_SPENCER_TYPE, register_model
from benchmark.foundation.errors import InputError, ParameterError
from damper.models.bouc_wen import (_abs_pow, _check_voltage_range, hermite_position,
                                    DEFAULT_SUBSTEP_TOLERANCE, SATURATED)
from damper.models.voltage_laws import (Polynomial, VoltageLaw, check_law, law_length,
                                        law_value_triple)

__all__ = [
    "Spencer",
    "pack_spencer_type",
    "spencer_type_rates",
    "spencer_type_step",
    "spencer_type_step_memo",
    "spencer_type_lockstep",
    "MEMO_LENGTH",
    "LOCKSTEP_MAX_SUBSTEPS",
    "LOCKSTEP_NODE_COLUMNS",
    "SPENCER_LOCKSTEP_ROWS",
    "spencer_type_force",
    "spencer_type_force_kernel",
    "spencer_type_tangent",
    "spencer_type_tangent_memo",
]

MAX_SUBSTEPS = 200_000


#: Length of the packed parameters' head (before the three laws).
_HEAD = 9


def pack_spencer_type(tol: float, k0: float, k1: float, x0: float, eta: float, rho: float,
                      sigma: float, n: float, alpha_w: VoltageLaw, c0: VoltageLaw,
                      c1: VoltageLaw, loading_tol: float | None = None) -> np.ndarray:
    """Kernel parameters ``[tol, k0, k1, x0, eta, rho, sigma, n, loading_tol, law(alpha_w), law(c0),
    law(c1)]``.

    ``alpha_w`` is the force scale of the normalized hysteretic variable [N] (``alpha * z0``).
    ``tol`` is the sub-step size ``lambda * h`` under the bound that covers both branches;
    ``loading_tol`` (default ``tol``) the one of a step that stays on the loading branch, which
    the kernel tries first when ``sigma > 1`` (see :func:`spencer_type_step`).

    Parameters
    ----------
    tol : float
        Sub-step tolerance of the integrator.
    k0 : float
        Stiffness k₀ at large velocities [N/m].
    k1 : float
        Accumulator stiffness k₁ [N/m].
    x0 : float
        Initial displacement x₀ of the accumulator spring [m].
    eta : float
        Rate η [1/s] of the field's first-order filter.
    rho : float
        Normalized Bouc-Wen rate parameter ρ [1/m] (> 0).
    sigma : float
        Normalized Bouc-Wen shape parameter σ (≥ 1/2).
    n : float
        Bouc-Wen exponent n (≥ 1).
    alpha_w : VoltageLaw
        Law of the hysteretic force scale α_w(u) = α z₀ [N] of the filtered voltage u.
    c0 : VoltageLaw
        Viscous coefficient law c₀(u) [N·s/m] (high velocity).
    c1 : VoltageLaw
        Viscous coefficient law c₁(u) [N·s/m] (low velocity).
    loading_tol : float | None, optional
        Sub-step tolerance on the loading branch; None: ``tol``.
    """
    head = np.array([tol, k0, k1, x0, eta, rho, sigma, n, tol if loading_tol is None else loading_tol],
                    dtype=np.float64)
    return np.ascontiguousarray(np.concatenate((head, alpha_w.to_array(), c0.to_array(),
                                                c1.to_array())))


def spencer_type_rates(state, x, xdot, v, *, k0, k1, x0, eta, rho, sigma, n, alpha_w, c0, c1):
    """Plain-numpy time derivatives ``[ydot, wdot, udot]`` (laws evaluated at the state's u).

    Parameters
    ----------
    state
        Internal states of the model (``n_states`` entries, see the model's docstring).
    x
        Displacement [m].
    xdot
        Velocity [m/s].
    v
        Coil input: voltage [V] (or current [A] for a model identified on currents).
    k0
        Stiffness k₀ at large velocities [N/m].
    k1
        Accumulator stiffness k₁ [N/m].
    x0
        Initial displacement x₀ of the accumulator spring [m].
    eta
        Rate η [1/s] of the field's first-order filter.
    rho
        Normalized Bouc-Wen rate parameter ρ [1/m] (> 0).
    sigma
        Normalized Bouc-Wen shape parameter σ (≥ 1/2).
    n
        Bouc-Wen exponent n (≥ 1).
    alpha_w
        Law of the hysteretic force scale α_w(u) = α z₀ [N] of the filtered voltage u.
    c0
        Viscous coefficient law c₀(u) [N·s/m] (high velocity).
    c1
        Viscous coefficient law c₁(u) [N·s/m] (low velocity).
    """
    y, w, u = (float(s) for s in state)
    a, d0, d1 = float(alpha_w(u)), float(c0(u)), float(c1(u))
    ydot = (a * w + d0 * xdot + k0 * (x - y)) / (d0 + d1)
    r = xdot - ydot
    aw = abs(w)
    wdot = rho * (r - sigma * abs(r) * aw ** (n - 1.0) * w + (sigma - 1.0) * r * aw ** n)
    return np.array([ydot, wdot, -eta * (u - v)])


def spencer_type_force(state, x, xdot, *, k0, k1, x0, rho, sigma, n, alpha_w, c0, c1, **_):
    """Plain-numpy force [N] ``c1 ydot + k1 (x - x0)``.

    Parameters
    ----------
    state
        Internal states of the model (``n_states`` entries, see the model's docstring).
    x
        Displacement [m].
    xdot
        Velocity [m/s].
    k0
        Stiffness k₀ at large velocities [N/m].
    k1
        Accumulator stiffness k₁ [N/m].
    x0
        Initial displacement x₀ of the accumulator spring [m].
    rho
        Normalized Bouc-Wen rate parameter ρ [1/m] (> 0).
    sigma
        Normalized Bouc-Wen shape parameter σ (≥ 1/2).
    n
        Bouc-Wen exponent n (≥ 1).
    alpha_w
        Law of the hysteretic force scale α_w(u) = α z₀ [N] of the filtered voltage u.
    c0
        Viscous coefficient law c₀(u) [N·s/m] (high velocity).
    c1
        Viscous coefficient law c₁(u) [N·s/m] (low velocity).
    **_
        Other packed parameters, ignored.
    """
    y, w, u = (float(s) for s in state)
    a, d0, d1 = float(alpha_w(u)), float(c0(u)), float(c1(u))
    ydot = (a * w + d0 * xdot + k0 * (x - y)) / (d0 + d1)
    return float(d1 * ydot + k1 * (x - x0))


class SpencerTypeModel(DamperModel):
    """What every Spencer-type device shares: packing, initial state, and the plain-numpy
    ``rates``/``force`` of the scipy oracle. A subclass defines ``_kernel_parameters()`` (the
    keyword arguments of :func:`pack_spencer_type`), ``substep_tolerance`` and ``voltage_range``.
    """

    kernel: ClassVar[int] = KERNEL_SPENCER_TYPE

    def _kernel_parameters(self) -> dict:  # pragma: no cover - defined by subclasses
        raise NotImplementedError

    def to_array(self) -> np.ndarray:
        """Packed parameters (:func:`pack_spencer_type` layout)."""
        return pack_spencer_type(self.substep_tolerance, **self._kernel_parameters())

    def initial_state(self) -> np.ndarray:
        """``[y, w, u] = [0, 0, u_off]``: at rest, field off.

        ``u_off`` is 0 V (or 0 A) clipped into ``voltage_range``: a coil without command. A range
        read from measurements can reach below zero (the Dyke recording's voltage channel dips to
        -0.44 V), where laws fitted on the measured levels are extrapolated and may be nearly
        singular; the field must not start there when the command is 0.
        """
        lo, hi = self.voltage_range
        return np.array([0.0, 0.0, min(max(0.0, float(lo)), float(hi))])

    def rates(self, state, x: float, xdot: float, v: float) -> np.ndarray:
        """``[ydot, wdot, udot]`` (plain numpy, for the scipy oracle); ``w = z / z0``."""
        return spencer_type_rates(state, x, xdot, v, **self._kernel_parameters())

    def force(self, state, x: float, xdot: float, v: float = 0.0) -> float:
        """Force [N] at the state (depends on the filtered voltage ``u = state[2]``, not ``v``)."""
        return spencer_type_force(state, x, xdot, **self._kernel_parameters())


@register_model
@dataclass(frozen=True)
class Spencer(SpencerTypeModel):
    """Spencer et al. (1997) phenomenological MR damper model (SI units).

    Parameters
    ----------
    alpha_a, alpha_b : float
        Hysteretic stiffness :math:`\\alpha = \\alpha_a + \\alpha_b u` [N/m, N/(m·V)].
    c0a, c0b : float
        Viscous damping at large velocities [N·s/m, N·s/(m·V)].
    k0 : float
        Stiffness at large velocities [N/m].
    c1a, c1b : float
        Dashpot producing the roll-off at low velocities [N·s/m, N·s/(m·V)].
    k1 : float
        Accumulator stiffness [N/m].
    x0 : float
        Initial displacement of the accumulator spring [m] (force offset ``-k1 x0``).
    gamma, beta : float
        Hysteresis shape [1/m^n] (Spencer's convention: ``gamma`` on the ``|xdot|`` term).
    A : float
        Hysteresis scale [-].
    n : float
        Hysteresis exponent, >= 1.
    eta : float
        Field (voltage filter) rate [1/s].
    voltage_range : tuple of float
        Admissible command voltages [V] (default (0, 2.25), the prototype's range).
    substep_tolerance : float
        RK4 sub-step size as ``lambda * h`` (default 0.05).
    """

    alpha_a: float
    alpha_b: float
    c0a: float
    c0b: float
    k0: float
    c1a: float
    c1b: float
    k1: float
    x0: float
    gamma: float
    beta: float
    A: float
    n: float
    eta: float
    voltage_range: tuple[float, float] = (0.0, 2.25)
    substep_tolerance: float = DEFAULT_SUBSTEP_TOLERANCE

    name: ClassVar[str] = "spencer"
    n_states: ClassVar[int] = 3
    state_names: ClassVar[tuple[str, ...]] = ("y", "w", "u")

    def __post_init__(self) -> None:
        for f in fields(self):
            if f.name == "voltage_range":
                continue
            value = getattr(self, f.name)
            try:
                value = float(value)
            except (TypeError, ValueError):
                raise ParameterError(f"Spencer.{f.name}: expected a number, got {value!r}") from None
            if not math.isfinite(value):
                raise ParameterError(f"Spencer.{f.name}: expected a finite number, got {value}")
            object.__setattr__(self, f.name, value)
        object.__setattr__(self, "voltage_range", _check_voltage_range(self.voltage_range))
        checks = [("A", self.A > 0, "A > 0"), ("n", self.n >= 1, "n >= 1"),
                  ("beta", self.beta + self.gamma > 0, "beta + gamma > 0"),
                  ("gamma", self.gamma >= self.beta,
                   "gamma >= beta (Spencer's gamma is on |xdot|; sigma >= 1/2)"),
                  ("k0", self.k0 >= 0, "k0 >= 0"), ("k1", self.k1 >= 0, "k1 >= 0"),
                  ("eta", self.eta > 0, "eta > 0"),
                  ("substep_tolerance", 0 < self.substep_tolerance <= 1, "0 < tol <= 1")]
        for name, ok, expected in checks:
            if not ok:
                raise ParameterError(f"Spencer.{name}: expected {expected}, got {getattr(self, name):g}")
        rng = self.voltage_range
        check_law(Polynomial((self.alpha_a, self.alpha_b)), "alpha", rng, lower=0.0)
        check_law(Polynomial((self.c0a, self.c0b)), "c0", rng, lower=0.0)
        check_law(Polynomial((self.c1a, self.c1b)), "c1", rng, lower=0.0)

    @classmethod
    def prototype_1997(cls, **overrides) -> "Spencer":
        """The 1.5 kN prototype of Spencer et al. (1997) in SI units (see module docstring).

        Parameters
        ----------
        **overrides
            Fields to change from the prototype (SI).
        """
        values = dict(alpha_a=140.0e2, alpha_b=695.0e2, c0a=21.0e2, c0b=3.50e2, k0=46.9e2,
                      c1a=283.0e2, c1b=2.95e2, k1=5.00e2, x0=0.143, gamma=363.0e4, beta=363.0e4,
                      A=301.0, n=2.0, eta=190.0)
        values.update(overrides)
        return cls(**values)

    @property
    def z0(self) -> float:
        """Scale of Spencer's z: :math:`(A/(\\beta+\\gamma))^{1/n}` [m]."""
        return (self.A / (self.beta + self.gamma)) ** (1.0 / self.n)

    def _kernel_parameters(self) -> dict:
        z0 = self.z0
        return dict(k0=self.k0, k1=self.k1, x0=self.x0, eta=self.eta, rho=self.A / z0,
                    sigma=self.gamma / (self.beta + self.gamma), n=self.n,
                    alpha_w=Polynomial((self.alpha_a * z0, self.alpha_b * z0)),
                    c0=Polynomial((self.c0a, self.c0b)), c1=Polynomial((self.c1a, self.c1b)))



# ------------------------------------------------------------------------ numba kernels

@numba.njit(cache=True)
def _laws(params, u):
    off1 = _HEAD + law_length(params, _HEAD)
    return law_value_triple(params, _HEAD, off1, off1 + law_length(params, off1), u)


@numba.njit(cache=True, inline="always")
def _rates(y, w, x, xd, a, d0, d1, k0, rho, sigma, n):
    """``(ydot, wdot, r)``: the rates and the element's relative velocity ``r = xd - ydot``."""
    ydot = (a * w + d0 * xd + k0 * (x - y)) / (d0 + d1)
    r = xd - ydot
    s = 1.0 if r * w > 0.0 else -1.0
    wdot = rho * r * (1.0 - (sigma * s + 1.0 - sigma) * _abs_pow(abs(w), n))
    return ydot, wdot, r


@numba.njit(cache=True, inline="always")
def _hermite_velocity(x0, x1, xd0, xd1, dt, s):
    s2 = s * s
    return ((6.0 * s2 - 6.0 * s) * (x0 - x1) / dt + (3.0 * s2 - 4.0 * s + 1.0) * xd0
            + (3.0 * s2 - 2.0 * s) * xd1)


#: Length of the per-device memo of :func:`spencer_type_step_memo` (key, the laws at the step's
#: start and end field, at the nodes of up to ``(MEMO_LENGTH - 16) // 6`` sub-steps, the laws at
#: the end field of the last step with that field (4 entries: the next step starts there), and
#: in its last two entries the force's tangent at the end of the last step
#: (:func:`spencer_type_tangent_memo`).
MEMO_LENGTH = 112
_END_SLOT = MEMO_LENGTH - 6
_TANGENT_SLOT = MEMO_LENGTH - 2


@numba.njit(cache=True)
def spencer_type_step(params, state, x0, x1, xd0, xd1, v, dt):
    """Advance ``state = [y, w, u]`` over one step; return the force at its end [N].

    Parameters
    ----------
    params
        Packed model parameters (the model's ``to_array()``, float64).
    state
        Internal states of the model (``n_states`` entries, see the model's docstring).
    x0
        Displacement at the start of the step [m].
    x1
        Displacement at the end of the step [m].
    xd0
        Velocity at the start of the step [m/s].
    xd1
        Velocity at the end of the step [m/s].
    v
        Coil input: voltage [V] (or current [A] for a model identified on currents).
    dt
        Step length [s].
    """
    return _spencer_step(params, state, x0, x1, xd0, xd1, v, dt, state, False)  # no memo


@numba.njit(cache=True)
def spencer_type_step_memo(params, state, x0, x1, xd0, xd1, v, dt, memo):
    """:func:`spencer_type_step` that keeps the voltage laws' values in ``memo`` (float64, length
    :data:`MEMO_LENGTH`, any initial content, one per device) and reuses them while the step's field
    (start value, commanded voltage, step length) and sub-step count are the same: the building's
    fixed-point iteration advances every device several times from the same state. Same results.

    Parameters
    ----------
    params
        Packed model parameters (the model's ``to_array()``, float64).
    state
        Internal states of the model (``n_states`` entries, see the model's docstring).
    x0
        Displacement at the start of the step [m].
    x1
        Displacement at the end of the step [m].
    xd0
        Velocity at the start of the step [m/s].
    xd1
        Velocity at the end of the step [m/s].
    v
        Coil input: voltage [V] (or current [A] for a model identified on currents).
    dt
        Step length [s].
    memo
        Per-device scratch array (float64, :data:`damper.models.registry.MEMO_LENGTH` entries) shared by the step
        and tangent calls of one device.
    """
    return _spencer_step(params, state, x0, x1, xd0, xd1, v, dt, memo, memo.shape[0] >= MEMO_LENGTH)


@numba.njit(cache=True, inline="always")
def _memo_laws(params, memo, slot, u, valid, store):
    # the laws at u, from memo[slot:slot+3] when valid, else evaluated (and stored if asked)
    if valid:
        return memo[slot], memo[slot + 1], memo[slot + 2]
    a, d0, d1 = _laws(params, u)
    if store:
        memo[slot] = a
        memo[slot + 1] = d0
        memo[slot + 2] = d1
    return a, d0, d1


@numba.njit(cache=True, inline="always")
def _step_setup(params, state, x0, x1, xd0, xd1, v, dt, memo, use_memo):
    """What a step needs before its sub-steps: ``(u1, du, field_settled, same_field, a, d0, d1,
    a_1, d0_1, d1_1, n_sub, n_loading)``, the field at the step's end, the laws at its start and
    end field, and the sub-step counts (``n_sub = -1``: the tolerance cannot be met;
    ``n_loading < n_sub``: try the loading branch's count first, for sigma > 1)."""
    tol = params[0]
    k0 = params[1]
    eta = params[4]
    rho = params[5]
    sigma = params[6]
    n = params[7]
    y = state[0]
    w = state[1]
    u0 = state[2]
    field_settled = abs(u0 - v) <= 1e-12 * (1.0 + abs(v))
    du = u0 - v
    u1 = v + du * math.exp(-eta * dt)
    # memo: [u0, v, dt, n_sub, laws(u0), laws(u1), laws at the nodes ...]; valid for the same
    # field and step (the laws depend on nothing else)
    same_field = use_memo and memo[0] == u0 and memo[1] == v and memo[2] == dt
    # the laws at the step's start: at v once the field has settled, else at u0
    start_u = v if field_settled else u0
    start_known = same_field
    if use_memo and not same_field:
        # a new step starts where the last one ended (u0 is that step's u1): its end laws,
        # kept in memo[_END_SLOT:], are this step's start laws (memo[2] == dt marks a memo this
        # kernel wrote)
        if memo[2] == dt and memo[_END_SLOT] == start_u:
            memo[4] = memo[_END_SLOT + 1]
            memo[5] = memo[_END_SLOT + 2]
            memo[6] = memo[_END_SLOT + 3]
            start_known = True
        memo[0] = u0
        memo[1] = v
        memo[2] = dt
        memo[3] = -1.0
    a, d0, d1 = _memo_laws(params, memo, 4, start_u, start_known, use_memo)
    if field_settled:
        a_1, d0_1, d1_1 = a, d0, d1
    else:
        # the field moves monotonically from u0 to u1 over the step: the laws at both ends bound
        # the sub-step rule, and those at u1 serve as the last node
        a_1, d0_1, d1_1 = _memo_laws(params, memo, 7, u1, same_field, use_memo)
    if use_memo:
        memo[_END_SLOT] = start_u if field_settled else u1
        memo[_END_SLOT + 1] = a_1
        memo[_END_SLOT + 2] = d0_1
        memo[_END_SLOT + 3] = d1_1
    ratio = max(a / (d0 + d1), a_1 / (d0_1 + d1_1))
    kratio = k0 / min(d0 + d1, d0_1 + d1_1)
    ydot0 = (a * w + d0 * xd0 + k0 * (x0 - y)) / (d0 + d1)
    aw = abs(w)
    w_factor = aw ** (n - 1.0) if aw > 1.0 else 1.0  # max(1, |w|)^(n-1) without pow when |w| <= 1
    speed = max(abs(xd0), abs(xd1), abs(x1 - x0) / dt) + abs(ydot0)
    unloading_factor = max(1.0, 2.0 * sigma - 1.0)
    lam_field = rho * ratio + kratio  # the dashpots' part of the rate bound, either branch
    lam = lam_field + rho * n * unloading_factor * w_factor * speed
    if not (lam * dt / tol <= MAX_SUBSTEPS):  # also NaN: the tolerance cannot be met
        return u1, du, field_settled, same_field, a, d0, d1, a_1, d0_1, d1_1, -1, -1
    n_sub = max(1, int(math.ceil(lam * dt / tol)))
    n_loading = n_sub
    if unloading_factor > 1.0:
        # sigma > 1: the bound above covers the unloading branch, stiffer by 2 sigma - 1 but
        # travelled only briefly after each reversal. A step that stays on the loading branch
        # takes the loading rate at the loading tolerance; one that meets unloading (r w < 0 at
        # any RK4 node) is redone from its start with the bound above.
        lam_loading = lam_field + rho * n * w_factor * speed
        n_loading = max(1, int(math.ceil(lam_loading * dt / params[8])))
    return u1, du, field_settled, same_field, a, d0, d1, a_1, d0_1, d1_1, n_sub, n_loading


@numba.njit(cache=True, inline="always")
def _step_end(params, state, memo, use_memo, y1, w1, u1, x1, xd1, a_1, d0_1, d1_1):
    """Store the step's end state and return its force (the laws at the end node are those at
    ``u1``, so no law is evaluated again)."""
    state[0] = y1
    state[1] = w1
    state[2] = u1
    ydot1 = (a_1 * w1 + d0_1 * xd1 + params[1] * (x1 - y1)) / (d0_1 + d1_1)
    if use_memo:  # the dashpots' series ratio and c0 at the end field, for the tangent
        memo[_TANGENT_SLOT] = d1_1 / (d0_1 + d1_1)
        memo[_TANGENT_SLOT + 1] = d0_1
    return d1_1 * ydot1 + params[2] * (x1 - params[3])


@numba.njit(cache=True, inline="always")
def _spencer_step(params, state, x0, x1, xd0, xd1, v, dt, memo, use_memo):
    (u1, du, field_settled, same_field, a, d0, d1, a_1, d0_1, d1_1,
     n_sub, n_loading) = _step_setup(params, state, x0, x1, xd0, xd1, v, dt, memo, use_memo)
    if n_sub < 0:
        for i in range(state.shape[0]):
            state[i] = math.nan
        return math.nan
    return _step_advance(params, state, x0, x1, xd0, xd1, v, dt, memo, use_memo, u1, du, field_settled,
                         same_field, a, d0, d1, a_1, d0_1, d1_1, n_sub, n_loading)


@numba.njit(cache=True, inline="always")
def _step_advance(params, state, x0, x1, xd0, xd1, v, dt, memo, use_memo, u1, du, field_settled,
                  same_field, a, d0, d1, a_1, d0_1, d1_1, n_sub, n_loading):
    """The step's sub-steps and its end. For sigma > 1 (``n_loading < n_sub``), in order: the
    saturated loading branch in closed form (:func:`_integrate_saturated`), the loading branch's
    uniform count (:func:`_integrate`), then, where a node meets the unloading branch, sub-steps
    sized where each starts (:func:`_integrate_local`); otherwise the uniform count of the bound
    that covers both branches."""
    y = state[0]
    w = state[1]
    done = False
    if n_loading < n_sub:
        if abs(1.0 - abs(w)) < SATURATED:
            y1, w1, done = _integrate_saturated(params, field_settled, y, w, x0, x1, xd0, xd1, dt, v,
                                                du, a, d0, d1, a_1, d0_1, d1_1)
        if not done:
            y1, w1, done = _integrate(params, memo, use_memo, same_field, field_settled, n_loading,
                                      True, y, w, x0, x1, xd0, xd1, dt, v, du, a, d0, d1, a_1, d0_1,
                                      d1_1)
        if not done:
            # sigma > 1 and the step meets the unloading branch: sub-steps sized by the rate
            # where each one starts, not by the branch's worst case over the whole step
            y1, w1 = _integrate_local(params, field_settled, y, w, x0, x1, xd0, xd1, dt, v, du,
                                      a, d0, d1, a_1, d0_1, d1_1)
            done = True
    if not done:
        y1, w1, _ = _integrate(params, memo, use_memo, same_field, field_settled, n_sub, False,
                               y, w, x0, x1, xd0, xd1, dt, v, du, a, d0, d1, a_1, d0_1, d1_1)
    return _step_end(params, state, memo, use_memo, y1, w1, u1, x1, xd1, a_1, d0_1, d1_1)


@numba.njit(cache=True, inline="always")
def _rk4_rest(y, w, h, ky1, kw1, xm, vm, am, dm0, dm1, xb, vb, ab, db0, db1, k0, rho, sigma, n):
    """RK4's second to fourth stages of a sub-step of length ``h`` from its first, ``(ky1, kw1)``,
    with the path and the laws at its midpoint and end; returns ``(y, w, unloads)``, the state at
    the sub-step's end and whether one of those three nodes found ``r w < 0``."""
    y2 = y + 0.5 * h * ky1
    w2 = w + 0.5 * h * kw1
    ky2, kw2, r2 = _rates(y2, w2, xm, vm, am, dm0, dm1, k0, rho, sigma, n)
    y3 = y + 0.5 * h * ky2
    w3 = w + 0.5 * h * kw2
    ky3, kw3, r3 = _rates(y3, w3, xm, vm, am, dm0, dm1, k0, rho, sigma, n)
    y4 = y + h * ky3
    w4 = w + h * kw3
    ky4, kw4, r4 = _rates(y4, w4, xb, vb, ab, db0, db1, k0, rho, sigma, n)
    unloads = r2 * w2 < 0.0 or r3 * w3 < 0.0 or r4 * w4 < 0.0
    return (y + h * (ky1 + 2.0 * ky2 + 2.0 * ky3 + ky4) / 6.0,
            w + h * (kw1 + 2.0 * kw2 + 2.0 * kw3 + kw4) / 6.0, unloads)


@numba.njit(cache=True, inline="always")
def _integrate(params, memo, use_memo, same_field, field_settled, n_sub, loading_only,
               y, w, x0, x1, xd0, xd1, dt, v, du, a, d0, d1, a_1, d0_1, d1_1):
    """RK4 in ``n_sub`` sub-steps along the step's Hermite path; returns ``(y, w, completed)``.

    ``a, d0, d1`` and ``a_1, d0_1, d1_1`` are the laws at the step's start and end field. With
    ``loading_only`` it stops (``completed`` False) at the first node where ``r w < 0``, the
    unloading branch its sub-step count was not chosen for."""
    k0 = params[1]
    eta = params[4]
    rho = params[5]
    sigma = params[6]
    n = params[7]
    nodes_fit = use_memo and 10 + 6 * n_sub <= _END_SLOT
    nodes_valid = same_field and nodes_fit and memo[3] == n_sub
    if use_memo:
        memo[3] = n_sub if nodes_fit else -1.0
    h = dt / n_sub
    hs = 1.0 / n_sub
    # Values at the end of one sub-step are those at the start of the next (path, velocity and,
    # while the field settles, the voltage laws along u(s) = v + (u0 - v) exp(-eta s dt), whose
    # exponential advances by the factor q per half sub-step).
    xa = x0
    va = xd0
    aa, da0, da1 = a, d0, d1
    q = math.exp(-0.5 * eta * h)
    decay = 1.0
    for k in range(n_sub):
        last = k == n_sub - 1
        s_a = k * hs
        s_m = s_a + 0.5 * hs
        s_b = 1.0 if last else s_a + hs
        xm = hermite_position(x0, x1, xd0, xd1, dt, s_m)
        xb = x1 if last else hermite_position(x0, x1, xd0, xd1, dt, s_b)
        vm = _hermite_velocity(x0, x1, xd0, xd1, dt, s_m)
        vb = _hermite_velocity(x0, x1, xd0, xd1, dt, s_b)
        if field_settled:
            am, dm0, dm1 = a, d0, d1
            ab, db0, db1 = a, d0, d1
        else:
            decay *= q
            am, dm0, dm1 = _memo_laws(params, memo, 10 + 6 * k, v + du * decay, nodes_valid, nodes_fit)
            decay *= q
            if last:
                ab, db0, db1 = a_1, d0_1, d1_1
            else:
                ab, db0, db1 = _memo_laws(params, memo, 13 + 6 * k, v + du * decay, nodes_valid, nodes_fit)
        ky1, kw1, r1 = _rates(y, w, xa, va, aa, da0, da1, k0, rho, sigma, n)
        y_b, w_b, unloads = _rk4_rest(y, w, h, ky1, kw1, xm, vm, am, dm0, dm1, xb, vb, ab, db0, db1,
                                      k0, rho, sigma, n)
        if loading_only and (r1 * w < 0.0 or unloads):
            if use_memo:
                memo[3] = -1.0  # the nodes past this sub-step were not stored
            return y, w, False
        y = y_b
        w = w_b
        xa = xb
        va = vb
        aa, da0, da1 = ab, db0, db1
    return y, w, True


@numba.njit(cache=True, inline="always")
def _node_laws(params, field_settled, v, du, eta, dt, s, a, d0, d1, a_1, d0_1, d1_1):
    """The laws at the point ``s`` (0-1) of the step: those of its start while the field has
    settled, those of its end at ``s = 1``, else at ``u(s) = v + (u0 - v) exp(-eta s dt)``."""
    if field_settled:
        return a, d0, d1
    if s >= 1.0:
        return a_1, d0_1, d1_1
    return _laws(params, v + du * math.exp(-eta * s * dt))


@numba.njit(cache=True, inline="always")
def _local_rate(w, speed, ratio, kratio, rho, sigma, n, unloading, above):
    """Bound of the rate of ``(y, w)`` at ``w`` (see :func:`_integrate_local`): on the loading
    branch the packed bound's; on the unloading branch, with ``g = 1 + (2 sigma - 1)|w|^n`` the
    factor of ``w``'s rate, ``rho g a/(c0+c1) + k0/(c0+c1) + rho n (2 sigma - 1)|w|^(n-1) speed``
    (``above``: ``|w|`` taken at least 1, for a node whose ``w`` is not known)."""
    aw = abs(w)
    big = aw ** (n - 1.0) if aw > 1.0 else 1.0
    lam = rho * ratio + kratio + rho * n * big * speed
    if unloading:
        if above:
            aw = max(1.0, aw)
        c = 2.0 * sigma - 1.0
        awn1 = _abs_pow(aw, n - 1.0)
        lam = max(lam, rho * ratio * (1.0 + c * aw * awn1) + kratio + rho * n * c * awn1 * speed)
    return lam


@numba.njit(cache=True, inline="always")
def _least_velocity(x0, x1, xd0, xd1, dt, d):
    """The least value of ``d`` times the Hermite path's velocity over the step (a quadratic in s,
    :func:`_hermite_velocity`)."""
    g = 6.0 * (x0 - x1) / dt
    qa = d * (g + 3.0 * xd0 + 3.0 * xd1)
    qb = d * (-g - 4.0 * xd0 - 2.0 * xd1)
    qc = d * xd0
    least = min(qc, qa + qb + qc)
    if qa > 0.0:
        s = -qb / (2.0 * qa)
        if 0.0 < s < 1.0:
            least = min(least, (qa * s + qb) * s + qc)
    return least


@numba.njit(cache=True, inline="always")
def _integrate_saturated(params, field_settled, y, w, x0, x1, xd0, xd1, dt, v, du, a, d0, d1,
                         a_1, d0_1, d1_1):
    """A step on a saturated loading branch (``1 - |w| < SATURATED``, the motion keeping
    ``r w > 0``) in closed form for ``w`` and RK4 for ``y`` alone; returns ``(y, w, completed)``,
    ``completed`` False (nothing changed) where an RK4 node meets ``r w <= 0``.

    With ``w = d (1 - e)``, ``d = sign(w)``, the loading branch reads
    ``e' = -rho |r| (n e + O(e^2))``: ``e`` decays as ``exp(-rho n int |r| dt)`` and ``w``
    enters ``y``'s rate as ``d`` to within ``e`` (below 1e-9 of the hysteretic force). ``y``'s
    own rate is then ``k0/(c0 + c1)``, not the loading branch's ``rho n |r|`` that the RK4 sub-steps
    of :func:`_integrate` must resolve where the state sits at ``|w| = 1``: most of a stroke at
    large ``n`` (the Bouc-Wen kernel does the same, :func:`damper.models.bouc_wen._rk4_branch`)."""
    k0 = params[1]
    eta = params[4]
    rho = params[5]
    n = params[7]
    ltol = params[8]
    d = 1.0 if w > 0.0 else -1.0
    # The branch holds while d r = (c1 d xdot - alpha_w - d k0 (x - y)) / (c0 + c1) > 0 at every
    # point of the step, not only at RK4's nodes: a brief dip of r below 0 between them unloads
    # w at once where sigma is large (at sigma = 50, 1.5 % of w in a third of a millisecond on
    # ranran_50). The path's velocity is a quadratic in s, whose least value is exact; the laws
    # are taken at their worst over the field's start, middle and end, and the spring's term at
    # the element's deformation x - y at the start plus what it can gain over the step (its
    # rate r = xdot - ydot), with a margin of a tenth.
    vmin = _least_velocity(x0, x1, xd0, xd1, dt, d)
    am, dm0, dm1 = _node_laws(params, field_settled, v, du, eta, dt, 0.5, a, d0, d1, a_1, d0_1, d1_1)
    speed = max(abs(xd0), abs(xd1), abs(x1 - x0) / dt)
    ydot0 = (a * w + d0 * xd0 + k0 * (x0 - y)) / (d0 + d1)
    spring = 1.1 * k0 * (abs(x0 - y) + 2.0 * dt * (speed + abs(ydot0)))
    if min(d1, dm1, d1_1) * vmin <= max(a, am, a_1) + spring:
        return y, w, False
    kratio = k0 / min(d0 + d1, d0_1 + d1_1)
    m = max(1, int(math.ceil(kratio * dt / ltol)))
    if m > MAX_SUBSTEPS:
        return y, w, False
    hs = 1.0 / m
    h = hs * dt
    travel = 0.0  # int |r| dt
    xa = x0
    va = xd0
    aa, da0, da1 = a, d0, d1
    for k in range(m):
        last = k == m - 1
        s_m = (k + 0.5) * hs
        s_b = 1.0 if last else (k + 1) * hs
        xm = hermite_position(x0, x1, xd0, xd1, dt, s_m)
        xb = x1 if last else hermite_position(x0, x1, xd0, xd1, dt, s_b)
        vm = _hermite_velocity(x0, x1, xd0, xd1, dt, s_m)
        vb = _hermite_velocity(x0, x1, xd0, xd1, dt, s_b)
        am, dm0, dm1 = _node_laws(params, field_settled, v, du, eta, dt, s_m, a, d0, d1, a_1, d0_1, d1_1)
        ab, db0, db1 = _node_laws(params, field_settled, v, du, eta, dt, s_b, a, d0, d1, a_1, d0_1, d1_1)
        ky1 = (aa * w + da0 * va + k0 * (xa - y)) / (da0 + da1)
        ky2 = (am * w + dm0 * vm + k0 * (xm - (y + 0.5 * h * ky1))) / (dm0 + dm1)
        ky3 = (am * w + dm0 * vm + k0 * (xm - (y + 0.5 * h * ky2))) / (dm0 + dm1)
        ky4 = (ab * w + db0 * vb + k0 * (xb - (y + h * ky3))) / (db0 + db1)
        r1 = (va - ky1) * d
        r2 = (vm - ky2) * d
        r3 = (vm - ky3) * d
        r4 = (vb - ky4) * d
        if r1 <= 0.0 or r2 <= 0.0 or r3 <= 0.0 or r4 <= 0.0:
            return y, w, False  # the motion leaves the loading branch: not in closed form
        travel += h * (r1 + 2.0 * r2 + 2.0 * r3 + r4) / 6.0
        y += h * (ky1 + 2.0 * ky2 + 2.0 * ky3 + ky4) / 6.0
        xa = xb
        va = vb
        aa, da0, da1 = ab, db0, db1
    e = (1.0 - d * w) * math.exp(-rho * n * travel)
    return y, d * (1.0 - e), True


@numba.njit(cache=True, inline="always")
def _integrate_local(params, field_settled, y, w, x0, x1, xd0, xd1, dt, v, du, a, d0, d1,
                     a_1, d0_1, d1_1):
    """RK4 along the step's Hermite path in sub-steps sized where each one starts; returns
    ``(y, w)`` (NaN past :data:`MAX_SUBSTEPS` sub-steps).

    For sigma > 1 the unloading branch is stiffer than the loading one by up to ``2 sigma - 1``
    at ``|w| = 1``, but only briefly: ``w``'s rate there, ``rho |r| n (2 sigma - 1)|w|^(n-1)``,
    falls as ``|w|`` returns towards 0, and its integral over a whole return,
    ``ln(1 + (2 sigma - 1)|w0|^n)``, grows only with the logarithm of sigma. Every sub-step meets
    the loading tolerance (``params[8]``) under the rate bound where it starts
    (:func:`_local_rate`: the loading branch's, or the unloading branch's at the current
    ``|w|``); a sub-step that starts loading and whose RK4 nodes meet the unloading branch is
    halved until none does, or down to that branch's bound with ``|w|`` taken at least 1. The
    uniform count of :func:`_integrate` pays the worst rate over the whole step: at sigma = 50 and
    n = 6.7 the residual loop on a Dyke recording took 321 s with it and 64 s with this
    (docs/diagnosis.md, "The unloading branch sub-stepped where it is stiff")."""
    k0 = params[1]
    eta = params[4]
    rho = params[5]
    sigma = params[6]
    n = params[7]
    ltol = params[8]
    ratio = max(a / (d0 + d1), a_1 / (d0_1 + d1_1))
    kratio = k0 / min(d0 + d1, d0_1 + d1_1)
    speed_x = max(abs(xd0), abs(xd1), abs(x1 - x0) / dt)
    s_a = 0.0
    xa = x0
    va = xd0
    aa, da0, da1 = a, d0, d1
    count = 0
    while s_a < 1.0:
        count += 1
        if count > MAX_SUBSTEPS:
            return math.nan, math.nan
        ky1, kw1, r1 = _rates(y, w, xa, va, aa, da0, da1, k0, rho, sigma, n)
        speed = speed_x + abs(ky1)
        unloading = r1 * w < 0.0
        lam = _local_rate(w, speed, ratio, kratio, rho, sigma, n, unloading, False)
        hs = ltol / (lam * dt)
        # the bound that covers a reversal inside the sub-step: halving stops there
        hs_min = ltol / (_local_rate(w, speed, ratio, kratio, rho, sigma, n, True, True) * dt)
        while True:
            if s_a + hs >= 1.0 - 1e-12:
                hs = 1.0 - s_a
            s_m = s_a + 0.5 * hs
            s_b = 1.0 if hs == 1.0 - s_a else s_a + hs
            h = hs * dt
            xm = hermite_position(x0, x1, xd0, xd1, dt, s_m)
            xb = x1 if s_b == 1.0 else hermite_position(x0, x1, xd0, xd1, dt, s_b)
            vm = _hermite_velocity(x0, x1, xd0, xd1, dt, s_m)
            vb = _hermite_velocity(x0, x1, xd0, xd1, dt, s_b)
            am, dm0, dm1 = _node_laws(params, field_settled, v, du, eta, dt, s_m, a, d0, d1, a_1, d0_1, d1_1)
            ab, db0, db1 = _node_laws(params, field_settled, v, du, eta, dt, s_b, a, d0, d1, a_1, d0_1, d1_1)
            y_b, w_b, unloads = _rk4_rest(y, w, h, ky1, kw1, xm, vm, am, dm0, dm1, xb, vb, ab, db0,
                                          db1, k0, rho, sigma, n)
            if unloading or hs <= hs_min or not unloads:
                break
            hs = max(0.5 * hs, hs_min)
            count += 1
        y = y_b
        w = w_b
        s_a = s_b
        xa = xb
        va = vb
        aa, da0, da1 = ab, db0, db1
    return y, w


#: Most sub-steps a device takes in :func:`spencer_type_lockstep` (its nodes' laws fit the memo);
#: a step that needs more takes the per-device update.
LOCKSTEP_MAX_SUBSTEPS = (_END_SLOT - 10) // 6
#: Columns of the node-law workspace of :func:`spencer_type_lockstep`: the laws at the step's
#: start, then at each sub-step's midpoint and end.
LOCKSTEP_NODE_COLUMNS = 3 + 6 * LOCKSTEP_MAX_SUBSTEPS
# rows of its workspace: a device's column holds its values in the order of decreasing sub-step
# counts (row _U1: the field at the step's end, in the device's own column)
_Y, _W, _K0, _RHO, _SIG, _N, _X0, _X1, _XD0, _XD1, _H, _HS, _XA, _VA = range(14)
_XM, _VM, _XB, _VB, _KY, _KW, _YS, _WS, _U1 = range(14, 23)
#: Rows of the workspace of :func:`spencer_type_lockstep`.
SPENCER_LOCKSTEP_ROWS = 23


@numba.njit(cache=True, inline="always")
def _midpoint_stage(ws, nodes, order, active, o, reach):
    """RK4's second or third stage of :func:`spencer_type_lockstep` for its first ``active``
    columns, at the sub-step's midpoint (node laws from column ``o`` of ``nodes``); the next
    stage's point is taken ``reach`` of the sub-step ahead (1/2 after the second, 1 after the
    third; ``reach * h`` is ``h`` exactly for 1)."""
    for c in range(active):
        j = order[c]
        h = ws[_H, c]
        ky, kw, _ = _rates(ws[_YS, c], ws[_WS, c], ws[_XM, c], ws[_VM, c], nodes[j, o], nodes[j, o + 1],
                           nodes[j, o + 2], ws[_K0, c], ws[_RHO, c], ws[_SIG, c], ws[_N, c])
        ws[_KY, c] += 2.0 * ky
        ws[_KW, c] += 2.0 * kw
        ws[_YS, c] = ws[_Y, c] + reach * h * ky
        ws[_WS, c] = ws[_W, c] + reach * h * kw


@numba.njit(cache=True)
def spencer_type_lockstep(params, state, memo, lock, x0, x1, xd0, xd1, v, dt, ws, nodes, order,
                          n_subs, force):
    """Advance the Spencer-type devices ``j`` with ``lock[j]`` over one step, their RK4 sub-steps
    in lock-step; write their forces [N] into ``force[j]``.

    The same update as :func:`spencer_type_step_memo` for each device, with the same arithmetic
    (the same results): each device's field, laws, sub-step count and its nodes' laws are set
    first, then sub-step *k* of every device that has one is taken stage by stage, each stage in
    one loop over the devices. A device's RK4 stages form one chain of dependent ``pow`` calls
    (about 21 ns each on this project's machine); the stages of different devices are
    independent, so the processor overlaps them (about 8 ns per ``pow``;
    docs/performance.md). A device whose shape has ``sigma > 1`` (the loading branch's count tried
    first) or whose step needs more than :data:`LOCKSTEP_MAX_SUBSTEPS` sub-steps takes the
    per-device update.

    Parameters
    ----------
    params, state, memo
        The devices' packed parameters ``(n, P)``, states ``(n, >= 3)`` (advanced in place) and
        memos ``(n, MEMO_LENGTH)`` (see :func:`spencer_type_step_memo`).
    lock
        ``(n,)`` bool: the devices to advance (Spencer-type kernels).
    x0, x1, xd0, xd1, v
        ``(n,)`` displacements [m] and velocities [m/s] at the step's start and end, commands [V].
    dt
        Step length [s].
    ws, nodes, order, n_subs
        Workspaces: ``(SPENCER_LOCKSTEP_ROWS, n)``, ``(n, LOCKSTEP_NODE_COLUMNS)``, ``(n,)`` int64
        and ``(n,)`` int64.
    force
        ``(n,)`` output.
    """
    m = 0
    for j in range(lock.shape[0]):
        if not lock[j]:
            continue
        pj = params[j]
        sj = state[j]
        mj = memo[j]
        (u1, du, field_settled, same_field, a, d0, d1, a_1, d0_1, d1_1,
         n_sub, n_loading) = _step_setup(pj, sj, x0[j], x1[j], xd0[j], xd1[j], v[j], dt, mj, True)
        if n_sub < 0:
            for i in range(sj.shape[0]):
                sj[i] = math.nan
            force[j] = math.nan
            continue
        if n_loading < n_sub or n_sub > LOCKSTEP_MAX_SUBSTEPS:
            force[j] = _step_advance(pj, sj, x0[j], x1[j], xd0[j], xd1[j], v[j], dt, mj, True, u1, du,
                                     field_settled, same_field, a, d0, d1, a_1, d0_1, d1_1, n_sub,
                                     n_loading)
            continue
        # the laws at every node, as _integrate takes them (and keeps them in the memo)
        nodes_valid = same_field and mj[3] == n_sub
        mj[3] = n_sub
        q = math.exp(-0.5 * pj[4] * (dt / n_sub))
        decay = 1.0
        nj = nodes[j]
        nj[0], nj[1], nj[2] = a, d0, d1
        for k in range(n_sub):
            o = 3 + 6 * k
            if field_settled:
                nj[o], nj[o + 1], nj[o + 2] = a, d0, d1
                nj[o + 3], nj[o + 4], nj[o + 5] = a, d0, d1
            else:
                decay *= q
                nj[o], nj[o + 1], nj[o + 2] = _memo_laws(pj, mj, 10 + 6 * k, v[j] + du * decay,
                                                         nodes_valid, True)
                decay *= q
                if k == n_sub - 1:
                    nj[o + 3], nj[o + 4], nj[o + 5] = a_1, d0_1, d1_1
                else:
                    nj[o + 3], nj[o + 4], nj[o + 5] = _memo_laws(pj, mj, 13 + 6 * k, v[j] + du * decay,
                                                                 nodes_valid, True)
        ws[_U1, j] = u1
        # insertion into the order of decreasing sub-step counts: the devices still stepping at
        # sub-step k are then the first columns
        c = m
        while c > 0 and n_subs[c - 1] < n_sub:
            order[c] = order[c - 1]
            n_subs[c] = n_subs[c - 1]
            c -= 1
        order[c] = j
        n_subs[c] = n_sub
        m += 1
    for c in range(m):
        j = order[c]
        ws[_Y, c] = state[j, 0]
        ws[_W, c] = state[j, 1]
        ws[_K0, c] = params[j, 1]
        ws[_RHO, c] = params[j, 5]
        ws[_SIG, c] = params[j, 6]
        ws[_N, c] = params[j, 7]
        ws[_X0, c] = x0[j]
        ws[_X1, c] = x1[j]
        ws[_XD0, c] = xd0[j]
        ws[_XD1, c] = xd1[j]
        ws[_H, c] = dt / n_subs[c]
        ws[_HS, c] = 1.0 / n_subs[c]
        ws[_XA, c] = x0[j]
        ws[_VA, c] = xd0[j]
    n_max = n_subs[0] if m > 0 else 0
    active = m
    for k in range(n_max):
        while n_subs[active - 1] <= k:
            active -= 1
        o = 3 + 6 * k
        # the path at the sub-step's midpoint and end (as _integrate), and the first stage
        for c in range(active):
            j = order[c]
            last = k == n_subs[c] - 1
            hs = ws[_HS, c]
            s_m = k * hs + 0.5 * hs
            s_b = 1.0 if last else k * hs + hs
            p0 = ws[_X0, c]
            p1 = ws[_X1, c]
            v0 = ws[_XD0, c]
            v1 = ws[_XD1, c]
            ws[_XM, c] = hermite_position(p0, p1, v0, v1, dt, s_m)
            ws[_XB, c] = p1 if last else hermite_position(p0, p1, v0, v1, dt, s_b)
            ws[_VM, c] = _hermite_velocity(p0, p1, v0, v1, dt, s_m)
            ws[_VB, c] = _hermite_velocity(p0, p1, v0, v1, dt, s_b)
            y = ws[_Y, c]
            w = ws[_W, c]
            h = ws[_H, c]
            ky, kw, _ = _rates(y, w, ws[_XA, c], ws[_VA, c], nodes[j, o - 3], nodes[j, o - 2],
                               nodes[j, o - 1], ws[_K0, c], ws[_RHO, c], ws[_SIG, c], ws[_N, c])
            ws[_KY, c] = ky
            ws[_KW, c] = kw
            ws[_YS, c] = y + 0.5 * h * ky
            ws[_WS, c] = w + 0.5 * h * kw
        _midpoint_stage(ws, nodes, order, active, o, 0.5)  # second stage: the third's point at h/2
        _midpoint_stage(ws, nodes, order, active, o, 1.0)  # third stage: the fourth's point at h
        for c in range(active):  # fourth stage, at the end; the sub-step's update
            j = order[c]
            h = ws[_H, c]
            ky, kw, _ = _rates(ws[_YS, c], ws[_WS, c], ws[_XB, c], ws[_VB, c], nodes[j, o + 3],
                               nodes[j, o + 4], nodes[j, o + 5], ws[_K0, c], ws[_RHO, c], ws[_SIG, c],
                               ws[_N, c])
            ws[_Y, c] += h * (ws[_KY, c] + ky) / 6.0
            ws[_W, c] += h * (ws[_KW, c] + kw) / 6.0
            ws[_XA, c] = ws[_XB, c]
            ws[_VA, c] = ws[_VB, c]
    for c in range(m):
        j = order[c]
        e = 3 + 6 * n_subs[c]
        force[j] = _step_end(params[j], state[j], memo[j], True, ws[_Y, c], ws[_W, c], ws[_U1, j], x1[j],
                             xd1[j], nodes[j, e - 3], nodes[j, e - 2], nodes[j, e - 1])


@numba.njit(cache=True)
def _force(params, state, x, xd):
    k0 = params[1]
    k1 = params[2]
    xs = params[3]
    a, d0, d1 = _laws(params, state[2])
    ydot = (a * state[1] + d0 * xd + k0 * (x - state[0])) / (d0 + d1)
    return d1 * ydot + k1 * (x - xs)


@numba.njit(cache=True)
def spencer_type_force_kernel(params, state, x, xd, v):
    """Force [N] at the current state (the filtered voltage is ``state[2]``; ``v`` unused).

    Parameters
    ----------
    params
        Packed model parameters (the model's ``to_array()``, float64).
    state
        Internal states of the model (``n_states`` entries, see the model's docstring).
    x
        Displacement [m].
    xd
        Velocity [m/s].
    v
        Voltage [V] (unused: the filtered voltage is ``state[2]``).
    """
    return _force(params, state, x, xd)


@numba.njit(cache=True)
def spencer_type_tangent(params, state, x, xd):
    r"""Partial derivatives of the force at the current state: ``(dF/dx [N/m], dF/dxd [N·s/m])``.

    With the internal states ``(y, w)`` and the field ``u = state[2]`` held:
    :math:`\partial F/\partial x = k_1 + c_1 k_0/(c_0 + c_1)`,
    :math:`\partial F/\partial \dot x = c_1 c_0/(c_0 + c_1)` (the two dashpots in series).
    The building's Newton iteration uses them at the end of a step (:mod:`benchmark.simulator.stepping`).

    Parameters
    ----------
    params
        Packed model parameters (the model's ``to_array()``, float64).
    state
        Internal states of the model (``n_states`` entries, see the model's docstring).
    x
        Displacement [m].
    xd
        Velocity [m/s].
    """
    a, d0, d1 = _laws(params, state[2])
    s = d1 / (d0 + d1)
    return params[2] + s * params[1], s * d0


@numba.njit(cache=True)
def spencer_type_tangent_memo(params, memo):
    """:func:`spencer_type_tangent` at the end of the last :func:`spencer_type_step_memo` with this
    ``memo``, from the end field's laws that step stored (no law evaluated again).

    Parameters
    ----------
    params
        Packed model parameters (the model's ``to_array()``, float64).
    memo
        Per-device scratch array (float64, :data:`damper.models.registry.MEMO_LENGTH` entries) shared by the step
        and tangent calls of one device.
    """
    s = memo[_TANGENT_SLOT]
    return params[2] + s * params[1], s * memo[_TANGENT_SLOT + 1]
