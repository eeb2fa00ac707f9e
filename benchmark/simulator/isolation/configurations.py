r"""Isolation layers: groups of bearings of one type, and the named configurations.

An :class:`IsolationLayer` assigns every one of the benchmark's 92 bearings (numbered 1–92 in
the order of ``structure.json``'s ``bearing_xy``; **0-based indices** in this API) to exactly
one :class:`BearingGroup` (a bearing type with its parameters). Any grouping is allowed; the
benchmark's default split is bearings 1–61 and 62–92.

Named configurations (:data:`ISOLATION_NAMES`, :func:`get_isolation`)
--------------------------------------------------------------------
``linear``
    All 92 bearings linear elastomeric, k = 919.422 kN/m, c = 27.717 kN·s/m each (the values of
    published re-implementations, FDZ; isolated periods ≈ 3.4/3.2/2.7 s, ≈ 3 % damping).
``friction-lrb`` (the default nonlinear configuration)
    Bearings 1–61 friction pendulum, bearings 62–92 lead-rubber (the common reading of the
    benchmark's 61 sliding + 31 elastomeric bearings). Values, chosen so that the post-yield
    (sliding) isolated period is 3.0 s:

    * vertical load per bearing :math:`W_i = M g / 92 = 2.2078` MN with the building's total
      mass :math:`M = 20\,704.73` t (8 floors 17 139 t + base 3 565.73 t, ``structure.json``)
      and g = 9.80665 m/s² (uniform load sharing assumed);
    * friction pendulum: R = 2.24 m (pendulum period :math:`2\pi\sqrt{R/g} = 3.00` s),
      :math:`\mu_\max = 0.06`, :math:`\mu_\min = 0.03`, a = 20 s/m (PTFE-type composite on
      polished stainless steel at high pressure; Mokha et al. 1990, Constantinou et al. 1990
      report f_max 0.05–0.12, f_min about half of it, a 20–30 s/m), Y = 0.5 mm;
    * lead-rubber: post-yield stiffness equal to the pendulum stiffness W_i/R = 0.9856 MN/m
      (so the whole layer has a 3.0 s post-yield period), :math:`\alpha = 0.1` (pre-yield
      stiffness 9.856 MN/m), characteristic strength :math:`Q_d = 0.05 W_i = 110.4` kN
      (yield force 122.7 kN, yield displacement 12.4 mm);
    * Park–Wen A = 1, β = 0.1, γ = 0.9 for both.

    Overall: characteristic strength 61·0.03–0.06 W_i + 31·0.05 W_i ≈ 2.8–4.8 % of the weight.
    Post-yield periods of the whole building (flexible superstructure, eigenvalues with the
    post-yield stiffness): 3.27 s (x), 3.08 s (y), 2.59 s (torsion); with the ``linear`` layer
    the same computation gives 3.38/3.18/2.67 s, the published values (both are tested).
``lead-rubber``, ``friction-pendulum``
    All 92 bearings of the one type, with the per-bearing values above.

A configuration can also be read from a JSON file (:func:`load_isolation`)::

    {"name": "my-layer", "groups": [
        {"type": "friction-pendulum", "bearings": "1-61",
         "parameters": {"weight": 2.2e6, "radius": 2.24, "mu_max": 0.06, "mu_min": 0.03,
                        "rate_parameter": 20}},
        {"type": "lead-rubber", "bearings": "62-92",
         "parameters": {"k_initial": 9.86e6, "alpha": 0.1, "yield_force": 1.2e5}}]}

(``bearings``: 1-based numbers as a list or a string like ``"1-10,15,20-30"``; parameters in SI.)
"""

from __future__ import annotations

import dataclasses
import functools
import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable, NamedTuple

import numpy as np

from benchmark.foundation.errors import DataNotFoundError, InputError, ParameterError
from benchmark.foundation.fields import check_field_names
from benchmark.simulator.isolation.base import BearingParameters
from benchmark.simulator.isolation.friction_pendulum import FrictionPendulumBearing
from benchmark.simulator.isolation.lead_rubber import LeadRubberBearing
from benchmark.simulator.isolation.linear import LinearBearing
from benchmark.simulator.isolation.registry import MAX_PARAMS, MAX_STATES, bearing_type
from benchmark.foundation.textfile import read_text

