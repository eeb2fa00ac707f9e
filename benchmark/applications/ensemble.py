"""Ensembles: records × controllers × parameter grids × synthetic-motion seeds, on all cores.

An ensemble is a list of :class:`EnsembleMember` objects expanded from an :class:`EnsembleConfig`
(usually a TOML file, see ``examples/ensemble.toml``) and a *run function*
``run(case) -> dict[str, float | numpy.ndarray]`` applied to each case:

* ``"simulation"`` (default, :func:`simulate_case`): one benchmark run (record, controller,
  parameter overrides) evaluated against the uncontrolled run of the same motion, giving the
  peaks and J1–J9;
* ``"peaks"`` (:func:`simulate_peaks_case`): the same simulation, peaks only (no uncontrolled
  run, about half the cost; what fragility studies need);
* ``"probe"`` (:func:`probe_case`): a cheap deterministic function of the case seed, for
  checking a cluster or an installation before spending hours on it;
* ``"package.module:function"``: any importable function with that signature.

Execution (:func:`run_ensemble`): cases run in worker processes (``jobs``) or on a Dask
cluster (``scheduler``/``client``); the parent process is the single writer. Each finished
run is appended to a fsync'd journal (:mod:`benchmark.applications.ensemble_journal`), the source of
truth; the HDF5 file is rebuilt from the journal atomically (temporary file + rename) at the
end, every ``checkpoint_seconds`` and on interruption. Re-running the same command after
Ctrl-C or ``kill -9`` runs only the cases missing from the journal.

Reproducibility: every case carries two seeds derived with :class:`numpy.random.SeedSequence`
from the base seed and a hash of a key — ``motion_seed`` from the *motion* key (template and
realisation: every controller, parameter set, PGA and both orientations see the same synthetic
pair), and ``seed`` from the full case key (measurement noise and anything else random in
the run). Results therefore do not depend on the number of processes, on the order in which
cases finish, on the machine that ran them, or on interruptions.

HDF5 layout (all SI; case *i* is row *i* in every dataset)::

    /                 attrs: provenance, name, base_seed, run, config (TOML text),
                             n_cases, n_done, n_failed, complete
    /cases/key, record, orientation, controller, status, error   (strings)
    /cases/synthetic (bool), realisation (int, -1 for recorded motions), pga [m/s²] (NaN: unscaled),
    /cases/seed, motion_seed (int64), elapsed_s [s]
    /cases/parameters/<name>                                      (float64)
    /results/<metric>     float64, shape (n_cases, ...), NaN for pending or failed runs
"""

from __future__ import annotations

import concurrent.futures as cf
import copy
import functools
import dataclasses
import contextlib
import hashlib
import importlib
import itertools
import json
import math
import os
import time
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping, Sequence

import numpy as np

from benchmark.foundation.atomic import atomic_path
from benchmark.applications.ensemble_journal import Journal, JournalEntry
from benchmark.foundation.errors import InputError, NumericalError, UserCodeError
from benchmark.applications.ensemble_simulation import check_grid_values, run_ensemble_case
from benchmark.foundation.provenance import provenance, sha256_of
from benchmark.foundation.errors import DataNotFoundError
from benchmark.foundation.paths import structure_file
from records import BENCHMARK_RECORDS, ORIENTATIONS
from records.catalogue import ORIENTATION_ALIASES, canonical_name
from records.resolve import looks_like_file, record_files
from controllers.registry import controller_names
from controllers.user import user_controller_file
from benchmark.foundation.textfile import read_text
from benchmark.simulator.criteria import CRITERIA
from benchmark.simulator.peaks import PEAK_UNITS
from benchmark.foundation.pools import WorkerPool
from benchmark.foundation.progress import progress_bar
from benchmark.applications.damper_choice import motion_notes, resolve_damper, resolve_layout
from benchmark.applications.run_inputs import damper_identities

__all__ = [
    "EnsembleMember",
    "EnsembleConfig",
    "EnsembleSummary",
    "building_description",
    "building_notes",
    "ensemble_motion_notes",
    "DEVICE_MOTION_UNITS",
    "EnsembleResults",
    "RUN_FUNCTIONS",
    "resolve_run_function",
    "derive_seed",
    "run_ensemble",
    "write_hdf5",
    "read_ensemble",
    "probe_case",
    "simulate_case",
    "simulate_peaks_case",
    "journal_path",
]

#: Named run functions (``run = "..."`` in the TOML file); anything else is ``module:function``.
#: Most cases one ensemble holds (each a journal line and a row of every result array).
MAX_CASES = 1_000_000

RUN_FUNCTIONS: dict[str, str] = {
    "simulation": "benchmark.applications.ensemble:simulate_case",
    "peaks": "benchmark.applications.ensemble:simulate_peaks_case",
    "probe": "benchmark.applications.ensemble:probe_case",
}

#: Seconds to wait for a Dask scheduler to answer before giving up with an InputError.
DASK_CONNECT_TIMEOUT_S = 30.0

_TOP_LEVEL_KEYS = {"name", "base_seed", "run", "controllers", "orientations", "pga", "records",
                   "synthetic", "grid", "damper", "devices", "damper_scale"}
_SYNTHETIC_KEYS = {"templates", "realisations"}


# ---------------------------------------------------------------------------------------------
# Seeds and cases
# ---------------------------------------------------------------------------------------------
def derive_seed(base_seed: int, key: str) -> int:
    """Return a 63-bit seed derived from ``base_seed`` and the text ``key``.

    Uses ``SeedSequence(base_seed, spawn_key=words)`` with ``words`` the first 16 bytes of
    SHA-256(``key``) as four 32-bit words: independent streams for different keys, the same
    seed for the same key on any machine and in any process.

    Parameters
    ----------
    base_seed : int
        The ensemble's seed.
    key : str
        Text naming the case (its key), so that each case has its own seed.
    """
    digest = hashlib.sha256(key.encode("utf-8")).digest()[:16]
    words = tuple(int.from_bytes(digest[i:i + 4], "little") for i in range(0, 16, 4))
    state = np.random.SeedSequence(int(base_seed), spawn_key=words).generate_state(1, np.uint64)[0]
    return int(state) & (2 ** 63 - 1)


def _fmt(value: float) -> str:
    return repr(float(value))


