"""Voltage laws: how an MR damper parameter depends on the coil voltage ``v`` [V].

A model parameter (``kappa_w``, ``rho``, ...) is either a number or a :class:`VoltageLaw`.
Each law evaluates in plain numpy (``law(v)``) and packs into a flat ``float64`` segment
``[kind, length, payload...]`` that the numba kernels evaluate with :func:`law_value`, so a
model's voltage dependence travels inside its ``params`` array.

Laws
----
* :class:`Constant` -- :math:`p(v) = c`.
* :class:`Polynomial` -- :math:`p(v) = \\sum_k a_k v^k` (ascending powers); the seed's
  eq. (6) :math:`\\kappa_{\\dot x}(v) = \\kappa_{\\dot x,a} + \\kappa_{\\dot x,b} v` is
  ``Polynomial((a, b))``.
* :class:`Exponential` -- :math:`p(v) = a + b\\,e^{-c v}`, the seed's eq. (7)-(9) for
  ``n`` (c = 13), ``rho`` and ``sigma`` (c = 14).
* :class:`SeedKappaW` -- the seed's three-region law eq. (10) for :math:`\\kappa_w`:

  .. math::

     \\kappa_w(v) = \\begin{cases}
        k_1 + k_2 v^{1.15} & v \\le 0.3 \\\\
        k_3 + k_4 \\sin\\frac{\\pi (v-0.3)}{0.8} + k_5 \\sin\\frac{3\\pi (v-0.3)}{0.8}
            & 0.3 \\le v \\le 0.7 \\\\
        k_6 + k_7 v + k_8 v^3 + k_9 v^5 & 0.7 \\le v
     \\end{cases}

* :class:`Saturating` -- :math:`p(v) = a + b\\tanh\\left((v/c)^e\\right)`: grows like
  :math:`v^e` at small voltage and saturates smoothly (magnetic saturation of the fluid).
* :class:`Tabulated` -- a smooth, shape-preserving law through values on a voltage grid:
  the piecewise-cubic Hermite interpolant with Fritsch-Carlson (PCHIP) slopes, monotone
  wherever the data are, held constant outside the grid. This turns parameters identified at
  a voltage grid (0, 0.1, ..., 1 V) into a model valid over the whole voltage range.

References
----------
Bahar, Pozo, Acho, Rodellar, Barbat (2009), *Parameter identification of large-scale
magnetorheological dampers in a benchmark building*, eq. (5)-(10).
Fritsch & Carlson (1980), *Monotone piecewise cubic interpolation*, SIAM J. Numer. Anal. 17.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar, Sequence, Union

import numba
import numpy as np

from benchmark.foundation.errors import ParameterError

__all__ = [
    "VoltageLaw",
    "Constant",
    "Polynomial",
    "Exponential",
    "SeedKappaW",
    "Tabulated",
    "pchip_slopes",
    "Saturating",
    "as_law",
    "law_value",
    "law_value_pair",
    "law_value_triple",
    "law_values",
    "law_length",
    "check_law",
    "ParameterLike",
]

LAW_CONSTANT = 0
LAW_POLYNOMIAL = 1
LAW_EXPONENTIAL = 2
LAW_SEED_KAPPA_W = 3
LAW_TABULATED = 4
LAW_SATURATING = 5

#: Voltages at which :func:`check_law` samples a law (in addition to grid nodes).
_CHECK_SAMPLES = 1001


class VoltageLaw:
    """Base class of the voltage laws: ``law(v)`` evaluates, ``to_array()`` packs."""

    kind: ClassVar[int]

    def __call__(self, v):
        """Value of the law at voltage(s) ``v`` [V]; a float for a scalar ``v``."""
        v_arr = np.asarray(v, dtype=float)
        out = self._evaluate(np.atleast_1d(v_arr))
        return float(out[0]) if v_arr.ndim == 0 else out.reshape(v_arr.shape)

    def _evaluate(self, v: np.ndarray) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def _payload(self) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def to_array(self) -> np.ndarray:
        """Packed form ``[kind, length, payload...]`` (``length`` counts the whole segment)."""
        # Laws are frozen: the packed form is computed once per instance (a fit packs the same
        # laws thousands of times, and a tabulated law's PCHIP slopes cost more than the copy).
        packed = self.__dict__.get("_packed")
        if packed is None:
            payload = np.asarray(self._payload(), dtype=np.float64).ravel()
            packed = np.concatenate(([float(self.kind), float(payload.size + 2)], payload))
            object.__setattr__(self, "_packed", packed)
        return packed.copy()

    @property
    def is_constant(self) -> bool:
        """True when the law does not depend on the voltage."""
        return False


@dataclass(frozen=True)
class Constant(VoltageLaw):
    """:math:`p(v) = c`.

    Parameters
    ----------
    value : float
        The constant value c (units of the parameter).
    """

    value: float
    kind: ClassVar[int] = LAW_CONSTANT

    def __post_init__(self) -> None:
        object.__setattr__(self, "value", _finite(self.value, "Constant.value"))

    def _evaluate(self, v):
        return np.full(v.shape, self.value)

    def _payload(self):
        return [self.value]

    @property
    def is_constant(self) -> bool:
        return True


@dataclass(frozen=True)
class Polynomial(VoltageLaw):
    """:math:`p(v) = a_0 + a_1 v + a_2 v^2 + \\dots` (``coefficients`` in ascending powers).

    Parameters
    ----------
    coefficients : tuple[float, ...]
        a₀, a₁, … in ascending powers of v (units of the parameter per V^k).
    """

    coefficients: tuple[float, ...]
    kind: ClassVar[int] = LAW_POLYNOMIAL

    def __post_init__(self) -> None:
        coeffs = tuple(_finite(c, f"Polynomial.coefficients[{i}]")
                       for i, c in enumerate(np.atleast_1d(np.asarray(self.coefficients, float))))
        if not coeffs:
            raise ParameterError("Polynomial.coefficients: expected at least one coefficient")
        object.__setattr__(self, "coefficients", coeffs)

    def _evaluate(self, v):
        return np.polynomial.polynomial.polyval(v, self.coefficients)

    def _payload(self):
        return list(self.coefficients)

    @property
    def is_constant(self) -> bool:
        return all(c == 0.0 for c in self.coefficients[1:])


@dataclass(frozen=True)
class Exponential(VoltageLaw):
    """:math:`p(v) = a + b\\,e^{-c v}` (seed eq. 7-9 with c = 13 or 14 V⁻¹).

    Parameters
    ----------
    a : float
        Value approached at high voltage (units of the parameter).
    b : float
        Amplitude of the exponential part (units of the parameter); ``a + b`` at 0 V.
    c : float
        Decay rate c [1/V].
    """

    a: float
    b: float
    c: float
    kind: ClassVar[int] = LAW_EXPONENTIAL

    def __post_init__(self) -> None:
        for name in ("a", "b", "c"):
            object.__setattr__(self, name, _finite(getattr(self, name), f"Exponential.{name}"))

    def _evaluate(self, v):
        return self.a + self.b * np.exp(-self.c * v)

    def _payload(self):
        return [self.a, self.b, self.c]

    @property
    def is_constant(self) -> bool:
        return self.b == 0.0 or self.c == 0.0


@dataclass(frozen=True)
class SeedKappaW(VoltageLaw):
    """The seed paper's piecewise law for :math:`\\kappa_w(v)`, eq. (10), coefficients k1..k9.

    Regions: ``v <= 0.3`` power law :math:`k_1 + k_2 v^{1.15}`; ``0.3 <= v <= 0.7`` two sines;
    ``v >= 0.7`` odd polynomial :math:`k_6 + k_7 v + k_8 v^3 + k_9 v^5` [N, v in V].

    Parameters
    ----------
    k : tuple[float, ...]
        The nine coefficients k₁…k₉ of eq. (10) of the seed paper (κ_w in N, v in V).
    """

    k: tuple[float, ...]
    kind: ClassVar[int] = LAW_SEED_KAPPA_W

    def __post_init__(self) -> None:
        k = tuple(_finite(c, f"SeedKappaW.k[{i + 1}]")
                  for i, c in enumerate(np.atleast_1d(np.asarray(self.k, float))))
        if len(k) != 9:
            raise ParameterError(f"SeedKappaW.k: expected 9 coefficients k1..k9, got {len(k)}")
        object.__setattr__(self, "k", k)

    def _evaluate(self, v):
        return np.array([_seed_kappa_w(np.asarray(self.k), float(vi)) for vi in v])

    def _payload(self):
        return list(self.k)


def _pchip_edge(h0: float, h1: float, m0: float, m1: float) -> float:
    """One-sided three-point end slope, made shape-preserving (Fritsch & Carlson)."""
    d = ((2.0 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
    if np.sign(d) != np.sign(m0):
        return 0.0
    if np.sign(m0) != np.sign(m1) and abs(d) > 3.0 * abs(m0):
        return 3.0 * m0
    return float(d)


def pchip_slopes(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Node slopes of the monotone piecewise-cubic Hermite interpolant (PCHIP) of ``y(x)``.

    Interior slopes are the weighted harmonic mean of the neighbouring secants (0 where the
    secants change sign or one vanishes), end slopes the shape-preserving three-point formula
    (Fritsch F.N., Carlson R.E. (1980), *Monotone piecewise cubic interpolation*, SIAM J.
    Numer. Anal. 17(2); the same slopes as :class:`scipy.interpolate.PchipInterpolator`).

    Parameters
    ----------
    x : np.ndarray
        Increasing nodes.
    y : np.ndarray
        Values at the nodes.
    """
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    h = np.diff(x)
    m = np.diff(y) / h
    if x.size == 2:
        return np.array([m[0], m[0]])
    d = np.zeros(x.size)
    m0, m1 = m[:-1], m[1:]
    flat = (np.sign(m0) != np.sign(m1)) | (m0 == 0.0) | (m1 == 0.0)
    w1 = 2.0 * h[1:] + h[:-1]
    w2 = h[1:] + 2.0 * h[:-1]
    ok = ~flat
    d[1:-1][ok] = (w1[ok] + w2[ok]) / (w1[ok] / m0[ok] + w2[ok] / m1[ok])
    d[0] = _pchip_edge(h[0], h[1], m[0], m[1])
    d[-1] = _pchip_edge(h[-1], h[-2], m[-1], m[-2])
    return d