__all__ = [
    "BearingGroup", "IsolationLayer", "PackedIsolation", "get_isolation", "load_isolation",
    "isolation_from_dict", "parse_bearing_numbers", "ISOLATION_NAMES", "DEFAULT_NONLINEAR",
    "N_BEARINGS", "GRAVITY", "TOTAL_MASS", "WEIGHT_PER_BEARING", "FDZ_K", "FDZ_C",
    "check_layer_carries", "MAX_ISOLATED_PERIOD",
]

#: number of bearings of the benchmark building
N_BEARINGS = 92
#: standard gravity [m/s²]
GRAVITY = 9.80665
#: total mass of the building above the isolation interface [kg]: floors 1–8 (2580 + 2247 +
#: 2057 + 5·2051 t) + base 3565.73 t (structure.json)
TOTAL_MASS = (2580.0 + 2247.0 + 2057.0 + 5 * 2051.0 + 3565.73) * 1.0e3
#: vertical load per bearing under uniform load sharing [N]
WEIGHT_PER_BEARING = TOTAL_MASS * GRAVITY / N_BEARINGS
#: linear bearing of the published re-implementations (FDZ) [N/m], [N·s/m]
FDZ_K = 919.422e3
FDZ_C = 27.717e3

_FP_RADIUS = 2.24
_LRB_ALPHA = 0.1
_LRB_QD_RATIO = 0.05


class PackedIsolation(NamedTuple):
    """Arrays the stepping kernel takes (one row per bearing, 0-based bearing order).

    Attributes
    ----------
    type_ids : (n_bearings,) int64
    params : (n_bearings, MAX_PARAMS) float64, zero-padded; ``params[:, 0]`` = k, ``params[:, 1]`` = c
    states : (n_bearings, MAX_STATES) float64, initial internal states, zero-padded
    n_states : (n_bearings,) int64
    """

    type_ids: np.ndarray
    params: np.ndarray
    states: np.ndarray
    n_states: np.ndarray


@dataclass(frozen=True)
class BearingGroup:
    """Bearings of one type and parameter set.

    Parameters
    ----------
    bearing : BearingParameters
        Parameters of every bearing of the group (e.g. :class:`LeadRubberBearing`).
    indices : tuple of int
        0-based bearing indices (bearing number − 1).
    label : str
        Free text for reports.
    """

    bearing: BearingParameters
    indices: tuple[int, ...]
    label: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.bearing, BearingParameters):
            raise ParameterError(f"BearingGroup.bearing = {self.bearing!r}: expected a bearing "
                                 "parameter object (LinearBearing, LeadRubberBearing, ...)")
        object.__setattr__(self, "indices", tuple(int(i) for i in self.indices))
        if not self.indices:
            raise ParameterError(f"BearingGroup {self.label!r}: expected at least one bearing index")


