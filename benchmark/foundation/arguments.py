"""Checks of scalar arguments, in one place for the command line and the libraries.

Two kinds of the same checks:

* :func:`positive` for the libraries (:mod:`damper.lab`): a value named in the message, an
  :class:`~benchmark.foundation.errors.InputError` when it is not a finite number above (or at)
  zero;
* ``argparse`` types for the commands (:mod:`benchmark.applications`): :func:`positive_int`
  (a count such as ``--jobs``), :func:`nonnegative`, :func:`fraction` (open interval, a held-out
  share) and :func:`fraction_from_zero`. They raise :class:`argparse.ArgumentTypeError`, which the
  project's parser prints as one ``sbib: error: argument --NAME: ...`` line (exit status 2).
"""

from __future__ import annotations

import argparse
import math

from benchmark.foundation.errors import InputError

__all__ = ["positive", "positive_int", "nonnegative", "fraction", "fraction_from_zero"]


def positive(name: str, value, strict: bool = True) -> float:
    """``value`` as a finite float above zero (``strict``) or at or above zero.

    Parameters
    ----------
    name : str
        The argument's name, for the message.
    value : object
        Anything ``float`` accepts.
    strict : bool
        Refuse zero too.

    Raises
    ------
    InputError
        Not a number, not finite, or below the bound.
    """
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name}: expected a number, got {value!r}") from None
    if not math.isfinite(number) or (number <= 0 if strict else number < 0):
        raise InputError(f"{name}: expected a finite number {'>' if strict else '>='} 0, got {number}")
    return number


def _number(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None


def positive_int(text: str) -> int:
    """``argparse`` type: a whole number >= 1 (a count of processes, iterations, samples).

    Parameters
    ----------
    text : str
        The command line's text.
    """
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, got {text}")
    return value


def nonnegative(text: str) -> float:
    """``argparse`` type: a finite number >= 0.

    Parameters
    ----------
    text : str
        The command line's text.
    """
    value = _number(text)
    if not (math.isfinite(value) and value >= 0):
        raise argparse.ArgumentTypeError(f"expected a finite number >= 0, got {text}")
    return value


def _fraction(text: str, zero: bool) -> float:
    # the two fraction types differ only in whether 0 is admitted
    value = _number(text)
    if not ((0.0 <= value if zero else 0.0 < value) and value < 1.0):
        bound = "0 <= fraction < 1" if zero else "a fraction between 0 and 1"
        raise argparse.ArgumentTypeError(f"expected {bound}, got {text!r}")
    return value


def fraction(text: str) -> float:
    """``argparse`` type: a fraction strictly between 0 and 1 (a held-out share).

    Parameters
    ----------
    text : str
        The command line's text.
    """
    return _fraction(text, zero=False)


def fraction_from_zero(text: str) -> float:
    """``argparse`` type: a fraction in [0, 1) (0: nothing held out).

    Parameters
    ----------
    text : str
        The command line's text.
    """
    return _fraction(text, zero=True)