@dataclass(frozen=True)
class Tabulated(VoltageLaw):
    """Shape-preserving cubic (PCHIP) law through ``values`` at ``voltages`` [V].

    Constant extrapolation outside the grid. The slopes at the nodes follow Fritsch &
    Carlson (as :class:`scipy.interpolate.PchipInterpolator`), so the law is monotone
    between nodes wherever the data are monotone, and C¹.

    Parameters
    ----------
    voltages : tuple[float, ...]
        Increasing voltage nodes [V].
    values : tuple[float, ...]
        Parameter values at the nodes (units of the parameter).
    """

    voltages: tuple[float, ...]
    values: tuple[float, ...]
    kind: ClassVar[int] = LAW_TABULATED

    def __post_init__(self) -> None:
        vg = np.atleast_1d(np.asarray(self.voltages, float))
        vals = np.atleast_1d(np.asarray(self.values, float))
        if vg.ndim != 1 or vals.shape != vg.shape:
            raise ParameterError(f"Tabulated: voltages and values must be 1-D of equal length, "
                                 f"got {vg.shape} and {vals.shape}")
        if vg.size < 1:
            raise ParameterError("Tabulated: expected at least one grid voltage")
        if not (np.all(np.isfinite(vg)) and np.all(np.isfinite(vals))):
            raise ParameterError("Tabulated: voltages and values must be finite")
        if np.any(np.diff(vg) <= 0):
            raise ParameterError("Tabulated.voltages: expected strictly increasing voltages")
        object.__setattr__(self, "voltages", tuple(float(x) for x in vg))
        object.__setattr__(self, "values", tuple(float(x) for x in vals))

    @property
    def slopes(self) -> np.ndarray:
        """PCHIP node slopes [unit/V]."""
        vg, vals = np.asarray(self.voltages), np.asarray(self.values)
        if vg.size < 2:
            return np.zeros(vg.size)
        # the same slopes as scipy's PchipInterpolator, computed directly: building the
        # interpolator cost more than a simulation, and the loop packs laws thousands of times
        return pchip_slopes(vg, vals)

    def _evaluate(self, v):
        # one compiled loop: check_law samples 1001 voltages each time a model is built
        return law_values(self.to_array(), 0, np.ascontiguousarray(v, dtype=np.float64))

    def _payload(self):
        return [float(len(self.voltages)), *self.voltages, *self.values, *self.slopes]

    @property
    def is_constant(self) -> bool:
        return len(set(self.values)) == 1


