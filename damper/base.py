"""The damper model contract: what every model in :mod:`damper.registry` implements.

A damper model is a frozen, validated dataclass of SI parameters that subclasses
:class:`DamperModel`. It declares

* ``name`` — the one name it is registered and looked up under (``sbib damper test --model``,
  JSON files, reports);
* ``model_id`` — its registered integer id (unique);
* ``kernel`` — the compiled kernel family that advances it (:data:`KERNELS`): the building's
  stepping kernel and :func:`damper.simulate` dispatch on this number, so a model that packs
  its parameters into an existing family's layout needs no kernel edit;
* ``n_states`` and ``state_names`` — its internal states;
* ``voltage_range`` — the admissible coil voltages ``(v_min, v_max)`` [V];
* ``to_array()`` — its parameters packed for its kernel family, and ``initial_state()`` —
  its states at rest;
* ``rates(state, x, xdot, v)`` and ``force(state, x, xdot, v)`` — plain-numpy equations, for
  oracles and readers.

Adding a model is one module with its class plus one :func:`damper.registry.register_model`
call (see ``docs/ARCHITECTURE.md``, "Where things go"); a new kernel family also adds one
branch to each of :func:`damper.registry.device_step` and :func:`damper.registry.device_force`.
"""

from __future__ import annotations

import abc
from typing import ClassVar

import numpy as np

__all__ = ["DamperModel", "KERNEL_BOUC_WEN", "KERNEL_SPENCER_TYPE", "KERNEL_BINGHAM",
           "KERNEL_HYPERBOLIC_TANGENT", "KERNELS"]

#: Bouc-Wen family (normalized, extended, Dahl): :func:`damper.bouc_wen.bouc_wen_step`.
KERNEL_BOUC_WEN = 1
#: Spencer-type family (Spencer, the virtual damper, Bouc-Wen with a series dashpot):
#: :func:`damper.spencer.spencer_type_step`.
KERNEL_SPENCER_TYPE = 2
#: Stateless Bingham law: :func:`damper.bingham.bingham_step`.
KERNEL_BINGHAM = 3
#: Stateless hyperbolic-tangent law: :func:`damper.hyperbolic_tangent.hyperbolic_tangent_step`.
KERNEL_HYPERBOLIC_TANGENT = 4
#: Kernel families by id.
KERNELS: dict[int, str] = {KERNEL_BOUC_WEN: "bouc_wen", KERNEL_SPENCER_TYPE: "spencer_type",
                           KERNEL_BINGHAM: "bingham", KERNEL_HYPERBOLIC_TANGENT: "hyperbolic_tangent"}


class DamperModel(abc.ABC):
    """Base class of every registered damper model (module docstring)."""

    name: ClassVar[str]
    model_id: ClassVar[int]
    kernel: ClassVar[int]
    n_states: ClassVar[int]
    state_names: ClassVar[tuple[str, ...]] = ()
    voltage_range: tuple[float, float]

    @abc.abstractmethod
    def to_array(self) -> np.ndarray:
        """Parameters packed for the model's kernel family (float64)."""

    @abc.abstractmethod
    def initial_state(self) -> np.ndarray:
        """Internal states at rest, shape ``(n_states,)``."""

    @abc.abstractmethod
    def rates(self, state: np.ndarray, x: float, xdot: float, v: float) -> np.ndarray:
        """Time derivatives of the internal states.

        Parameters
        ----------
        state : np.ndarray
            Internal states of the model (``n_states`` entries, see the model's docstring).
        x : float
            Displacement [m].
        xdot : float
            Velocity [m/s].
        v : float
            Coil input: voltage [V] (or current [A] for a model identified on currents).
        """

    @abc.abstractmethod
    def force(self, state: np.ndarray, x: float, xdot: float, v: float) -> float:
        """Force [N] at ``state``, displacement ``x`` [m], velocity ``xdot`` [m/s], voltage ``v`` [V].

        Parameters
        ----------
        state : np.ndarray
            Internal states of the model (``n_states`` entries, see the model's docstring).
        x : float
            Displacement [m].
        xdot : float
            Velocity [m/s].
        v : float
            Coil input: voltage [V] (or current [A] for a model identified on currents).
        """
