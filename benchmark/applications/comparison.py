"""The controller comparison: every record × orientation × controller, on all cores.

For each record and orientation the uncontrolled building (no devices) is the reference; each
controller's run is evaluated against it (:func:`benchmark.simulator.evaluation.evaluate`, J1–J9) and its
peaks kept (:meth:`benchmark.simulator.peaks.Peaks.as_record`, the ``peak_*`` file names). Runs are independent and go to a process pool
(one task per run; the tasks of one record go to the same worker so that its reference run is
computed once); :func:`benchmark.foundation.progress.progress_bar` shows progress. The result prints as
a table (J's per run, mean and max over records per controller, the key of the J's), converts
to JSON, writes one HDF5 file (atomically) and draws PNG figures (J's per controller and record;
base-displacement, device-force and voltage histories).
"""

from __future__ import annotations

import copy
import sys
import os
import time
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from benchmark.foundation.cache import register_cache
from benchmark.foundation.errors import InputError, NumericalError, UserCodeError
from benchmark.simulator.building import Building
from controllers.registry import controller_names
from records import BENCHMARK_RECORDS, ORIENTATIONS
from benchmark.foundation.atomic import atomic_path
from benchmark.foundation.provenance import file_identity, provenance
from benchmark.foundation.errors import DataNotFoundError
from benchmark.foundation.paths import structure_file
from benchmark.applications.run_inputs import controller_identity, damper_identities, record_identity
from benchmark.applications import comparison_plots
from controllers.registry import get_controller
from records.resolve import is_warning, resolve_record
from records.resolve import looks_like_file
from records.catalogue import ORIENTATION_ALIASES
from benchmark.simulator.simulation import check_control_step
from benchmark.simulator.case import DEFAULT_CONTROL_STEP, Case, ReferenceCache, run_case
from benchmark.simulator.criteria import J_NAMES, key_json, key_lines  # the single definition table of the J's
from benchmark.simulator.evaluation import PEAK_UNITS
from benchmark.foundation.progress import progress_bar
from benchmark.applications import model_comparison
import dataclasses

from benchmark.applications.damper_choice import (command_unit, device_motion, motion_notes, parse_scale,
                                                  resolve_damper, resolve_layout)
from controllers.user import is_user_controller_spec
from benchmark.foundation.pools import WorkerPool
from benchmark.applications.identification_validation import measured_from_runs

__all__ = ["ComparisonRun", "ComparisonResult", "compare", "parse_list", "J_NAMES"]

_HISTORY_STEP = 0.02  # [s] sampling of the stored histories


@dataclass
class ComparisonRun:
    """One controlled run: J's, peaks, down-sampled histories (SI), wall time.

    Parameters
    ----------
    record : str
        Record name.
    orientation : str
        ``FN-x`` or ``FP-x``.
    controller : str
        Controller name.
    J : dict
        Evaluation criteria J1–J9 by key (ratios to the uncontrolled run).
    peaks : dict
        Peak responses by name (SI).
    histories : dict, optional
        Down-sampled histories by name (SI), for the plots.
    elapsed_s : float, optional
        Wall time of the run [s].
    synthetic : bool, optional
        Whether the record was a synthetic stand-in (record files absent).
    damper : str, optional
        The damper model's file name (or registered name) when dampers are compared; empty
        otherwise.
    """

    record: str
    orientation: str
    controller: str
    J: dict
    peaks: dict
    histories: dict = field(default_factory=dict, repr=False)
    elapsed_s: float = 0.0
    synthetic: bool = False
    damper: str = ""  # the damper model's file name (or registered name) when dampers are compared

    @property
    def key(self) -> tuple:
        """``(record, orientation, controller)``: the runs a model comparison sets side by side."""
        return (self.record, self.orientation, self.controller)

    @property
    def label(self) -> str:
        """The record as tables show it: ``"kobe (synthetic)"`` for a generated motion."""
        return f"{self.record} (synthetic)" if self.synthetic else self.record

    def to_json(self) -> dict:
        """JSON-ready summary: record, label, synthetic, orientation, controller, J's, peaks (SI)
        and the damper when set (histories left out)."""
        out = {"record": self.record, "label": self.label, "synthetic": self.synthetic,
               "orientation": self.orientation, "controller": self.controller, "J": self.J, "peaks": self.peaks}
        if self.damper:
            out["damper"] = self.damper
        return out


