"""Device slots at the isolation level: where the MR dampers sit, which way they act, which model.

A :class:`DeviceLayout` is a tuple of :class:`DeviceSlot`. Each slot has a plan position
(x, y) [m] relative to the base centre of mass, a direction (0 = x, 1 = y) and a damper model
from :mod:`damper.models.registry` (any registered model object: ``model_id``, ``to_array()``,
``initial_state()``, ``voltage_range``). Device *j* is a point on the rigid base, so it moves by

.. math::

    x_j = e_{d_j}^T T_j u_b, \\qquad T_j = \\begin{bmatrix} 1 & 0 & -y_j \\\\ 0 & 1 & x_j \\end{bmatrix},

and its force :math:`f_j` acts on the base as :math:`T_j^T e_{d_j} f_j` (Narasimhan et al. 2006, Part I).

Default layout (:meth:`DeviceLayout.default`)
---------------------------------------------
The benchmark's own device count and placement were not available (Narasimhan et al. 2006, Part I), so the
project chooses 16 devices, 8 per direction, beside perimeter bearings of the L-shaped plan,
where they resist torsion best, and balanced so that each direction's devices sit close to the
base centre of mass on average (small torsional coupling):

* x-direction (8): on the north edge y = 30.69 m at x = −7.32, 1.82, 18.17, 25.97 m; on the
  south edge y = −47.79 m at x = −7.32, 1.82 m; on the inner edge y = −11.16 m at
  x = 18.17, 25.97 m (mean y = 0.61 m);
* y-direction (8): on the west edge x = −17.25 m at y = −39.93, −16.18, 7.35, 22.83 m; on the
  east edge x = 32.83 m at y = 3.41, 19.11 m; on the inner edge x = 12.53 m at
  y = −39.75, −24.05 m (mean x = 2.71 m).

All positions are bearing positions of ``structure.json``. The default damper model is the
project's virtual benchmark damper (:mod:`damper.models.virtual`, ~1000 kN class, 0–1 V); any other
model can be given (``DeviceLayout.default(model=...)``) and every slot can be changed.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable, Sequence

import numpy as np

from benchmark.foundation.errors import InputError
from benchmark.simulator.structure import transformation
from damper.models.virtual import VirtualBenchmarkDamper
from damper.models.base import DamperModel
from damper.models.registry import MODELS, check_registered, get_model_class, kernel_id_of

__all__ = ["DeviceSlot", "DeviceLayout", "default_damper_model", "DEFAULT_X_POSITIONS",
           "DEFAULT_Y_POSITIONS", "DIRECTION_NAMES"]

DIRECTION_NAMES = ("x", "y")

#: Default x-direction device positions (x, y) [m].
DEFAULT_X_POSITIONS = ((-7.32, 30.69), (1.82, 30.69), (18.17, 30.69), (25.97, 30.69),
                       (-7.32, -47.79), (1.82, -47.79), (18.17, -11.16), (25.97, -11.16))
#: Default y-direction device positions (x, y) [m].
DEFAULT_Y_POSITIONS = ((-17.25, -39.93), (-17.25, -16.18), (-17.25, 7.35), (-17.25, 22.83),
                       (32.83, 3.41), (32.83, 19.11), (12.53, -39.75), (12.53, -24.05))


def default_damper_model() -> DamperModel:
    """Return the default damper model of a device slot: the virtual benchmark damper."""

    return VirtualBenchmarkDamper()


def _check_model(model: object, where: str) -> None:
    if not isinstance(model, DamperModel):
        raise InputError(f"{where}: {type(model).__name__} is not a damper model; expected a "
                         "damper.models.base.DamperModel registered in damper.models.registry")
    check_registered(model)


@dataclass(frozen=True)
class DeviceSlot:
    """One device: plan position, direction and damper model.

    Parameters
    ----------
    x, y : float
        Plan position relative to the base centre of mass [m].
    direction : int or str
        0 or ``"x"``; 1 or ``"y"``.
    model : damper model
        A registered damper model object (see :mod:`damper.models.registry`).
    label : str
        Free text for reports.
    """

    x: float
    y: float
    direction: int | str
    model: DamperModel | str
    label: str = ""

    def __post_init__(self) -> None:
        if isinstance(self.model, str):  # a registered model's name, with its default parameters
            if self.model not in MODELS:
                raise InputError(f"device {self.label}: {self.model!r} is not a damper model or a registered "
                                 f"model name; expected one of {', '.join(sorted(MODELS))}")
            try:
                object.__setattr__(self, "model", get_model_class(self.model)())
            except TypeError:
                raise InputError(f"device {self.label}: model {self.model!r} needs parameters; pass an "
                                 "instance") from None
        d = self.direction
        if isinstance(d, str):
            if d not in DIRECTION_NAMES:
                raise InputError(f"device {self.label or ''}: direction {d!r}; expected 'x' or 'y'")
            d = DIRECTION_NAMES.index(d)
        if isinstance(d, bool) or d not in (0, 1):
            raise InputError(f"device {self.label or ''}: direction {self.direction!r}; expected 0 (x) or 1 (y)")
        object.__setattr__(self, "direction", int(d))
        for name in ("x", "y"):
            value = getattr(self, name)
            if isinstance(value, (bool, str)):  # float(True) is 1 m, float("1.0") a typo's silent reading
                raise InputError(f"device {self.label}: {name} = {value!r}; expected a position in m (a number)")
            try:
                value = float(value)
            except (TypeError, ValueError):
                raise InputError(f"device {self.label}: {name} = {value!r}; expected a position in m") from None
            if not np.isfinite(value):
                raise InputError(f"device {self.label}: {name} = {value!r}; expected a finite position in m")
            object.__setattr__(self, name, value)
        _check_model(self.model, f"device {self.label or (self.x, self.y)}")


@dataclass(frozen=True)
class DeviceLayout:
    """The devices installed at the isolation level.

    Parameters
    ----------
    slots : sequence of DeviceSlot
        At least one slot.
    name : str
        Layout name (stored with results).
    """

    slots: tuple[DeviceSlot, ...]
    name: str = "custom"

    def __post_init__(self) -> None:
        slots = tuple(self.slots)
        if not slots:
            raise InputError("device layout: expected at least one device slot")
        for s in slots:
            if not isinstance(s, DeviceSlot):
                raise InputError(f"device layout: {s!r} is not a DeviceSlot")
        object.__setattr__(self, "slots", slots)

    # ------------------------------------------------------------------ construction
    @classmethod
    def default(cls, model: DamperModel | str | None = None) -> "DeviceLayout":
        """The documented default: 8 devices per direction at the plan's perimeter.

        Parameters
        ----------
        model : damper model, optional
            The model of every device (default: :func:`default_damper_model`).
        """
        model = default_damper_model() if model is None else model
        slots = [DeviceSlot(x, y, 0, model, label=f"x{i + 1}") for i, (x, y) in enumerate(DEFAULT_X_POSITIONS)]
        slots += [DeviceSlot(x, y, 1, model, label=f"y{i + 1}") for i, (x, y) in enumerate(DEFAULT_Y_POSITIONS)]
        return cls(tuple(slots), name="perimeter-16")

    @classmethod
    def from_positions(cls, positions: Sequence[Sequence[float]], directions: Iterable[int | str],
                       model: DamperModel | str, name: str = "custom") -> "DeviceLayout":
        """Build a layout of identical devices from positions (n, 2) [m] and directions (n,).

        Parameters
        ----------
        positions : Sequence[Sequence[float]]
            Plan positions (n, 2) [m] relative to the base centre of mass.
        directions : Iterable[int | str]
            Direction of each device: 0/``"x"`` or 1/``"y"``.
        model : DamperModel | str
            A damper model instance, or a registered model name.
        name : str, optional
            Name of the layout.
        """
        xy = np.asarray(positions, dtype=float)
        dirs = list(directions)
        if xy.ndim != 2 or xy.shape[1] != 2 or len(dirs) != len(xy):
            raise InputError(f"device layout: positions must have shape (n, 2) and directions length n; "
                             f"got {xy.shape} and {len(dirs)}")
        return cls(tuple(DeviceSlot(x, y, d, model, label=f"d{i + 1}")
                         for i, ((x, y), d) in enumerate(zip(xy, dirs))), name=name)

    def with_model(self, model: DamperModel | str) -> "DeviceLayout":
        """The same slots with every device's model replaced by ``model``.

        Parameters
        ----------
        model : DamperModel | str
            A damper model instance, or a registered model name.
        """
        return DeviceLayout(tuple(DeviceSlot(s.x, s.y, s.direction, model, s.label) for s in self.slots),
                            name=self.name)

    def with_substep_tolerance(self, tolerance: float) -> "DeviceLayout":
        """A copy whose models have ``substep_tolerance`` replaced (models without the field are kept).

        Parameters
        ----------
        tolerance : float
            The new ``substep_tolerance`` of the models (see each model).
        """
        import dataclasses

        slots = []
        for s in self.slots:
            m = s.model
            if dataclasses.is_dataclass(m) and any(f.name == "substep_tolerance" for f in dataclasses.fields(m)):
                m = dataclasses.replace(m, substep_tolerance=float(tolerance))
            slots.append(DeviceSlot(s.x, s.y, s.direction, m, s.label))
        return DeviceLayout(tuple(slots), name=self.name)

    # ------------------------------------------------------------------ views
    @property
    def n_devices(self) -> int:
        return len(self.slots)

    def __len__(self) -> int:
        return len(self.slots)

    @property
    def models(self) -> list:
        """Damper model of each slot."""
        return [s.model for s in self.slots]

    @property
    def xy(self) -> np.ndarray:
        """Plan positions (n_devices, 2) [m]."""
        return np.array([[s.x, s.y] for s in self.slots], dtype=float)

    @property
    def directions(self) -> np.ndarray:
        """Directions (n_devices,) int64: 0 = x, 1 = y."""
        return np.array([s.direction for s in self.slots], dtype=np.int64)

    @property
    def voltage_max(self) -> np.ndarray:
        """Upper voltage limit of each device [V] (its model's ``voltage_range[1]``)."""
        return np.array([float(m.voltage_range[1]) for m in self.models])

    def influence(self) -> np.ndarray:
        """Matrix (n_devices, 3) mapping base displacement to device displacement.

        Row *j* is :math:`e_{d_j}^T T_j`; its transpose maps device forces to the generalised
        force on the base (x, y, θ).
        """
        T = transformation(self.xy)
        return T[np.arange(self.n_devices), self.directions, :]

    def pack(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Arrays for the stepping kernel.

        Returns
        -------
        kernel_ids : (n,) int64, each model's kernel family (:func:`damper.models.registry.kernel_id_of`)
        params : (n, P) float64, each model's ``to_array()`` zero-padded to the longest
        states : (n, S) float64, each model's ``initial_state()`` zero-padded (S >= 1)
        n_states : (n,) int64
        """

        arrays = [np.asarray(m.to_array(), dtype=np.float64) for m in self.models]
        inits = [np.asarray(m.initial_state(), dtype=np.float64) for m in self.models]
        n = self.n_devices
        params = np.zeros((n, max(a.size for a in arrays)))
        states = np.zeros((n, max(1, max(s.size for s in inits))))
        for j, (a, s) in enumerate(zip(arrays, inits)):
            params[j, :a.size] = a
            states[j, :s.size] = s
        ids = np.array([kernel_id_of(m) for m in self.models], dtype=np.int64)
        return ids, params, states, np.array([s.size for s in inits], dtype=np.int64)

    def describe(self) -> dict:
        """JSON-serialisable description of the layout."""
        return {"name": self.name, "n_devices": self.n_devices,
                "slots": [{"label": s.label, "x": s.x, "y": s.y, "direction": DIRECTION_NAMES[int(s.direction)],
                           "model": getattr(s.model, "name", type(s.model).__name__)} for s in self.slots]}
