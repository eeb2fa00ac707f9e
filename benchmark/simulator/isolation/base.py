"""Interface every bearing type follows, and the validation helpers their dataclasses share.

A bearing type is one module holding a frozen dataclass derived from :class:`BearingParameters`.
The flat parameter array (``to_array()``) of *every* type starts with its **linear part**::

    params[0] = k_linear  [N/m]     (stiffness the building puts in its exact discretisation)
    params[1] = c_linear  [N·s/m]   (viscous damping, likewise)
    params[2:]            type-specific (documented in each module)

so that the building core can read the linear part without knowing the type, and the
numba kernel returns only the remaining (hysteretic) force. See :mod:`benchmark.simulator.isolation.registry`.

Adding a bearing type is **one class** decorated with :func:`register_bearing`: a frozen dataclass
of SI parameters deriving from :class:`BearingParameters`, with a ``name`` (the one name it is
looked up under, in isolation files and :func:`benchmark.simulator.isolation.registry.bearing_type`)
and a ``kernel``: the compiled kernel family that advances it (:data:`BEARING_KERNELS`). A type that
packs its parameters into an existing family's layout (for example a high-damping rubber bearing
written as a Park–Wen element in the lead-rubber layout) needs no kernel edit; a new family adds
its numba step beside the class and one branch to each dispatch kernel of the registry.
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np

from benchmark.foundation.errors import ParameterError
from benchmark.foundation.registry import Registry

__all__ = ["BearingParameters", "BEARINGS", "BEARING_KERNELS", "KERNEL_LINEAR", "KERNEL_LEAD_RUBBER",
           "KERNEL_FRICTION_PENDULUM", "register_bearing", "require_positive", "require_nonnegative",
           "require_range"]

#: Kernel family ids: the number the building's stepping kernel dispatches on (never chosen per type).
KERNEL_LINEAR = 0
KERNEL_LEAD_RUBBER = 1
KERNEL_FRICTION_PENDULUM = 2
#: kernel family id -> the module whose numba step advances it
BEARING_KERNELS: dict[int, str] = {KERNEL_LINEAR: "linear", KERNEL_LEAD_RUBBER: "lead_rubber",
                                   KERNEL_FRICTION_PENDULUM: "friction_pendulum"}


def _check_number(cls_name: str, field: str, value: object) -> float:
    try:
        x = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise ParameterError(f"{cls_name}.{field} = {value!r}: expected a real number") from None
    if not math.isfinite(x):
        raise ParameterError(f"{cls_name}.{field} = {value!r}: expected a finite number")
    return x


def require_positive(obj: object, field: str) -> None:
    """Raise :class:`ParameterError` unless ``obj.field`` is a finite number > 0.

    Parameters
    ----------
    obj : object
        The parameter object checked.
    field : str
        Name of its field.
    """
    x = _check_number(type(obj).__name__, field, getattr(obj, field))
    if not x > 0.0:
        raise ParameterError(f"{type(obj).__name__}.{field} = {x!r}: expected > 0")


def require_nonnegative(obj: object, field: str) -> None:
    """Raise :class:`ParameterError` unless ``obj.field`` is a finite number >= 0.

    Parameters
    ----------
    obj : object
        The parameter object checked.
    field : str
        Name of its field.
    """
    x = _check_number(type(obj).__name__, field, getattr(obj, field))
    if not x >= 0.0:
        raise ParameterError(f"{type(obj).__name__}.{field} = {x!r}: expected >= 0")


def require_range(obj: object, field: str, low: float, high: float,
                  low_open: bool = False, high_open: bool = False) -> None:
    """Raise :class:`ParameterError` unless ``low <= obj.field <= high``.

    ``low_open`` / ``high_open`` make the lower / upper bound strict.

    Parameters
    ----------
    obj : object
        The parameter object checked.
    field : str
        Name of its field.
    low : float
        Lower bound.
    high : float
        Upper bound.
    low_open : bool, optional
        Exclude the lower bound.
    high_open : bool, optional
        Exclude the upper bound.
    """
    x = _check_number(type(obj).__name__, field, getattr(obj, field))
    ok_low = x > low if low_open else x >= low
    ok_high = x < high if high_open else x <= high
    if not (ok_low and ok_high):
        lb = "(" if low_open else "["
        hb = ")" if high_open else "]"
        raise ParameterError(f"{type(obj).__name__}.{field} = {x!r}: expected in {lb}{low}, {high}{hb}")


class BearingParameters:
    """Base class of the bearing parameter dataclasses (frozen, SI units).

    Subclasses define ``name``, ``kernel`` (:data:`BEARING_KERNELS`), ``n_states`` and implement
    :meth:`to_array`, :meth:`initial_state`, :meth:`linear_part`, :meth:`rates` and :meth:`force`,
    and are registered with :func:`register_bearing`.
    """

    name: ClassVar[str]
    kernel: ClassVar[int]
    n_states: ClassVar[int]

    def to_array(self) -> np.ndarray:
        """Flat ``float64`` parameter array for the kernels (``[k_linear, c_linear, ...]``)."""
        raise NotImplementedError

    def initial_state(self) -> np.ndarray:
        """Internal states at rest (length ``n_states``)."""
        return np.zeros(self.n_states)

    def linear_part(self) -> tuple[float, float]:
        """``(k, c)``: linear stiffness [N/m] and damping [N·s/m] per direction."""
        p = self.to_array()
        return float(p[0]), float(p[1])

    def rates(self, state: np.ndarray, ux: float, uy: float, vx: float, vy: float) -> np.ndarray:
        """Continuous-time state derivatives ``d state / dt`` (plain numpy, for the scipy oracle).

        Parameters
        ----------
        state : np.ndarray
            Internal (hysteretic) states of the bearing.
        ux : float
            Bearing displacement in x [m].
        uy : float
            Bearing displacement in y [m].
        vx : float
            Bearing velocity in x [m/s].
        vy : float
            Bearing velocity in y [m/s].
        """
        raise NotImplementedError

    def force(self, state: np.ndarray, ux: float, uy: float, vx: float, vy: float) -> tuple[float, float]:
        """Total bearing force ``(fx, fy)`` [N] including the linear part (plain numpy).

        Parameters
        ----------
        state : np.ndarray
            Internal (hysteretic) states of the bearing.
        ux : float
            Bearing displacement in x [m].
        uy : float
            Bearing displacement in y [m].
        vx : float
            Bearing velocity in x [m/s].
        vy : float
            Bearing velocity in y [m/s].
        """
        raise NotImplementedError

    def hysteretic_force(self, state: np.ndarray, ux: float, uy: float,
                         vx: float, vy: float) -> tuple[float, float]:
        """Force minus the linear part, ``f - k u - c u̇`` [N]: what the kernel writes.

        Parameters
        ----------
        state : np.ndarray
            Internal (hysteretic) states of the bearing.
        ux : float
            Bearing displacement in x [m].
        uy : float
            Bearing displacement in y [m].
        vx : float
            Bearing velocity in x [m/s].
        vy : float
            Bearing velocity in y [m/s].
        """
        fx, fy = self.force(state, ux, uy, vx, vy)
        k, c = self.linear_part()
        return fx - k * ux - c * vx, fy - k * uy - c * vy


def _check_kernel(cls: type) -> str | None:
    kernel = getattr(cls, "kernel", None)
    if isinstance(kernel, bool) or kernel not in BEARING_KERNELS:
        return (f"kernel {kernel!r} is not a bearing kernel family; expected one of "
                + ", ".join(f"{k} ({v})" for k, v in BEARING_KERNELS.items()))
    if not isinstance(getattr(cls, "n_states", None), int):
        return "no n_states (a class attribute: the number of internal states)"
    return None


#: Registered bearing types by name (filled by :func:`register_bearing`).
BEARINGS: Registry = Registry("bearing type", BearingParameters, _check_kernel)


def register_bearing(cls):
    """Register a bearing type under its ``name`` (a class decorator) and return it.

    Parameters
    ----------
    cls : type
        A :class:`BearingParameters` subclass with a ``name``, a ``kernel`` of
        :data:`BEARING_KERNELS` and ``n_states``.

    Returns
    -------
    type
        ``cls`` itself.

    Raises
    ------
    InputError
        If ``cls`` is not a :class:`BearingParameters` subclass, names an unknown kernel family,
        or its name is already taken by another class.
    """
    return BEARINGS.register(cls)