@dataclass(frozen=True)
class EnsembleMember:
    """One member of an ensemble: a grid point (motion, controller, parameters) with its seeds.

    :func:`benchmark.applications.ensemble_simulation.run_ensemble_case` turns it into a
    :class:`benchmark.simulator.case.Case` and runs it.

    Parameters
    ----------
    index : int
        Row in the ensemble (and in every HDF5 dataset).
    key : str
        Canonical text that identifies the run (journal key, seed source).
    record : str
        Benchmark record name (``"kobe"``) or synthetic template name.
    orientation : str
        ``"FN-x"`` or ``"FP-x"``.
    synthetic : bool
        ``True`` for a synthetic benchmark-like motion (``records.synthetic.benchmark_like``).
    realisation : int
        Index of the synthetic realisation (``-1`` for recorded motions).
    pga : float
        Target peak ground acceleration of the stronger component [m/s²]; NaN: unscaled.
    controller : str
        Controller name (``controllers.registry``).
    parameters : tuple of (str, float)
        Parameter overrides from the grid, in the config's order.
    seed : int
        Seed of everything random in the run (from the full key).
    motion_seed : int
        Seed of the synthetic motion, from (template, realisation): the same pair for every
        controller, parameter set, PGA and orientation.
    building : tuple of str, optional
        ``(damper, devices, damper_scale)`` of the config (:mod:`benchmark.applications.damper_choice`;
        model files as absolute paths, ``""`` for one not given); empty: the default devices.
    """

    index: int
    key: str
    record: str
    orientation: str
    synthetic: bool
    realisation: int
    pga: float
    controller: str
    parameters: tuple[tuple[str, float], ...]
    seed: int
    motion_seed: int
    #: ``(damper, devices, damper_scale)`` of the config (:mod:`benchmark.applications.damper_choice`;
    #: model files as absolute paths), empty: the default devices.
    building: tuple = ()

    @property
    def parameter_dict(self) -> dict[str, float]:
        """The parameter overrides as a dict."""
        return dict(self.parameters)

    @property
    def motion_key(self) -> str:
        """Key of the ground motion alone (record, orientation, realisation, PGA)."""
        return self.key.split("|controller=")[0]


def _check_str_list(value: Any, where: str, allowed: Sequence[str] | None = None) -> tuple[str, ...]:
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list) or not value or not all(isinstance(v, str) and v for v in value):
        raise InputError(f"{where}: expected a non-empty list of names, got {value!r}")
    if allowed is not None:
        bad = [v for v in value if v not in allowed]
        if bad:
            raise InputError(f"{where}: unknown {bad}; expected some of {list(allowed)}")
    if len(set(value)) != len(value):
        raise InputError(f"{where}: duplicate entries in {value!r}")
    return tuple(value)


def _check_float_list(value: Any, where: str, positive: bool = False) -> tuple[float, ...]:
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        value = [value]
    if (not isinstance(value, list) or not value
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)):
        raise InputError(f"{where}: expected a non-empty list of numbers, got {value!r}")
    out = tuple(float(v) for v in value)
    if not all(math.isfinite(v) for v in out):
        raise InputError(f"{where}: values must be finite, got {value!r}")
    if positive and any(v <= 0 for v in out):
        raise InputError(f"{where}: values must be > 0, got {value!r}")
    if len(set(out)) != len(out):
        raise InputError(f"{where}: duplicate values in {value!r}")
    return out


