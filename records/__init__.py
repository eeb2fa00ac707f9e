"""Ground-motion records: readers, the benchmark catalogue, checks, spectra and a synthetic generator.

Main API (all accelerations in m/s², times in s)::

    from records import load_benchmark_record, load_record, benchmark_like, response_spectrum
    rec = load_benchmark_record("kobe", orientation="FN-x")     # two components, x then y
    own = load_record("my_record.AT2")                          # PEER .AT2, benchmark, single-column, CSV
    syn = benchmark_like("kobe", "FN-x", seed=0)                # synthetic, labelled as such
    spec = response_spectrum(rec)                               # 5 %-damped spectra

Importing this package does not import the simulator.
"""

from records.baseline import baseline_correct
from records.catalogue import (
    ALIASES,
    BENCHMARK_RECORDS,
    CATALOGUE,
    ORIENTATION_ALIASES,
    ORIENTATION_HELP,
    ORIENTATIONS,
    SEED_ORIENTATION_NAMES,
    CatalogueEntry,
    canonical_orientation,
    canonical_name,
    check_catalogue,
    get_entry,
    load_benchmark_record,
    record_path,
)
from records.checks import Flaw, check_record
from records.readers import FORMATS, detect_format, load_record, unit_factor, write_csv
from records.record import STANDARD_GRAVITY, Record
from records.spectra import ResponseSpectrum, response_spectrum
from records import synthetic
from records.synthetic import benchmark_like, benchmark_like_set

__all__ = [
    "Record",
    "STANDARD_GRAVITY",
    "load_record",
    "detect_format",
    "write_csv",
    "unit_factor",
    "FORMATS",
    "load_benchmark_record",
    "record_path",
    "check_catalogue",
    "canonical_name",
    "get_entry",
    "CatalogueEntry",
    "CATALOGUE",
    "BENCHMARK_RECORDS",
    "ORIENTATIONS",
    "ORIENTATION_ALIASES",
    "SEED_ORIENTATION_NAMES",
    "ORIENTATION_HELP",
    "canonical_orientation",
    "ALIASES",
    "Flaw",
    "check_record",
    "baseline_correct",
    "ResponseSpectrum",
    "response_spectrum",
    "synthetic",
    "benchmark_like",
    "benchmark_like_set",
]