@dataclass(frozen=True)
class Saturating(VoltageLaw):
    """:math:`p(v) = a + b\\tanh((v/c)^e)` for ``v >= 0`` (``a`` at 0 V, ``a + b`` when saturated).

    ``c`` [V] > 0 sets the voltage scale, ``e`` > 0 the initial shape (``e > 1``: slow start).

    Parameters
    ----------
    a : float
        Value at 0 V (units of the parameter).
    b : float
        Increase when saturated (units of the parameter).
    c : float
        Voltage scale c [V] (> 0).
    e : float, optional
        Dimensionless exponent e of v/c.
    """

    a: float
    b: float
    c: float
    e: float = 1.0
    kind: ClassVar[int] = LAW_SATURATING

    def __post_init__(self) -> None:
        for name in ("a", "b", "c", "e"):
            object.__setattr__(self, name, _finite(getattr(self, name), f"Saturating.{name}"))
        if self.c <= 0 or self.e <= 0:
            raise ParameterError(f"Saturating: expected c > 0 and e > 0, got c={self.c}, e={self.e}")

    def _evaluate(self, v):
        return self.a + self.b * np.tanh((np.maximum(v, 0.0) / self.c) ** self.e)

    def _payload(self):
        return [self.a, self.b, self.c, self.e]

    @property
    def is_constant(self) -> bool:
        return self.b == 0.0