@dataclass(frozen=True)
class EnsembleConfig:
    """What an ensemble runs (validated; usually read from TOML by :meth:`from_toml`).

    Parameters
    ----------
    controllers : tuple of str
        Controller names.
    records : tuple of str
        Benchmark records (recorded motions); may be empty if ``synthetic_templates`` is not.
    orientations : tuple of str
        ``"FN-x"`` and/or ``"FP-x"`` (applied to recorded and synthetic motions).
    synthetic_templates : tuple of str
        Records whose character the synthetic motions imitate (``benchmark_like``).
    realisations : int
        Synthetic realisations per template and orientation.
    pga : tuple of float
        Target PGAs [m/s²] (stronger component); empty: motions unscaled.
    grid : tuple of (str, tuple of float)
        Parameter grid (cartesian product), in order.
    base_seed : int
        Seed every case seed is derived from.
    run : str
        Run function: a name in :data:`RUN_FUNCTIONS` or ``"module:function"``.
    name : str
        Label stored with the results.
    source : str
        Where the config came from (file path), for messages.
    text : str
        The TOML text (stored in the HDF5 file).
    building : tuple of str, optional
        ``(damper, devices, damper_scale)`` as ``sbib run``'s ``--damper``, ``--devices`` and
        ``--damper-scale`` (files stored as absolute paths, ``""`` for one not given); empty:
        the default devices.
    """

    controllers: tuple[str, ...]
    records: tuple[str, ...] = ()
    orientations: tuple[str, ...] = ("FN-x", "FP-x")
    synthetic_templates: tuple[str, ...] = ()
    realisations: int = 0
    pga: tuple[float, ...] = ()
    grid: tuple[tuple[str, tuple[float, ...]], ...] = ()
    base_seed: int = 0
    run: str = "simulation"
    name: str = "ensemble"
    source: str = "<python>"
    text: str = ""
    #: ``damper = "FILE.json|NAME"``, ``devices = N | "LAYOUT.json"``, ``damper_scale = F | "1000kN"``
    #: (as ``sbib run``'s options; files relative to the TOML file's folder, stored absolute).
    building: tuple = ()

    def __post_init__(self) -> None:
        where = self.source
        if not self.records and not (self.synthetic_templates and self.realisations > 0):
            raise InputError(f"{where}: no motions: give records = [...] and/or [synthetic] templates "
                             "with realisations >= 1")
        if not isinstance(self.base_seed, int) or isinstance(self.base_seed, bool) or self.base_seed < 0:
            raise InputError(f"{where}: field 'base_seed' must be an integer >= 0, got {self.base_seed!r}")
        if not isinstance(self.realisations, int) or self.realisations < 0:
            raise InputError(f"{where}: field 'synthetic.realisations' must be an integer >= 0, "
                             f"got {self.realisations!r}")
        for name, values in self.grid:
            if "|" in name or "=" in name or "/" in name or not name:
                raise InputError(f"{where}: grid parameter name {name!r} must not be empty or contain "
                                 "'|', '=' or '/'")

    # -- construction ----------------------------------------------------------------------------
    @classmethod
    def from_toml(cls, path: str | os.PathLike) -> "EnsembleConfig":
        """Read and validate a TOML ensemble description (see ``examples/ensemble.toml``).

        Parameters
        ----------
        path : str | os.PathLike
            TOML file.

        Raises
        ------
        DataNotFoundError
            If the file does not exist.
        InputError
            On a TOML syntax error (with line) or a field of the wrong type, value or name.
        """

        path = Path(path)
        if not path.is_file():
            raise DataNotFoundError(f"ensemble config {path} not found")
        text = read_text(path, "ensemble config")  # binary or not UTF-8: one-line InputError
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise InputError(f"{path}: invalid TOML: {exc}") from None
        return cls.from_dict(data, source=str(path), text=text)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], source: str = "<dict>", text: str = "") -> "EnsembleConfig":
        """Validate a parsed TOML document; every error names ``source`` and the field.

        Parameters
        ----------
        data : Mapping[str, Any]
            The parsed TOML document.
        source : str, optional
            Where it came from, for error messages (a file name).
        text : str, optional
            The TOML text, to quote lines in error messages; empty: none.
        """
        orientations_allowed = _orientations()
        unknown = sorted(set(data) - _TOP_LEVEL_KEYS)
        if unknown:
            raise InputError(f"{source}: unknown field(s) {unknown}; expected some of {sorted(_TOP_LEVEL_KEYS)}")
        if "controllers" not in data:
            raise InputError(f"{source}: missing field 'controllers' (a list of controller names)")
        controllers = _check_str_list(data["controllers"], f"{source}: field 'controllers'")
        records: tuple[str, ...] = ()
        if "records" in data:
            value = data["records"]
            if value == "all":
                value = list(BENCHMARK_RECORDS)
            records = _check_str_list(value, f"{source}: field 'records'")
        orientations = _check_str_list(_seed_orientation_names(data.get("orientations", list(orientations_allowed))),
                                       f"{source}: field 'orientations'", allowed=orientations_allowed)
        templates: tuple[str, ...] = ()
        realisations = 0
        if "synthetic" in data:
            syn = data["synthetic"]
            if not isinstance(syn, dict):
                raise InputError(f"{source}: field 'synthetic' must be a table [synthetic]")
            bad = sorted(set(syn) - _SYNTHETIC_KEYS)
            if bad:
                raise InputError(f"{source}: unknown field(s) {['synthetic.' + b for b in bad]}; expected "
                                 f"{sorted('synthetic.' + k for k in _SYNTHETIC_KEYS)}")
            if "templates" not in syn:
                raise InputError(f"{source}: missing field 'synthetic.templates'")
            templates = _check_str_list(syn["templates"], f"{source}: field 'synthetic.templates'")
            realisations = syn.get("realisations", 1)
            if not isinstance(realisations, int) or isinstance(realisations, bool) or realisations < 1:
                raise InputError(f"{source}: field 'synthetic.realisations' must be an integer >= 1, "
                                 f"got {realisations!r}")
        pga = _check_float_list(data["pga"], f"{source}: field 'pga'", positive=True) if "pga" in data else ()
        grid: list[tuple[str, tuple[float, ...]]] = []
        if "grid" in data:
            if not isinstance(data["grid"], dict):
                raise InputError(f"{source}: field 'grid' must be a table [grid] of name = [values]")
            for name, values in _flatten(data["grid"]):
                grid.append((name, _check_float_list(values, f"{source}: field 'grid.{name}'")))
        base_seed = data.get("base_seed", 0)
        if not isinstance(base_seed, int) or isinstance(base_seed, bool) or base_seed < 0:
            raise InputError(f"{source}: field 'base_seed' must be an integer >= 0, got {base_seed!r}")
        run = data.get("run", "simulation")
        if not isinstance(run, str) or not (run in RUN_FUNCTIONS or ":" in run):
            raise InputError(f"{source}: field 'run' must be one of {sorted(RUN_FUNCTIONS)} or "
                             f"'module:function', got {run!r}")
        name = data.get("name", Path(source).stem if source not in ("<dict>", "<python>") else "ensemble")
        if not isinstance(name, str):
            raise InputError(f"{source}: field 'name' must be a string, got {name!r}")
        config = cls(controllers=controllers, records=records, orientations=orientations,
                     synthetic_templates=templates, realisations=realisations, pga=pga, grid=tuple(grid),
                     base_seed=base_seed, run=run, name=name, source=source, text=text,
                     building=_building_fields(data, source))
        if run in ("simulation", "peaks"):
            _check_simulated_names(records, controllers, source)
            try:
                check_grid_values(config.grid, config.building)
            except InputError as exc:
                raise InputError(f"{source}: {exc}") from None
        return config

    # -- expansion -------------------------------------------------------------------------------
    def motions(self) -> list[tuple[str, str, bool, int, float]]:
        """(record, orientation, synthetic, realisation, pga) of every motion, in order."""
        pgas = self.pga or (math.nan,)
        out = []
        for record in self.records:
            for orientation in self.orientations:
                for pga in pgas:
                    out.append((record, orientation, False, -1, pga))
        for template in self.synthetic_templates:
            for orientation in self.orientations:
                for realisation in range(self.realisations):
                    for pga in pgas:
                        out.append((template, orientation, True, realisation, pga))
        return out

    @property
    def n_cases(self) -> int:
        """Number of cases, counted without expanding them."""
        n = len(self.motions()) * len(self.controllers)
        for _, values in self.grid:
            n *= len(values)
        return n

    def cases(self) -> list[EnsembleMember]:
        """Expand into cases: motions × controllers × grid (cartesian product, in this order).

        Raises
        ------
        InputError
            More than :data:`MAX_CASES` cases (a 9-million grid had taken 3.7 GB and 90 s of
            silence before its first run).
        """
        if self.n_cases > MAX_CASES:
            raise InputError(f"{self.source}: {self.n_cases:,} cases ({len(self.motions())} motions x "
                             f"{len(self.controllers)} controllers x the grid's "
                             + " x ".join(str(len(v)) for _, v in self.grid) + f"); at most {MAX_CASES:,} in "
                             "one ensemble: split the grid over several")
        names = [name for name, _ in self.grid]
        grid_points = list(itertools.product(*[values for _, values in self.grid]))
        cases: list[EnsembleMember] = []
        for record, orientation, synthetic, realisation, pga in self.motions():
            motion = (f"synthetic={record}#{realisation}" if synthetic else f"record={record}")
            motion += f"|orientation={orientation}"
            # The PGA scales a motion, it does not change it; a synthetic realisation in FP-x is
            # its FN-x pair swapped (records.synthetic.benchmark_like), as for recorded pairs.
            motion_seed_key = f"synthetic={record}#{realisation}" if synthetic else f"record={record}"
            if not math.isnan(pga):
                motion += f"|pga={_fmt(pga)}"
            motion_seed = derive_seed(self.base_seed, motion_seed_key)
            for controller in self.controllers:
                for point in grid_points:
                    key = motion + f"|controller={controller}"
                    key += "".join(f"|{n}={_fmt(v)}" for n, v in zip(names, point))
                    if self.building:  # another device is another case (and another seed)
                        key += "".join(f"|{n}={Path(v).name if n != 'damper_scale' else v}"
                                       for n, v in zip(("damper", "devices", "damper_scale"), self.building) if v)
                    cases.append(EnsembleMember(index=len(cases), key=key, record=record, orientation=orientation,
                                      synthetic=synthetic, realisation=realisation, pga=pga,
                                      controller=controller, parameters=tuple(zip(names, point)),
                                      seed=derive_seed(self.base_seed, key), motion_seed=motion_seed,
                                      building=self.building))
        return cases

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """Names of the grid parameters, in order."""
        return tuple(name for name, _ in self.grid)