@dataclass
class ComparisonResult:
    """All runs of a comparison, the references' peaks and the settings.

    Parameters
    ----------
    runs : list
        The :class:`ComparisonRun` of every record × orientation × controller.
    references : dict
        Peaks of the uncontrolled run, by ``(record, orientation)`` key.
    reference_histories : dict, optional
        Down-sampled histories of the uncontrolled runs, for the plots.
    settings : dict, optional
        The comparison's settings (records, controllers, isolation, control step, seed, …).
    measured : dict, optional
        Full-rate runs of the controllers named in ``compare(measure=...)``, by ``(record,
        orientation, controller)``: each a
        :class:`~benchmark.applications.identification_validation.MeasuredRun` (device histories
        at the record step and the reference's responses). Kept in memory only.
    """

    runs: list
    references: dict          # (record, orientation) -> peaks of the uncontrolled run
    reference_histories: dict = field(default_factory=dict, repr=False)
    settings: dict = field(default_factory=dict)
    measured: dict = field(default_factory=dict, repr=False)

    @property
    def controllers(self) -> list[str]:
        return list(dict.fromkeys(r.controller for r in self.runs))

    @property
    def dampers(self) -> list[str]:
        """The damper models compared (empty: one damper, not named per run)."""
        return list(dict.fromkeys(r.damper for r in self.runs if r.damper))

    def model_differences(self) -> list[dict]:
        """Per record, orientation and controller: each model's J's and their differences from the
        first model's (``J[model] - J[first]``), and the peak and RMS of the force difference of the
        most loaded device between the two runs [N] (:func:`model_comparison.force_difference`)."""
        return model_comparison.differences(self)

    @property
    def cases(self) -> list[tuple[str, str]]:
        return list(dict.fromkeys((r.record, r.orientation) for r in self.runs))

    def summary(self) -> dict:
        """Mean and max of every J over records and orientations, per controller."""
        out = {}
        for name in self._summary_keys():
            runs = [r for r in self.runs if self._summary_key(r) == name]
            entry = {}
            for j in J_NAMES:
                values = [r.J.get(j) for r in runs if r.J.get(j) is not None]
                entry[j] = {"mean": float(np.mean(values)) if values else None,
                            "max": float(np.max(values)) if values else None}
            out[name] = entry
        return out

    def _summary_key(self, run) -> str:
        return f"{run.controller} [{run.damper}]" if len(self.dampers) > 1 else run.controller

    def _summary_keys(self) -> list[str]:
        return list(dict.fromkeys(self._summary_key(r) for r in self.runs))

    def to_json(self) -> dict:
        """``{"runs": [...], "summary": {...}, "settings": {...}, "criteria": {J1: {...}, ...},
        "peak_units": {peak: unit}}``
        (``criteria``: the key of :func:`benchmark.simulator.criteria.key_json`); with several
        dampers each run names its model under ``damper`` and ``model_differences`` is added."""
        out = {"runs": [r.to_json() for r in self.runs], "summary": self.summary(),
               "settings": self.settings, "criteria": key_json(),
               "peak_units": {k: PEAK_UNITS[k] for r in self.runs[:1] for k in r.peaks if k in PEAK_UNITS}}
        if len(self.dampers) > 1:
            out["model_differences"] = self.model_differences()
        return out

    def table(self) -> str:
        """Fixed-width text table: J1–J9 per run, mean and max per controller, then the key."""

        def fmt(v):
            return "   -  " if v is None else f"{v:6.3f}"
        width = max([10] + [len(r.label) for r in self.runs])  # "kobe (synthetic)", file names
        cw = max([16] + [len(self._summary_key(r)) for r in self.runs])
        head = f"{'record':<{width}} {'orient':<6} {'controller':<{cw}}" + "".join(f"{j:>7}" for j in J_NAMES)
        lines = [head, "-" * len(head)]
        for r in self.runs:
            lines.append(f"{r.label:<{width}} {r.orientation:<6} {self._summary_key(r):<{cw}}"
                         + "".join(" " + fmt(r.J.get(j)) for j in J_NAMES))
        lines.append("-" * len(head))
        for name, entry in self.summary().items():
            for stat in ("mean", "max"):
                lines.append(f"{stat:<{width}} {'all':<6} {name:<{cw}}" + "".join(" " + fmt(entry[j][stat]) for j in J_NAMES))
        lines.append("-" * len(head))
        if len(self.dampers) > 1:
            lines.extend(model_comparison.table_lines(self))
            lines.append("-" * len(head))
        lines.extend(key_lines())
        return "\n".join(lines)

    def write_hdf5(self, path: str | os.PathLike) -> Path:
        """Write every run (J's and peaks as attributes, histories as datasets) atomically.

        Parameters
        ----------
        path : str | os.PathLike
            HDF5 file to write (replaced atomically).
        """
        import h5py
        import json


        path = Path(path)
        with atomic_path(path) as tmp:
            with h5py.File(tmp, "w") as h5:
                damper = self.settings.get("damper")  # model files, scale and its basis, input mapping
                extra = {"damper": json.dumps(damper, default=str)} if damper else {}
                for key, value in provenance(kind="controller comparison", **extra).items():
                    h5.attrs[key] = value
                h5.attrs["settings"] = json.dumps(self.settings, default=str)
                if "inputs" in self.settings:  # as sbib run writes them: each file by path and SHA-256
                    h5.attrs["inputs"] = json.dumps(self.settings["inputs"])
                h5.attrs["summary"] = json.dumps(self.summary())
                h5.attrs["units"] = ("SI: m, N, s; device commands in each damper model's input unit "
                                     "(V, or A for a model identified on the coil current); J's dimensionless")
                h5.attrs["criteria"] = json.dumps(key_json())
                for (rec, ori), p in self.references.items():
                    g = h5.require_group(f"reference/{rec}/{ori}")
                    for k, v in p.items():
                        g.attrs[k] = v
                    for k, v in self.reference_histories.get((rec, ori), {}).items():
                        g.create_dataset(k, data=v, compression="gzip").attrs["units"] = HISTORY_UNITS.get(k, "")
                for r in self.runs:
                    name = r.controller.replace("/", "|") + (f"/{r.damper.replace('/', '|')}" if r.damper else "")
                    g = h5.require_group(f"runs/{r.record}/{r.orientation}/{name}")
                    for k, v in r.J.items():
                        g.attrs[k] = np.nan if v is None else v
                    for k, v in r.peaks.items():
                        g.attrs[k] = v
                    g.attrs["elapsed_s"] = r.elapsed_s
                    g.attrs["synthetic_record"] = r.synthetic
                    unit = command_unit(damper, r.damper or None)  # one model: r.damper is ""
                    for k, v in r.histories.items():
                        d = g.create_dataset(k, data=v, compression="gzip")
                        d.attrs["units"] = unit if k in ("voltage", "voltage_full") else HISTORY_UNITS.get(k, "")
        return path

    def plot(self, directory: str | os.PathLike, part: tuple[int, int] = (0, 1)) -> list[Path]:
        """Draw the figures into ``directory`` (PNG) and return their paths.

        ``part = (i, n)``: only the i-th of n shares (:func:`comparison_plots.plot_all`).

        Parameters
        ----------
        directory : str | os.PathLike
            Directory to draw the figures into (created).
        part : tuple[int, int], optional
            ``(index, count)``: draw only this share of the per-record figures (for parallel drawing); ``(0, 1)``:
            all.
        """

        paths = comparison_plots.plot_all(self, Path(directory), part)
        if len(self.dampers) > 1 and part[0] == 0:
            paths += model_comparison.plot_force_differences(self, Path(directory))
        return paths