ParameterLike = Union[float, int, VoltageLaw]


def as_law(value: ParameterLike, field: str = "parameter") -> VoltageLaw:
    """Return ``value`` as a :class:`VoltageLaw` (a number becomes :class:`Constant`).

    Parameters
    ----------
    value : ParameterLike
        A number or a :class:`VoltageLaw`.
    field : str, optional
        Parameter name, for error messages.
    """
    if isinstance(value, VoltageLaw):
        return value
    if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool):
        return Constant(_finite(value, field))
    raise ParameterError(f"{field}: expected a number or a VoltageLaw, got {type(value).__name__}")


def check_law(law: VoltageLaw, field: str, voltage_range: Sequence[float], *,
              lower: float | None = None, strict: bool = True) -> None:
    """Raise :class:`ParameterError` unless ``law(v) > lower`` (or ``>=``) over ``voltage_range``.

    The law is sampled at 1001 voltages across the range and at its grid nodes.

    Parameters
    ----------
    law : VoltageLaw
        The law to check.
    field : str
        Parameter name, for the error message.
    voltage_range : Sequence[float]
        ``(min, max)`` voltages [V] over which the law is checked.
    lower : float | None, optional
        Lower bound of the law's values; None: no check of the bound.
    strict : bool, optional
        Require ``law(v) > lower`` (True) or ``>= lower`` (False).
    """
    v_lo, v_hi = float(voltage_range[0]), float(voltage_range[1])
    if law.is_constant:
        samples = np.array([v_lo])
    else:
        samples = np.linspace(v_lo, v_hi, _CHECK_SAMPLES)
        if isinstance(law, Tabulated):
            nodes = np.asarray(law.voltages)
            samples = np.concatenate((samples, nodes[(nodes >= v_lo) & (nodes <= v_hi)]))
    values = np.atleast_1d(law(samples))
    if not np.all(np.isfinite(values)):
        bad = samples[~np.isfinite(values)][0]
        raise ParameterError(f"{field}: value is not finite at coil input {bad:.4g}")
    if lower is None:
        return
    bad = values <= lower if strict else values < lower
    if np.any(bad):
        i = int(np.argmax(bad))
        relation = ">" if strict else ">="
        where = "" if law.is_constant else f" at coil input {samples[i]:.4g}"  # V or A: the caller says which
        raise ParameterError(f"{field}: expected {field} {relation} {lower:g}, "
                             f"got {values[i]:.6g}{where}")


