"""Units that users' files bring, converted to SI at the edge: one table for every reader.

A test rig's logger writes millimetres, kilonewtons, pounds-force or milliamperes as often as SI;
the readers of damper tests (:mod:`damper.io.data`), of force histories
(:mod:`damper.hysteresis.files`) and of ground motions (:mod:`records.readers`) look a unit up
here and multiply by its factor, so that everything past the reader is SI.

Units are matched without regard to case or spaces (``kN``, ``KN``, ``mm / s``), and ``²`` is read
as ``^2``. The exact factors: 1 in = 0.0254 m, 1 lbf = 4.4482216152605 N (the international
pound times standard gravity), 1 kip = 1000 lbf, 1 kgf = 9.80665 N, 1 g = 9.80665 m/s²
(NIST Special Publication 811, 2008, appendix B).
"""

from __future__ import annotations

import re

from benchmark.foundation.errors import InputError

__all__ = ["COLUMN_ALIASES", "QUANTITY_UNITS", "SI_UNIT", "STANDARD_GRAVITY", "column_name_unit", "si_factor",
           "unit_key"]

#: Standard gravity [m/s²] (CGPM 1901; NIST SP 811).
STANDARD_GRAVITY = 9.80665

_INCH = 0.0254
_LBF = 4.4482216152605

#: The SI unit each quantity is held in past the readers.
SI_UNIT = {"time": "s", "length": "m", "velocity": "m/s", "acceleration": "m/s2", "force": "N",
           "voltage": "V", "current": "A"}


def _per_second(lengths: dict[str, float]) -> dict[str, float]:
    return {f"{u}/{s}": f for u, f in lengths.items() for s in ("s", "sec")}


def _per_second_squared(lengths: dict[str, float]) -> dict[str, float]:
    out = {}
    for u, f in lengths.items():
        for s in ("s", "sec"):
            for sq in (f"{s}2", f"{s}^2", f"{s}**2", f"{s}/{s}"):
                out[f"{u}/{sq}"] = f
    return out


_LENGTHS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3, "in": _INCH}

#: Accepted units per quantity (keys as :func:`unit_key` writes them) and their factor to SI.
QUANTITY_UNITS: dict[str, dict[str, float]] = {
    "time": {"s": 1.0, "sec": 1.0, "ms": 1e-3},
    "length": dict(_LENGTHS),
    "velocity": _per_second(_LENGTHS),
    # the records' units: g, m/s2 and its spellings, cm/s2 (gal), mm/s2
    "acceleration": {"g": STANDARD_GRAVITY, "gal": 1e-2,
                     **_per_second_squared({"m": 1.0, "cm": 1e-2, "mm": 1e-3})},
    "force": {"n": 1.0, "kn": 1e3, "lbf": _LBF, "lb": _LBF, "kip": 1e3 * _LBF, "kgf": STANDARD_GRAVITY},
    "voltage": {"v": 1.0, "mv": 1e-3},
    "current": {"a": 1.0, "ma": 1e-3},
}

#: What an error message lists as accepted, per quantity.
_EXPECTED = {"time": "s, ms", "length": "m, cm, mm, in", "velocity": "m/s, cm/s, mm/s, in/s",
             "acceleration": "g, m/s2, cm/s2 (gal), mm/s2", "force": "N, kN, lbf, kip, kgf",
             "voltage": "V, mV", "current": "A, mA"}


def unit_key(unit: str) -> str:
    """The spelling a unit is looked up by: lower case, no spaces, ``²`` as ``^2``.

    Parameters
    ----------
    unit : str
        A unit as a file writes it (``"mm / s"``, ``"m/s²"``, ``"kN"``).
    """
    return "".join(str(unit).split()).lower().replace("²", "^2")  # any whitespace, NBSP included


def si_factor(quantity: str, unit: str, where: str = "units") -> float:
    """Return the factor that converts a value of ``quantity`` in ``unit`` to SI.

    Parameters
    ----------
    quantity : str
        One of ``time``, ``length``, ``velocity``, ``acceleration``, ``force``, ``voltage``,
        ``current`` (:data:`SI_UNIT`).
    unit : str
        The unit as written (matched by :func:`unit_key`).
    where : str
        What to name in the error message (a file and line, an option).

    Returns
    -------
    float
        The SI value is the file's value times this factor.

    Raises
    ------
    InputError
        A unit this quantity does not accept; the message lists those it does.
    """
    table = QUANTITY_UNITS[quantity]
    try:
        return table[unit_key(unit)]
    except KeyError:
        raise InputError(f"{where}: unknown {quantity} unit {unit!r}; expected one of "
                         f"{_EXPECTED[quantity]}") from None


#: Other names loggers give the columns of a test (matched without regard to case).
COLUMN_ALIASES = {"t": "time", "disp": "displacement", "x": "displacement", "position": "displacement",
                  "stroke": "displacement", "vel": "velocity", "xdot": "velocity", "speed": "velocity", "f": "force",
                  "load": "force", "tout": "time", "timestamp": "time", "datetime": "time"}

_COLUMN = re.compile(r"([A-Za-z_]+)\s*(?:\[\s*([^\]]*)\s*\]|\(\s*([^)]*)\s*\))?")


def column_name_unit(cell: str) -> tuple[str, str | None] | None:
    """Split a header cell into the column's name and the unit written with it.

    ``"disp [mm]"``, ``"Disp (mm)"`` and ``'"load"'`` give ``("displacement", "mm")``,
    ``("displacement", "mm")`` and ``("force", None)``: the name in lower case with a logger's
    alias (:data:`COLUMN_ALIASES`) read as the quantity's name, the unit as written (brackets or
    parentheses) or None where none is. The readers of damper tests and of force histories
    share this rule.

    Parameters
    ----------
    cell : str
        One cell of a CSV header line (quotes and surrounding spaces are ignored).

    Returns
    -------
    tuple or None
        ``(name, unit)``, or None where the cell is not a name with an optional unit.
    """
    text = cell.strip().strip('"').strip("'").strip()
    m = _COLUMN.fullmatch(text)
    if not m:
        return None
    unit = m.group(2) if m.group(2) is not None else m.group(3)
    name = m.group(1).lower()
    return COLUMN_ALIASES.get(name, name), (unit.strip() or None) if unit is not None else None
