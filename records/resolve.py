"""One resolver for "a benchmark record name or a record file, in an orientation".

Every command that takes a record (``sbib run --record``, ``sbib compare --records``,
``sbib records show``) and their Python functions go through :func:`resolve_record`, so that
names, files, orientations (the seed paper's ``FP-y`` / ``FN-y`` included), ``dt``, units,
format and baseline correction mean the same everywhere. The command-line options that feed
it are added by :func:`records.options.add_record_options`.

Orientation of a record file: a file with two or more components puts column 1 on x and
column 2 on y for ``FN-x`` and swaps them for ``FP-x``; a one-component file goes on x for
``FN-x`` and on y for ``FP-x`` (the other direction is zero). Benchmark records by name follow
:func:`records.catalogue.load_benchmark_record` (the same rule on the file's two columns).

Every record returned carries ``metadata["orientation"]``, ``metadata["units_assumed"]``
(the units its file's values were read in and why, e.g. ``"cm/s2 (benchmark default ...)"``)
and ``metadata["flaws"]`` (:func:`records.checks.check_record`, plausibility included).
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from benchmark.foundation.errors import DataNotFoundError, InputError
from records.record import Record, units_assumed
from records.catalogue import canonical_name, canonical_orientation, load_benchmark_record
from records.checks import check_record
from records.readers import is_vertical_label, load_record
from records.station_files import STATION_SUFFIXES
from records.baseline import baseline_correct as _correct
from records.synthetic import benchmark_like
from records.catalogue import BENCHMARK_RECORDS

__all__ = ["resolve_record", "looks_like_file", "record_files", "join_components", "units_assumed",
           "RECORD_SUFFIXES", "PAIR_SEPARATOR"]

#: File suffixes that make a ``--record`` value a path even when the file does not exist.
RECORD_SUFFIXES = frozenset({".txt", ".at2", ".csv", ".dat", ".acc", ".tsv"}) | STATION_SUFFIXES

#: Joins two one-component files into one record, the first on x: ``RSN1_H1.AT2+RSN1_H2.AT2``,
#: ``MYG0041103111446.EW+MYG0041103111446.NS`` (PEER, K-NET and ESM give each component in its
#: own file).
PAIR_SEPARATOR = "+"


def _pair(text: str) -> list[str] | None:
    """The two files of a pair spec, or None (a file whose own name holds a ``+`` is a file)."""
    if PAIR_SEPARATOR not in text or Path(text).expanduser().exists():
        return None
    parts = [p.strip() for p in text.split(PAIR_SEPARATOR)]
    if len(parts) != 2 or not all(parts):
        raise InputError(f"record {text!r}: a pair of component files is written FILE_X{PAIR_SEPARATOR}FILE_Y "
                         "(two files, the first on x)")
    return parts


def looks_like_file(spec: str | os.PathLike) -> bool:
    """True when ``spec`` names a file (or a pair of files, ``X+Y``) rather than a benchmark
    record (it exists, has a directory part or a record suffix such as ``.AT2``).

    Parameters
    ----------
    spec : str | os.PathLike
        A record name (``"kobe"``) or a file path, as given by the user.
    """
    text = str(spec)
    path = Path(text).expanduser()
    if path.exists():
        return True
    if PAIR_SEPARATOR in text:
        return any(looks_like_file(part.strip()) for part in text.split(PAIR_SEPARATOR) if part.strip())
    return "/" in text or "\\" in text or path.suffix.lower() in RECORD_SUFFIXES


def record_files(spec: str | os.PathLike) -> list[Path]:
    """The files a record spec reads: none for a benchmark name, one for a file, two for a pair.

    Parameters
    ----------
    spec : str | os.PathLike
        As given to :func:`resolve_record`.
    """
    text = str(spec)
    if not looks_like_file(text):
        return []
    return [Path(p).expanduser() for p in (_pair(text) or [text])]


#: The phrase of a record flaw that states an assumed unit (:func:`unit_not_stated`); the commands
#: print such flaws as warnings, as they print implausible ones (:func:`is_warning`).
UNIT_NOT_STATED = "the file does not state the unit of its values"


def unit_not_stated(record: Record) -> str | None:
    """A warning when a record file's values were read in a format's default unit (the file names
    none, no ``--units`` was given), else None.

    A default unit is right for the format's own files (the benchmark's cm/s², SLAMMER's g) and a
    factor of 9.81 or 981 off for anyone else's, which no plausibility bound catches within a
    factor of 9.81 (a record of 0.02 g read as m/s² is still a record). The unit is read from the
    file wherever it is written (a header, a comment, a column title); this says where it was not.

    Parameters
    ----------
    record : Record
        One file's record, as its reader returned it.
    """
    origin = str(record.metadata.get("units_from", ""))
    if "default" not in origin:
        return None
    units = record.metadata.get("units_in_file", "?")
    return (f"{record.name}: values read as {units}: {UNIT_NOT_STATED} (the {record.metadata.get('format', '?')} "
            f"format's default); give --units to confirm, e.g. --units {units}")


def is_warning(flaw: str) -> bool:
    """Whether a record flaw is printed as a warning by the commands (implausible values, a unit
    the file does not state) rather than only kept in the results.

    Parameters
    ----------
    flaw : str
        A message of ``metadata["flaws"]``.
    """
    return "implausible" in flaw or UNIT_NOT_STATED in flaw


def join_components(x: Record, y: Record) -> Record:
    """One two-component record from two one-component records (``x`` on x for ``FN-x``).

    Parameters
    ----------
    x, y : Record
        One component each, sampled at the same step. A shorter one is padded with zeros at its
        end (PEER's two components often differ by a few samples), which ``metadata["columns"]``
        says; records from different stations are joined and named so there.

    Raises
    ------
    InputError
        A record with more than one component, different steps, both the same direction, or two
        different start times stated by their files.
    """
    for rec in (x, y):
        if rec.n_components != 1:
            raise InputError(f"{rec.source}: holds {rec.n_components} components; a pair joins one-component "
                             "files (give a two-column file on its own)")
    if not abs(x.dt - y.dt) <= 1e-6 * x.dt:
        raise InputError(f"{x.source} is sampled every {x.dt:g} s, {y.source} every {y.dt:g} s; resample one "
                         f"(sbib records resample FILE --step {x.dt:g}) before joining them")
    for rec in (x, y):
        if is_vertical_label(rec.labels[0]):
            raise InputError(f"{rec.source}: component {rec.labels[0]!r} is the vertical; a pair takes the two "
                             "horizontal directions (the building is excited horizontally)")
    sensors = [r.metadata.get("sensor") for r in (x, y)]
    if all(sensors) and sensors[0] != sensors[1]:
        raise InputError(f"{x.source} is a {sensors[0]} sensor, {y.source} a {sensors[1]} one (KiK-net's two "
                         "instruments); a pair takes two components of one instrument")
    if x.labels[0].strip().upper() == y.labels[0].strip().upper() and x.labels[0] not in ("component 1",):
        raise InputError(f"{x.source} and {y.source} are both component {x.labels[0]!r}; a pair takes the two "
                         "horizontal directions")
    starts = [r.metadata.get("record_time") or r.metadata.get("first_sample") for r in (x, y)]
    if all(starts) and starts[0] != starts[1]:
        raise InputError(f"{x.source} starts at {starts[0]} and {y.source} at {starts[1]}; the components of a "
                         "pair must start together")
    n = max(x.n_samples, y.n_samples)
    acc = np.zeros((n, 2))
    acc[:x.n_samples, 0] = np.asarray(x.acceleration)[:, 0]
    acc[:y.n_samples, 1] = np.asarray(y.acceleration)[:, 0]
    notes = [f"x: {x.labels[0]} from {Path(x.source).name}", f"y: {y.labels[0]} from {Path(y.source).name}"]
    for rec in (x, y):
        if rec.n_samples < n:
            notes.append(f"{Path(rec.source).name} is {n - rec.n_samples} samples shorter, padded with zeros at its end")
    stations = [r.metadata.get("station") for r in (x, y)]
    if all(stations) and stations[0] != stations[1]:
        notes.append(f"components from two stations ({stations[0]}, {stations[1]})")
    same = all(stations) and stations[0] == stations[1]
    units = [units_assumed(r) for r in (x, y)]
    meta = {"format": "+".join(str(r.metadata.get("format", "?")) for r in (x, y)), "columns": "; ".join(notes),
            "source_files": [x.source, y.source],
            "units_in_file": x.metadata.get("units_in_file") if units[0] == units[1] else None,
            "units_assumed": units[0] if units[0] == units[1] else f"x: {units[0]}; y: {units[1]}"}
    for key in ("event", "origin", "event_name", "station", "record_time", "first_sample", "magnitude"):
        if x.metadata.get(key) and (key != "station" or same):
            meta[key] = x.metadata[key]
    name = str(stations[0]) if same else f"{x.name}{PAIR_SEPARATOR}{y.name}"
    return Record(name=name, dt=x.dt, acceleration=acc, labels=(x.labels[0], y.labels[0]),
                  source=f"{x.source} {PAIR_SEPARATOR} {y.source}", metadata=meta)


def _orient_file_record(record: Record, orientation: str) -> Record:
    acc = np.asarray(record.acceleration, dtype=float)
    # a reader that took the components out of the file's order says where each came from
    column = record.metadata.get("file_columns") or list(range(1, acc.shape[1] + 1))
    if acc.shape[1] == 1:
        if record.labels and is_vertical_label(record.labels[0]):
            raise InputError(f"{record.source}: its one component, {record.labels[0]!r}, is the vertical; the building "
                             "is excited horizontally: give a horizontal component, or two as FILE_X+FILE_Y")
        zeros = np.zeros_like(acc)
        both = np.hstack([acc, zeros]) if orientation == "FN-x" else np.hstack([zeros, acc])
        label = tuple(record.labels)[0] if record.labels else "component"
        labels = (label, "zero") if orientation == "FN-x" else ("zero", label)
        record = record.replace(acceleration=both, labels=labels)
        meta = dict(record.metadata, x_file_column=column[0] if orientation == "FN-x" else None,
                    y_file_column=None if orientation == "FN-x" else column[0])
    else:
        order = [0, 1] if orientation == "FN-x" else [1, 0]
        labels = tuple(record.labels)
        record = record.select(order)
        meta = dict(record.metadata, x_file_column=column[order[0]], y_file_column=column[order[1]])
        if acc.shape[1] > 2:  # the building takes two horizontal components: say which were left
            left = ", ".join(f"{labels[i]} (acceleration column {column[i]})" for i in range(2, acc.shape[1]))
            note = f"components past the first two not used: {left}"
            meta["columns"] = f"{meta['columns']}; {note}" if meta.get("columns") else note
    meta["orientation"] = orientation
    return record.replace(metadata=meta)


def resolve_record(spec: str | os.PathLike, orientation: str = "FN-x", records_dir: str | os.PathLike | None = None,
                   baseline_correct: bool = False, format: str = "auto", dt: float | None = None,
                   units: str | None = None, synthetic: bool = False, seed: int = 0) -> Record:
    """Load a record by benchmark name or file path, oriented as asked (component 0 on x, 1 on y).

    Parameters
    ----------
    spec : str or path-like
        A benchmark record name (:data:`records.BENCHMARK_RECORDS`, ``erzincan`` accepted) or a
        record file in any format :func:`records.readers.load_record` reads.
    orientation : str
        ``FN-x``, ``FP-x`` or the seed paper's ``FP-y`` (= FN-x), ``FN-y`` (= FP-x).
    records_dir : path-like, optional
        Directory of the benchmark's files (names only).
    baseline_correct : bool
        Apply :func:`records.baseline.baseline_correct`.
    format : {"auto", "benchmark", "at2", "single", "csv", "knet", "esm", "cosmos"}
        File format (files only; both files of a pair ``FILE_X+FILE_Y``).
    dt : float, optional
        Time step [s] (files only): required for single-column files, checked against the others.
    units : str, optional
        Units of the file's values (files only), e.g. ``"g"``, ``"cm/s2"``; see
        :func:`records.readers.unit_factor`.
    synthetic : bool
        Return the synthetic benchmark-like record (:func:`records.synthetic.benchmark_like`)
        of the named benchmark record instead of the recorded one.
    seed : int
        Seed of the synthetic record.

    Returns
    -------
    Record
        Two components [m/s²] (x, y), with ``metadata["orientation"]`` (canonical FN-x or FP-x),
        ``metadata["units_assumed"]`` and ``metadata["flaws"]`` (messages).

    Raises
    ------
    InputError
        Unknown name or orientation, malformed file, options that do not apply.
    DataNotFoundError
        The file, or the benchmark records directory, does not exist.
    """

    orientation = canonical_orientation(orientation)
    text = str(spec)
    if not looks_like_file(text):
        try:
            canonical_name(text)
        except InputError:
            raise InputError(f"record {text!r} is neither a benchmark record ({', '.join(BENCHMARK_RECORDS)}; "
                             "erzincan accepted) nor an existing file") from None
        if dt is not None or units is not None or format not in (None, "auto"):
            raise InputError(f"record {text!r}: --dt, --units and --format apply to record files; the "
                             "benchmark records' step and units are known")
        if synthetic:
            record = benchmark_like(canonical_name(text), orientation, seed=seed)
            meta = dict(record.metadata)
            meta.setdefault("flaws", [f.message for f in check_record(record)])
        else:
            record = load_benchmark_record(text, orientation=orientation, records_dir=records_dir)
            meta = dict(record.metadata)
    else:
        if synthetic:
            raise InputError(f"--synthetic needs a benchmark record name, got the file {text!r}")

        parts = []
        for path in record_files(text):
            if not path.is_file():
                raise DataNotFoundError(f"record {path}: file not found" if not path.exists()
                                        else f"record {path}: not a regular file")
            parts.append(load_record(path, format=format or "auto", dt=dt, units=units))
        assumed = [unit_not_stated(p) for p in parts]
        record = join_components(*parts) if len(parts) == 2 else parts[0]
        meta = dict(record.metadata)
        meta["flaws"] = [a for a in assumed if a] + [f.message for f in check_record(record)]
        record = _orient_file_record(record.replace(metadata=meta), orientation)
        meta = dict(record.metadata)
    meta["units_assumed"] = units_assumed(record)
    record = record.replace(metadata=meta)
    if baseline_correct:
        record = _correct(record)
    return record
