"""The scalar checks shared by the commands and the libraries (benchmark/foundation/arguments.py).

Before they were shared, ``--jobs`` was checked in three commands with three messages and not at
all in ``sbib identify``, and ``--holdout`` accepted 0 in one command and not in the other
without saying why; tests/reliability/test_cli_error_exits.py runs the commands themselves."""

from __future__ import annotations

import argparse
import math

import pytest

from benchmark.foundation.arguments import fraction, fraction_from_zero, nonnegative, positive, positive_int
from benchmark.foundation.errors import InputError


@pytest.mark.parametrize("text, value", [("1", 1), ("16", 16)])
def test_positive_int_takes_whole_numbers_from_one(text, value):
    assert positive_int(text) == value


@pytest.mark.parametrize("text", ["0", "-2", "1.5", "two", "", "nan"])
def test_positive_int_refuses_the_rest(text):
    with pytest.raises(argparse.ArgumentTypeError, match="whole number >= 1"):
        positive_int(text)


def test_fractions_differ_only_at_zero():
    assert fraction("0.3") == 0.3 and fraction_from_zero("0.3") == 0.3
    assert fraction_from_zero("0") == 0.0
    for bad in ("0", "1", "-0.1", "nan", "inf"):
        with pytest.raises(argparse.ArgumentTypeError):
            fraction(bad)
    for bad in ("1", "-0.1", "nan"):
        with pytest.raises(argparse.ArgumentTypeError):
            fraction_from_zero(bad)
    with pytest.raises(argparse.ArgumentTypeError, match="expected a number"):
        fraction("half")


def test_nonnegative_refuses_negative_and_non_finite():
    assert nonnegative("0") == 0.0 and nonnegative("2.5") == 2.5
    for bad in ("-1e-9", "inf", "nan"):
        with pytest.raises(argparse.ArgumentTypeError, match=">= 0"):
            nonnegative(bad)


def test_positive_names_the_argument_and_honours_strict():
    assert positive("amplitude", "0.1") == 0.1
    assert positive("noise", 0, strict=False) == 0.0
    with pytest.raises(InputError, match=r"^amplitude: expected a finite number > 0, got 0\.0$"):
        positive("amplitude", 0)
    with pytest.raises(InputError, match=r"noise: expected a finite number >= 0"):
        positive("noise", -1, strict=False)
    with pytest.raises(InputError, match="cycles: expected a number, got 'many'"):
        positive("cycles", "many")
    with pytest.raises(InputError):
        positive("frequency", math.inf)