@dataclass(frozen=True)
class IsolationLayer:
    """The isolation layer: every bearing assigned to exactly one group.

    Parameters
    ----------
    name : str
        Configuration name (stored with results).
    groups : tuple of BearingGroup
    n_bearings : int
        Number of bearings (92 for the benchmark).
    description : str
    """

    name: str
    groups: tuple[BearingGroup, ...]
    n_bearings: int = N_BEARINGS
    description: str = ""
    _owner: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "groups", tuple(self.groups))
        if not self.groups:
            raise ParameterError(f"isolation layer {self.name!r}: expected at least one bearing group")
        owner = np.full(self.n_bearings, -1, dtype=np.int64)
        for g, group in enumerate(self.groups):
            for i in group.indices:
                if not 0 <= i < self.n_bearings:
                    raise ParameterError(f"isolation layer {self.name!r}, group {g} ({group.label}): "
                                         f"bearing index {i} outside 0..{self.n_bearings - 1} "
                                         f"(bearing numbers 1..{self.n_bearings})")
                if owner[i] >= 0:
                    raise ParameterError(f"isolation layer {self.name!r}: bearing {i + 1} is in groups "
                                         f"{owner[i]} and {g}; expected each bearing in exactly one group")
                owner[i] = g
        missing = np.flatnonzero(owner < 0)
        if missing.size:
            hint = (f"; the layer is for the benchmark's {N_BEARINGS} bearings (the default): for a plan of "
                    "another size give its \"n_bearings\"" if self.n_bearings == N_BEARINGS else "")
            raise ParameterError(f"isolation layer {self.name!r}: bearings "
                                 f"{_format_numbers(missing + 1)} belong to no group; "
                                 f"expected every bearing in exactly one group{hint}")
        object.__setattr__(self, "_owner", owner)

    # -- per-bearing views -------------------------------------------------------------
    def bearing(self, index: int) -> BearingParameters:
        """Parameters of bearing ``index`` (0-based).

        Parameters
        ----------
        index : int
            0-based bearing index.
        """
        return self.groups[int(self._owner[index])].bearing

    def group_of(self) -> np.ndarray:
        """``(n_bearings,)`` group number of each bearing."""
        return self._owner.copy()

    @property
    def is_linear(self) -> bool:
        """True when every bearing is linear (no internal states)."""
        return all(g.bearing.n_states == 0 for g in self.groups)

    # The layer is frozen: what it derives is computed once per instance (every run of a building
    # packed its 92 bearings again, ~1 ms of Python against a 3-ms linear run); callers get copies.
    @functools.cached_property
    def _linear_parts(self) -> np.ndarray:
        return np.array([self.bearing(i).linear_part() for i in range(self.n_bearings)], dtype=float).reshape(-1, 2)

    def linear_stiffness(self) -> np.ndarray:
        """``(n_bearings,)`` linear stiffness k_i [N/m] (the part the building treats exactly)."""
        return self._linear_parts[:, 0].copy()

    def linear_damping(self) -> np.ndarray:
        """``(n_bearings,)`` linear damping c_i [N·s/m]."""
        return self._linear_parts[:, 1].copy()

    @functools.cached_property
    def _packed(self) -> PackedIsolation:
        return self._pack()

    def pack(self) -> PackedIsolation:
        """Arrays for the stepping kernel (see :class:`PackedIsolation`); fresh copies each call."""
        p = self._packed
        return PackedIsolation(p.type_ids.copy(), p.params.copy(), p.states.copy(), p.n_states.copy())

    def _pack(self) -> PackedIsolation:
        n = self.n_bearings
        type_ids = np.empty(n, dtype=np.int64)
        params = np.zeros((n, MAX_PARAMS))
        states = np.zeros((n, max(MAX_STATES, 1)))
        n_states = np.empty(n, dtype=np.int64)
        for group in self.groups:
            p = group.bearing.to_array()
            s = group.bearing.initial_state()
            for i in group.indices:
                type_ids[i] = group.bearing.kernel
                params[i, :p.size] = p
                states[i, :s.size] = s
                n_states[i] = group.bearing.n_states
        return PackedIsolation(type_ids, params, states, n_states)

    def with_substep_tolerance(self, tolerance: float) -> "IsolationLayer":
        """A copy with ``substep_tolerance`` replaced in every nonlinear bearing group.

        Parameters
        ----------
        tolerance : float
            The new ``substep_tolerance`` of the nonlinear bearing groups.
        """
        groups = []
        for g in self.groups:
            b = g.bearing
            if any(f.name == "substep_tolerance" for f in dataclasses.fields(b)):
                b = dataclasses.replace(b, substep_tolerance=float(tolerance))
            groups.append(dataclasses.replace(g, bearing=b))
        return dataclasses.replace(self, groups=tuple(groups))

    def describe(self) -> dict:
        """JSON-serialisable description (type, 1-based bearing numbers, SI parameters per group)."""
        return {
            "name": self.name,
            "description": self.description,
            "n_bearings": self.n_bearings,
            "groups": [{"type": g.bearing.name, "label": g.label,
                        "bearings": _format_numbers(np.asarray(g.indices) + 1),
                        "parameters": {f.name: getattr(g.bearing, f.name)
                                       for f in dataclasses.fields(g.bearing)}}
                       for g in self.groups],
        }

    def to_json(self) -> str:
        """The :meth:`describe` dict as JSON (readable back by :func:`isolation_from_dict`)."""
        return json.dumps(self.describe(), sort_keys=False)


