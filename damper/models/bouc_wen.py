"""Normalized and extended Bouc-Wen models of a shear-mode MR damper, and the standard form.

Normalized Bouc-Wen model (Ikhouane & Rodellar 2007; seed eq. 1-2):

.. math::

   F = \\kappa_{\\dot x}(v)\\,\\dot x + \\kappa_w(v)\\,w, \\qquad
   \\dot w = \\rho\\left(\\dot x - \\sigma|\\dot x||w|^{n-1}w + (\\sigma-1)\\dot x|w|^n\\right)

Extended model (seed eq. 3-4) adds a linear elastic force :math:`\\kappa_x(v)\\,x`:

.. math::

   F = \\kappa_x(v)\\,x + \\kappa_{\\dot x}(v)\\,\\dot x + \\kappa_w(v)\\,w .

Admissible class (BIBO-stable, physically meaningful loops): :math:`\\kappa_{\\dot x} > 0`,
:math:`\\kappa_w > 0`, :math:`\\rho > 0`, :math:`\\sigma \\ge 1/2`, :math:`n \\ge 1`, and here
:math:`\\kappa_x \\ge 0` (``kappa_x = 0`` is the normalized model). Each parameter may be a
number or a :class:`~damper.models.voltage_laws.VoltageLaw`; the class is checked over the whole
``voltage_range`` on construction, raising :class:`~benchmark.foundation.errors.ParameterError`.
Units: ``kappa_x`` [N/m], ``kappa_xdot`` [N·s/m], ``kappa_w`` [N], ``rho`` [1/m],
``sigma`` and ``n`` dimensionless, ``w`` dimensionless (|w| <= 1 from w(0) = 0).

Standard (over-parametrized) form, Wen's sign convention (Ikhouane & Rodellar 2007):

.. math::

   F = c_0\\dot x + k_0 x + \\alpha z, \\qquad
   D\\dot z = A\\dot x - \\beta|\\dot x||z|^{n-1}z - \\gamma\\dot x|z|^n ,

maps onto the normalized form with :math:`z_0 = (A/(\\beta+\\gamma))^{1/n}`, :math:`w = z/z_0`,
:math:`\\rho = A/(D z_0)`, :math:`\\sigma = \\beta/(\\beta+\\gamma)`,
:math:`\\kappa_w = \\alpha z_0`, :math:`\\kappa_{\\dot x} = c_0`, :math:`\\kappa_x = k_0`
(Bahar et al. 2009, appendix). The reverse map is not unique: ``to_standard(A, D)`` picks the
free scale.

Numerics: the model is rate-independent, :math:`dw/dx = \\rho\\,g(w, \\mathrm{sgn}\\,\\Delta x)`,
and stiff (:math:`|\\partial \\dot w/\\partial w| \\le \\rho n \\max(1, 2\\sigma-1)|w|^{n-1}|\\dot x|`).
The kernel follows the cubic Hermite path through :math:`(x_0, \\dot x_0)`, :math:`(x_1, \\dot x_1)`,
splits it at its turning points into monotone pieces (only their end displacements matter), and
on each piece integrates :math:`w` in displacement: while :math:`w` opposes the motion it returns
to zero at a distance found by Gauss-Legendre quadrature of :math:`dx/dw` (unless a lower bound
of that distance already exceeds the piece), then loads; each smooth
regime is integrated with classical RK4 in
:math:`N = \\lceil \\rho\\,n\\max(1, 2\\sigma-1)\\max(1,|w|)^{n-1}|\\Delta x| / \\mathrm{tol} \\rceil`
sub-steps (``tol = substep_tolerance``). Error is O(tol⁴) and independent of the time step.
A loading branch within :data:`SATURATED` of :math:`|w| = 1` is linear to double precision,
:math:`1 - |w| \\propto e^{-\\rho n u}`, and is advanced in that closed form instead: most of a
large stroke is travelled saturated (2-3× fewer sub-steps on the UTFSM tests).

The limit cycle under a periodic wave input between :math:`X_{min}` and :math:`X_{max}` peaks at
:math:`w_0` solving :math:`\\psi(w_0) - \\psi(-w_0) = \\rho(X_{max} - X_{min})`
(:func:`limit_cycle_peak`).

References
----------
Ikhouane F., Rodellar J. (2007) *Systems with Hysteresis*, Wiley.
Bahar A., Pozo F., Acho L., Rodellar J., Barbat A. (2009) *Parameter identification of
large-scale magnetorheological dampers in a benchmark building* (the seed paper).
Wen Y.K. (1976) *Method for random vibration of hysteretic systems*, J. Eng. Mech. 102(2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import ClassVar

import numba
import numpy as np
from scipy.special import hyp2f1

from damper.models.base import DamperModel, KERNEL_BOUC_WEN, register_model
from benchmark.foundation.errors import InputError, ParameterError
from damper.models.voltage_laws import ParameterLike, VoltageLaw, as_law, check_law, law_length, law_value

__all__ = [
    "NormalizedBoucWen",
    "ExtendedBoucWen",
    "StandardBoucWen",
    "limit_cycle_peak",
    "limit_cycle_psi",
    "g_integral",
    "h_integral",
    "bouc_wen_step",
    "bouc_wen_step_memo",
    "BOUC_WEN_MEMO_LENGTH",
    "bouc_wen_force",
    "DEFAULT_SUBSTEP_TOLERANCE",
]


#: Largest change of ``rho * n * max(1, 2 sigma - 1) * |dx|`` per RK4 sub-step.
DEFAULT_SUBSTEP_TOLERANCE = 0.05
#: Upper bound on sub-steps per step (guards against absurd parameters).
MAX_SUBSTEPS = 200_000
#: Distance of ``|w|`` from 1 below which a loading branch is advanced in closed form.
SATURATED = 1e-9

_LAW_ORDER = ("kappa_x", "kappa_xdot", "kappa_w", "rho", "sigma", "n")


def _check_voltage_range(voltage_range) -> tuple[float, float]:
    try:
        lo, hi = (float(voltage_range[0]), float(voltage_range[1]))
    except (TypeError, ValueError, IndexError):
        raise ParameterError(f"voltage_range: expected (v_min, v_max) in V, got {voltage_range!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise ParameterError(f"voltage_range: expected finite v_min < v_max, got ({lo}, {hi})")
    return lo, hi


class _BoucWenBase(DamperModel):
    """Methods shared by the normalized and the extended model (the kernel is common)."""

    name: ClassVar[str]
    kernel: ClassVar[int] = KERNEL_BOUC_WEN
    n_states: ClassVar[int] = 1
    state_names: ClassVar[tuple[str, ...]] = ("w",)
    parameter_names: ClassVar[tuple[str, ...]]

    def _law(self, name: str) -> VoltageLaw:
        if name == "kappa_x" and "kappa_x" not in self.parameter_names:
            return as_law(0.0)
        return as_law(getattr(self, name), name)

    def _validate(self) -> None:
        object.__setattr__(self, "voltage_range", _check_voltage_range(self.voltage_range))
        for name in self.parameter_names:
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating,
                                                                  VoltageLaw)):
                raise ParameterError(f"{type(self).__name__}.{name}: expected a number or a "
                                     f"VoltageLaw, got {type(value).__name__}")
            if not isinstance(value, VoltageLaw):
                object.__setattr__(self, name, float(value))
        rng = self.voltage_range
        if "kappa_x" in self.parameter_names:
            check_law(self._law("kappa_x"), "kappa_x", rng, lower=0.0, strict=False)
        check_law(self._law("kappa_xdot"), "kappa_xdot", rng, lower=0.0)
        check_law(self._law("kappa_w"), "kappa_w", rng, lower=0.0)
        check_law(self._law("rho"), "rho", rng, lower=0.0)
        check_law(self._law("sigma"), "sigma", rng, lower=0.5, strict=False)
        check_law(self._law("n"), "n", rng, lower=1.0, strict=False)
        tol = float(self.substep_tolerance)
        if not (math.isfinite(tol) and 0.0 < tol <= 1.0):
            raise ParameterError(f"substep_tolerance: expected 0 < tol <= 1, got {tol}")
        object.__setattr__(self, "substep_tolerance", tol)

    # -- packing ---------------------------------------------------------------------
    def to_array(self) -> np.ndarray:
        """Flat ``float64`` parameters: ``[tol, law(kappa_x), law(kappa_xdot), law(kappa_w),
        law(rho), law(sigma), law(n)]`` (each law packed as in :mod:`damper.models.voltage_laws`)."""
        parts = [np.array([self.substep_tolerance])]
        parts += [self._law(name).to_array() for name in _LAW_ORDER]
        return np.ascontiguousarray(np.concatenate(parts), dtype=np.float64)

    def initial_state(self) -> np.ndarray:
        """``[w] = [0]``: the device starts unloaded."""
        return np.zeros(1)

    # -- the force is read from the state ------------------------------------------------
    def state_parameters(self) -> np.ndarray:
        """The packed parameters that the state's evolution reads: ``[tol, law(rho), law(sigma), law(n)]``.

        :math:`\\dot w` involves ρ, σ, n only; κ_x, κ_ẋ and κ_w only read the force off the
        state (module docstring). Two models of this family with equal ``state_parameters``,
        initial state and input therefore follow the same history of :math:`w`, and
        :meth:`force_history` gives either one's force from it. A fit's finite-difference
        Jacobian uses this for its κ columns (:class:`damper.diagnosis.augmented.BaseForceMemo`).
        """
        return np.concatenate([[self.substep_tolerance]] + [self._law(p).to_array() for p in ("rho", "sigma", "n")])

    def force_history(self, x: np.ndarray, xdot: np.ndarray, u: np.ndarray, states: np.ndarray) -> np.ndarray:
        """The force [N] at each sample, read off a simulated state history.

        The same sum as the kernel (:func:`bouc_wen_step`), with the coefficients at the input the
        kernel reads for each sample: the held input of the step that ends there (``u[k-1]``),
        ``u[0]`` at the first sample (:func:`damper.models.response.simulate`).

        Parameters
        ----------
        x, xdot : ndarray (n,)
            Displacement [m] and velocity [m/s] at the samples.
        u : ndarray (n,)
            Coil input at the samples [V] (or [A]), held from each sample to the next.
        states : ndarray (n, 1)
            The state ``w`` after each sample (``DamperResponse.states``).
        """
        u = np.asarray(u, dtype=float)
        held = np.concatenate((u[:1], u[:-1]))
        w = states[:, 0]
        force = self._law("kappa_xdot")(held) * xdot + self._law("kappa_w")(held) * w
        if "kappa_x" in self.parameter_names:
            force = force + self._law("kappa_x")(held) * x
        return force

    # -- plain numpy description (the scipy oracle) ----------------------------------------
    def check_voltage(self, v: float) -> float:
        """Return ``v`` as float, or raise :class:`InputError` outside ``voltage_range``."""
        v = float(v)
        lo, hi = self.voltage_range
        if not (lo - 1e-12 <= v <= hi + 1e-12):
            raise InputError(f"voltage: expected {lo:g} <= v <= {hi:g} V for {self.name}, got {v:g} V")
        return v

    def coefficients(self, v: float = 0.0) -> dict[str, float]:
        """Parameter values at voltage ``v`` [V] (SI)."""
        v = self.check_voltage(v)
        return {name: float(self._law(name)(v)) for name in _LAW_ORDER
                if name in self.parameter_names}

    def at_voltage(self, v: float):
        """The same model with every parameter frozen at its value at voltage ``v``."""
        return replace(self, **self.coefficients(v))

    def rates(self, state, x: float, xdot: float, v: float) -> np.ndarray:
        """Time derivative of the state ``[w]`` at displacement ``x``, velocity ``xdot``, voltage ``v``."""
        c = self.coefficients(v)
        w = float(state[0])
        aw = abs(w)
        dw = c["rho"] * (xdot - c["sigma"] * abs(xdot) * aw ** (c["n"] - 1.0) * w
                         + (c["sigma"] - 1.0) * xdot * aw ** c["n"])
        return np.array([dw])

    def force(self, state, x: float, xdot: float, v: float) -> float:
        """Device force [N] at the given state and inputs."""
        c = self.coefficients(v)
        return float(c.get("kappa_x", 0.0) * x + c["kappa_xdot"] * xdot + c["kappa_w"] * float(state[0]))

    def to_standard(self, A: float = 1.0, D: float = 1.0, v: float | None = None) -> "StandardBoucWen":
        """One standard-form model with the same loop (``A``, ``D`` fix the free scale).

        Inverse of :meth:`StandardBoucWen.to_normalized`: :math:`z_0 = 1/(\\rho D/A)`,
        :math:`\\beta + \\gamma = A / z_0^n`, :math:`\\beta = \\sigma(\\beta+\\gamma)`,
        :math:`\\alpha = \\kappa_w / z_0`. Voltage laws are first evaluated at ``v`` (required then).
        """
        if v is None:
            if not all(self._law(p).is_constant for p in self.parameter_names):
                raise ParameterError("to_standard: the model has voltage laws; pass v=<voltage>")
            v = self.voltage_range[0]
        c = self.coefficients(v)
        if not (A > 0 and D > 0):
            raise ParameterError(f"to_standard: expected A > 0 and D > 0, got A={A}, D={D}")
        z0 = A / (c["rho"] * D)
        beta_plus_gamma = A / z0 ** c["n"]
        return StandardBoucWen(c0=c["kappa_xdot"], k0=c.get("kappa_x", 0.0), alpha=c["kappa_w"] / z0,
                               A=A, beta=c["sigma"] * beta_plus_gamma,
                               gamma=(1.0 - c["sigma"]) * beta_plus_gamma, n=c["n"], D=D)


@register_model
@dataclass(frozen=True)
class NormalizedBoucWen(_BoucWenBase):
    """Normalized Bouc-Wen model of a shear-mode MR damper (seed eq. 1-2).

    .. math::

       F = \\kappa_{\\dot x}(v)\\dot x + \\kappa_w(v) w,\\quad
       \\dot w = \\rho(\\dot x - \\sigma|\\dot x||w|^{n-1}w + (\\sigma-1)\\dot x|w|^n)

    Parameters
    ----------
    kappa_xdot : float or VoltageLaw
        Viscous coefficient [N·s/m], > 0.
    kappa_w : float or VoltageLaw
        Hysteretic ("dry friction") force scale [N], > 0.
    rho : float or VoltageLaw
        Inverse of the characteristic displacement [1/m], > 0.
    sigma : float or VoltageLaw
        Loop-shape parameter, >= 1/2.
    n : float or VoltageLaw
        Sharpness of the elastic-plastic transition, >= 1.
    voltage_range : tuple of float
        Admissible coil voltages [V]; the class is checked over it. Default (0, 1).
    substep_tolerance : float
        RK4 sub-step size in units of :math:`\\rho n \\max(1, 2\\sigma-1)|\\Delta x|` (default 0.05).
    """

    kappa_xdot: ParameterLike
    kappa_w: ParameterLike
    rho: ParameterLike
    sigma: ParameterLike
    n: ParameterLike
    voltage_range: tuple[float, float] = (0.0, 1.0)
    substep_tolerance: float = DEFAULT_SUBSTEP_TOLERANCE

    name: ClassVar[str] = "normalized_bouc_wen"
    parameter_names: ClassVar[tuple[str, ...]] = ("kappa_xdot", "kappa_w", "rho", "sigma", "n")

    def __post_init__(self) -> None:
        self._validate()

    def extended(self, kappa_x: ParameterLike = 0.0) -> "ExtendedBoucWen":
        """The extended model with this normalized part and elastic coefficient ``kappa_x``.

        Parameters
        ----------
        kappa_x : ParameterLike, optional
            Elastic coefficient κ_x [N/m] (≥ 0), a number or a voltage law.
        """
        return ExtendedBoucWen(kappa_x, self.kappa_xdot, self.kappa_w, self.rho, self.sigma, self.n,
                               voltage_range=self.voltage_range,
                               substep_tolerance=self.substep_tolerance)


@register_model
@dataclass(frozen=True)
class ExtendedBoucWen(_BoucWenBase):
    """Extended normalized Bouc-Wen model (seed eq. 3-4): adds :math:`\\kappa_x(v)\\,x`.

    .. math::

       F = \\kappa_x(v) x + \\kappa_{\\dot x}(v)\\dot x + \\kappa_w(v) w,\\quad
       \\dot w = \\rho(\\dot x - \\sigma|\\dot x||w|^{n-1}w + (\\sigma-1)\\dot x|w|^n)

    Parameters
    ----------
    kappa_x : float or VoltageLaw
        Elastic coefficient [N/m], >= 0 (seed eq. 5: constant).
    kappa_xdot, kappa_w, rho, sigma, n, voltage_range, substep_tolerance
        As in :class:`NormalizedBoucWen`.
    """

    kappa_x: ParameterLike
    kappa_xdot: ParameterLike
    kappa_w: ParameterLike
    rho: ParameterLike
    sigma: ParameterLike
    n: ParameterLike
    voltage_range: tuple[float, float] = (0.0, 1.0)
    substep_tolerance: float = DEFAULT_SUBSTEP_TOLERANCE

    name: ClassVar[str] = "extended_bouc_wen"
    parameter_names: ClassVar[tuple[str, ...]] = ("kappa_x", "kappa_xdot", "kappa_w", "rho",
                                                  "sigma", "n")

    def __post_init__(self) -> None:
        self._validate()

    def normalized(self) -> NormalizedBoucWen:
        """The normalized part (drops ``kappa_x``)."""
        return NormalizedBoucWen(self.kappa_xdot, self.kappa_w, self.rho, self.sigma, self.n,
                                 voltage_range=self.voltage_range,
                                 substep_tolerance=self.substep_tolerance)


@dataclass(frozen=True)
class StandardBoucWen:
    """Standard (over-parametrized) Bouc-Wen form of an MR damper, constant parameters.

    .. math::

       F = c_0\\dot x + k_0 x + \\alpha z,\\qquad
       D\\dot z = A\\dot x - \\beta|\\dot x||z|^{n-1}z - \\gamma\\dot x|z|^n

    Wen's sign convention (Spencer et al. 1997 swap the roles of β and γ). Only the
    normalized form is simulated: use :meth:`to_normalized`. Units: ``c0`` [N·s/m], ``k0``
    [N/m], ``alpha`` [N per unit z], ``A`` and ``D`` dimensionless (z in metres when
    ``A = D = 1``), ``beta``, ``gamma`` [1/m^n].

    Parameters
    ----------
    c0 : float
        Viscous coefficient c₀ [N·s/m] (> 0).
    k0 : float
        Elastic coefficient k₀ [N/m] (≥ 0).
    alpha : float
        Hysteretic coefficient α [N per unit z] (> 0).
    A : float
        Dimensionless gain A of the evolution equation (> 0).
    beta : float
        Coefficient β [1/m^n] (β ≥ γ, β + γ > 0).
    gamma : float
        Coefficient γ [1/m^n].
    n : float
        Exponent n (≥ 1).
    D : float, optional
        Dimensionless scale D of ż (> 0; z in metres when A = D = 1).
    """

    c0: float
    k0: float
    alpha: float
    A: float
    beta: float
    gamma: float
    n: float
    D: float = 1.0

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            try:
                value = float(value)
            except (TypeError, ValueError):
                raise ParameterError(f"StandardBoucWen.{f.name}: expected a number, got {value!r}") from None
            if not math.isfinite(value):
                raise ParameterError(f"StandardBoucWen.{f.name}: expected a finite number, got {value}")
            object.__setattr__(self, f.name, value)
        checks = [("c0", self.c0 > 0, "c0 > 0"), ("k0", self.k0 >= 0, "k0 >= 0"),
                  ("alpha", self.alpha > 0, "alpha > 0"), ("A", self.A > 0, "A > 0"),
                  ("D", self.D > 0, "D > 0"), ("n", self.n >= 1, "n >= 1"),
                  ("beta+gamma", self.beta + self.gamma > 0, "beta + gamma > 0"),
                  ("beta", self.beta >= self.gamma,
                   "beta >= gamma (sigma >= 1/2, the admissible normalized class)")]
        for name, ok, expected in checks:
            if not ok:
                raise ParameterError(f"StandardBoucWen.{name}: expected {expected}; got "
                                     + ", ".join(f"{f.name}={getattr(self, f.name):g}" for f in fields(self)))

    @property
    def z0(self) -> float:
        """Scale :math:`z_0 = (A/(\\beta+\\gamma))^{1/n}` of the hysteretic variable."""
        return (self.A / (self.beta + self.gamma)) ** (1.0 / self.n)

    def to_normalized(self, voltage_range: tuple[float, float] = (0.0, 1.0)) -> ExtendedBoucWen:
        """The unique normalized (extended) model with the same input-output behaviour.

        Parameters
        ----------
        voltage_range : tuple[float, float], optional
            Admissible voltages ``(min, max)`` [V] of the normalized model.
        """
        z0 = self.z0
        return ExtendedBoucWen(kappa_x=self.k0, kappa_xdot=self.c0, kappa_w=self.alpha * z0,
                               rho=self.A / (self.D * z0), sigma=self.beta / (self.beta + self.gamma),
                               n=self.n, voltage_range=voltage_range)

    def rates(self, state, x: float, xdot: float, v: float = 0.0) -> np.ndarray:
        """:math:`\\dot z` (plain numpy, for checks of the conversion).

        Parameters
        ----------
        state
            ``[z]``, the standard hysteretic variable.
        x : float
            Displacement [m].
        xdot : float
            Velocity [m/s].
        v : float, optional
            Coil input: voltage [V] (or current [A] for a model identified on currents).
        """
        z = float(state[0])
        az = abs(z)
        return np.array([(self.A * xdot - self.beta * abs(xdot) * az ** (self.n - 1.0) * z
                          - self.gamma * xdot * az ** self.n) / self.D])

    def force(self, state, x: float, xdot: float, v: float = 0.0) -> float:
        """Force [N] for the standard state ``[z]``.

        Parameters
        ----------
        state
            ``[z]``, the standard hysteretic variable.
        x : float
            Displacement [m].
        xdot : float
            Velocity [m/s].
        v : float, optional
            Coil input: voltage [V] (or current [A] for a model identified on currents).
        """
        return float(self.c0 * xdot + self.k0 * x + self.alpha * float(state[0]))


# ------------------------------------------------------------------- limit cycle (DOMAIN §4)

def g_integral(w: np.ndarray | float, n: float) -> np.ndarray:
    """:math:`G_n(w) = \\int_0^w d\\mu/(1 - \\mu^n)` for :math:`0 \\le w < 1`.

    Closed form :math:`w\\,{}_2F_1(1, 1/n; 1 + 1/n; w^n)` (term-wise integration of the
    geometric series). On the loading branch of the normalized Bouc-Wen model,
    :math:`G_n(\\bar w(x)) = \\rho (x - x^*)` for :math:`x \\ge x^*`.

    Parameters
    ----------
    w : float or ndarray
        Normalized hysteretic variable(s), :math:`0 \\le |w| < 1`.
    n : float
        Bouc-Wen exponent (:math:`n \\ge 1`).

    Returns
    -------
    ndarray
        :math:`G_n(w)`, odd in ``w``.
    """
    w = np.asarray(w, dtype=float)
    return w * hyp2f1(1.0, 1.0 / n, 1.0 + 1.0 / n, np.abs(w) ** n)


def h_integral(w: np.ndarray | float, sigma: float, n: float) -> np.ndarray:
    """:math:`H_{\\sigma,n}(w) = \\int_0^w d\\mu / (1 + (2\\sigma - 1)\\mu^n)` for :math:`w \\ge 0`.

    On the loading branch for :math:`x < x^*` (where :math:`\\bar w < 0`),
    :math:`H_{\\sigma,n}(-\\bar w(x)) = \\rho (x^* - x)`.

    Parameters
    ----------
    w : float or ndarray
        Normalized hysteretic variable(s), :math:`w \\ge 0`.
    sigma, n : float
        Bouc-Wen shape parameters (:math:`\\sigma \\ge 1/2`, :math:`n \\ge 1`).

    Returns
    -------
    ndarray
        :math:`H_{\\sigma,n}(w)`.
    """
    w = np.asarray(w, dtype=float)
    return w * hyp2f1(1.0, 1.0 / n, 1.0 + 1.0 / n, -(2.0 * sigma - 1.0) * np.abs(w) ** n)


def limit_cycle_psi(w0: float, sigma: float, n: float) -> float:
    """:math:`\\psi(w_0) - \\psi(-w_0) = G_n(w_0) + H_{\\sigma,n}(w_0)` for :math:`0 \\le w_0 < 1`.

    The stroke :math:`\\rho (X_{max} - X_{min})` that a limit cycle with peak :math:`w_0` needs:
    the loading branch climbs from :math:`-w_0` to 0 (:math:`H`) and from 0 to :math:`w_0` (:math:`G`).

    Parameters
    ----------
    w0 : float
        Peak of the limit cycle, :math:`0 \\le w_0 < 1`.
    sigma, n : float
        Bouc-Wen shape parameters.

    Returns
    -------
    float
        :math:`\\rho (X_{max} - X_{min})` [-].

    Raises
    ------
    InputError
        If ``w0`` is outside [0, 1).
    """
    if not 0.0 <= w0 < 1.0:
        raise InputError(f"w0: expected 0 <= w0 < 1, got {w0}")
    return float(g_integral(w0, n) + h_integral(w0, sigma, n))


def limit_cycle_peak(rho_stroke: float, sigma: float, n: float) -> float:
    """Peak :math:`w_0` of the normalized Bouc-Wen limit cycle under a wave input.

    Solves :math:`\\psi(w_0) - \\psi(-w_0) = \\rho (X_{max} - X_{min})` (Ikhouane & Rodellar 2007,
    :func:`limit_cycle_psi`). The loading branch runs from :math:`-w_0` at :math:`X_{min}` to
    :math:`w_0` at :math:`X_{max}`; the "plastic" assumption :math:`\\bar w \\approx 1` needs
    :math:`\\rho(X_{max}-X_{min}) \\gtrsim 6` (0.72 at 2, 0.95 at 4, 0.993 at 6 for n = 1,
    :math:`\\sigma = 1/2`).

    Parameters
    ----------
    rho_stroke : float
        :math:`\\rho (X_{max} - X_{min})` [-]: ``rho`` [1/m] times the stroke [m].
    sigma, n : float
        Bouc-Wen shape parameters.

    Returns
    -------
    float
        :math:`w_0` in [0, 1): 0 for no stroke, the largest double below 1 where the cycle
        saturates beyond double precision.
    """
    from scipy.optimize import brentq
    rho_stroke = float(rho_stroke)
    if not rho_stroke > 0.0:
        return 0.0
    hi = 1.0 - 1e-15
    if limit_cycle_psi(hi, sigma, n) <= rho_stroke:
        return hi
    return float(brentq(lambda w: limit_cycle_psi(w, sigma, n) - rho_stroke, 0.0, hi, xtol=1e-14))


# ------------------------------------------------------------------------ numba kernels

@numba.njit(cache=True)
def _coefficients(params, v):
    """Unpack ``[tol, 6 laws]`` at voltage v -> (tol, kx, kxd, kw, rho, sigma, n)."""
    off = 1
    kx = law_value(params, off, v)
    off += law_length(params, off)
    kxd = law_value(params, off, v)
    off += law_length(params, off)
    kw = law_value(params, off, v)
    off += law_length(params, off)
    rho = law_value(params, off, v)
    off += law_length(params, off)
    sigma = law_value(params, off, v)
    off += law_length(params, off)
    n = law_value(params, off, v)
    return params[0], kx, kxd, kw, rho, sigma, n


@numba.njit(cache=True, inline="always")
def _abs_pow(a, n):
    if n == 1.0:
        return a
    if n == 2.0:
        return a * a
    if a == 0.0:
        return 0.0
    return a ** n


# Gauss-Legendre nodes/weights on [0, 1] (16 points) for the distance to the zero of w.
_GL_X, _GL_W = np.polynomial.legendre.leggauss(16)
_GL_NODES = 0.5 * (_GL_X + 1.0)
_GL_WEIGHTS = 0.5 * _GL_W


@numba.njit(cache=True, inline="always")
def hermite_position(x0, x1, xd0, xd1, dt, s):
    """Cubic Hermite path through (x0, xd0) at s = 0 and (x1, xd1) at s = 1 (s = tau/dt)."""
    s2 = s * s
    s3 = s2 * s
    return ((2.0 * s3 - 3.0 * s2 + 1.0) * x0 + (s3 - 2.0 * s2 + s) * dt * xd0
            + (-2.0 * s3 + 3.0 * s2) * x1 + (s3 - s2) * dt * xd1)


@numba.njit(cache=True)
def hermite_turning_points(x0, x1, xd0, xd1, dt):
    """Values of s in (0, 1) where the Hermite path reverses (sorted; 0, 1 or 2 of them).

    Returns (count, s1, s2)."""
    m0 = dt * xd0
    m1 = dt * xd1
    a = 6.0 * x0 + 3.0 * m0 - 6.0 * x1 + 3.0 * m1
    b = -6.0 * x0 - 4.0 * m0 + 6.0 * x1 - 2.0 * m1
    c = m0
    r1 = -1.0
    r2 = -1.0
    scale = abs(a) + abs(b) + abs(c)
    if scale == 0.0:
        return 0, r1, r2
    if abs(a) <= 1e-14 * scale:
        if b != 0.0:
            r1 = -c / b
    else:
        disc = b * b - 4.0 * a * c
        if disc > 0.0:
            sq = math.sqrt(disc)
            q = -0.5 * (b + sq) if b >= 0.0 else -0.5 * (b - sq)
            r1 = q / a
            r2 = c / q if q != 0.0 else -1.0
    count = 0
    s1 = 2.0
    s2 = 2.0
    for r in (r1, r2):
        if 0.0 < r < 1.0:
            if count == 0:
                s1 = r
            else:
                s2 = r
            count += 1
    if count == 2 and s2 < s1:
        s1, s2 = s2, s1
    return count, s1, s2


@numba.njit(cache=True, inline="always")
def _branch_rate(w, direction, c, rho, n):
    """dw/du along a monotone piece (u = distance travelled): rho d (1 - c |w|^n)."""
    return rho * direction * (1.0 - c * _abs_pow(abs(w), n))


@numba.njit(cache=True)
def _rk4_branch(w, direction, c, rho, n, length, n_sub):
    h = length / n_sub
    loading = c == 1.0
    for i in range(n_sub):
        if loading:
            # Saturated: near w = direction the loading branch is linear, e' = -rho n e for
            # e = 1 - direction w (the next term is O(e^2), below 1e-17 here). Most of a large
            # stroke is travelled in this state; the exponential replaces its sub-steps.
            e = 1.0 - direction * w
            if abs(e) < SATURATED:
                return direction * (1.0 - e * math.exp(-rho * n * (n_sub - i) * h))
        k1 = _branch_rate(w, direction, c, rho, n)
        k2 = _branch_rate(w + 0.5 * h * k1, direction, c, rho, n)
        k3 = _branch_rate(w + 0.5 * h * k2, direction, c, rho, n)
        k4 = _branch_rate(w + h * k3, direction, c, rho, n)
        w = w + h * (k1 + 2.0 * k2 + 2.0 * k3 + k4) / 6.0
    return w


@numba.njit(cache=True)
def _distance_to_zero(aw, rho, sigma, n):
    """Displacement needed to bring |w| = aw to 0 against the motion:
    L = int_0^aw dmu / (rho (1 + (2 sigma - 1) mu^n)) (16-point Gauss-Legendre)."""
    total = 0.0
    for i in range(_GL_NODES.size):
        mu = aw * _GL_NODES[i]
        total += _GL_WEIGHTS[i] / (1.0 + (2.0 * sigma - 1.0) * _abs_pow(mu, n))
    return aw * total / rho


@numba.njit(cache=True, inline="always")
def _above_one_pow(aw, p):
    """``max(1, aw) ** p`` without the ``pow`` call for ``aw <= 1`` (the bounded loops' every
    state), where it is exactly 1."""
    return aw ** p if aw > 1.0 else 1.0


@numba.njit(cache=True)
def _substeps(x):
    """Sub-steps for a stiffness-length product ``x``; MAX_SUBSTEPS + 1 when more are needed."""
    if not (x <= MAX_SUBSTEPS):  # also NaN
        return MAX_SUBSTEPS + 1
    return max(1, int(math.ceil(x)))


@numba.njit(cache=True)
def bouc_wen_piece(w, xa, xb, rho, sigma, n, tol):
    """Integrate w along a monotone displacement piece xa -> xb.

    On a monotone piece with direction d the model has two smooth regimes: while d*w < 0 the
    state returns towards 0 with dw/du = rho d (1 + (2 sigma - 1)|w|^n); after the zero
    (located exactly by quadrature) it loads with dw/du = rho d (1 - |w|^n). Each regime is
    integrated with RK4 in u (distance travelled) in ceil(stiffness * length / tol) sub-steps.
    """
    length = abs(xb - xa)
    if length == 0.0:
        return w
    d = 1.0 if xb > xa else -1.0
    if d * w < 0.0:
        aw = abs(w)
        stiff = rho * n * max(1.0, 2.0 * sigma - 1.0) * _above_one_pow(aw, n - 1.0)
        # The quadrature's nodes take the integrand 1 / (1 + (2 sigma - 1) mu^n), decreasing in
        # mu for sigma >= 1/2, at most 1 and at least its value at aw, and its weights sum to 1:
        # it is at least aw / (rho (1 + (2 sigma - 1) aw^n)). When that bound already exceeds the
        # piece (most steps of a return), the 16-node quadrature would only confirm it.
        if sigma >= 0.5 and aw >= length * rho * (1.0 + (2.0 * sigma - 1.0) * _abs_pow(aw, n)):
            to_zero = length
        else:
            to_zero = _distance_to_zero(aw, rho, sigma, n)
        if to_zero >= length:
            n_sub = _substeps(stiff * length / tol)
            if n_sub > MAX_SUBSTEPS:
                return math.nan  # the tolerance cannot be met: reported as a NumericalError
            w = _rk4_branch(w, d, 1.0 - 2.0 * sigma, rho, n, length, n_sub)
            return w if d * w <= 0.0 else 0.0
        w = 0.0
        length -= to_zero
    stiff = rho * n * _above_one_pow(abs(w), n - 1.0)
    n_sub = _substeps(stiff * length / tol)
    if n_sub > MAX_SUBSTEPS:
        return math.nan  # the tolerance cannot be met: reported as a NumericalError
    return _rk4_branch(w, d, 1.0, rho, n, length, n_sub)


@numba.njit(cache=True)
def bouc_wen_integrate(w, x0, x1, xd0, xd1, dt, rho, sigma, n, tol):
    """Integrate w along the Hermite path of one step, split into monotone pieces; return w(end)."""
    count, s1, s2 = hermite_turning_points(x0, x1, xd0, xd1, dt)
    if count == 0:
        return bouc_wen_piece(w, x0, x1, rho, sigma, n, tol)
    xa = hermite_position(x0, x1, xd0, xd1, dt, s1)
    w = bouc_wen_piece(w, x0, xa, rho, sigma, n, tol)
    if count == 2:
        xb = hermite_position(x0, x1, xd0, xd1, dt, s2)
        w = bouc_wen_piece(w, xa, xb, rho, sigma, n, tol)
        xa = xb
    return bouc_wen_piece(w, xa, x1, rho, sigma, n, tol)


@numba.njit(cache=True)
def bouc_wen_step(params, state, x0, x1, xd0, xd1, v, dt):
    """Advance ``state = [w]`` over one step along the path (x0, xd0) -> (x1, xd1); return F(end) [N].

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
    tol, kx, kxd, kw, rho, sigma, n = _coefficients(params, v)
    w = bouc_wen_integrate(state[0], x0, x1, xd0, xd1, dt, rho, sigma, n, tol)
    state[0] = w
    return kx * x1 + kxd * xd1 + kw * w


