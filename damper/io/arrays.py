"""Damper tests in MATLAB (``.mat``) and HDF5 (``.h5``, ``.hdf5``) files: named vectors.

A test is a set of equally long numeric vectors named as the CSV columns are
(:func:`damper.io.data.column_of`): ``time``, ``displacement``, ``force`` and, optionally,
``velocity`` and one of ``voltage`` or ``current``, or a loggers' name (``t``, ``disp``, ``x``,
``position``, ``stroke``, ``vel``, ``xdot``, ``speed``, ``f``, ``load``), in any case, with a
unit after an underscore (``force_kN``, ``disp_mm``). In HDF5 a dataset's ``units`` (or
``unit``) attribute gives its unit (``force`` with ``units = "kN"``), as the project's own result
files write it. A ``voltage`` or ``current`` that is a single number is the test's constant coil
input. A vector without a unit is SI, and the report says what was read as SI. Anything else
(a matrix, text, a channel no damper test uses) is named in the report and not read; a file
without the three required vectors is refused in one line that lists what it holds.

MATLAB files of version 7.3 are HDF5 files and are read as such (MATLAB writes a vector there as
a 1 x n or n x 1 dataset: both are vectors). The variables are read at the file's top level (a
MATLAB workspace, an HDF5 file's root); a group's name selects another level of an HDF5 file.

The test then goes through the same screening as a CSV file (:func:`damper.io.data.build_test`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from benchmark.foundation.errors import DataNotFoundError, InputError
from damper.io.data import DamperTest, build_test, column_of

__all__ = ["ARRAY_SUFFIXES", "is_array_file", "read_arrays"]

#: File suffixes read as named vectors.
ARRAY_SUFFIXES = (".mat", ".h5", ".hdf5")

_EXPECTED = "time, displacement, force[, velocity][, voltage|current]"


def is_array_file(path) -> bool:
    """Whether ``path`` names a MATLAB or HDF5 file (by its suffix).

    Parameters
    ----------
    path : str or Path
        A damper-test file.
    """
    return Path(path).suffix.lower() in ARRAY_SUFFIXES


def _shape(a: np.ndarray) -> str:
    return "x".join(str(n) for n in a.shape) or "scalar"


def _mat_variables(path: Path) -> dict[str, tuple[np.ndarray, str | None]]:
    """The variables of a MATLAB file before version 7.3 (scipy.io), without units."""
    from scipy.io import loadmat  # imported here: the readers load with every command

    try:
        content = loadmat(str(path), squeeze_me=True)
    except NotImplementedError:  # version 7.3: an HDF5 file
        return _h5_variables(path, None)
    except Exception as exc:  # scipy raises ValueError, TypeError, OSError... for a bad file
        raise InputError(f"{path}: not a MATLAB file that can be read ({exc})") from None
    return {k: (np.asarray(v), None) for k, v in content.items() if not k.startswith("__")}


def _h5_variables(path: Path, group: str | None) -> dict[str, tuple[np.ndarray, str | None]]:
    """The datasets of an HDF5 file's root (or ``group``), with their ``units`` attributes."""
    import h5py

    try:
        fh = h5py.File(path, "r")
    except OSError as exc:
        raise InputError(f"{path}: not an HDF5 file that can be read ({exc})") from None
    with fh:
        node = fh if group is None else fh.get(group)
        if not isinstance(node, h5py.Group):
            raise InputError(f"{path}: no group {group!r}; groups at the top: "
                             + ", ".join(k for k in fh if isinstance(fh[k], h5py.Group)))
        out: dict[str, tuple[np.ndarray, str | None]] = {}
        for key, item in node.items():
            if not isinstance(item, h5py.Dataset):
                continue
            unit = item.attrs.get("units", item.attrs.get("unit"))
            if isinstance(unit, bytes):
                unit = unit.decode("utf-8", "replace")
            if unit is not None and not isinstance(unit, str):
                unit = None
            out[key] = (np.asarray(item[()]), unit)
    return out