def _format_numbers(numbers: Iterable[int]) -> str:
    """``[1, 2, 3, 7]`` -> ``"1-3,7"``."""
    nums = sorted(int(x) for x in numbers)
    parts: list[str] = []
    start = prev = None
    for x in nums + [None]:  # type: ignore[operator]
        if start is None:
            start = prev = x
        elif x is not None and x == prev + 1:
            prev = x
        else:
            parts.append(str(start) if start == prev else f"{start}-{prev}")
            start = prev = x
    return ",".join(parts)


def parse_bearing_numbers(spec: str | Iterable[int], n_bearings: int = N_BEARINGS,
                          where: str = "bearings") -> tuple[int, ...]:
    """Parse 1-based bearing numbers into 0-based indices.

    Parameters
    ----------
    spec : str or iterable of int
        ``"1-61"``, ``"1-10,15,20-30"`` or a list of numbers (1-based).
    n_bearings : int
        Largest admissible number.
    where : str
        Location named in error messages (file and field).

    Raises
    ------
    InputError
        Malformed ranges or numbers outside ``1..n_bearings``.
    """
    out: list[int] = []
    if isinstance(spec, str):
        for part in spec.replace(" ", "").split(","):
            if not part:
                continue
            try:
                if "-" in part:
                    a, b = part.split("-", 1)
                    lo, hi = int(a), int(b)
                    if hi < lo:
                        raise ValueError
                    out.extend(range(lo, hi + 1))
                else:
                    out.append(int(part))
            except ValueError:
                raise InputError(f"{where}: {part!r} is not a bearing number or range like '1-61'") from None
    else:
        try:
            out = [int(x) for x in spec]
        except (TypeError, ValueError):
            raise InputError(f"{where}: expected a list of bearing numbers or a string like '1-61'") from None
    for x in out:
        if not 1 <= x <= n_bearings:
            raise InputError(f"{where}: bearing number {x} outside 1..{n_bearings}")
    return tuple(x - 1 for x in out)


def isolation_from_dict(data: dict, where: str = "isolation") -> IsolationLayer:
    """Build an :class:`IsolationLayer` from a dict.

    Parameters
    ----------
    data : dict
        ``{"name", "description", "n_bearings", "groups": [{"type", "bearings", "parameters",
        "label"}]}`` (the JSON format of the module docstring; parameters in SI).
    where : str
        Location named in error messages (e.g. the file path).

    Raises
    ------
    InputError, ParameterError
        Missing or unknown fields, bad bearing numbers, inadmissible parameters, bearings in no
        group or in two.
    """
    if not isinstance(data, dict) or "groups" not in data:
        raise InputError(f"{where}: expected an object with a 'groups' list")
    check_field_names(data, ("name", "description", "n_bearings", "groups"), where)
    n = data.get("n_bearings", N_BEARINGS)
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise InputError(f"{where}: field 'n_bearings' = {n!r}; expected a positive integer")
    if not isinstance(data["groups"], list):
        raise InputError(f"{where}: field 'groups' = {data['groups']!r}; expected a list of groups")
    groups = []
    for j, g in enumerate(data["groups"]):
        loc = f"{where}: groups[{j}]"
        if not isinstance(g, dict) or "type" not in g or "bearings" not in g:
            raise InputError(f"{loc}: expected an object with 'type', 'bearings' and 'parameters'")
        # a group holds nothing free-form: "paramters" would leave every parameter at its default
        check_field_names(g, ("type", "bearings", "parameters", "label"), loc, strict=True)
        cls = bearing_type(g["type"])
        params = g.get("parameters", {})
        if not isinstance(params, dict):
            raise InputError(f"{loc}.parameters = {params!r}; expected an object of named values")
        for key, value in params.items():
            # every bearing parameter is a number: "2.2e6" or true would pass float() and then
            # be used as a string, or as 1
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise InputError(f"{loc}.parameters.{key} = {value!r}; expected a number (SI)")
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = set(params) - names
        if unknown:
            raise InputError(f"{loc}.parameters: unknown field(s) {sorted(unknown)}; "
                             f"{cls.__name__} takes {sorted(names)}")
        try:
            bearing = cls(**params)
        except TypeError as exc:
            raise InputError(f"{loc}.parameters: {exc}") from None
        except ParameterError as exc:
            raise ParameterError(f"{loc}: {exc}") from None
        groups.append(BearingGroup(bearing, parse_bearing_numbers(g["bearings"], n, f"{loc}.bearings"),
                                   label=str(g.get("label", ""))))
    try:
        return IsolationLayer(str(data.get("name", "custom")), tuple(groups), n_bearings=n,
                              description=str(data.get("description", "")))
    except ParameterError as exc:  # name the file, not only the layer
        raise ParameterError(f"{where}: {exc}") from None