#: Entries of a Bouc-Wen device's memo used by :func:`bouc_wen_step_memo`: the voltage (the
#: key; NaN, the memo's initial content, matches none) and the seven coefficients at it.
BOUC_WEN_MEMO_LENGTH = 8


@numba.njit(cache=True)
def bouc_wen_step_memo(params, state, x0, x1, xd0, xd1, v, dt, memo):
    """:func:`bouc_wen_step` with the coefficients at ``v`` kept in ``memo[:8]``.

    The six voltage laws cost about 50 ns a step even when constant; at a constant or
    piecewise-constant voltage (a fit at one voltage, a bang-bang controller) they are evaluated
    once per voltage. The same arithmetic on the same values as :func:`bouc_wen_step`: equal to
    rounding (the compiled code's shape may move the last digits;
    ``tests/damper/test_bouc_wen_shortcuts.py``).

    Parameters
    ----------
    params, state, x0, x1, xd0, xd1, v, dt
        As :func:`bouc_wen_step`.
    memo
        Scratch array of at least :data:`BOUC_WEN_MEMO_LENGTH` entries, NaN before the first
        step, kept for this device and these ``params``.
    """
    if not memo[0] == v:  # NaN (a fresh memo) never matches
        tol, kx, kxd, kw, rho, sigma, n = _coefficients(params, v)
        memo[0] = v
        memo[1] = tol
        memo[2] = kx
        memo[3] = kxd
        memo[4] = kw
        memo[5] = rho
        memo[6] = sigma
        memo[7] = n
    w = bouc_wen_integrate(state[0], x0, x1, xd0, xd1, dt, memo[5], memo[6], memo[7], memo[1])
    state[0] = w
    return memo[2] * x1 + memo[3] * xd1 + memo[4] * w


@numba.njit(cache=True)
def bouc_wen_force(params, state, x, xd, v):
    """Force [N] of the (extended) Bouc-Wen model at the current state.

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
        Coil input: voltage [V] (or current [A] for a model identified on currents).
    """
    tol, kx, kxd, kw, rho, sigma, n = _coefficients(params, v)
    return kx * x + kxd * xd + kw * state[0]
