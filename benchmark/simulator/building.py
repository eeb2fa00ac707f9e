"""The building: superstructure (full or reduced) + isolation layer + device layout.

:class:`Building` is the one object the simulator, the linear model and the controllers
receive. It only gathers its three parts; the numbers live in :mod:`benchmark.simulator.structure`,
:mod:`benchmark.simulator.isolation` and :mod:`benchmark.simulator.devices`.

Example
-------
>>> from benchmark.simulator.building import Building                       # doctest: +SKIP
>>> b = Building.default()                    # friction-lrb isolation, 16 virtual dampers
>>> b = Building.default(isolation="linear", devices=None, n_modes=9)
"""

from __future__ import annotations

import os
from dataclasses import dataclass, replace

import numpy as np

from benchmark.foundation.errors import InputError
from benchmark.simulator.structure import Superstructure, load_superstructure
from benchmark.simulator.isolation.configurations import (DEFAULT_NONLINEAR, IsolationLayer, check_layer_carries,
                                                        get_isolation)
from benchmark.simulator.structure import bearing_gaps, location_matrix
from benchmark.simulator.devices import DeviceLayout
from damper.models.base import DamperModel

__all__ = ["Building"]


@dataclass(frozen=True, eq=False)
class Building:
    """Superstructure + isolation layer + device layout.

    Parameters
    ----------
    superstructure : Superstructure
        Full or reduced (:meth:`Superstructure.reduced`).
    isolation : benchmark.simulator.isolation.configurations.IsolationLayer
        The bearings (one row per bearing of ``superstructure.bearing_xy``).
    devices : benchmark.simulator.devices.DeviceLayout or None
        The MR dampers; ``None`` for a building without devices.
    name : str
        Free text stored with results.
    """

    superstructure: Superstructure
    isolation: IsolationLayer
    devices: DeviceLayout | None = None
    name: str = "benchmark"

    def __post_init__(self) -> None:
        n_iso = getattr(self.isolation, "n_bearings", None)
        if n_iso != self.superstructure.n_bearings:
            raise InputError(f"building: the isolation layer {getattr(self.isolation, 'name', '?')!r} has "
                             f"{n_iso} bearings, the superstructure's plan has {self.superstructure.n_bearings}")
        check_layer_carries(self.isolation, self.superstructure.total_mass)
        if self.devices is not None:
            self._check_device_positions()

    def _check_device_positions(self) -> None:
        """Every device on the base: within the bearings' plan (its bounding box, widened by 5 %
        of the plan's size and 1 m, as a device may sit beside an edge bearing, and near a
        bearing: no farther from one than the plan's bearings stand from their nearest
        neighbour, plus 1 m). A position off
        the base (a typo, or the default layout on a structure variant of another plan) would
        act through a lever arm the building does not have."""
        xy = np.asarray(self.superstructure.bearing_xy, dtype=float)
        lo, hi = xy.min(axis=0), xy.max(axis=0)
        margin = 0.05 * float(np.max(hi - lo)) + 1.0
        # a plan that is not a rectangle (the benchmark's is L-shaped) has corners of its bounding
        # box with no slab: a device farther from every bearing than any bearing is from its
        # nearest neighbour (7.9 m on the benchmark's plan), plus a metre, is off the slab
        reach = float(bearing_gaps(xy).min(axis=1).max()) + 1.0
        for slot in self.devices.slots:  # type: ignore[union-attr]
            p = np.array([slot.x, slot.y], dtype=float)
            if np.any(p < lo - margin) or np.any(p > hi + margin):
                raise InputError(f"devices: {slot.label or 'a device'} at ({slot.x:g}, {slot.y:g}) m lies off the "
                                 f"base (its bearings span x {lo[0]:g}..{hi[0]:g} m, y {lo[1]:g}..{hi[1]:g} m); "
                                 "expected positions on the base (--devices LAYOUT.json)")
            nearest = float(np.hypot(*(xy - p).T).min())
            if nearest > reach:
                raise InputError(f"devices: {slot.label or 'a device'} at ({slot.x:g}, {slot.y:g}) m is {nearest:.3g} m "
                                 f"from the nearest bearing, where the plan's bearings stand at most {reach - 1:.3g} m "
                                 "from a neighbour: off the slab (a notch of the plan?); expected positions on the "
                                 "base (--devices LAYOUT.json)")

    @classmethod
    def default(cls, isolation: str | os.PathLike | IsolationLayer | None = None,
                devices: DeviceLayout | str | None = "default", n_modes: int | None = None,
                damper_model: DamperModel | str | None = None, structure_path: str | os.PathLike | None = None) -> "Building":
        """The benchmark building with the project's defaults.

        Parameters
        ----------
        isolation : str or IsolationLayer, optional
            A name of :data:`benchmark.simulator.isolation.configurations.ISOLATION_NAMES`, a JSON file
            path, or a layer; default the default nonlinear configuration (``friction-lrb``).
        devices : "default", DeviceLayout or None
            ``"default"``: :meth:`benchmark.simulator.devices.DeviceLayout.default` (16 devices);
            ``None``: no devices.
        n_modes : int, optional
            Keep only the first ``n_modes`` superstructure modes (reduced order).
        damper_model : damper model, optional
            Model of every device of the default layout (default: the virtual benchmark damper).
        structure_path : path-like, optional
            ``structure.json`` to read (default from :mod:`benchmark.foundation.paths`).
        """

        sup = load_superstructure(structure_path)
        if n_modes is not None:
            sup = sup.reduced(n_modes)
        if isolation is None:
            isolation = DEFAULT_NONLINEAR
        if isinstance(isolation, (str, os.PathLike)):
            # a named configuration's bearings carry this structure's weight on its plan
            isolation = get_isolation(str(isolation), total_mass=sup.total_mass, n_bearings=sup.n_bearings,
                                      linear_bearing=sup.linear_bearing)
        if isinstance(devices, str):
            if devices != "default":
                raise InputError(f"devices: {devices!r}; expected 'default', a DeviceLayout or None")

            devices = DeviceLayout.default(model=damper_model)
        return cls(sup, isolation, devices)

    # ------------------------------------------------------------------ variants
    def without_devices(self) -> "Building":
        """The same building with no devices (the uncontrolled reference)."""
        return replace(self, devices=None)

    def with_devices(self, devices: DeviceLayout | None) -> "Building":
        """The same building with another device layout.

        Parameters
        ----------
        devices : DeviceLayout or None
            The devices (models, positions, directions); None: no devices.
        """
        return replace(self, devices=devices)

    def with_isolation(self, isolation: IsolationLayer) -> "Building":
        """The same building on another isolation layer.

        Parameters
        ----------
        isolation : IsolationLayer or str or path-like
            The layer, the name of a configuration, or a JSON file (:func:`get_isolation`).
        """
        if isinstance(isolation, (str, os.PathLike)):
            sup = self.superstructure
            isolation = get_isolation(str(isolation), total_mass=sup.total_mass, n_bearings=sup.n_bearings,
                                      linear_bearing=sup.linear_bearing)
        return replace(self, isolation=isolation)

    def reduced(self, n_modes: int | None) -> "Building":
        """The same building with a reduced (``n_modes``) or, for ``None``, full superstructure.

        Parameters
        ----------
        n_modes : int | None
            Number of superstructure modes kept; None: the full superstructure.
        """
        sup = self.superstructure.full() if n_modes is None else self.superstructure.reduced(n_modes)
        return replace(self, superstructure=sup)

    # ------------------------------------------------------------------ views
    @property
    def n_devices(self) -> int:
        return 0 if self.devices is None else self.devices.n_devices

    @property
    def n_bearings(self) -> int:
        return self.superstructure.n_bearings

    def isolation_linear_matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """Base stiffness and damping of the bearings' linear parts (3×3 each).

        :math:`K_b = \\sum_i k_i T_i^T T_i`, :math:`C_b = \\sum_i c_i T_i^T T_i` with
        :math:`(k_i, c_i)` each bearing's linear part (``IsolationLayer.linear_stiffness``).
        """

        xy = self.superstructure.bearing_xy
        return (location_matrix(xy, self.isolation.linear_stiffness()),
                location_matrix(xy, self.isolation.linear_damping()))

    def describe(self) -> dict:
        """JSON-serialisable description (stored with results)."""
        sup = self.superstructure
        return {
            "name": self.name,
            "superstructure": {"source": sup.source, "n_modes": sup.n_modes if sup.is_reduced else f"all ({sup.n_dof})"},
            "isolation": self.isolation.describe() if hasattr(self.isolation, "describe") else str(self.isolation),
            "devices": None if self.devices is None else self.devices.describe(),
        }