def load_isolation(path: str | os.PathLike) -> IsolationLayer:
    """Read an isolation layer from the JSON file ``path`` (format in the module docstring).

    Parameters
    ----------
    path : str | os.PathLike
        JSON file.

    Raises
    ------
    DataNotFoundError
        If the file does not exist.
    InputError
        Invalid JSON (with the line number) or content (see :func:`isolation_from_dict`).
    """
    path = Path(path)
    if not path.is_file():
        raise DataNotFoundError(f"isolation configuration file {path} not found")
    try:
        data = json.loads(read_text(path, "isolation configuration file"))
    except json.JSONDecodeError as exc:
        raise InputError(f"{path}:{exc.lineno}: invalid JSON ({exc.msg})") from None
    return isolation_from_dict(data, where=str(path))


# -- named configurations -------------------------------------------------------------------
# Each is a function of the building it carries: the vertical load per bearing [N] (the weight
# above the isolation interface shared uniformly, computed once by get_isolation) and the number
# of bearings of its plan. The benchmark's values (WEIGHT_PER_BEARING, N_BEARINGS) are the
# defaults; a variant of the structure file (other floor masses, another bearing plan) gets
# bearings loaded by its own weight (:meth:`benchmark.simulator.building.Building.default`
# passes them).

#: friction pendulums of ``friction-lrb`` on the benchmark's 92 bearings (the same share on another plan)
_SLIDING_OF_92 = 61


def _friction_pendulum_default(weight: float = WEIGHT_PER_BEARING) -> FrictionPendulumBearing:
    return FrictionPendulumBearing(weight=weight, radius=_FP_RADIUS, mu_max=0.06,
                                   mu_min=0.03, rate_parameter=20.0, yield_displacement=5.0e-4)


def _lead_rubber_default(weight: float = WEIGHT_PER_BEARING) -> LeadRubberBearing:
    kd = weight / _FP_RADIUS
    qd = _LRB_QD_RATIO * weight
    return LeadRubberBearing(k_initial=kd / _LRB_ALPHA, alpha=_LRB_ALPHA,
                             yield_force=qd / (1.0 - _LRB_ALPHA))


def _linear(weight: float, n: int, kc: tuple[float, float] | None = None) -> IsolationLayer:
    # the FDZ values per bearing, whatever the building's weight (they are published as such),
    # unless the structure file gives its own (``fdz_linear_bearing``)
    k, c = (FDZ_K, FDZ_C) if kc is None else kc
    source = ("FDZ re-implementation values" if kc is None or (k, c) == (FDZ_K, FDZ_C)
              else "the structure file's fdz_linear_bearing")
    return IsolationLayer("linear", (BearingGroup(LinearBearing(k, c), tuple(range(n)),
                                                  f"linear elastomeric 1-{n}"),), n_bearings=n,
                          description=f"{n} linear elastomeric bearings, k = {k / 1e3:.7g} kN/m, "
                                      f"c = {c / 1e3:.7g} kN·s/m ({source})")


