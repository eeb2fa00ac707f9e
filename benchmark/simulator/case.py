"""One way to run a case: a record on a building with a controller, and its uncontrolled reference.

A :class:`Case` names everything a run needs: the record (a benchmark name, a file, or a
:class:`records.Record`) and its orientation, the building (given, or the default one with an
isolation layer, a number of modes and a damper model), the controller and the options of
:func:`benchmark.simulator.simulation.simulate`. :func:`run_case` resolves the record through the
one resolver (:func:`records.resolve.resolve_record`), picks the control step, runs the
controlled building and, once per building and record, the same building without devices (the
reference of J1-J9, Narasimhan et al. 2006), and evaluates both. ``sbib run``, ``sbib compare``,
ensembles, the identification study's runs in the building and the main job all go through it.

The reference runs are kept in a small cache (:class:`ReferenceCache`): a comparison of five
controllers on one record runs the uncontrolled building once.
"""

from __future__ import annotations

import hashlib
import math
from collections import OrderedDict
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from benchmark.foundation.cache import register_cache
from benchmark.foundation.errors import InputError, NumericalError
from benchmark.simulator.building import Building
from benchmark.simulator.evaluation import evaluate
from benchmark.simulator.peaks import Peaks, peaks_of
from benchmark.simulator.isolation.configurations import DEFAULT_NONLINEAR
from benchmark.simulator.simulation import SimulationResult, check_control_step, simulate
from controllers.registry import get_controller
from damper.models.base import DamperModel
from records.record import Record
from records.resolve import is_warning, resolve_record

__all__ = ["Case", "CaseResult", "ReferenceCache", "REFERENCES", "run_case",
           "DEFAULT_CONTROL_STEP", "resolve_case_record", "with_record_note"]

#: The benchmark's control sample time [s] (Narasimhan et al. 2006), used when it fits the record.
DEFAULT_CONTROL_STEP = 0.005


@dataclass(frozen=True)
class Case:
    """Everything one run needs (SI units).

    Parameters
    ----------
    record : str or records.Record
        A benchmark record name, a record file, or a record already loaded (then ``orientation``
        and ``record_options`` are not used).
    orientation : str
        ``FN-x``, ``FP-x`` or the seed paper's ``FP-y`` (= FN-x), ``FN-y`` (= FP-x).
    controller : str, controller object or None
        A name of :mod:`controllers.registry` (``"none"``: no devices), or an object with
        ``step(measurements) -> voltages``.
    building : Building, optional
        The building; default :meth:`Building.default` with ``isolation``, ``n_modes`` and
        ``damper_model``.
    isolation : str, optional
        Named isolation layer or JSON file (default: ``friction-lrb``).
    n_modes : int, optional
        Reduced superstructure (default all 24 modes).
    damper_model : DamperModel or str, optional
        Model of every device of the default layout (default: the virtual benchmark damper).
    control_step : float, optional
        Control sample time [s]; ``None``: the benchmark's 0.005 s (:data:`DEFAULT_CONTROL_STEP`).
        Checked when the case is made (:func:`benchmark.simulator.simulation.check_control_step`);
        any record step fits it (the simulator integrates on a step that divides it).
    record_options : dict
        Keyword arguments of :func:`records.resolve.resolve_record` (``records_dir``,
        ``baseline_correct``, ``format``, ``dt``, ``units``, ``synthetic``, ``seed``).
    options : dict
        Keyword arguments of :func:`benchmark.simulator.simulation.simulate` for both runs
        (``substep_tolerance``, ``integration_step``, ``max_halvings``, ``noise``, ``seed``,
        ``record_states``, ...).
    label : str
        Free text carried into the results' ``info``.
    """

    record: str | Record
    orientation: str = "FN-x"
    controller: Any = "none"
    building: Building | None = None
    isolation: str | None = None
    n_modes: int | None = None
    damper_model: DamperModel | str | None = None
    control_step: float | None = None
    record_options: dict = field(default_factory=dict)
    options: dict = field(default_factory=dict)
    label: str = ""

    def __post_init__(self) -> None:
        # the one check of the control step on the way into run_case (names --control-step)
        if self.control_step is not None:
            object.__setattr__(self, "control_step", check_control_step(self.control_step))


