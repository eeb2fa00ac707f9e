"""Units in which figures and printed summaries show each kind of quantity (one place).

Everything inside the package is SI; this table says how a quantity is *shown*. Every figure
converts at the edge with :func:`to_display` and labels its axes with :func:`axis_label`, so that
a force reads in kN and a displacement in m in every plot (a damper's diagnosis as much as its
identification or a building's response).

=================  ==========  ===========================================================
kind               shown in    why
=================  ==========  ===========================================================
force              kN          damper and storey forces are 1e3-1e6 N
displacement       m           base and damper strokes are 0.01-0.5 m
velocity           m/s
acceleration       m/s²
voltage            V           command of an MR damper's current driver
current            A           coil current of a measured damper (UTFSM tests)
time               s
stiffness          kN/m        :math:`\\kappa_x`
damping            kN·s/m      :math:`\\kappa_{\\dot x}`
inverse_length     1/m         :math:`\\rho`
inverse_velocity   s/m         :math:`\\beta` of the hyperbolic-tangent model
dimensionless      -           :math:`\\sigma`, :math:`n`, drift ratios, J's
energy             kJ
frequency          Hz
=================  ==========  ===========================================================
"""

from __future__ import annotations

from typing import Any

import numpy as np

from benchmark.foundation.errors import InputError

__all__ = ["DISPLAY_UNITS", "SI_UNITS", "PARAMETER_KINDS", "display_unit", "to_display", "axis_label",
           "si_unit", "parameter_kind", "format_si"]

#: kind -> (unit shown, factor from SI to the shown unit)
DISPLAY_UNITS: dict[str, tuple[str, float]] = {
    "force": ("kN", 1e-3),
    "displacement": ("m", 1.0),
    "velocity": ("m/s", 1.0),
    "acceleration": ("m/s²", 1.0),
    "voltage": ("V", 1.0),
    "current": ("A", 1.0),
    "time": ("s", 1.0),
    "stiffness": ("kN/m", 1e-3),
    "damping": ("kN·s/m", 1e-3),
    "inverse_length": ("1/m", 1.0),
    "inverse_velocity": ("s/m", 1.0),
    "dimensionless": ("-", 1.0),
    "energy": ("kJ", 1e-3),
    "frequency": ("Hz", 1.0),
}

#: kind -> SI unit (for printed values and files)
SI_UNITS: dict[str, str] = {
    "force": "N", "displacement": "m", "velocity": "m/s", "acceleration": "m/s^2", "voltage": "V",
    "current": "A", "time": "s", "stiffness": "N/m", "damping": "N s/m", "inverse_length": "1/m",
    "inverse_velocity": "s/m", "dimensionless": "-", "energy": "J", "frequency": "Hz",
}

#: kind of each named MR-damper model parameter (Bouc-Wen family, DOMAIN.md §3)
PARAMETER_KINDS: dict[str, str] = {
    "kappa_x": "stiffness", "kappa_xdot": "damping", "kappa_w": "force", "rho": "inverse_length",
    "sigma": "dimensionless", "n": "dimensionless",
    "c": "damping", "k": "stiffness", "alpha": "force", "beta": "inverse_velocity", "delta": "dimensionless",
    "f0": "force", "f_c": "force", "c0": "damping",
}


def _check(kind: str) -> None:
    if kind not in DISPLAY_UNITS:
        raise InputError(f"unknown quantity kind {kind!r}; expected one of {', '.join(DISPLAY_UNITS)}")


def display_unit(kind: str) -> str:
    """The unit a figure shows quantities of ``kind`` in (e.g. ``"kN"`` for ``"force"``).

    Parameters
    ----------
    kind : str
        Quantity kind (e.g. ``"force"``, ``"displacement"``, ``"acceleration"``).
    """
    _check(kind)
    return DISPLAY_UNITS[kind][0]


def si_unit(kind: str) -> str:
    """The SI unit of ``kind`` (e.g. ``"N"`` for ``"force"``).

    Parameters
    ----------
    kind : str
        Quantity kind (e.g. ``"force"``, ``"displacement"``, ``"acceleration"``).
    """
    _check(kind)
    return SI_UNITS[kind]


def to_display(value: Any, kind: str) -> Any:
    """``value`` (SI) converted to the display unit of ``kind`` (arrays stay arrays).

    Parameters
    ----------
    value : Any
        A number or array in SI units.
    kind : str
        Quantity kind (e.g. ``"force"``, ``"displacement"``, ``"acceleration"``).
    """
    _check(kind)
    factor = DISPLAY_UNITS[kind][1]
    if np.ndim(value) == 0:
        return float(value) * factor
    return np.asarray(value, dtype=float) * factor


def axis_label(text: str, kind: str) -> str:
    """``"text [unit]"`` with the display unit of ``kind``, e.g. ``"force [kN]"``.

    Parameters
    ----------
    text : str
        The axis text without the unit.
    kind : str
        Quantity kind (e.g. ``"force"``, ``"displacement"``, ``"acceleration"``).
    """
    return f"{text} [{display_unit(kind)}]"


def parameter_kind(name: str) -> str:
    """The quantity kind of a model parameter (``"dimensionless"`` when unknown).

    Parameters
    ----------
    name : str
        A model parameter name (e.g. ``"kappa_x"``).
    """
    return PARAMETER_KINDS.get(name, "dimensionless")


def format_si(name: str, value: float, digits: int = 4) -> str:
    """``"name = value unit"`` in SI for a model parameter, e.g. ``"kappa_x = 4.156e-10 N/m"``.

    Parameters
    ----------
    name : str
        A model parameter name (e.g. ``"kappa_x"``).
    value : float
        A number or array in SI units.
    digits : int, optional
        Significant digits.
    """
    unit = si_unit(parameter_kind(name))
    text = f"{name} = {value:.{digits}g}"
    return text if unit == "-" else f"{text} {unit}"