def _friction_lrb(weight: float, n: int) -> IsolationLayer:
    m = min(n - 1, max(1, round(n * _SLIDING_OF_92 / N_BEARINGS)))  # at least one of each type
    return IsolationLayer("friction-lrb", (
        BearingGroup(_friction_pendulum_default(weight), tuple(range(m)), f"friction pendulum 1-{m}"),
        BearingGroup(_lead_rubber_default(weight), tuple(range(m, n)), f"lead-rubber {m + 1}-{n}")),
        n_bearings=n,
        description=f"bearings 1-{m} friction pendulum (R = 2.24 m, mu 0.03-0.06), {m + 1}-{n} lead-rubber "
                    f"(alpha 0.1, Qd = 5 % of the load); post-yield period 3.0 s; load per bearing "
                    f"{weight / 1e6:.4g} MN")


def _all_lead_rubber(weight: float, n: int) -> IsolationLayer:
    return IsolationLayer("lead-rubber", (BearingGroup(_lead_rubber_default(weight), tuple(range(n)),
                                                       f"lead-rubber 1-{n}"),), n_bearings=n,
                          description=f"{n} lead-rubber bearings (alpha 0.1, Qd = 5 % of the load); "
                                      f"post-yield period 3.0 s; load per bearing {weight / 1e6:.4g} MN")


def _all_friction_pendulum(weight: float, n: int) -> IsolationLayer:
    return IsolationLayer("friction-pendulum", (BearingGroup(_friction_pendulum_default(weight),
                                                             tuple(range(n)),
                                                             f"friction pendulum 1-{n}"),), n_bearings=n,
                          description=f"{n} friction pendulum bearings (R = 2.24 m, mu 0.03-0.06); "
                                      f"pendulum period 3.0 s; load per bearing {weight / 1e6:.4g} MN")


_NAMED = {
    "linear": _linear,
    "friction-lrb": _friction_lrb,
    "lead-rubber": _all_lead_rubber,
    "friction-pendulum": _all_friction_pendulum,
}

#: names accepted by :func:`get_isolation`
ISOLATION_NAMES: tuple[str, ...] = tuple(_NAMED)
#: the default nonlinear configuration
DEFAULT_NONLINEAR = "friction-lrb"


#: Longest isolated period a layer may give the building [s]: isolated buildings sit at 2-5 s; a
#: stiffness in kN/m read as N/m (98 s on the benchmark) or a pendulum's weight in kN read as N
#: leaves a building that the bearings do not hold.
MAX_ISOLATED_PERIOD = 20.0


def check_layer_carries(layer: IsolationLayer, total_mass: float) -> None:
    """Refuse a layer whose bearings cannot carry a building of ``total_mass`` [kg]: a unit slip
    in an isolation file otherwise runs silently (a probe's linear bearings in kN/m gave a 98-s
    isolated period, the base moving with the ground; its pendulums' weights in kN, the same).

    Two checks, each far outside any real isolation system: the isolated period from the
    bearings' post-yield (or linear) lateral stiffness, :math:`2\\pi\\sqrt{M/\\sum k}`, at most
    :data:`MAX_ISOLATED_PERIOD`; and the friction pendulums' vertical loads, which together
    cannot exceed 1.5 times the building's weight.

    Parameters
    ----------
    layer : IsolationLayer
        The bearings.
    total_mass : float
        Mass above the isolation interface [kg].

    Raises
    ------
    InputError
        Naming the layer, the figure and the likely slip.
    """
    stiffness, pendulum_load = 0.0, 0.0
    for group in layer.groups:
        b, n = group.bearing, len(group.indices)
        # every registered bearing's linear part: k, W/R of a pendulum, the post-yield stiffness
        # of a lead-rubber bearing
        stiffness += n * b.linear_part()[0]
        if isinstance(b, FrictionPendulumBearing):
            pendulum_load += n * b.weight
    weight = total_mass * GRAVITY
    if pendulum_load > 1.5 * weight:
        raise InputError(f"isolation layer {layer.name!r}: its friction pendulums carry {pendulum_load / 1e6:.4g} MN "
                         f"together, the building weighs {weight / 1e6:.4g} MN (weights in N expected)")
    period = 2.0 * math.pi * math.sqrt(total_mass / stiffness) if stiffness > 0 else math.inf
    if period > MAX_ISOLATED_PERIOD:
        raise InputError(f"isolation layer {layer.name!r}: its bearings' lateral stiffness gives the building an "
                         f"isolated period of {period:.3g} s (at most {MAX_ISOLATED_PERIOD:g} s holds a building: "
                         "stiffness in N/m, weights in N, forces in N expected; kN given?)")


