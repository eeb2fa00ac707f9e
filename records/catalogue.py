"""The seven earthquake records of the smart base-isolated benchmark (Narasimhan et al. 2006).

The benchmark distributes each record as a two-column file (``newhall.txt``, ...; cm/s²,
dt = 0.005 s) and runs every pair twice: column 1 on x and column 2 on y (``"FN-x"``), then
swapped (``"FP-x"``), 14 runs in all. This module holds their metadata, finds the files and
loads them in either orientation, and checks a records directory against the catalogue.

Catalogue numbers and where they come from
-------------------------------------------
* event, station, column meaning, PGA (g), PGV and length: the benchmark's record set
  (Narasimhan et al. 2006, Part I, Table 2) and the provenance file of the shared records
  (``records/raw/SOURCES.md`` in the shared data directory; computed there from the files: PGV
  trapezoidal, no baseline correction).
* ``significant_duration_s`` (D5–95, Arias), ``mean_period_s`` (Rathje et al. 2004, 0.25–20 Hz)
  and ``pulse_period_s`` (Mavroeidis–Papageorgiou fit, :func:`records.pulse.fit_pulse`) were
  measured on the benchmark files as distributed with :mod:`records.measures` and
  :mod:`records.pulse` (rounded); ``tests/records/test_catalogue_records.py`` recomputes them.
  They calibrate :func:`records.synthetic.benchmark_like`. For comparison, the pulse periods
  Baker (2007) lists for the NGA fault-normal versions are, as remembered and **unverified**:
  Newhall 1.0 s, Sylmar 2.4–3.1 s, Rinaldi 1.2 s, Kobe JMA 1.0 s, TCU068 12.2 s, Erzincan 2.7 s;
  El Centro 1940 is not pulse-like (so it gets no pulse).

Records directory lookup: an explicit argument (``--records-dir``), ``SBIB_RECORDS_DIR``, then
``<shared>/records/raw/FDZ`` (:func:`benchmark.foundation.paths.records_dir`).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from benchmark.foundation.errors import DataNotFoundError, InputError
from benchmark.foundation.paths import records_dir as _records_dir
from records.checks import Flaw, check_record
from records.readers import BENCHMARK_DT, read_benchmark
from records.record import Record
from records.baseline import baseline_correct as _correct
from records.record import units_assumed

__all__ = [
    "CatalogueEntry",
    "CATALOGUE",
    "BENCHMARK_RECORDS",
    "ORIENTATIONS",
    "ORIENTATION_ALIASES",
    "SEED_ORIENTATION_NAMES",
    "ORIENTATION_HELP",
    "canonical_orientation",
    "ALIASES",
    "canonical_name",
    "get_entry",
    "record_path",
    "load_benchmark_record",
    "check_catalogue",
]


@dataclass(frozen=True)
class CatalogueEntry:
    """Metadata of one benchmark record (two columns, in file order).

    Attributes
    ----------
    name, file : str
        Catalogue name and file name in the records directory.
    event, station : str
        Earthquake and recording station.
    column_labels : tuple[str, str]
        Short labels of file columns 1 and 2 (what they really are; the benchmark calls them FN / FP).
    pga_g : tuple[float, float]
        Expected PGA of columns 1 and 2 [g].
    pgv_m_s : tuple[float, float]
        PGV of the file's columns [m/s] (trapezoidal, no baseline correction).
    duration_s : float
        Length n·dt [s].
    significant_duration_s, mean_period_s : tuple[float, float]
        D5–95 [s] and mean period [s] of each column, measured on the file.
    pulse_period_s : tuple[float | None, float | None]
        Velocity-pulse period [s] of each column, or None (not pulse-like).
    pgd_m : tuple[float, float]
        PGD of the file's columns [m] after :func:`records.baseline.baseline_correct` (cubic
        displacement baseline; without it the drifting columns of jiji and rinaldi reach metres).
    known_flaws : tuple[str, ...]
        Flaw kinds (:class:`records.checks.Flaw`) the benchmark copy is known to have.
    notes : str
        What a user should know about the file.
    dt : float
        Time step [s] (0.005 s for every benchmark file).
    metadata : dict
        Anything else.
    """

    name: str
    file: str
    event: str
    station: str
    column_labels: tuple[str, str]
    pga_g: tuple[float, float]
    pgv_m_s: tuple[float, float]
    duration_s: float
    significant_duration_s: tuple[float, float]
    mean_period_s: tuple[float, float]
    pulse_period_s: tuple[float | None, float | None]
    known_flaws: tuple[str, ...] = ()
    notes: str = ""
    pgd_m: tuple[float, float] = (float("nan"), float("nan"))
    dt: float = BENCHMARK_DT
    metadata: dict[str, Any] = field(default_factory=dict)

    @property
    def n_samples(self) -> int:
        """Expected number of samples (duration / dt)."""
        return int(round(self.duration_s / self.dt))

    def to_dict(self) -> dict[str, Any]:
        """Plain-JSON form."""
        return {
            "name": self.name, "file": self.file, "event": self.event, "station": self.station,
            "column_labels": list(self.column_labels), "pga_g": list(self.pga_g), "pgv_m_s": list(self.pgv_m_s),
            "pgd_m": list(self.pgd_m), "duration_s": self.duration_s, "dt_s": self.dt,
            "significant_duration_s": list(self.significant_duration_s),
            "mean_period_s": list(self.mean_period_s), "pulse_period_s": list(self.pulse_period_s),
            "known_flaws": list(self.known_flaws), "notes": self.notes,
        }


_ENTRIES = (
    CatalogueEntry(
        name="newhall", file="newhall.txt", event="1994 Northridge (Mw 6.7)",
        station="Newhall, LA County Fire Station", column_labels=("FN (N32E)", "FP (N122E)"),
        pga_g=(0.736, 0.656), pgv_m_s=(1.171, 0.490), pgd_m=(0.390, 0.185), duration_s=30.0,
        significant_duration_s=(5.53, 6.16), mean_period_s=(0.712, 0.462), pulse_period_s=(0.90, None),
        notes="truly rotated to fault-normal N32E / fault-parallel"),
    CatalogueEntry(
        name="sylmar", file="sylmar.txt", event="1994 Northridge (Mw 6.7)",
        station="Sylmar, Olive View County Hospital", column_labels=("360 (FN)", "090 (FP)"),
        pga_g=(0.875, 0.605), pgv_m_s=(1.290, 0.761), pgd_m=(0.300, 0.202), duration_s=30.0,
        significant_duration_s=(5.31, 6.75), mean_period_s=(0.765, 0.796), pulse_period_s=(1.95, None),
        notes="as recorded 360 / 090, labelled FN / FP; PGA about 4 % above NGA's"),
    CatalogueEntry(
        name="elcentro", file="elcentro.txt", event="1940 Imperial Valley (Mw 7.0)",
        station="El Centro Array #9", column_labels=("180 (FN)", "270 (FP)"),
        pga_g=(0.313, 0.215), pgv_m_s=(0.298, 0.297), pgd_m=(0.131, 0.217), duration_s=30.0,
        significant_duration_s=(23.84, 23.64), mean_period_s=(0.538, 0.611), pulse_period_s=(None, None),
        notes="the 1940 record (the header's '1979' is wrong); as recorded 180 / 270"),
    CatalogueEntry(
        name="rinaldi", file="rinaldi.txt", event="1994 Northridge (Mw 6.7)",
        station="Rinaldi Receiving Station", column_labels=("228 (FN)", "318 (FP)"),
        pga_g=(0.840, 0.476), pgv_m_s=(1.596, 0.766), pgd_m=(0.450, 0.543), duration_s=30.0,
        significant_duration_s=(7.05, 8.49), mean_period_s=(0.767, 0.643), pulse_period_s=(1.22, None),
        known_flaws=("baseline_drift",),
        notes="column 2 not baseline-corrected (mean -0.67 cm/s², displacement drifts about 4.8 m)"),
    CatalogueEntry(
        name="kobe", file="kobe.txt", event="1995 Hyogo-ken Nanbu (Kobe, Mw 6.9)",
        station="Kobe JMA", column_labels=("N-S (FN)", "E-W (FP)"),
        pga_g=(0.841, 0.631), pgv_m_s=(0.918, 0.766), pgd_m=(0.224, 0.192), duration_s=30.0,
        significant_duration_s=(8.07, 9.51), mean_period_s=(0.646, 0.656), pulse_period_s=(0.95, None),
        notes="JMA N-S / E-W, about 3.2 s more lead-in than NGA's"),
    CatalogueEntry(
        name="jiji", file="jiji.txt", event="1999 Chi-Chi (Mw 7.6)",
        station="TCU068", column_labels=("'N-S' (matches E-W)", "'E-W' (matches N-S)"),
        pga_g=(0.512, 0.369), pgv_m_s=(2.803, 3.059), pgd_m=(4.512, 3.912), duration_s=90.0,
        significant_duration_s=(12.45, 13.26), mean_period_s=(1.504, 1.284), pulse_period_s=(13.4, None),
        known_flaws=("baseline_drift",),
        notes="column labels look swapped; not baseline-corrected (displacement drifts tens of metres)"),
    CatalogueEntry(
        name="erzikan", file="erzikan.txt", event="1992 Erzincan (Mw 6.7)",
        station="Erzincan", column_labels=("N-S", "E-W"),
        pga_g=(0.515, 0.496), pgv_m_s=(0.840, 0.643), pgd_m=(0.277, 0.227), duration_s=21.3,
        significant_duration_s=(7.47, 7.36), mean_period_s=(1.385, 0.839), pulse_period_s=(2.19, None),
        known_flaws=("identical_components",),
        notes="in the last 105 samples column 2 equals column 1 (copying error); no second source"),
)

#: Catalogue entries by name.
CATALOGUE: dict[str, CatalogueEntry] = {e.name: e for e in _ENTRIES}
#: The seven benchmark record names, in the benchmark's order.
BENCHMARK_RECORDS: tuple[str, ...] = tuple(CATALOGUE)
#: ``"FN-x"``: file column 1 on x, column 2 on y; ``"FP-x"``: swapped.
ORIENTATIONS: tuple[str, ...] = ("FN-x", "FP-x")
#: The seed paper's names for the same two runs (its Fig. 11 is "Kobe ground motion (FP-y)"):
#: naming the component on y instead of the one on x. Column 2 (FP) on y means column 1 (FN)
#: on x, so ``FP-y`` is ``FN-x``; ``FN-y`` is ``FP-x``.
ORIENTATION_ALIASES: dict[str, str] = {"FP-y": "FN-x", "FN-y": "FP-x"}
#: The seed paper's name of each orientation (inverse of :data:`ORIENTATION_ALIASES`).
SEED_ORIENTATION_NAMES: dict[str, str] = {v: k for k, v in ORIENTATION_ALIASES.items()}
#: One line for ``--help`` texts: the accepted orientation names.
ORIENTATION_HELP = ("FN-x: file column 1 (FN) on x, column 2 on y; FP-x: swapped. The seed paper's "
                    "names are accepted: FP-y = FN-x, FN-y = FP-x")
#: Other accepted spellings.
ALIASES: dict[str, str] = {"erzincan": "erzikan", "el_centro": "elcentro", "el-centro": "elcentro",
                           "chichi": "jiji", "chi-chi": "jiji"}


def canonical_name(name: str) -> str:
    """Return the catalogue name for ``name`` (case-insensitive, aliases such as ``erzincan`` accepted).

    Parameters
    ----------
    name : str
        A record name or alias, any case (``"Erzincan"``, ``erzincan``).

    Raises
    ------
    InputError
        If the name is not in the catalogue (the message lists the names).
    """
    key = str(name).strip().lower()
    key = key[:-4] if key.endswith(".txt") else key
    key = ALIASES.get(key, key)
    if key not in CATALOGUE:
        raise InputError(f"record {name!r} is not a benchmark record; expected one of "
                         f"{', '.join(BENCHMARK_RECORDS)} (or 'erzincan')")
    return key


def get_entry(name: str) -> CatalogueEntry:
    """Return the :class:`CatalogueEntry` of a benchmark record.

    Parameters
    ----------
    name : str
        Record name (case-insensitive; aliases such as ``erzincan`` accepted).
    """
    return CATALOGUE[canonical_name(name)]


def canonical_orientation(orientation: str) -> str:
    """Return ``"FN-x"`` or ``"FP-x"`` for an orientation name (case-insensitive).

    The seed paper's names are aliases (:data:`ORIENTATION_ALIASES`): ``FP-y`` (fault-parallel
    component on y) is ``FN-x``, ``FN-y`` is ``FP-x``.

    Parameters
    ----------
    orientation : str
        ``FN-x``, ``FP-x``, ``FP-y`` or ``FN-y``, any case.

    Raises
    ------
    InputError
        If the name is none of FN-x, FP-x, FP-y, FN-y.
    """
    key = str(orientation).strip().upper()
    for o in ORIENTATIONS:
        if key == o.upper():
            return o
    for alias, o in ORIENTATION_ALIASES.items():
        if key == alias.upper():
            return o
    raise InputError(f"orientation {orientation!r}; expected one of {', '.join(ORIENTATIONS)} "
                     f"(or the seed paper's {', '.join(f'{a} = {o}' for a, o in ORIENTATION_ALIASES.items())})")


_check_orientation = canonical_orientation  # the old private name, kept for callers


def record_path(name: str, records_dir: str | os.PathLike | None = None) -> Path:
    """Return the path of a benchmark record's file.

    Parameters
    ----------
    name : str
        Record name.
    records_dir : path-like, optional
        Directory of the files (lookup order in the module docstring).

    Raises
    ------
    DataNotFoundError
        If the records directory or the file is absent (the message names both).
    """
    entry = get_entry(name)
    directory = _records_dir(records_dir)
    path = directory / entry.file
    if not path.is_file():
        raise DataNotFoundError(f"benchmark record {entry.name!r}: file {entry.file} not found in {directory} "
                                "(give --records-dir or set SBIB_RECORDS_DIR)")
    return path


def _read_catalogue_file(path: Path, entry: CatalogueEntry) -> Record:
    """A catalogue file read with the benchmark's step as known, not assumed: not every file
    states it (newhall.txt does not), but the catalogue does (every benchmark record is sampled
    at 0.005 s), so a record given by name needs no ``--dt``."""
    record = read_benchmark(path, name=entry.name, labels=entry.column_labels)  # the header's step, else 0.005 s
    if str(record.metadata.get("dt_from", "")).startswith("benchmark default"):
        record = record.replace(metadata=dict(record.metadata, dt_from=f"benchmark catalogue ({BENCHMARK_DT:g} s)"))
    return record


def load_benchmark_record(name: str, orientation: str = "FN-x", records_dir: str | os.PathLike | None = None,
                          baseline_correct: bool = False) -> Record:
    """Load a benchmark record as a two-component record, component 0 on x and 1 on y.

    Parameters
    ----------
    name : str
        One of :data:`BENCHMARK_RECORDS` (``erzincan`` accepted).
    orientation : {"FN-x", "FP-x", "FP-y", "FN-y"}
        ``"FN-x"``: file column 1 on x, column 2 on y; ``"FP-x"``: swapped; the seed paper's
        ``"FP-y"`` / ``"FN-y"`` are the same as ``"FN-x"`` / ``"FP-x"`` (:func:`canonical_orientation`).
    records_dir : path-like, optional
        Directory of the files (see the module docstring for the lookup order).
    baseline_correct : bool
        Apply :func:`records.baseline.baseline_correct` (off by default so that the benchmark is
        reproduced as distributed).

    Returns
    -------
    Record
        Acceleration in m/s² (the file's cm/s² × 0.01), dt = 0.005 s. ``metadata`` holds the
        event, station, orientation, the file column on x, and the flaws found (messages).

    Raises
    ------
    InputError
        Unknown name or orientation, malformed file.
    DataNotFoundError
        Directory or file absent.
    """
    entry = get_entry(name)
    orientation = _check_orientation(orientation)
    path = record_path(entry.name, records_dir)
    raw = _read_catalogue_file(path, entry)
    flaws = check_record(raw, entry.pga_g, entry.duration_s)
    order = [0, 1] if orientation == "FN-x" else [1, 0]
    record = raw.select(order)
    meta = dict(record.metadata)
    meta.update({"event": entry.event, "station": entry.station, "orientation": orientation,
                 "x_file_column": order[0] + 1, "y_file_column": order[1] + 1,
                 "flaws": [f.message for f in flaws], "catalogue": entry.to_dict()})
    record = record.replace(metadata=meta)
    if baseline_correct:
        record = _correct(record)
    return record


def _flaw_dicts(flaws: list[Flaw], entry: CatalogueEntry) -> list[dict[str, Any]]:
    out = []
    for f in flaws:
        d = f.to_dict()
        d["known"] = f.kind in entry.known_flaws
        out.append(d)
    return out


def check_catalogue(records_dir: str | os.PathLike | None = None) -> dict[str, Any]:
    """Check a records directory against the catalogue; never raises for absent data.

    Parameters
    ----------
    records_dir : str | os.PathLike | None, optional
        Directory holding the benchmark record files; None: the default records directory
        (:mod:`benchmark.foundation.paths`).

    Returns
    -------
    dict
        ``records_dir`` (str or None), ``error`` (why the directory could not be used, or None),
        ``n_found``, and ``records``: one dict per catalogue entry with ``name``, ``file``,
        ``found``, ``path``, ``event``, ``station``, ``column_labels``, ``expected_pga_g``, and when
        found ``units_assumed``, ``pga_g``, ``pgv_m_s``, ``duration_s``, ``dt_s``, ``n_samples``, ``flaws`` (dicts with
        ``known`` telling whether the benchmark copy is known to have it), or ``error`` if the
        file could not be read.
    """
    report: dict[str, Any] = {"records_dir": None, "error": None, "n_found": 0, "records": []}
    try:
        directory = _records_dir(records_dir)
        report["records_dir"] = str(directory)
    except DataNotFoundError as exc:
        directory = None
        report["error"] = str(exc)
    for entry in _ENTRIES:
        item: dict[str, Any] = {"name": entry.name, "file": entry.file, "found": False, "path": None,
                                "event": entry.event, "station": entry.station,
                                "column_labels": list(entry.column_labels), "expected_pga_g": list(entry.pga_g),
                                "expected_duration_s": entry.duration_s}
        if directory is not None and (directory / entry.file).is_file():
            path = directory / entry.file
            item.update(found=True, path=str(path))
            try:
                rec = _read_catalogue_file(path, entry)
            except InputError as exc:
                item["error"] = str(exc)
            else:
                item.update(units_assumed=units_assumed(rec),
                            pga_g=[float(x) for x in rec.pga_g], pgv_m_s=[float(x) for x in rec.pgv],
                            duration_s=rec.duration, dt_s=rec.dt, n_samples=rec.n_samples,
                            flaws=_flaw_dicts(check_record(rec, entry.pga_g, entry.duration_s), entry))
                report["n_found"] += 1
        report["records"].append(item)
    return report