@dataclass
class CaseResult:
    """A run, its reference and their evaluation.

    Attributes
    ----------
    case : Case
    record : records.Record
        The record as run (oriented, corrected, scaled).
    building : Building
        The building with devices (without devices when the case has no controller).
    result, reference : SimulationResult
        The controlled run and the same building without devices (the same object when the case
        has no controller).
    control_step : float
        The control step used [s].
    notes : list of str
        Lines for the user: implausible-record flags and the runs' own notes
        (``result.info["notes"]``: the record interpolated onto the integration step, a step
        halved after a fixed point that did not converge, ``"warning: ..."`` when the controller
        cannot act on the devices).
    J : dict
        J1-J9 of :func:`benchmark.simulator.evaluation.evaluate` (``None`` where undefined).
    peaks : Peaks or None
        Peak responses of ``result`` (:func:`benchmark.simulator.peaks.peaks_of`, SI); files and
        JSON write them under their ``peak_*`` names with :meth:`Peaks.as_record`.
    """

    case: Case
    record: Record
    building: Building
    result: SimulationResult
    reference: SimulationResult
    control_step: float
    notes: list[str] = field(default_factory=list)
    J: dict = field(default_factory=dict)
    peaks: Peaks | None = None


def _record_key(record: Record) -> tuple:
    acc = np.ascontiguousarray(record.acceleration)
    return (record.name, float(record.dt), acc.shape, hashlib.sha1(acc.tobytes()).hexdigest())


def _reference_options(options: dict) -> dict:
    """The options of the uncontrolled run: no sensors, so no noise and no noise seed."""
    return {k: v for k, v in options.items() if k not in ("noise", "seed", "slew_rate")}


def _options_key(options: dict) -> tuple:
    out = []
    for k in sorted(options):
        v = options[k]
        if isinstance(v, np.ndarray):
            v = ("array", v.shape, hashlib.sha1(np.ascontiguousarray(v).tobytes()).hexdigest())
        elif not isinstance(v, (int, float, str, bool, type(None), tuple)):
            v = ("object", id(v))
        out.append((k, v))
    return tuple(out)


class ReferenceCache:
    """The last few uncontrolled runs, by building, record, control step and options.

    A building is keyed by identity and kept alive by the cache while its entry lives, so a
    caller that reuses one building (a comparison, an ensemble, a study) runs each reference once.

    Parameters
    ----------
    size : int
        Most runs kept (the least recently used goes first).
    name : str
        Its name in :func:`benchmark.foundation.cache.caches`.
    """

    def __init__(self, size: int = 8, name: str = "simulator.references") -> None:
        self.name = str(name)
        self.size = int(size)
        self._entries: OrderedDict[tuple, tuple[Building, SimulationResult]] = OrderedDict()

    def get(self, building: Building, record: Record, control_step: float, options: dict) -> SimulationResult:
        """The run of ``building`` without devices under ``record`` (computed on a miss).

        Buildings that differ only in their devices share the entry (the reference has none),
        and so do options that only concern sensors (``noise``, ``seed``).

        Parameters
        ----------
        building : Building
            The building (its devices are ignored).
        record : Record
            The ground motion.
        control_step : float
            Control step [s].
        options : dict
            Further simulation options that change the run.
        """
        options = _reference_options(options)
        key = (id(building.superstructure), id(building.isolation), _record_key(record), float(control_step),
               _options_key(options))
        hit = self._entries.get(key)
        if hit is not None and hit[0].superstructure is building.superstructure \
                and hit[0].isolation is building.isolation:
            self._entries.move_to_end(key)
            return hit[1]
        info = {"record": record.name, "orientation": record.metadata.get("orientation", ""),
                "isolation": building.isolation.name}
        reference = simulate(building.without_devices(), record, controller=None, control_step=control_step,
                             info=info, **options)
        self._entries[key] = (building, reference)
        while len(self._entries) > self.size:
            self._entries.popitem(last=False)
        return reference

    def clear(self) -> None:
        """Forget every entry."""
        self._entries.clear()

    def __len__(self) -> int:
        return len(self._entries)


#: The process-wide cache :func:`run_case` uses by default (``cache=`` gives another; listed by
#: :func:`benchmark.foundation.cache.caches`, emptied by ``REFERENCES.clear()`` or ``clear_caches()``).
REFERENCES = register_cache(ReferenceCache())


def resolve_case_record(case: Case) -> Record:
    """The case's record: given, or through :func:`records.resolve.resolve_record` (the one
    resolver of a benchmark name or a file with an orientation).

    Parameters
    ----------
    case : Case
        The case.
    """
    if isinstance(case.record, Record):
        return case.record
    if not isinstance(case.record, str) or not case.record:
        raise InputError(f"case record: expected a benchmark record name, a file or a Record, got {case.record!r}")
    return resolve_record(case.record, case.orientation, **case.record_options)