def check_substep_tolerance(substep_tolerance: Any) -> float:
    """``substep_tolerance`` as a float, checked in one place for :func:`get_isolation` and
    :func:`benchmark.simulator.simulation.simulate`.

    Parameters
    ----------
    substep_tolerance : float
        Relative sub-step tolerance of the hysteretic bearings and devices [-].

    Raises
    ------
    ParameterError
        A tolerance that is not a finite number in (0, 2].
    """
    if isinstance(substep_tolerance, bool) or not (isinstance(substep_tolerance, (int, float))
                                                   and math.isfinite(substep_tolerance)
                                                   and 0 < substep_tolerance <= 2):
        raise ParameterError(f"substep_tolerance = {substep_tolerance!r}: expected in (0, 2]")
    return float(substep_tolerance)


def get_isolation(name: str, substep_tolerance: float | None = None, *, total_mass: float | None = None,
                  n_bearings: int | None = None, linear_bearing: tuple[float, float] | None = None) -> IsolationLayer:
    """Return a named isolation layer, or one read from a ``.json`` file path.

    Parameters
    ----------
    name : str
        One of :data:`ISOLATION_NAMES` or the path of a JSON configuration file.
    substep_tolerance : float, optional
        Replace the sub-step tolerance of every nonlinear bearing.
    total_mass : float, optional
        Mass above the isolation interface [kg] whose weight the named configurations' bearings
        share (default :data:`TOTAL_MASS`, the benchmark's); a file's parameters are kept.
    n_bearings : int, optional
        Bearings of the plan for a named configuration (default :data:`N_BEARINGS`).
    linear_bearing : tuple of float, optional
        ``(k [N/m], c [N·s/m])`` of the ``linear`` configuration's bearings (a structure file's
        ``fdz_linear_bearing``, :attr:`benchmark.simulator.structure.Superstructure.linear_bearing`);
        default :data:`FDZ_K`, :data:`FDZ_C`.

    Raises
    ------
    InputError
        Unknown name (the message lists the known ones), or a mass or bearing count that is not
        positive.
    """
    if name in _NAMED:
        mass = TOTAL_MASS if total_mass is None else float(total_mass)
        n = N_BEARINGS if n_bearings is None else int(n_bearings)
        if not (math.isfinite(mass) and mass > 0.0):
            raise InputError(f"isolation {name!r}: total_mass must be a positive mass in kg, got {total_mass!r}")
        if n < 2 if name == "friction-lrb" else n < 1:
            raise InputError(f"isolation {name!r}: n_bearings {n} is too few for this configuration")
        layer = (_linear(mass * GRAVITY / n, n, linear_bearing) if name == "linear"
                 else _NAMED[name](mass * GRAVITY / n, n))
    elif str(name).lower().endswith(".json"):
        layer = load_isolation(name)
    else:
        raise InputError(f"isolation {name!r} unknown: expected one of {', '.join(ISOLATION_NAMES)} "
                         "or a .json configuration file")
    if substep_tolerance is not None:
        layer = layer.with_substep_tolerance(check_substep_tolerance(substep_tolerance))
    return layer
