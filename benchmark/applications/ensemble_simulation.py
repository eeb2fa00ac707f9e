"""The ensemble's simulation run function: one case → peaks and J1–J9.

A case (:class:`benchmark.applications.ensemble.EnsembleMember`) names a motion, a controller and grid parameters.
:func:`run_ensemble_case` loads or generates the motion, scales it, builds the building with the
overrides, simulates it with the controller (:func:`benchmark.simulator.simulation.simulate`) and
evaluates it against the uncontrolled run of the same motion and building
(:func:`benchmark.simulator.evaluation.evaluate`), like :mod:`benchmark.applications.comparison` does for the
benchmark suite. The uncontrolled run, the motion and the building are cached per worker
process (cases of one motion are consecutive, so a worker usually reuses them).

Grid parameters understood (names in the TOML ``[grid]`` table):

``control_step``
    Control sample time [s] (a multiple of the record step).
``n_modes``
    Retained superstructure modes (integer; reduced-order building).
``substep_tolerance``
    Sub-step tolerance of every bearing and device kernel.
``isolation.<field>``
    Replaces ``<field>`` of the parameters of every bearing group that has it (SI, e.g.
    ``isolation.mu_fast`` for friction-pendulum bearings, if that is the field's name).
``device.<field>``
    Replaces ``<field>`` of every device's damper model (SI; a voltage-dependent field
    becomes the constant value).
``noise.<anything>``
    Reserved; unknown names are an :class:`~benchmark.foundation.errors.InputError` naming the parameter.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from functools import lru_cache
from typing import Any

import numpy as np

from benchmark.foundation.errors import InputError
from benchmark.simulator.building import Building
from benchmark.simulator.case import Case, run_case
from benchmark.simulator.isolation.configurations import check_substep_tolerance
from benchmark.simulator.simulation import check_control_step
from controllers.registry import get_controller
from records.resolve import resolve_record
from benchmark.simulator.isolation.configurations import BearingGroup
from benchmark.simulator.devices import DeviceLayout, DeviceSlot
from benchmark.applications.damper_choice import device_motion, resolve_damper, resolve_layout

__all__ = ["run_ensemble_case", "load_motion", "build_building", "check_grid_values", "SIMULATION_PARAMETERS"]

#: Plain grid parameters (besides ``isolation.<field>`` and ``device.<field>``).
SIMULATION_PARAMETERS = ("control_step", "n_modes", "substep_tolerance")


def _split(parameters: tuple[tuple[str, float], ...]) -> tuple[dict, tuple, tuple]:
    plain: dict[str, float] = {}
    isolation, devices = [], []
    for name, value in parameters:
        if name in SIMULATION_PARAMETERS:
            plain[name] = value
        elif name.startswith("isolation.") and len(name) > len("isolation."):
            isolation.append((name[len("isolation."):], value))
        elif name.startswith("device.") and len(name) > len("device."):
            devices.append((name[len("device."):], value))
        elif name.startswith("probe."):
            continue  # the probe's own parameters are harmless here
        else:
            raise InputError(f"grid parameter {name!r} unknown to the simulation; expected one of "
                             f"{', '.join(SIMULATION_PARAMETERS)}, isolation.<field> or device.<field>")
    return plain, tuple(isolation), tuple(devices)


@lru_cache(maxsize=8)
def load_motion(record: str, orientation: str, synthetic: bool, motion_seed: int, pga: float) -> Any:
    """The ground motion of a case: a benchmark record or a synthetic realisation, scaled.

    ``pga`` [m/s²] (NaN: unscaled) becomes the peak absolute acceleration of the stronger
    component; both components are scaled by the same factor.
    """
    motion = resolve_record(record, orientation, synthetic=bool(synthetic), seed=int(motion_seed))
    if not math.isnan(pga):
        peak = float(np.max(np.abs(motion.acceleration)))
        if not peak > 0:
            raise InputError(f"record {record!r}: zero acceleration cannot be scaled to PGA {pga} m/s^2")
        motion = motion.scaled(pga / peak)
    return motion


def _replace_fields(obj: Any, overrides: tuple, what: str, strict: bool) -> tuple[Any, set]:
    if not dataclasses.is_dataclass(obj):
        return obj, set()
    names = {f.name for f in dataclasses.fields(obj)}
    changes = {k: float(v) for k, v in overrides if k in names}
    if strict and len(changes) != len(overrides):
        missing = [k for k, _ in overrides if k not in names]
        raise InputError(f"grid parameter {what}.{missing[0]}: {type(obj).__name__} has no field "
                         f"{missing[0]!r}; fields: {', '.join(sorted(names))}")
    return (dataclasses.replace(obj, **changes) if changes else obj), set(changes)


@lru_cache(maxsize=4)
def _base_building(n_modes: int | None, damper: tuple = ()) -> Any:
    if damper:
        spec, layout_spec, scale = (v or None for v in damper)
        choice = resolve_damper(spec, scale)
        layout, _ = resolve_layout(layout_spec, choice, scale)
        return Building.default(n_modes=n_modes, devices=layout)
    return Building.default(n_modes=n_modes)


def _with_overrides(building: Any, isolation: tuple, devices: tuple) -> Any:
    """``building`` with the isolation and device field overrides (each model's own checks apply)."""
    if isolation:
        layer = building.isolation
        groups, used = [], set()
        for group in layer.groups:
            bearing, changed = _replace_fields(group.bearing, isolation, "isolation", strict=False)
            used |= changed
            groups.append(BearingGroup(bearing, group.indices, group.label))
        unused = [k for k, _ in isolation if k not in used]
        if unused:
            raise InputError(f"grid parameter isolation.{unused[0]}: no bearing group of "
                             f"{layer.name!r} has a field {unused[0]!r}")
        building = building.with_isolation(dataclasses.replace(layer, groups=tuple(groups)))
    if devices:
        slots = []
        for slot in building.devices.slots:
            model, _ = _replace_fields(slot.model, devices, "device", strict=True)
            slots.append(DeviceSlot(slot.x, slot.y, slot.direction, model, slot.label))
        building = building.with_devices(DeviceLayout(tuple(slots), name=building.devices.name))
    return building


@lru_cache(maxsize=4)
def build_building(n_modes: int | None, isolation: tuple, devices: tuple, damper: tuple = ()) -> Any:
    """The default building with ``n_modes``, the config's ``(damper, devices, damper_scale)``
    (:mod:`benchmark.applications.damper_choice`) and the isolation/device field overrides."""
    return _with_overrides(_base_building(n_modes, tuple(damper)), isolation, devices)


#: Grid points of the isolation (or device) fields checked together before an ensemble runs; a
#: larger product has each value checked on its own (:func:`check_grid_values`).
MAX_CHECKED_POINTS = 10_000


def _n_modes(value: float | None) -> int | None:
    if value is None:
        return None
    if value != int(value) or value < 1:
        raise InputError(f"grid parameter n_modes = {value!r}: expected a positive integer")
    return int(value)


def check_grid_values(grid: tuple[tuple[str, tuple[float, ...]], ...], damper: tuple = ()) -> None:
    """Refuse, before any run, a grid value the simulation would refuse when its case runs.

    ``n_modes``, ``control_step`` and ``substep_tolerance`` are checked value by value (whole
    modes, a step and a tolerance in range); the ``isolation.*`` fields are checked together at
    every point of their product, and so are the ``device.*`` fields, on the building they change
    (built, not run: the models' own checks apply, such as ``mu_min <= mu_max``, which only a
    point of both fields can judge); past :data:`MAX_CHECKED_POINTS` points each value on its
    own. A bad value had stopped an ensemble only when its case came up, after the runs before it.

    Parameters
    ----------
    grid : tuple of (str, tuple of float)
        The ensemble's grid (:attr:`benchmark.applications.ensemble.EnsembleConfig.grid`).
    damper : tuple
        The config's ``(damper, devices, damper_scale)`` (empty for the defaults).

    Raises
    ------
    InputError
        Naming the parameters and the values.
    """
    def refuse(point: str, exc: InputError) -> None:
        text = str(exc)
        if text.startswith("grid parameter"):  # an unknown name: the message names it
            raise InputError(text) from None
        raise InputError(f"grid {'point' if ',' in point else 'parameter'} {point}: {text}") from None

    fields: dict[str, list[tuple[str, tuple[float, ...]]]] = {"isolation": [], "device": []}
    for name, values in grid:
        for value in values:
            try:
                plain, isolation, devices = _split(((name, value),))
                n_modes = _n_modes(plain.get("n_modes"))
                if "control_step" in plain:
                    check_control_step(plain["control_step"])
                if "substep_tolerance" in plain:
                    check_substep_tolerance(plain["substep_tolerance"])
                if n_modes is not None:
                    _base_building(n_modes, tuple(damper))
            except InputError as exc:
                refuse(f"{name} = {value!r}", exc)
        kind = name.split(".", 1)[0]
        if kind in fields and name.startswith(kind + ".") and len(name) > len(kind) + 1:
            fields[kind].append((name[len(kind) + 1:], values))
    base = None
    for kind, items in fields.items():
        if not items:
            continue
        base = base or _base_building(None, tuple(damper))
        names = [n for n, _ in items]
        size = math.prod(len(v) for _, v in items)
        points = (itertools.product(*[v for _, v in items]) if size <= MAX_CHECKED_POINTS else
                  (tuple(v if j == i else items[j][1][0] for j in range(len(items)))
                   for i in range(len(items)) for v in items[i][1]))
        for point in points:
            overrides = tuple(zip(names, point))
            try:
                _with_overrides(base, overrides if kind == "isolation" else (),
                                overrides if kind == "device" else ())
            except InputError as exc:
                refuse(", ".join(f"{kind}.{n} = {v!r}" for n, v in overrides), exc)


def run_ensemble_case(case: Any, evaluate_criteria: bool = True) -> dict[str, float]:
    """Simulate one ensemble case and evaluate it (see the module docstring).

    Parameters
    ----------
    case : benchmark.applications.ensemble.EnsembleMember
        The case.
    evaluate_criteria : bool
        Also run the uncontrolled building (cached per motion) and return J1–J9.

    Returns
    -------
    dict
        The peaks of :meth:`benchmark.simulator.peaks.Peaks.as_record` (SI) and ``J1``..``J9`` (NaN where a
        criterion is undefined, e.g. J6 without devices).

    Raises
    ------
    InputError
        Unknown controller, record or grid parameter.
    NumericalError
        The simulation failed (the ensemble records the case as failed and goes on).
    """

    plain, isolation, devices = _split(case.parameters)
    n_modes = _n_modes(plain.get("n_modes"))
    substep = plain.get("substep_tolerance")
    kwargs: dict[str, Any] = {"bearing_histories": False, "seed": int(case.seed) % (2 ** 32)}
    if "control_step" in plain:
        kwargs["control_step"] = plain["control_step"]
    if substep is not None:
        kwargs["substep_tolerance"] = substep
    motion_args = (case.record, case.orientation, bool(case.synthetic), int(case.motion_seed), float(case.pga))
    motion = load_motion(*motion_args)
    controller = get_controller(case.controller)
    building = build_building(n_modes, isolation, devices if controller is not None else (),
                              tuple(getattr(case, "building", ())))
    control_step = kwargs.pop("control_step", None)
    # the one way to run a case; the reference of a motion is run once per building (cached)
    run = run_case(Case(record=motion, controller=controller, building=building, control_step=control_step,
                        options=kwargs), reference=evaluate_criteria or controller is None)
    out = {name: float(value) for name, value in run.peaks.as_record().items()}
    if controller is not None:
        # the devices' largest stroke and velocity: what a model fitted on laboratory motions is
        # compared with once the ensemble is done (DEVICE_MOTION_UNITS, ensemble_motion_notes)
        out["peak_device_stroke"], out["peak_device_velocity"] = device_motion(run.result)
    if evaluate_criteria:
        for name, value in run.J.items():
            out[name] = math.nan if value is None else float(value)
    return out