def _case_building(case: Case, with_devices: bool) -> Building:
    if case.building is not None:
        return case.building if with_devices else case.building.without_devices()
    # substep_tolerance (an option) is applied once, by simulate; a named layer is built by
    # Building.default for the structure it loads (its weight on its bearing plan)
    return Building.default(isolation=case.isolation or DEFAULT_NONLINEAR, devices="default" if with_devices else None, n_modes=case.n_modes,
                            damper_model=case.damper_model)


def with_record_note(exc: NumericalError, implausible: list[str]) -> NumericalError | InputError:
    """``exc`` itself, or, when the record was flagged implausible, an :class:`InputError` that
    leads with the flag and ends with ``exc`` (one line): a run that blows up on a record read in
    the wrong units is a problem of its input (exit status 2), not of the numerics.

    Parameters
    ----------
    exc : NumericalError
        The error of the run.
    implausible : list[str]
        The record's implausibility flags (:func:`records.plausibility.check_plausibility`).
    """
    if not implausible:
        return exc
    extra = f" ({len(implausible) - 1} more)" if len(implausible) > 1 else ""
    return InputError(f"the record is implausible: {implausible[0]}{extra}; the run then failed: {exc}")


def run_case(case: Case, reference: bool = True, cache: ReferenceCache | None = REFERENCES) -> CaseResult:
    """Run ``case`` and (``reference=True``) its uncontrolled reference, and evaluate them.

    Parameters
    ----------
    case : Case
    reference : bool
        Also run the building without devices and compute J1-J9 (cached in ``cache``).
    cache : ReferenceCache or None
        Where the references are kept (``None``: not kept).

    Returns
    -------
    CaseResult

    Raises
    ------
    InputError
        An unknown record, controller or option, or a control step that does not fit the record.
    NumericalError
        A run failed (its time and state are in the error).
    """
    record = resolve_case_record(case)
    controller = get_controller(case.controller) if isinstance(case.controller, str) else case.controller
    notes = [f for f in record.metadata.get("flaws", []) if is_warning(str(f))]
    # without a controller the control step sets only the time grid, which the reference of a
    # controlled run shares
    control_step = DEFAULT_CONTROL_STEP if case.control_step is None else case.control_step
    building = _case_building(case, with_devices=controller is not None)
    options = dict(case.options)
    info = {"record": record.name, "orientation": record.metadata.get("orientation", case.orientation),
            "isolation": building.isolation.name, **({"label": case.label} if case.label else {})}
    try:
        ref, result = _runs(case, record, building, controller, control_step, options, info, reference, cache)
    except NumericalError as exc:
        raise with_record_note(exc, [n for n in notes if "implausible" in n]) from None
    for run in (ref, result):  # each line once (the reference's notes repeat the run's)
        for note in (run.info.get("notes", []) if run is not None else []):
            if note not in notes:
                notes.append(note)
    out = CaseResult(case=case, record=record, building=building, result=result,
                     reference=ref if ref is not None else result, control_step=float(control_step), notes=notes)
    out.peaks = peaks_of(result)
    if ref is not None:
        out.J = evaluate(result, ref)
    return out


def _runs(case, record, building, controller, control_step, options, info, reference, cache):
    def run_reference(opts):
        if cache is None:
            return simulate(building.without_devices(), record, controller=None, control_step=control_step,
                            info=info, **_reference_options(opts))
        return cache.get(building, record, control_step, opts)

    def run_controlled(opts):
        return simulate(building, record, controller=controller, control_step=control_step, info=info, **opts)

    ref: SimulationResult | None = None
    if reference or controller is None:
        ref = run_reference(options)
    if controller is None:
        assert ref is not None
        return ref, ref
    result = run_controlled(options)
    # J1-J9 compare the two runs sample by sample: when one of them had to halve its step
    # (simulate's retry), the other runs again on the finer grid
    for _ in range(4):
        if ref is None:
            break
        h_ref, h_run = ref.info["integration_step"], result.info["integration_step"]
        if math.isclose(h_ref, h_run, rel_tol=1e-9):
            break
        finer = dict(options, integration_step=min(h_ref, h_run))
        if h_ref > h_run:
            ref = run_reference(finer)
        else:
            result = run_controlled(finer)
    return ref, result