def _check_simulated_names(records: Sequence[str], controllers: Sequence[str], source: str) -> None:
    """Refuse, before any run, a record or controller a simulation cannot resolve (a misspelt
    name had failed only when its cases ran, after the others' runs; a user's run function may
    read them as labels of its own, so only the simulations' are checked)."""
    for name in records:
        if not looks_like_file(name):
            try:
                canonical_name(name)
            except InputError:
                raise InputError(f"{source}: field 'records': {name!r} is neither a benchmark record "
                                 f"({', '.join(BENCHMARK_RECORDS)}) nor an existing file") from None
    known = set(controller_names())
    for name in controllers:
        if name not in known and ":" not in name:
            raise InputError(f"{source}: field 'controllers': unknown controller {name!r}; expected one of "
                             f"{', '.join(sorted(known))} or a user's 'module:Class' / 'file.py:Class'")


def _building_fields(data: Mapping[str, Any], source: str) -> tuple:
    """``(damper, devices, damper_scale)`` from the TOML (empty when none is given), checked now:
    a bad model file or layout stops the ensemble before its first run, in one line."""
    if not any(k in data for k in ("damper", "devices", "damper_scale")):
        return ()
    base = Path(source).parent if source not in ("<dict>", "<python>") else Path(".")
    out = []
    for key in ("damper", "devices", "damper_scale"):
        value = data.get(key)
        if value is None:
            out.append("")
            continue
        if isinstance(value, bool) or not isinstance(value, (str, int, float)):
            raise InputError(f"{source}: field {key!r}: expected a string or a number, got {value!r}")
        text = str(value)
        if key in ("damper", "devices") and (text.endswith(".json") or "/" in text):
            text = str((base / text).resolve()) if not Path(text).is_absolute() else text
        out.append(text)
    try:
        choice = resolve_damper(out[0] or None, out[2] or None)
        resolve_layout(out[1] or None, choice, out[2] or None)
    except InputError as exc:
        raise InputError(f"{source}: {exc}") from None
    return tuple(out)


def _seed_orientation_names(value: Any) -> Any:
    """Map the seed paper's ``FP-y`` / ``FN-y`` in a list to ``FN-x`` / ``FP-x`` (other values untouched)."""
    aliases = {k.lower(): v for k, v in ORIENTATION_ALIASES.items()}
    if not isinstance(value, list):
        return value
    return [aliases.get(v.strip().lower(), v) if isinstance(v, str) else v for v in value]


def _orientations() -> tuple[str, ...]:
    return tuple(ORIENTATIONS)


def _building_file_hashes(building) -> dict:
    """``{file name: SHA-256}`` of the damper model and layout files of ``building``."""
    out = {}
    for value in building or ():
        if value and isinstance(value, str) and Path(value).is_file():
            out[Path(value).name] = sha256_of(value)
    return out


def building_description(building) -> dict | None:
    """What an ensemble's runs install at the isolation level, as ``sbib run`` states it: the
    layout, each damper model (file, scale and its basis, input mapping, effects, notes) and the
    model files' SHA-256; ``None`` for the benchmark's own devices.

    Parameters
    ----------
    building : tuple
        ``(damper, devices, damper_scale)`` of the TOML (:attr:`EnsembleConfig.building`), empty
        when none is given.
    """
    if not building:
        return None
    # resolving a model file measures its capacity and dropped share (damper simulations): once
    # per content of the files, not at every checkpoint of the HDF5 file
    return copy.deepcopy(_described(tuple(building), _stamps(building)))


def _stamps(building) -> tuple:
    return tuple((p, os.stat(p).st_mtime_ns, os.stat(p).st_size) for p in building
                 if isinstance(p, str) and p and Path(p).is_file())


@functools.lru_cache(maxsize=4)
def _resolved(building: tuple, stamps: tuple) -> tuple:  # noqa: ARG001 (stamps: the cache key)
    damper, devices, scale = (list(building) + ["", "", ""])[:3]
    choice = resolve_damper(damper or None, scale or None)
    return resolve_layout(devices or None, choice, scale or None)


@functools.lru_cache(maxsize=4)
def _described(building: tuple, stamps: tuple) -> dict:
    layout, used = _resolved(building, stamps)
    described = [c.describe() for c in used]
    return {"layout": {"name": layout.name, "n_devices": layout.n_devices}, "dampers": described,
            "files": damper_identities({"dampers": described})}


def building_notes(building) -> list[str]:
    """The notes and warnings of an ensemble's damper models (a scale, effects the building cannot
    run and their share of the force, an input range past the fitted levels), each once, as
    ``sbib run`` prints them.

    Parameters
    ----------
    building : tuple
        ``(damper, devices, damper_scale)`` of the TOML (:attr:`EnsembleConfig.building`).
    """
    described = building_description(building)
    notes = [n for d in (described or {}).get("dampers", []) for n in d.get("notes", [])]
    return list(dict.fromkeys(notes))


#: Units of the device motion each run of the built-in run functions returns beside its peaks.
DEVICE_MOTION_UNITS = {"peak_device_stroke": "m", "peak_device_velocity": "m/s"}