def parse_list(value: str | Sequence[str] | None, allowed: Sequence[str], what: str,
               all_words: tuple[str, ...] = ("all",)) -> list[str]:
    """Split a comma list and check every entry against ``allowed`` (``all`` → everything).

    Parameters
    ----------
    value : str | Sequence[str] | None
        Comma-separated text or a sequence of names; None: all.
    allowed : Sequence[str]
        The admissible names.
    what : str
        What the names are (``"record"``), for the error message.
    all_words : tuple[str, ...], optional
        Words that stand for every allowed name.

    Raises
    ------
    InputError
        Naming the unknown entry and the allowed values.
    """
    if value is None:
        return list(allowed)
    items = [v.strip() for v in (value.split(",") if isinstance(value, str) else value) if v.strip()]
    if not items:
        raise InputError(f"--{what}: empty list; expected a comma-separated list of {', '.join(allowed)}")
    if len(items) == 1 and items[0].lower() in all_words:
        return list(allowed)
    lookup = {a.lower(): a for a in allowed}
    out = []
    for item in items:
        if item.lower() not in lookup:
            raise InputError(f"--{what}: {item!r} unknown; expected one of {', '.join(allowed)}"
                             f" or {all_words[0]}")
        if lookup[item.lower()] in out:
            # run once, a name given twice would count twice in the mean and max over the runs
            raise InputError(f"--{what}: {item!r} given twice; expected each once")
        out.append(lookup[item.lower()])
    return out