def read_arrays(path, voltage: float | None = None, current: float | None = None, name: str | None = None,
                keep_flagged: bool = False, group: str | None = None) -> DamperTest:
    """Read a damper test from a MATLAB or HDF5 file of named vectors (module docstring), screened.

    Parameters
    ----------
    path : str or Path
        The ``.mat``, ``.h5`` or ``.hdf5`` file.
    voltage, current : float, optional
        Constant coil voltage [V] or current [A] for a file without that variable.
    name : str, optional
        The test's name (default: the file's stem).
    keep_flagged : bool
        Keep the flagged samples in the mask (only missing values stay out).
    group : str, optional
        The HDF5 group that holds the vectors (default: the root).

    Raises
    ------
    DataNotFoundError
        The file does not exist.
    InputError
        Not such a file, a required vector missing (the message lists what the file holds), two
        variables for one quantity, vectors of different lengths, or a unit the quantity does not
        have.
    """
    path = Path(path)
    if not path.is_file():
        raise DataNotFoundError(f"{path}: damper test file not found")
    if voltage is not None and current is not None:
        raise InputError("read_arrays: give a constant voltage or a current, not both")
    if path.suffix.lower() == ".mat" and group is None:
        variables = _mat_variables(path)
    else:
        variables = _h5_variables(path, group)
    columns: dict[str, np.ndarray] = {}
    source: dict[str, str] = {}
    written: dict[str, str] = {}
    unstated: list[str] = []
    ignored: list[str] = []
    constant: dict[str, float] = {}
    for key, (value, unit) in variables.items():
        cell = key if unit is None else f"{key} [{unit}]"
        where = f"{path}: variable {key!r}"
        try:
            quantity, factor, unit_read = column_of(cell, where, dyke_letters=False)
        except InputError as err:
            try:
                quantity = column_of(key, where, dyke_letters=False)[0]
            except InputError:
                quantity = None  # a name no column rule reads (spaces, symbols): another channel
            if quantity is not None:
                raise err from None  # a test's quantity in a unit it does not have
            factor, unit_read = 1.0, None
        numeric = value.dtype.kind in "fiub"
        data = np.squeeze(value) if numeric else value
        if quantity is None or not numeric or data.ndim > 1:
            ignored.append(f"{key} ({_shape(value)})")
            continue
        if quantity in source:
            raise InputError(f"{path}: variables {source[quantity]!r} and {key!r} both name the {quantity}; "
                             "expected one")
        source[quantity] = key
        if data.ndim == 0:
            if quantity not in ("voltage", "current"):
                ignored.append(f"{key} (scalar)")
                del source[quantity]
                continue
            constant[quantity] = float(data) * factor
            continue
        columns[quantity] = np.asarray(data, dtype=float) * factor  # SI from here on
        if unit_read is not None and factor != 1.0:
            written[quantity] = unit_read
        if unit_read is None and quantity in ("displacement", "force"):
            unstated.append(quantity)
    missing = [c for c in ("time", "displacement", "force") if c not in columns]
    if missing:
        held = ", ".join(f"{k} ({_shape(v)})" for k, (v, _) in variables.items()) or "nothing"
        raise InputError(f"{path}: missing vector(s) {', '.join(missing)}; expected {_EXPECTED} "
                         f"(the file holds: {held})")
    if "voltage" in columns and "current" in columns or "voltage" in constant and "current" in constant:
        raise InputError(f"{path}: expected a voltage or a current, not both")
    lengths = {q: v.size for q, v in columns.items()}
    if len(set(lengths.values())) > 1:
        raise InputError(f"{path}: the vectors differ in length ("
                         + ", ".join(f"{source[q]} {n}" for q, n in lengths.items()) + "); expected one length")
    for quantity, value in constant.items():
        given = voltage if quantity == "voltage" else current
        if given is not None or quantity in columns:
            raise InputError(f"{path}: the file has a {quantity}; do not also give a constant value")
        if quantity == "voltage":
            voltage = value
        else:
            current = value
    metadata: dict = {}
    if written:
        metadata["file_units"] = written
    if unstated:
        metadata["units_unstated"] = unstated
    if ignored:
        metadata["columns_ignored"] = ignored
    return build_test(path, columns, voltage=voltage, current=current, name=name or path.stem,
                      metadata=metadata, keep_flagged=keep_flagged)