def ensemble_motion_notes(building, results: Mapping[str, np.ndarray]) -> list[str]:
    """Warnings for model files whose fitted motion the ensemble's devices exceeded, as ``sbib run``
    and ``sbib compare`` give them (:func:`benchmark.applications.damper_choice.motion_notes`),
    over the largest stroke and velocity of all finished runs.

    Parameters
    ----------
    building : tuple
        ``(damper, devices, damper_scale)`` of the TOML (:attr:`EnsembleConfig.building`); empty:
        the benchmark's own devices, which have no fitted motion.
    results : mapping
        The runs' metrics by name (``peak_device_stroke`` [m], ``peak_device_velocity`` [m/s]; NaN
        for a run not finished).
    """
    stroke, velocity = (np.asarray(results.get(k, []), dtype=float) for k in DEVICE_MOTION_UNITS)
    if not building or not np.any(np.isfinite(stroke)) or not np.any(np.isfinite(velocity)):
        return []
    _, used = _resolved(tuple(building), _stamps(building))
    return motion_notes(used, float(np.nanmax(stroke)), float(np.nanmax(velocity)))


def _input_file_hashes(config) -> dict:
    """``{absolute path: SHA-256}`` of the record files an ensemble names, of its users' controller
    files (``file.py:Class`` or ``package.module:Class``) and of the structure file its runs read
    (``--structure`` / ``SBIB_STRUCTURE``, else the benchmark's)."""
    paths = [p for r in config.records if isinstance(r, str) for p in record_files(r) if p.is_file()]
    # an edited controller is another controller: its runs are not resumed (a probe's edited
    # file.py:Class had been resumed with the old commands' J's)
    paths += [p for p in (user_controller_file(c) for c in config.controllers) if p is not None]
    try:
        paths.append(structure_file())
    except DataNotFoundError:  # the runs will say so
        pass
    return {str(p.resolve()): sha256_of(p) for p in paths}


def _flatten(table: Mapping[str, Any], prefix: str = "") -> Iterable[tuple[str, Any]]:
    """Flatten nested TOML tables: ``[grid.damper] kappa_w = [...]`` → ``damper.kappa_w``."""
    for name, value in table.items():
        full = f"{prefix}{name}"
        if isinstance(value, dict):
            yield from _flatten(value, full + ".")
        else:
            yield full, value


# ---------------------------------------------------------------------------------------------
# Run functions
# ---------------------------------------------------------------------------------------------
_RESOLVED: dict[str, Callable[[EnsembleMember], dict[str, Any]]] = {}


def resolve_run_function(spec: str | Callable[[EnsembleMember], dict[str, Any]]) -> Callable[[EnsembleMember], dict[str, Any]]:
    """Return the run function for a name in :data:`RUN_FUNCTIONS`, ``"module:function"`` or a callable.

    Parameters
    ----------
    spec : str or callable
        ``"simulation"``, ``"peaks"``, ``"probe"``, ``"package.module:function"`` or the function.

    Raises
    ------
    InputError
        If the module or function cannot be found.
    """
    if callable(spec):
        return spec
    if spec in _RESOLVED:
        return _RESOLVED[spec]
    target = RUN_FUNCTIONS.get(spec, spec)
    module_name, _, function_name = target.partition(":")
    if not module_name or not function_name:
        raise InputError(f"run function {spec!r}: expected one of {sorted(RUN_FUNCTIONS)} or 'module:function'")
    try:
        module = importlib.import_module(module_name)
    except ImportError as exc:
        raise InputError(f"run function {spec!r}: cannot import module {module_name!r} ({exc})") from None
    function = getattr(module, function_name, None)
    if not callable(function):
        raise InputError(f"run function {spec!r}: module {module_name!r} has no function {function_name!r}")
    _RESOLVED[spec] = function
    return function


def probe_case(case: EnsembleMember) -> dict[str, Any]:
    """A cheap deterministic run function for checking the ensemble machinery and a cluster.

    Draws from ``numpy.random.default_rng(case.seed)`` and the motion seed, so its results
    depend only on the case: a run on another machine, in another process count, or after a
    resume must give the same bits. Grid parameters are summed into ``parameter_sum``. A grid
    parameter ``probe.delay`` [s] makes each run sleep that long (to test interruptions);
    ``probe.fail_above`` makes runs whose first draw exceeds it fail with a
    :class:`~benchmark.foundation.errors.NumericalError` (to test failure handling).

    Parameters
    ----------
    case : EnsembleMember
        One case of the ensemble (:class:`benchmark.simulator.case.Case`).

    Returns
    -------
    dict
        ``draw`` (float), ``motion_draw`` (float), ``samples`` (array of 4 floats),
        ``parameter_sum`` (float), ``pga`` (float, NaN when unscaled).
    """
    params = case.parameter_dict
    delay = params.get("probe.delay", 0.0)
    if delay > 0:
        time.sleep(delay)
    rng = np.random.default_rng(case.seed)
    draw = float(rng.random())
    if "probe.fail_above" in params and draw > params["probe.fail_above"]:
        raise NumericalError(f"probe draw {draw:.6g} above probe.fail_above", time=0.0,
                             hint="this is the probe's deliberate failure")
    return {
        "draw": draw,
        "motion_draw": float(np.random.default_rng(case.motion_seed).random()),
        "samples": rng.standard_normal(4),
        "parameter_sum": float(sum(v for n, v in case.parameters if not n.startswith("probe."))),
        "pga": case.pga,
    }


def simulate_case(case: EnsembleMember) -> dict[str, Any]:
    """Run function of the benchmark: one simulation evaluated against the uncontrolled run.

    The motion is the benchmark record ``case.record`` (or a synthetic benchmark-like
    realisation seeded by ``case.motion_seed``) in ``case.orientation``, scaled to ``case.pga``
    when given; the controller is ``case.controller``; grid parameters override the building
    and controller settings (see :func:`benchmark.applications.ensemble_simulation.run_ensemble_case`).

    Parameters
    ----------
    case : EnsembleMember
        One case of the ensemble (:class:`benchmark.simulator.case.Case`).

    Returns
    -------
    dict
        The peaks of :meth:`benchmark.simulator.peaks.Peaks.as_record` and the criteria J1–J9.
    """

    return run_ensemble_case(case)


