"""The one entry for a damper-test file of any supported format: :func:`read_test`.

``sbib diagnose --data/--validate``, ``sbib identify --data`` and the Python API read tests through
it, so every command accepts the same formats and screens them the same way
(:mod:`damper.io.screening`):

* a MATLAB (``.mat``) or HDF5 (``.h5``, ``.hdf5``) file of named vectors, recognised by its
  suffix (:func:`damper.io.arrays.read_arrays`);
* a UTFSM preprocessed ``.txt`` file, recognised by its name pattern
  (:func:`damper.io.data.read_utfsm`);
* a Dyke random-voltage record, recognised by its header (``t`` and at least three of
  ``D, Y, V, F``; :mod:`damper.io.dyke`);
* a raw UTFSM logger export, recognised by its ``Header Size:`` line
  (:func:`damper.io.data.read_utfsm_raw`): an export of one coil current, named for it
  (``15Hz1A.txt``), is that current's test; of an export of the five currents back to back
  (``Datos_crudos/ME*.txt``) :func:`read_tests` gives one test per current
  (:func:`damper.io.data.split_utfsm_raw`), :func:`read_test` the whole file without its current;
* otherwise a damper CSV with units in its header (:func:`damper.io.data.read_csv`).
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from benchmark.foundation.errors import InputError
from damper.io.data import (DamperTest, is_utfsm_raw_file, parse_utfsm_name, read_csv, read_csv_parts, read_utfsm,
                            read_utfsm_raw, split_utfsm_raw)
from damper.io.arrays import is_array_file, read_arrays
from damper.io.dyke import looks_like_dyke_file, read_dyke
from damper.io.screening import CLIPPED_FORCE_SHARE, clipped_force_share, next_reversal, screening_of

__all__ = ["read_test", "read_tests", "read_usable", "require_samples", "unique_names", "check_coil_inputs", "count_reversals", "MIN_SAMPLES"]

#: Fewest samples, and fewest usable (unflagged) samples, of a test worth a fit (the
#: screening's own floor; the diagnosis differentiates the velocity, which needs three).
MIN_SAMPLES = 10


def read_test(path, keep_flagged: bool = False) -> DamperTest:
    """Read one damper test, screened; the format is recognised from the file (module docstring).

    Parameters
    ----------
    path : str or Path
        A MATLAB or HDF5 file of named vectors, a UTFSM preprocessed ``.txt`` file, a Dyke CSV or a
        damper CSV.
    keep_flagged : bool
        Keep the samples the screening flags in fits and errors (the findings are still reported).

    Returns
    -------
    DamperTest
        The test in SI units, with the screening's findings and mask in its metadata.

    Raises
    ------
    InputError
        A file that cannot be read as any of the formats (the message names the file and line).
    """
    p = Path(path)
    kind = _file_format(p)
    if kind == "arrays":
        return read_arrays(p, keep_flagged=keep_flagged)
    if kind == "utfsm":
        return read_utfsm(p, keep_flagged=keep_flagged)
    if kind == "dyke":
        return read_dyke(p, keep_flagged=keep_flagged)
    if kind == "utfsm_raw":
        return read_utfsm_raw(p, keep_flagged=keep_flagged)
    return read_csv(p, keep_flagged=keep_flagged)


def _file_format(p: Path) -> str:
    """Which reader a damper-test file is for (module docstring): ``arrays``, ``utfsm``, ``dyke``,
    ``utfsm_raw`` or ``csv``."""
    if is_array_file(p):
        return "arrays"
    if p.suffix.lower() == ".txt":
        try:
            parse_utfsm_name(p)
        except InputError:
            pass
        else:
            return "utfsm"
    if p.is_file() and looks_like_dyke_file(p):  # a Dyke header, complete or not (read_dyke names what is missing)
        return "dyke"
    if p.is_file() and is_utfsm_raw_file(p):
        return "utfsm_raw"
    return "csv"


def read_tests(path, keep_flagged: bool = False) -> list[DamperTest]:
    """The tests of one file: a raw UTFSM logger export of the five coil currents gives one per
    current (:func:`damper.io.data.split_utfsm_raw`), any other file (a raw export named for its one
    current among them) its one test (:func:`read_test`).

    Parameters
    ----------
    path : str or Path
        A damper-test file of any supported format.
    keep_flagged : bool
        Keep the samples the screening flags in fits and errors (the findings are still reported).

    Raises
    ------
    InputError
        As :func:`read_test`; a raw export whose spans of motion are not one per current.
    """
    p = Path(path)
    kind = _file_format(p)
    if kind == "utfsm_raw":
        test = read_utfsm_raw(p, keep_flagged=keep_flagged)
        return [test] if test.current is not None else split_utfsm_raw(test, keep_flagged=keep_flagged)
    if kind == "csv":
        return read_csv_parts(p, keep_flagged=keep_flagged)  # one test per recording where the clock restarts
    return [read_test(p, keep_flagged=keep_flagged)]


def count_reversals(x: np.ndarray, most: int = 2, hysteresis: float = 0.05) -> int:
    """Displacement reversals of ``x``, counted up to ``most`` (the screening's trigger,
    :func:`damper.io.screening.next_reversal`: a return by ``hysteresis`` of the stroke).

    Parameters
    ----------
    x : np.ndarray
        Displacement history [m].
    most : int
        Stop counting here (2: whether the test holds a cycle of motion).
    hysteresis : float
        Return, as a fraction of the stroke, that counts as a reversal.
    """
    turns, at = 0, 0
    while turns < most and (at := next_reversal(x, at, hysteresis)) < x.size:
        turns, at = turns + 1, at + 1
    return turns


def check_coil_inputs(labelled: list, what: str) -> bool:
    """Whether the tests record their coil input; refuse a mix of tests with and without it.

    Parameters
    ----------
    labelled : list of (str, DamperTest)
        Each test with the name a message gives it.
    what : str
        The message's prefix (``"diagnose"``, ``"--data"``).

    Returns
    -------
    bool
        False when no test has a voltage or current column (a passive test at 0 V, said by the
        caller).

    Raises
    ------
    InputError
        Some tests have the column and others not: 0 V beside recorded levels would be a level
        nobody measured.
    """
    missing = [label for label, test in labelled
               if getattr(test, "voltage", None) is None and getattr(test, "current", None) is None]
    if missing and len(missing) < len(labelled):
        kind = "voltage" if any(getattr(t, "voltage", None) is not None for _, t in labelled) else "current"
        raise InputError(f"{what}: {', '.join(missing)}: no voltage or current column, while the other tests "
                         f"give the {kind}; expected the coil input in every file (a column of 0 for a passive test)")
    return not missing


def require_samples(test: DamperTest, path, minimum: int = MIN_SAMPLES) -> DamperTest:
    """Return ``test``, or refuse it in one line when it is too short to fit or the screening
    leaves too few usable samples (before a fit meets the gap deeper down).

    Parameters
    ----------
    test : DamperTest
        A test read by :func:`read_test`.
    path : str or Path
        Its file, for the message.
    minimum : int
        Fewest samples, and fewest usable samples, accepted.

    Raises
    ------
    InputError
        Fewer than ``minimum`` samples, fewer than ``minimum`` usable ones (the message sums up
        the screening's findings), a force clipped over more than :data:`CLIPPED_FORCE_SHARE` of
        the test, or amplitudes no MR damper test has (a ``units`` finding:
        a time in ms, a stroke in mm read as SI), or a force that does net negative work on
        the motion (a ``polarity`` finding: the force's sign inverted against the displacement).
    """
    if test.n_samples < minimum:
        raise InputError(f"{path}: {test.n_samples} samples; expected at least {minimum} (a test of a few "
                         "cycles of motion)")
    screening = screening_of(test)
    usable = int(test.usable.sum())
    if usable < minimum:
        steps = np.diff(np.asarray(test.time, dtype=float))
        median = float(np.median(steps))
        irregular = float(np.mean(np.abs(steps - median) > 0.5 * median))
        if irregular > 0.1:
            # the gap and settling findings of a file sampled at random instants say less than this
            raise InputError(f"{path}: the sampling is not uniform: {100 * irregular:.0f} % of the steps differ "
                             f"from the median {1e3 * median:.3g} ms by more than half of it (steps "
                             f"{1e3 * float(steps.min()):.3g}-{1e3 * float(steps.max()):.3g} ms); resample the test "
                             "onto a uniform grid")
        raise InputError(f"{path}: the screening leaves {usable} of {test.n_samples} samples usable, fewer "
                         f"than {minimum} ({screening.brief()}; --keep-flagged fits the flagged samples too)")
    clipped = clipped_force_share(test)
    if clipped > CLIPPED_FORCE_SHARE:
        raise InputError(f"{path}: the force is clipped over {100 * clipped:.0f} % of the test ({screening.brief()}): "
                         "its peaks are not measured, and a model fitted on the rest extrapolates past the clip "
                         "level; give a test within the load cell's range (--keep-flagged fits the clipped values as "
                         "measured)")
    units = screening.units_problem()
    if units is not None and (turns := count_reversals(np.asarray(test.displacement, dtype=float))) < 2:
        # less than a cycle: its amplitude and rate say nothing of the units
        duration = float(test.time[-1] - test.time[0])
        raise InputError(f"{path}: the displacement reverses {turns} time(s) in {duration:.3g} s of "
                         f"{test.n_samples} samples; expected a test of at least one cycle of motion")
    if units is not None:
        # a time in ms or a stroke in mm read as SI: any fit would be of the wrong device
        raise InputError(f"{path}: implausible units ({units}); give each column's unit in the header "
                         "(time [ms], disp [mm], vel [mm/s], force [kN]: converted on reading) or "
                         "convert the file to SI")
    polarity = screening.polarity_problem()
    if polarity is not None:
        # every model of the library dissipates: a fit would only find the parameters' bounds
        raise InputError(f"{path}: {polarity}")
    return test


def read_usable(paths, keep_flagged: bool = False) -> list[tuple[str, DamperTest]]:
    """Every test of ``paths`` (:func:`read_tests`: a raw UTFSM export of the five currents gives
    one per current), each checked by :func:`require_samples`, with its file as given: what the
    commands fit and score, read before any fit so that a bad file stops them in one line.

    Parameters
    ----------
    paths : sequence of str or Path
        Damper-test files of any supported format.
    keep_flagged : bool
        Keep the samples the screening flags in fits and errors.
    """
    return [(str(p), require_samples(t, p)) for p in paths for t in read_tests(p, keep_flagged=keep_flagged)]


def unique_names(loaded: list) -> list:
    """``(label, test)`` pairs with every test's name unique: two files with one ``# name:`` line
    or one stem (``a/val.csv``, ``b/val.csv``) would otherwise share a held-out or validation
    entry and a figure; a later one gets its label (its file) after its name.

    Parameters
    ----------
    loaded : list of (str, DamperTest)
        Each test with the label that tells it apart (its file as given).
    """
    seen: set[str] = set()
    out = []
    for label, test in loaded:
        name, k = test.name, 2
        while name in seen:
            name = f"{test.name} ({label})" if k == 2 else f"{test.name} ({label}, {k - 1})"
            k += 1
        if name != test.name:
            test = dataclasses.replace(test, name=name)
        seen.add(name)
        out.append((label, test))
    return out