def _finite(value, field: str) -> float:
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{field}: expected a number, got {value!r}") from None
    if not math.isfinite(out):
        raise ParameterError(f"{field}: expected a finite number, got {out}")
    return out


# --------------------------------------------------------------------------- numba kernels

@numba.njit(cache=True)
def law_length(params, offset):
    """Number of array entries of the law packed at ``params[offset]``.

    Parameters
    ----------
    params
        Packed model parameters (the model's ``to_array()``, float64).
    offset
        Index in ``params`` where the packed law starts.
    """
    return int(params[offset + 1])


@numba.njit(cache=True)
def _seed_kappa_w(k, v):
    if v <= 0.3:
        return k[0] + k[1] * max(v, 0.0) ** 1.15
    if v <= 0.7:
        s = math.pi * (v - 0.3) / 0.8
        return k[2] + k[3] * math.sin(s) + k[4] * math.sin(3.0 * s)
    return k[5] + k[6] * v + k[7] * v ** 3 + k[8] * v ** 5


@numba.njit(cache=True, inline="always")
def _pchip_basis(params, p, v):
    """Where a packed :class:`Tabulated` law (its data ``[m, nodes, values, slopes]`` from
    ``params[p]``) stands at ``v``: ``(r, clamped, b0, b1, b2, b3)``, ``params[p + r]`` the value
    at the interval's left node (the end value when ``clamped``: ``v`` beyond the nodes) and
    ``b0..b3`` the cubic Hermite weights of that value, its slope, the next value and its slope
    (the slopes' weights carry the interval's width). Laws on the same nodes share it."""
    m = int(params[p])
    vg = params[p + 1:p + 1 + m]
    if v <= vg[0]:
        return 1 + m, True, 0.0, 0.0, 0.0, 0.0
    if v >= vg[m - 1]:
        return 2 * m, True, 0.0, 0.0, 0.0, 0.0
    i = 0
    while i < m - 2 and v > vg[i + 1]:
        i += 1
    h = vg[i + 1] - vg[i]
    s = (v - vg[i]) / h
    s2 = s * s
    s3 = s2 * s
    return (1 + m + i, False, 2.0 * s3 - 3.0 * s2 + 1.0, (s3 - 2.0 * s2 + s) * h,
            -2.0 * s3 + 3.0 * s2, (s3 - s2) * h)


@numba.njit(cache=True, inline="always")
def _pchip_value(params, y, m, clamped, b0, b1, b2, b3):
    """A :class:`Tabulated` law's value from :func:`_pchip_basis` (``y``: the index of its value
    at the left node, ``m`` its node count): the value and its slope ``m`` entries apart."""
    if clamped:
        return params[y]
    return b0 * params[y] + b1 * params[y + m] + b2 * params[y + 1] + b3 * params[y + m + 1]


@numba.njit(cache=True)
def law_value(params, offset, v):
    """Evaluate the law packed at ``params[offset]`` at voltage ``v`` [V].

    Parameters
    ----------
    params
        Packed model parameters (the model's ``to_array()``, float64).
    offset
        Index in ``params`` where the packed law starts.
    v
        Voltage [V].
    """
    kind = int(params[offset])
    p = offset + 2
    if kind == 0:
        return params[p]
    if kind == 1:
        m = int(params[offset + 1]) - 2
        acc = 0.0
        for i in range(m - 1, -1, -1):  # Horner
            acc = acc * v + params[p + i]
        return acc
    if kind == 2:
        return params[p] + params[p + 1] * math.exp(-params[p + 2] * v)
    if kind == 3:
        return _seed_kappa_w(params[p:p + 9], v)
    if kind == 4:
        r, clamped, b0, b1, b2, b3 = _pchip_basis(params, p, v)
        return _pchip_value(params, p + r, int(params[p]), clamped, b0, b1, b2, b3)
    if kind == 5:
        x = max(v, 0.0) / params[p + 2]
        if x == 0.0:  # tanh(0) = 0: skips pow and tanh (a damper at 0 V)
            return params[p]
        e = params[p + 3]
        if e != 1.0:  # pow(x, 1) is x: skip the call
            x = x ** e
        return params[p] + params[p + 1] * math.tanh(x)
    return math.nan