def simulate_peaks_case(case: EnsembleMember) -> dict[str, Any]:
    """Run function ``"peaks"``: like :func:`simulate_case` without the uncontrolled run (no J's).

    Parameters
    ----------
    case : EnsembleMember
        One case of the ensemble (:class:`benchmark.simulator.case.Case`).

    Returns
    -------
    dict
        The peaks of :meth:`benchmark.simulator.peaks.Peaks.as_record` (SI).
    """

    return run_ensemble_case(case, evaluate_criteria=False)


# ---------------------------------------------------------------------------------------------
# Execution
# ---------------------------------------------------------------------------------------------
@dataclass
class EnsembleSummary:
    """What :func:`run_ensemble` did.

    Parameters
    ----------
    path : Path
        The ensemble's HDF5 file.
    journal : Path
        Its journal file (finished runs, for resuming).
    n_cases : int
        Number of cases.
    n_resumed : int
        Cases taken from the journal of an earlier, interrupted run.
    n_run : int
        Cases run now.
    n_failed : int
        Cases that failed (recorded with their error).
    complete : bool
        Whether every case has a result.
    elapsed_s : float
        Wall time [s].
    workers : str
        What ran the cases (e.g. ``"4 processes"``, a Dask scheduler address).
    """

    path: Path
    journal: Path
    n_cases: int
    n_resumed: int
    n_run: int
    n_failed: int
    complete: bool
    elapsed_s: float
    workers: str

    def as_dict(self) -> dict[str, Any]:
        """The summary as a JSON-ready dict (paths as strings)."""
        d = dataclasses.asdict(self)
        d["path"], d["journal"] = str(self.path), str(self.journal)
        return d


def journal_path(out: str | os.PathLike) -> Path:
    """The journal file of an ensemble whose HDF5 file is ``out`` (``<out>.journal``).

    Parameters
    ----------
    out : str | os.PathLike
        The ensemble's HDF5 file.
    """
    out = Path(out)
    return out.with_name(out.name + ".journal")


def _execute(run: str | Callable[[EnsembleMember], dict[str, Any]], case: EnsembleMember) -> JournalEntry:
    """Run one case on a worker; a NumericalError or a user's code failing during the run (a
    controller raising at some step) becomes a failed entry, other errors propagate."""
    function = resolve_run_function(run)
    own = isinstance(run, str) and run in RUN_FUNCTIONS
    start = time.perf_counter()
    try:
        result = function(case)
    except (NumericalError, UserCodeError) as exc:
        return JournalEntry(key=case.key, status="failed", error=str(exc),
                            elapsed_s=time.perf_counter() - start)
    except InputError as exc:
        # a grid value the simulation refuses is only seen when its case runs: name the case (its
        # key holds the configuration's values), not just the model field deep inside
        raise InputError(f"case {case.key}: {exc}") from None
    except Exception as exc:
        if own:
            raise
        # a user's run function failing on one case is that case's failure (the others go on), as
        # a user's controller failing at some step is; it had ended the ensemble in a traceback
        return JournalEntry(key=case.key, status="failed",
                            error=f"run function {run!r} raised {type(exc).__name__}: {exc}",
                            elapsed_s=time.perf_counter() - start)
    if not isinstance(result, dict):
        raise InputError(f"run function {run!r} returned {type(result).__name__} for case {case.key!r}; "
                         "expected a dict of metric name -> number or array")
    for name, value in list(result.items()):
        if not isinstance(name, str) or not name or "/" in name:
            raise InputError(f"run function {run!r}: metric name {name!r} must be a non-empty string "
                             "without '/'")
        if not isinstance(value, (np.ndarray, bool, int, float, np.bool_, np.integer, np.floating)):
            try:  # a list or tuple of numbers is an array
                result[name] = np.asarray(value, dtype=float)
            except (TypeError, ValueError):
                raise InputError(f"run function {run!r}: metric {name!r} of case {case.key!r} is "
                                 f"{type(value).__name__}; expected a number or an array of numbers") from None
    return JournalEntry(key=case.key, status="ok", result=result, elapsed_s=time.perf_counter() - start)


def _local_results(run: Any, cases: list[EnsembleMember], jobs: int, mp_context: str | None) -> Iterable[JournalEntry]:
    """Yield entries as cases finish, on ``jobs`` local processes (in-process when jobs == 1)."""
    if jobs == 1:
        for case in cases:
            yield _execute(run, case)
        return
    # WorkerPool: the workers ignore Ctrl-C (the parent owns it) and an interrupt or a failed
    # run stops them at once, without waiting for the running cases (finished ones are journaled).
    executor = WorkerPool(jobs, mp_context=mp_context or "spawn")
    pending: set[cf.Future] = set()
    queue = iter(cases)
    with executor:
        for case in itertools.islice(queue, 2 * jobs):
            pending.add(executor.submit(_execute, run, case))
        while pending:
            done, pending = cf.wait(pending, return_when=cf.FIRST_COMPLETED)
            for future in done:
                entry = future.result()
                for case in itertools.islice(queue, 1):
                    pending.add(executor.submit(_execute, run, case))
                yield entry


def _dask_results(run: Any, cases: list[EnsembleMember], scheduler: str | None, client: Any) -> Iterable[JournalEntry]:
    """Yield entries as cases finish on a Dask cluster (``client`` or a new client of ``scheduler``)."""
    try:
        import distributed
    except ImportError:
        raise InputError("--scheduler needs dask.distributed: pip install 'sbib[dask]'") from None
    own_client = client is None
    if own_client:
        try:
            client = distributed.Client(scheduler, timeout=f"{DASK_CONNECT_TIMEOUT_S}s")
        except (OSError, TimeoutError) as exc:
            raise InputError(f"cannot connect to the Dask scheduler at {scheduler!r}: {exc}") from None
    try:
        n_workers = max(1, sum(w.get("nthreads", 1) for w in client.scheduler_info()["workers"].values()))
        queue = iter(cases)
        completed = distributed.as_completed()
        for case in itertools.islice(queue, 2 * n_workers):
            completed.add(client.submit(_execute, run, case, pure=False))
        for future in completed:
            entry = future.result()
            future.release()
            for case in itertools.islice(queue, 1):
                completed.add(client.submit(_execute, run, case, pure=False))
            yield entry
    finally:
        if own_client:
            client.close()


