"""Unusual and malformed damper-test files: read right, or refused in one line naming the file."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.foundation.errors import InputError
from damper.io.reader import MIN_SAMPLES, read_test, require_samples

T = np.arange(0.0, 2.0, 0.005)
X = 0.01 * np.sin(2 * np.pi * T)
F = 1e4 * X + 300.0 * np.cos(2 * np.pi * T)


def _write(tmp_path, name, text, bom=False):
    path = tmp_path / name
    path.write_bytes((b"\xef\xbb\xbf" if bom else b"") + text.encode("utf-8"))
    return path


def _rows(sep=",", decimal=".", end=""):
    return "".join(sep.join(f"{v:.6g}".replace(".", decimal) for v in row) + end + "\n"
                   for row in zip(T, X, F))


def _refused(path, words):
    with pytest.raises(InputError) as info:
        read_test(path)
    message = str(info.value)
    assert str(path) in message and "\n" not in message and words in message, message


@pytest.mark.parametrize("name, text", [
    ("semicolons.csv", "time;displacement;force\n" + _rows(";")),
    ("decimal_commas.csv", "time;displacement;force\n" + _rows(";", ",")),
    ("tabs.txt", "time\tdisplacement\tforce\n" + _rows("\t")),
    ("spaces.dat", "time displacement force\n" + _rows(" ")),
    ("parentheses.csv", "time (s),displacement (m),force (N)\n" + _rows()),
    ("trailing_comma.csv", "time,displacement,force,\n" + _rows(end=",")),
    ("quoted.csv", '"time","displacement","force"\n' + _rows()),
])
def test_spreadsheet_exports_read_as_the_same_test(tmp_path, name, text):
    test = read_test(_write(tmp_path, name, text))
    assert test.n_samples == T.size
    np.testing.assert_allclose(test.force, F, rtol=1e-5)
    np.testing.assert_allclose(test.displacement, X, rtol=1e-5, atol=1e-9)


def _dyke(sep=","):
    head = sep.join(f'"{c}"' for c in ("t", "A", "D", "Y", "fs", "V", "F")) + sep + "\n"
    return head + "".join(sep.join(f"{v:.6g}" for v in (t, 0.0, 100 * x, 1.0, 3000.0, 0.0, f)) + sep + "\n"
                          for t, x, f in zip(T, X, F))


@pytest.mark.parametrize("sep, bom", [(",", True), (";", False), ("\t", False)])
def test_dyke_record_with_a_bom_or_saved_by_a_spreadsheet(tmp_path, sep, bom):
    test = read_test(_write(tmp_path, "dyke.csv", _dyke(sep), bom=bom))
    np.testing.assert_allclose(test.displacement, X, rtol=1e-5, atol=1e-9)   # cm -> m: read as Dyke's
    assert test.constant_voltage == 1.0


@pytest.mark.parametrize("sep", [";", "\t"])
def test_dyke_record_saved_with_decimal_commas(tmp_path, sep):
    text = "\n".join(line if i == 0 else line.replace(".", ",")
                     for i, line in enumerate(_dyke(sep).splitlines())) + "\n"
    test = read_test(_write(tmp_path, "dyke_dc.csv", text))
    np.testing.assert_allclose(test.displacement, X, rtol=1e-5, atol=1e-9)
    np.testing.assert_allclose(test.force, F, rtol=1e-5)


def test_dyke_header_without_a_column_names_it(tmp_path):
    text = _dyke().replace('"F",', "", 1)
    _refused(_write(tmp_path, "dyke_noF.csv", text), "missing column(s) F")


def test_headerless_file_says_the_header_is_missing(tmp_path):
    _refused(_write(tmp_path, "data.txt", _rows(" ")), "the first line is data, not a header")


def test_a_directory_is_not_reported_missing(tmp_path):
    (tmp_path / "tests.csv").mkdir()
    _refused(tmp_path / "tests.csv", "not a regular file")


def test_two_samples_without_velocity_read_and_are_refused_for_a_fit(tmp_path):
    # the velocity of a two-sample file was a numpy ValueError (a traceback in sbib diagnose)
    path = _write(tmp_path, "two.csv", "time,displacement,force\n0,0,0\n0.01,0.001,1\n")
    test = read_test(path)
    np.testing.assert_allclose(test.velocity, [0.1, 0.1])
    with pytest.raises(InputError, match=f"2 samples; expected at least {MIN_SAMPLES}"):
        require_samples(test, path)


def test_a_test_the_screening_empties_is_refused_for_a_fit(tmp_path):
    path = _write(tmp_path, "frozen.csv", "time,displacement,force\n"
                  + "".join(f"{t:.3f},0,{f:.3f}\n" for t, f in zip(T, F)))
    with pytest.raises(InputError) as info:
        require_samples(read_test(path), path)
    assert str(path) in str(info.value) and "the screening leaves 0 of" in str(info.value)


def test_space_separated_damper_csv_with_units_in_the_header(tmp_path):
    # "time [s] displacement [m] force [N]": each unit belongs to the name before it
    text = "time [s]  displacement [m]  force [N]\n" + "".join(f"{t:.6g} {x:.6g} {f:.6g}\n" for t, x, f in zip(T, X, F))
    test = read_test(_write(tmp_path, "spaced.csv", text))
    np.testing.assert_allclose(test.force, F, rtol=1e-5)
    np.testing.assert_allclose(test.displacement, X, rtol=1e-5, atol=1e-9)