# --------------------------------------------------------------------------- workers
def _load_record(name: str, orientation: str, records_dir: str | None, synthetic: bool, **options):
    """A benchmark record by name (recorded or synthetic) or a record file, through the resolver
    every command uses (:func:`records.resolve.resolve_record`; ``options``: format, dt, units,
    baseline_correct; format, dt and units are for files and ignored for names, so that
    ``--records kobe,ELC-180 --dt 0.01 --units g`` mixes both)."""
    if not looks_like_file(name):
        options = {k: v for k, v in options.items() if k not in ("format", "dt", "units")}
    return resolve_record(name, orientation, records_dir=records_dir, synthetic=synthetic, **options)


def _record_options(settings: dict) -> dict:
    return {k: settings.get(k) for k in ("format", "dt", "units", "baseline_correct") if settings.get(k) is not None}


def _parse_records(records: str | Sequence[str], names: Sequence[str]) -> list[str]:
    """Benchmark names (checked, canonical) and record files (kept as given), in order."""

    items = [r.strip() for r in records.split(",")] if isinstance(records, str) else [str(r) for r in records]
    items = [r for r in items if r]
    out: list[str] = []
    for item in items:
        if looks_like_file(item):
            out.append(item)
        else:
            out.extend(parse_list(item, names, "records"))
    if not out:
        raise InputError("--records: no record given")
    return list(dict.fromkeys(out))


def _canonical_orientations(orientations: str | Sequence[str]) -> Any:
    """Map the seed paper's FP-y / FN-y to FN-x / FP-x; leave anything else to :func:`parse_list`."""

    aliases = {k.lower(): v for k, v in ORIENTATION_ALIASES.items()}
    items = orientations.split(",") if isinstance(orientations, str) else list(orientations)
    mapped = [aliases.get(str(o).strip().lower(), str(o).strip()) for o in items]
    return ",".join(mapped) if isinstance(orientations, str) else mapped


def _check_records(record_list: list[str], orientation: str, settings: dict, warn: bool,
                   identities: dict | None = None) -> tuple[dict[str, str], dict[str, str], dict[str, float], list[str]]:
    """Load each record once here: bad files and control steps that do not fit fail before any
    run, and each gets its row label (the catalogue name, or the file's record name, made unique).
    Returns the labels by spec, by label the units each record's values were read in and its
    control step [s], and the lines to print after the runs (implausible records, chosen steps);
    ``identities``, if given, gets each record's files by label (path and SHA-256)."""
    messages: list[str] = []
    labels: dict[str, str] = {}
    units: dict[str, str] = {}
    steps: dict[str, float] = {}
    seen: set[str] = set()
    for spec in record_list:
        record = _load_record(spec, orientation, settings.get("records_dir"), settings.get("synthetic", False),
                              **_record_options(settings))
        # a synthetic row keeps the catalogue name and says "(synthetic)" through ComparisonRun.label
        base = record.name if looks_like_file(spec) else spec
        label, k = base, 2
        while label in seen:
            label, k = f"{base}-{k}", k + 1
        seen.add(label)
        labels[spec] = label
        units[label] = record.metadata.get("units_assumed", "")
        files = record.metadata.get("source_files")
        if identities is not None:
            identities[label] = record_identity(list(files) if files else getattr(record, "source", ""))
        steps[label] = settings["control_step"] or DEFAULT_CONTROL_STEP  # checked once, in compare()
        for flaw in record.metadata.get("flaws", []):
            if is_warning(flaw):
                messages.append(f"sbib compare: warning: {flaw}")
    return labels, units, steps, messages