def run_ensemble(config: EnsembleConfig, out: str | os.PathLike, jobs: int = 1,
                 scheduler: str | None = None, client: Any = None,
                 run: str | Callable[[EnsembleMember], dict[str, Any]] | None = None,
                 progress: bool = True, checkpoint_seconds: float = 60.0,
                 mp_context: str | None = None, max_cases: int | None = None) -> EnsembleSummary:
    """Run (or resume) an ensemble and write its results to one HDF5 file.

    Parameters
    ----------
    config : EnsembleConfig
        What to run.
    out : path-like
        HDF5 file to write; its journal is ``<out>.journal`` (:func:`journal_path`).
    jobs : int
        Local worker processes (1: run in this process). Ignored with a Dask scheduler.
    scheduler : str, optional
        Address of a Dask scheduler (``tcp://host:8786``); runs go to its workers.
    client : distributed.Client, optional
        An existing Dask client (e.g. of a ``LocalCluster``); wins over ``scheduler``.
    run : str or callable, optional
        Run function; defaults to ``config.run``. A callable must be importable by the
        workers (a module-level function).
    progress : bool
        Show progress on stderr (:func:`benchmark.foundation.progress.progress_bar`: a bar on a terminal,
        one line per run otherwise).
    checkpoint_seconds : float
        Rebuild the HDF5 file from the journal at most this often during the run.
    mp_context : str, optional
        ``multiprocessing`` start method of the local workers (default ``"spawn"``).
    max_cases : int, optional
        Run at most this many new cases, then stop (the ensemble stays resumable).

    Returns
    -------
    EnsembleSummary

    Raises
    ------
    InputError
        Bad settings, a journal that belongs to another ensemble, a run function that
        cannot be found or returns something other than a dict.
    KeyboardInterrupt
        After writing the HDF5 file of the finished runs; re-run to resume.
    """
    if not isinstance(jobs, int) or jobs < 1:
        raise InputError(f"jobs must be an integer >= 1, got {jobs!r}")
    run_spec = config.run if run is None else run
    run_label = run_spec if isinstance(run_spec, str) else f"{run_spec.__module__}:{run_spec.__qualname__}"
    resolve_run_function(run_spec)  # fail early, in the parent, with a clear message
    out = Path(out)
    cases = config.cases()
    header = {"base_seed": config.base_seed, "run": run_label}
    files = _building_file_hashes(config.building)
    if files:  # an edited damper or layout file is another device: its runs are not resumed
        header["building_files_sha256"] = files
    # so is an edited record file or structure file (a probe's doubled record and 10 % damping had
    # been resumed with the old runs' numbers)
    header["input_files_sha256"] = _input_file_hashes(config)
    journal = Journal(journal_path(out), header=header)
    known = {c.key for c in cases}
    n_resumed = sum(1 for key in journal.entries if key in known)
    todo = [c for c in cases if c.key not in journal.entries]
    if max_cases is not None:
        todo = todo[:max(0, int(max_cases))]
    workers = (f"dask:{scheduler or 'client'}" if (scheduler or client is not None)
               else f"{jobs} local process{'es' if jobs > 1 else ''}")
    start = time.perf_counter()
    n_run = 0
    bar = None
    if progress:
        bar = progress_bar(len(cases), desc=config.name, unit="run", initial=n_resumed)
    if scheduler or client is not None:
        stream = _dask_results(run_spec, todo, scheduler, client)
    else:
        stream = _local_results(run_spec, todo, jobs, mp_context)
    last_checkpoint = time.monotonic()
    try:
        with journal:
            for entry in stream:
                journal.append(entry)
                n_run += 1
                if bar is not None:
                    bar.update(1)
                if todo and time.monotonic() - last_checkpoint > checkpoint_seconds:
                    write_hdf5(config, cases, journal.entries, out, run_label)
                    last_checkpoint = time.monotonic()
    except BaseException:  # Ctrl-C or an error that ends the ensemble: keep the finished runs
        close = getattr(stream, "close", None)
        if close is not None:  # stop the workers first (the generator's pool), then write
            close()
        if bar is not None:
            bar.close()
            bar = None
        if journal.entries:
            write_hdf5(config, cases, journal.entries, out, run_label)
        else:  # nothing finished (a case the config could not build): no journal to block a fix
            with contextlib.suppress(OSError):
                journal.path.unlink()
        raise
    finally:
        if bar is not None:
            bar.close()
        close = getattr(stream, "close", None)
        if close is not None:
            close()
    complete = write_hdf5(config, cases, journal.entries, out, run_label)
    n_failed = sum(1 for c in cases if c.key in journal.entries and journal.entries[c.key].status != "ok")
    return EnsembleSummary(path=out, journal=journal.path, n_cases=len(cases), n_resumed=n_resumed,
                           n_run=n_run, n_failed=n_failed, complete=complete,
                           elapsed_s=time.perf_counter() - start, workers=workers)