@numba.njit(cache=True, inline="always")
def law_value_pair(params, offset0, offset1, v):
    """The laws packed at ``params[offset0]`` and ``params[offset1]``, both at voltage ``v`` [V].

    Bit for bit two :func:`law_value` calls. Two :class:`Saturating` laws with the same ``c``
    and ``e`` (the Spencer-type dampers' :math:`c_0(u)` and :math:`c_1(u)` usually share their
    saturation) share one ``tanh``: the building's kernel evaluates both at every node of
    every step while a damper's field moves, where the transcendental functions are most
    of a damper's cost (docs/performance.md).

    Parameters
    ----------
    params
        Packed model parameters (the model's ``to_array()``, float64).
    offset0, offset1
        Indices in ``params`` where the two packed laws start.
    v
        Voltage [V].
    """
    p0 = offset0 + 2
    p1 = offset1 + 2
    if (params[offset0] == LAW_SATURATING and params[offset1] == LAW_SATURATING
            and params[p0 + 2] == params[p1 + 2] and params[p0 + 3] == params[p1 + 3]):
        x = max(v, 0.0) / params[p0 + 2]
        if x == 0.0:
            return params[p0], params[p1]
        e = params[p0 + 3]
        if e != 1.0:
            x = x ** e
        t = math.tanh(x)
        return params[p0] + params[p0 + 1] * t, params[p1] + params[p1 + 1] * t
    return law_value(params, offset0, v), law_value(params, offset1, v)


@numba.njit(cache=True, inline="always")
def _same_nodes(params, p0, p1):
    # two packed Tabulated laws (their data at p0, p1: m, nodes, ...) on the same nodes
    m = params[p0]
    if params[p1] != m:
        return False
    for i in range(1, int(m) + 1):
        if params[p0 + i] != params[p1 + i]:
            return False
    return True


@numba.njit(cache=True, inline="always")
def law_value_triple(params, offset0, offset1, offset2, v):
    """The laws packed at ``params[offset0]``, ``params[offset1]`` and ``params[offset2]``, all at
    voltage ``v`` [V].

    Bit for bit :func:`law_value` of the first and :func:`law_value_pair` of the other two.
    Three :class:`Tabulated` laws on the same nodes (the residual loop's Spencer-type base: its
    force scale and two dashpots on two or three nodes) share the interval search and the
    cubic Hermite basis, evaluated once instead of three times: the Spencer-type kernel
    evaluates the three laws at every RK4 node while the field moves, which on a recording with
    a changing command is about half of a sub-step's cost (docs/performance.md).

    Parameters
    ----------
    params
        Packed model parameters (the model's ``to_array()``, float64).
    offset0, offset1, offset2
        Indices in ``params`` where the three packed laws start.
    v
        Voltage [V].
    """
    p0 = offset0 + 2
    p1 = offset1 + 2
    p2 = offset2 + 2
    if (params[offset0] == LAW_TABULATED and params[offset1] == LAW_TABULATED
            and params[offset2] == LAW_TABULATED and _same_nodes(params, p0, p1)
            and _same_nodes(params, p0, p2)):
        # law_value's Tabulated branch, its interval and basis found once for the three
        m = int(params[p0])
        r, clamped, b0, b1, b2, b3 = _pchip_basis(params, p0, v)
        a = _pchip_value(params, p0 + r, m, clamped, b0, b1, b2, b3)
        b = _pchip_value(params, p1 + r, m, clamped, b0, b1, b2, b3)
        c = _pchip_value(params, p2 + r, m, clamped, b0, b1, b2, b3)
        return a, b, c
    a = law_value(params, offset0, v)
    b, c = law_value_pair(params, offset1, offset2, v)
    return a, b, c


@numba.njit(cache=True)
def law_values(params, offset, v):
    """:func:`law_value` at each voltage of the array ``v`` [V].

    Parameters
    ----------
    params
        Packed model parameters (the model's ``to_array()``, float64).
    offset
        Index in ``params`` where the packed law starts.
    v
        Voltages [V], an array.
    """
    out = np.empty(v.size)
    for i in range(v.size):
        out[i] = law_value(params, offset, v[i])
    return out