_BUILDING_OVERRIDE: Any = None  # a caller's Building (or {damper: Building}), installed in each worker by _init_worker


#: The reference runs a worker keeps. The tasks go record by record, orientation by
#: orientation, with every controller of one pair in a row, so the pair in hand and the one
#: before it are all a worker needs; the default cache's 8 full uncontrolled runs (~11 MB each)
#: only raised a worker's peak memory.
_WORKER_REFERENCES = register_cache(ReferenceCache(size=2, name="compare.worker_references"))


def _init_worker(building: Any) -> None:
    global _BUILDING_OVERRIDE
    _BUILDING_OVERRIDE = building
    _WORKER_REFERENCES.clear()


@lru_cache(maxsize=4)
def _default_building(isolation: str | None, n_modes: int | None):
    return Building.default(isolation=isolation, n_modes=n_modes)


def _building(isolation: str | None, n_modes: int | None, damper: str = ""):
    if isinstance(_BUILDING_OVERRIDE, dict):
        return _BUILDING_OVERRIDE[damper]
    if _BUILDING_OVERRIDE is not None:
        return _BUILDING_OVERRIDE
    return _default_building(isolation, n_modes)


@lru_cache(maxsize=2)
def _record(record_name: str, orientation: str, settings_key: tuple):
    settings = dict(settings_key)
    return _load_record(record_name, orientation, settings.get("records_dir"), settings.get("synthetic", False),
                        **_record_options(settings))


#: Units of the histories a comparison keeps (each dataset's ``units`` attribute; the commands
#: ``voltage`` and ``voltage_full`` take the damper model's input unit, V or A).
HISTORY_UNITS = {"t": "s", "t_full": "s", "base_displacement": "m (x, y)", "device_force_total": "N (x, y)",
                 "device_force": "N", "device_displacement": "m", "device_velocity": "m/s", "replay_force": "N"}


def _histories(result, step: float, full_devices: bool = False) -> dict:
    t = np.asarray(result.t)
    stride = max(1, int(round(step / (t[1] - t[0])))) if t.size > 1 else 1
    out = {"t": t[::stride], "base_displacement": np.asarray(result.base_displacement)[::stride, :2]}
    if full_devices and getattr(result, "device_force", None) is not None and np.size(result.device_force):
        # every device at the record step: the force difference between models (seed Fig. 11)
        out.update(t_full=t, device_force=np.asarray(result.device_force), voltage_full=np.asarray(result.voltage),
                   device_displacement=np.asarray(result.device_displacement),
                   device_velocity=np.asarray(result.device_velocity))
    for name in ("device_force_total", "voltage"):
        value = getattr(result, name, None)
        if value is not None and np.size(value):
            value = np.asarray(value)[::stride]
            out[name] = value[:, :2] if name == "device_force_total" else value
    return out


def _make_controller(spec):
    if isinstance(spec, str):
        return get_controller(spec)
    return copy.deepcopy(spec)


def _controller_label(spec) -> str:
    return spec if isinstance(spec, str) else str(getattr(spec, "name", type(spec).__name__))


def _run_chunk(tasks: list) -> list:
    """Worker: :func:`_run_one` for a few consecutive tasks (the same record share a reference)."""
    return [_run_one(task) for task in tasks]