# ---------------------------------------------------------------------------------------------
# HDF5
# ---------------------------------------------------------------------------------------------
def write_hdf5(config: EnsembleConfig, cases: list[EnsembleMember], entries: Mapping[str, JournalEntry],
               out: str | os.PathLike, run_label: str | None = None) -> bool:
    """Write the HDF5 file of an ensemble from its journal entries, atomically.

    Rows are in case order, whatever order the runs finished in, so the file's datasets are
    the same for any number of processes. Returns ``True`` when every case has finished.

    Parameters
    ----------
    config : EnsembleConfig
        The ensemble (its TOML text and settings are stored as attributes).
    cases : list of EnsembleMember
        ``config.cases()``.
    entries : mapping of str to JournalEntry
        Finished runs by case key (the journal's entries).
    out : path-like
        HDF5 file, replaced atomically.
    run_label : str, optional
        Run function label stored as an attribute (default ``config.run``).

    Raises
    ------
    InputError
        If two runs return the same metric with different shapes.
    """
    import h5py


    n = len(cases)
    shapes: dict[str, tuple[int, ...]] = {}
    origin: dict[str, str] = {}
    for case in cases:
        entry = entries.get(case.key)
        if entry is None or entry.status != "ok":
            continue
        for metric, value in entry.result.items():
            shape = np.shape(value)
            if metric not in shapes:
                shapes[metric], origin[metric] = shape, case.key
            elif shapes[metric] != shape:
                raise InputError(f"metric {metric!r} has shape {shape} in case {case.key!r} but "
                                 f"{shapes[metric]} in case {origin[metric]!r}")
    results = {m: np.full((n,) + s, np.nan) for m, s in shapes.items()}
    status, error, elapsed = [], [], np.full(n, np.nan)
    for i, case in enumerate(cases):
        entry = entries.get(case.key)
        if entry is None:
            status.append("pending")
            error.append("")
            continue
        status.append(entry.status)
        error.append(entry.error)
        elapsed[i] = entry.elapsed_s
        if entry.status == "ok":
            for metric, value in entry.result.items():
                results[metric][i] = value
    n_done = sum(s != "pending" for s in status)
    n_failed = sum(s == "failed" for s in status)
    complete = n_done == n
    strings = h5py.string_dtype()
    with atomic_path(out) as tmp:
        with h5py.File(tmp, "w") as f:
            f.attrs.update(provenance(name=config.name, base_seed=config.base_seed,
                                      run=run_label or str(config.run), config_source=config.source))
            f.attrs["config"] = config.text or json.dumps(dataclasses.asdict(config), default=str)
            described = building_description(config.building)
            if described is not None:  # the devices the runs had: model files, scale, mapping, effects
                f.attrs["damper"] = json.dumps(described, default=str)
            notes = ensemble_motion_notes(config.building, results)
            if notes:  # devices driven beyond a model's fitted motion (sbib ensemble prints them too)
                f.attrs["motion_notes"] = json.dumps(notes)
            f.attrs["n_cases"], f.attrs["n_done"], f.attrs["n_failed"] = n, n_done, n_failed
            f.attrs["complete"] = complete
            g = f.create_group("cases")
            for name, values in (("key", [c.key for c in cases]), ("record", [c.record for c in cases]),
                                 ("orientation", [c.orientation for c in cases]),
                                 ("controller", [c.controller for c in cases]),
                                 ("status", status), ("error", error)):
                g.create_dataset(name, data=np.array(values, dtype=object), dtype=strings)
            g["synthetic"] = np.array([c.synthetic for c in cases], dtype=bool)
            g["realisation"] = np.array([c.realisation for c in cases], dtype=np.int64)
            g["pga"] = np.array([c.pga for c in cases], dtype=np.float64)
            g["pga"].attrs["units"] = "m/s^2 (stronger component; NaN: unscaled)"
            g["seed"] = np.array([c.seed for c in cases], dtype=np.int64)
            g["motion_seed"] = np.array([c.motion_seed for c in cases], dtype=np.int64)
            g["elapsed_s"] = elapsed
            p = g.create_group("parameters")
            for k, name in enumerate(config.parameter_names):
                p[name] = np.array([c.parameters[k][1] for c in cases], dtype=np.float64)
            r = f.create_group("results")
            for metric, values in results.items():
                r[metric] = values
                if metric in CRITERIA:   # the J's carry their key (benchmark.simulator.criteria)
                    c = CRITERIA[metric]
                    r[metric].attrs.update(name=c.name, formula=c.formula, normalised_by=c.normalised_by,
                                           source=c.source, choice=c.choice, units="1")
                elif metric in PEAK_UNITS or metric in DEVICE_MOTION_UNITS:
                    r[metric].attrs["units"] = {**PEAK_UNITS, **DEVICE_MOTION_UNITS}[metric]
                else:  # a run function of the user's: its own quantity
                    r[metric].attrs["units"] = "as returned by the run function"
    return complete


@dataclass
class EnsembleResults:
    """An ensemble's HDF5 file read back (:func:`read_ensemble`).

    Attributes
    ----------
    cases : dict[str, numpy.ndarray]
        ``key``, ``record``, ``orientation``, ``controller``, ``status``, ``error`` (str arrays),
        ``synthetic``, ``realisation``, ``pga``, ``seed``, ``motion_seed``, ``elapsed_s``.
    parameters : dict[str, numpy.ndarray]
        Grid parameter values per case.
    results : dict[str, numpy.ndarray]
        Metric → array with the case along axis 0 (NaN where pending or failed).
    attrs : dict
        File attributes (provenance, config, counts, ``complete``).
    """

    cases: dict[str, np.ndarray]
    parameters: dict[str, np.ndarray]
    results: dict[str, np.ndarray]
    attrs: dict[str, Any] = field(default_factory=dict)

    @property
    def n_cases(self) -> int:
        return len(self.cases["key"])

    def mask(self, **criteria: Any) -> np.ndarray:
        """Boolean mask of the cases whose case fields or parameters equal the given values.

        Example: ``res.mask(controller="clipped-optimal", status="ok")``.

        Parameters
        ----------
        **criteria
            EnsembleMember fields or parameters and the values they must equal (e.g. ``record="kobe"``).
        """
        m = np.ones(self.n_cases, dtype=bool)
        for name, value in criteria.items():
            column = self.cases.get(name, self.parameters.get(name))
            if column is None:
                raise InputError(f"no case field or parameter {name!r}; have "
                                 f"{sorted(self.cases) + sorted(self.parameters)}")
            match = column == value
            if not match.any() and name != "status":
                # a misspelt value would select nothing without a word (and a mean over nothing)
                have = sorted({str(v) for v in np.unique(column)})
                raise InputError(f"no case has {name} = {value!r}; the values are {', '.join(have[:20])}"
                                 + (" ..." if len(have) > 20 else ""))
            m &= match
        return m


def read_ensemble(path: str | os.PathLike) -> EnsembleResults:
    """Read an ensemble HDF5 file written by :func:`run_ensemble`.

    Parameters
    ----------
    path : path-like
        The ``--out`` file of the ensemble.

    Raises
    ------
    DataNotFoundError
        If the file does not exist.
    InputError
        If it is not an ensemble file.
    """
    import h5py


    path = Path(path)
    if not path.is_file():
        raise DataNotFoundError(f"ensemble results {path} not found")
    with h5py.File(path, "r") as f:
        if "cases" not in f or "results" not in f:
            raise InputError(f"{path}: not an sbib ensemble file (groups /cases and /results expected)")
        cases: dict[str, np.ndarray] = {}
        for name, ds in f["cases"].items():
            if isinstance(ds, h5py.Dataset):
                cases[name] = (ds.asstr()[()] if h5py.check_string_dtype(ds.dtype) else ds[()])
        parameters = {name: ds[()] for name, ds in f["cases/parameters"].items()}
        results = {name: ds[()] for name, ds in f["results"].items()}
        attrs = {k: (v.item() if isinstance(v, np.generic) else v) for k, v in f.attrs.items()}
    cases = {k: (np.asarray(v, dtype=str) if v.dtype == object else v) for k, v in cases.items()}
    return EnsembleResults(cases=cases, parameters=parameters, results=results, attrs=attrs)