def _run_one(task) -> tuple:
    """Worker: one controlled run and its reference (cached per worker), through the one way to
    run a case (:func:`benchmark.simulator.case.run_case`); with ``measure`` also the run in full
    (:func:`~benchmark.applications.identification_validation.measured_from_runs`)."""
    record_name, orientation, spec, settings_key, *label = task
    damper = label[1] if len(label) > 1 else ""
    measure = len(label) > 2 and label[2]
    t0 = time.perf_counter()
    settings = dict(settings_key)
    record = _record(record_name, orientation, settings_key)
    # peaks, J's and decimated histories only: no per-bearing histories (they were 2/3 of a
    # worker's memory)
    options: dict = {"bearing_histories": False}
    if settings.get("noise") is not None:
        options.update(noise=settings["noise"], seed=settings.get("seed", 0))
    case = Case(record=record, controller=_make_controller(spec),
                building=_building(settings.get("isolation"), settings.get("n_modes"), damper),
                control_step=settings["control_step"], options=options)
    try:
        out = run_case(case, cache=_WORKER_REFERENCES)
    except UserCodeError as exc:  # a user's controller failed: say in which of the runs
        raise UserCodeError(f"{label[0] if label else record_name} {orientation}: {exc}") from None
    except NumericalError as exc:  # a run that failed numerically (a controller's NaN too): which one
        where = f"{label[0] if label else record_name} {orientation}" + (f" ({damper})" if damper else "")
        raise NumericalError(f"{where}: {exc}") from None
    result, reference = out.result, out.reference
    run = ComparisonRun(record=label[0] if label else record_name, orientation=orientation,
                        controller=_controller_label(spec),
                        J=out.J, peaks=out.peaks.as_record(),
                        histories=_histories(result, _HISTORY_STEP, full_devices=bool(settings.get("dampers"))),
                        elapsed_s=time.perf_counter() - t0,
                        synthetic=bool(getattr(record, "synthetic", False)), damper=damper)
    full = measured_from_runs(record_name, orientation, record, result, reference) if measure else None
    return run, reference.peaks.as_record(), _histories(reference, _HISTORY_STEP), full, device_motion(result)


def _damper_buildings(dampers, devices, damper_scale, isolation, n_modes) -> tuple[dict, dict, dict]:
    """One building per damper (``{label: Building}``), what the results say about them, and
    each building's damper choices (``{label: [DamperChoice]}``, for :func:`motion_notes`)."""
    items = [d.strip() for d in dampers.split(",") if d.strip()] if isinstance(dampers, str) \
        else list(dampers or [None])
    if not items:
        raise InputError("--dampers: empty list; expected model files or registered names")
    buildings: dict = {}
    choices: dict = {}
    info: dict = {"layout": None, "dampers": []}
    seen: set = set()
    names = [Path(str(i)).name for i in items if i]
    clash = {n for n in names if names.count(n) > 1}  # d1/final_model.json, d2/final_model.json
    for k, item in enumerate(items):
        where = str(Path(str(item)).resolve()) if item and Path(str(item)).exists() else item
        if where in seen:
            raise InputError(f"--dampers: {item} given twice")
        seen.add(where)
        choice = resolve_damper(item, damper_scale)
        if item and Path(str(item)).name in clash:
            choice = dataclasses.replace(choice, label=str(item))
        if k == 0 and parse_scale(damper_scale) is not None:
            # one device, one similitude: every model gets the first model's factor
            damper_scale, basis = choice.scale, choice.scale_basis
        elif k > 0 and parse_scale(damper_scale) is not None:
            choice = dataclasses.replace(choice, scale_basis=f"the factor of {items[0]}: {basis}")
        if choice.label in buildings:
            raise InputError(f"--dampers: {choice.label} given twice")
        layout, used = resolve_layout(devices, choice, damper_scale)
        buildings[choice.label] = Building.default(isolation=isolation, devices=layout, n_modes=n_modes)
        choices[choice.label] = used
        info["layout"] = {"name": layout.name, "n_devices": layout.n_devices}
        info["dampers"] += [c.describe() for c in used]
    return buildings, info, choices


def compare(records: str | Sequence[str] = "all", orientations: str | Sequence[str] = "both",
            controllers: str | Sequence[Any] = ("passive-off", "passive-on", "clipped-optimal"),
            isolation: str | None = None, records_dir: str | None = None, jobs: int | None = None,
            control_step: float | None = None, noise: Any = None, seed: int = 0, n_modes: int | None = None,
            synthetic: bool = False, building: Any = None, progress: bool = True, format: str = "auto",
            dt: float | None = None, units: str | None = None, baseline_correct: bool = False,
            warn: bool = True, dampers: Sequence[str] | str | None = None, devices: Any = None,
            damper_scale: Any = None, measure: Sequence[str] = ()) -> ComparisonResult:
    """Run every record × orientation × controller and evaluate each against the uncontrolled run.

    Parameters
    ----------
    records : "all", comma list or sequence
        Benchmark record names (:data:`records.BENCHMARK_RECORDS`) and/or record files (any
        format :func:`records.load_record` reads; rows are labelled with the file's stem).
    orientations : "both", comma list or sequence
        ``FN-x`` and/or ``FP-x`` (the seed paper's ``FP-y`` = FN-x and ``FN-y`` = FP-x accepted).
    controllers : comma list or sequence
        Registered names (:mod:`controllers.registry`) or controller objects (picklable when
        ``jobs > 1``; each run gets a deep copy).
    isolation : str, optional
        Isolation configuration name (default: the building's default).
    records_dir : str, optional
        Directory of the record files.
    jobs : int, optional
        Worker processes (default: all cores; 1 runs in this process).
    control_step : float or None
        [s]; ``None``: the benchmark's 0.005 s, whatever the record's step (the simulator
        integrates on a step that divides it, :func:`benchmark.simulator.simulation.choose_integration_step`).
    noise : optional
        Measurement noise (e.g. :class:`controllers.noise.MeasurementNoise`), seeded by ``seed``.
    n_modes : int, optional
        Reduced superstructure (default: all modes, 24 in the benchmark).
    synthetic : bool
        Use the labelled synthetic benchmark-like records (no files needed).
    building : benchmark.simulator.building.Building, optional
        The building to use instead of ``Building.default(isolation, n_modes)`` (then
        ``isolation`` and ``n_modes`` are ignored).
    progress : bool
        Show progress on stderr (:func:`benchmark.foundation.progress.progress_bar`: a bar on a terminal,
        one line per run otherwise).
    format, dt, units, baseline_correct : optional
        How to read record files (:func:`records.resolve.resolve_record`).
    warn : bool
        Print each record's implausibility flaws (:mod:`records.plausibility`) and any chosen
        control step on stderr after the runs.
    seed : int, optional
        Seed of the measurement noise (and of synthetic records), so that runs are reproducible.
    dampers : comma list or sequence, optional
        Damper model files or registered names (:mod:`benchmark.applications.damper_choice`):
        one damper for every run, or several run side by side in the same runs with the same
        controllers (each run names its model under ``damper``; :meth:`ComparisonResult.model_differences`).
    devices, damper_scale : optional
        ``--devices N|LAYOUT.json`` and ``--damper-scale F|FORCE`` (same module), for every damper.
    measure : sequence of str, optional
        Controllers whose runs are also kept in full (``ComparisonResult.measured``): the main
        job hands them to the identification study's validation, which runs the same building,
        records and controller, instead of running them again.
    """
    record_list = _parse_records(records, BENCHMARK_RECORDS)
    orientation_list = parse_list(_canonical_orientations(orientations), ORIENTATIONS, "orientations",
                                  ("both", "all"))
    items = [c.strip() for c in controllers.split(",") if c.strip()] if isinstance(controllers, str) \
        else list(controllers)
    # built-in names are checked here; a user's class (module:Class, file.py:Class) is checked by loading it
    specs: list = [c if not isinstance(c, str) else (get_controller(c) and c) if is_user_controller_spec(c)
                   else parse_list([c], controller_names(), "controllers")[0] for c in items]
    if not specs:
        raise InputError("--controllers: no controller given")
    labels = [_controller_label(s) for s in specs]
    if len(set(labels)) != len(labels):
        raise InputError(f"--controllers: duplicate names {labels}")
    # the control step is checked once, here, before any run (any record step fits it)
    settings = {"control_step": None if control_step is None else check_control_step(control_step), "isolation": isolation,
                "records_dir": None if records_dir is None else str(records_dir), "n_modes": n_modes,
                "synthetic": bool(synthetic), "seed": int(seed), "noise": noise,
                "format": None if format in (None, "auto") else format, "dt": dt, "units": units,
                "baseline_correct": bool(baseline_correct) or None,
                "building": None if building is None else f"custom:{getattr(building, 'name', '?')}:{id(building)}"}
    damper_names, damper_info, damper_choices = [""], None, {}
    if dampers is not None or devices is not None or damper_scale is not None:
        if building is not None:
            raise InputError("compare: give a building or dampers/devices/damper_scale, not both")
        building, damper_info, damper_choices = _damper_buildings(dampers, devices, damper_scale, isolation, n_modes)
        damper_names = list(building) if len(building) > 1 else [""]
        if len(building) == 1:
            building = next(iter(building.values()))
        settings["building"] = None
        settings["dampers"] = tuple(damper_names) if damper_names != [""] else None
    settings_key = tuple(sorted(settings.items(), key=lambda kv: kv[0]))
    record_inputs: dict = {}
    labels_by_spec, record_units, control_steps, messages = _check_records(record_list, orientation_list[0],
                                                                            settings, warn, record_inputs)
    unknown = sorted(set(measure) - set(labels))
    if unknown:
        raise InputError(f"measure: {unknown} are not among the controllers {labels}")
    tasks = [(rec, ori, spec, settings_key, labels_by_spec[rec], damper, _controller_label(spec) in measure)
             for rec in record_list for ori in orientation_list for spec in specs for damper in damper_names]
    n_jobs = max(1, min(jobs or os.cpu_count() or 1, len(tasks)))

    bar = progress_bar(len(tasks), desc="compare", unit="run", enabled=progress)
    outcomes = []
    try:
        if n_jobs == 1:
            _init_worker(building)
            for task in tasks:
                outcomes.append(_run_one(task))
                bar.set_postfix_str(f"{task[0]} {task[1]} {_controller_label(task[2])}")
                bar.update()
        else:
            chunk = max(1, min(len(specs), len(tasks) // n_jobs))
            # WorkerPool: the workers ignore Ctrl-C and an interrupt stops them at once (no wait
            # for the running simulations). Futures gathered in order, never cancelled here.
            with WorkerPool(n_jobs, initializer=_init_worker, initargs=(building,)) as pool:
                futures = [pool.submit(_run_chunk, tasks[i:i + chunk]) for i in range(0, len(tasks), chunk)]
                for future in futures:
                    for outcome in future.result():
                        outcomes.append(outcome)
                        bar.set_postfix_str(f"{outcome[0].record} {outcome[0].orientation} "
                                            f"{outcome[0].controller}")
                        bar.update()
    finally:
        bar.close()
        if n_jobs == 1:
            _init_worker(None)
    # a model fitted on laboratory motions, driven far beyond them (as sbib run says)
    moved: dict = {}
    for run, *_, (stroke, speed) in outcomes:
        old = moved.get(run.damper, (0.0, 0.0))
        moved[run.damper] = (max(old[0], stroke), max(old[1], speed))
    motion = [note for label, used in damper_choices.items()
              for note in motion_notes(used, *moved.get(label if len(damper_choices) > 1 else "", (0.0, 0.0)))]
    if warn:  # after the runs: a run that fails says so in one line (with the record's flag)
        for message in [*messages, *(f"sbib compare: {note}" for note in motion)]:
            print(message, file=sys.stderr, flush=True)
    runs, references, ref_hist, measured = [], {}, {}, {}
    for run, ref_peaks, ref_histories, full, _ in outcomes:
        runs.append(run)
        references[(run.record, run.orientation)] = ref_peaks
        ref_hist[(run.record, run.orientation)] = ref_histories
        if full is not None:
            measured[run.key] = full
    if isinstance(building, dict):  # several dampers: each model replayed under the first one's runs
        model_comparison.add_replays(runs, building, None if damper_info is None else
                                     {label: command_unit(damper_info, label) for label in building})
    public_settings = {k: v for k, v in settings.items() if k != "noise"}
    public_settings["noise"] = None if noise is None else repr(noise)
    public_settings["controllers"] = labels
    public_settings["jobs"] = n_jobs
    public_settings["record_units"] = record_units  # units each record's values were read in
    public_settings["control_step_by_record"] = control_steps  # [s], chosen or given
    if damper_info is not None:
        public_settings["damper"] = {**damper_info, "motion_notes": motion}  # model, scale, input mapping, notes
    # each file the runs read, by path and SHA-256, as sbib run writes them (run_inputs)
    try:
        structure = file_identity(structure_file())
    except DataNotFoundError:
        structure = {}
    public_settings["inputs"] = {"records": record_inputs,
                                 "controllers": {label: controller_identity(spec) for label, spec
                                                 in zip(labels, specs) if isinstance(spec, str)},
                                 "structure": structure, "dampers": damper_identities(damper_info)}
    return ComparisonResult(runs=runs, references=references, reference_histories=ref_hist,
                            settings=public_settings, measured=measured)
