"""Files without a coil-input column, and a user's ``t, D, V, F, Y`` file (a review, 2026-11-26).

A file with no voltage or current column beside files that have one was fitted as 0 V, a level
nobody measured; a user's SI file whose columns are named with Dyke's letters was read in
Dyke's units (cm, cm/s): 100 times off. Both are now refused in one line naming the file; a
set of files none of which records the coil input is a passive test, fitted at 0 V and said so.
"""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.applications.cli import main
from benchmark.foundation.errors import InputError
from damper.diagnosis.dataset import DiagnosisData
from damper.io.reader import read_test


def _sine(path, coil: str | None, amp=0.01, freq=1.0, rate=500.0, cycles=4):
    t = np.arange(0.0, cycles / freq, 1.0 / rate)
    x = amp * np.sin(2 * np.pi * freq * t)
    v = amp * 2 * np.pi * freq * np.cos(2 * np.pi * freq * t)
    f = 1000.0 * np.tanh(v / 0.01) + 2000.0 * v
    cols = ["time", "displacement", "velocity", "force"] + ([coil] if coil else [])
    rows = [[a, b, c, d] + ([0.5] if coil else []) for a, b, c, d in zip(t, x, v, f)]
    path.write_text(",".join(cols) + "\n" + "".join(",".join(f"{u:.10g}" for u in r) + "\n" for r in rows))
    return path


def test_a_file_without_the_coil_input_beside_files_with_it_is_refused(tmp_path):
    a = read_test(_sine(tmp_path / "a.csv", "current"))
    b = read_test(_sine(tmp_path / "b.csv", None))
    with pytest.raises(InputError, match=r"b: no voltage or current column, while the other tests give the current"):
        DiagnosisData.from_tests([a, b])


def test_tests_none_of_which_records_the_coil_input_are_fitted_at_0_V_and_said_so(tmp_path):
    tests = [read_test(_sine(tmp_path / f"p{i}.csv", None, amp=a)) for i, a in enumerate((0.01, 0.005))]
    data = DiagnosisData.from_tests(tests)
    assert not data.input_recorded and data.input_name == "voltage"
    assert DiagnosisData.from_tests([read_test(_sine(tmp_path / "c.csv", "voltage"))]).input_recorded


def test_identify_refuses_a_mix_of_files_with_and_without_the_coil_input(tmp_path, capsys):
    a = _sine(tmp_path / "a.csv", "current")
    b = _sine(tmp_path / "b.csv", None)
    assert main(["identify", "--data", str(a), str(b), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "b.csv: no voltage or current column" in err and not (tmp_path / "out").exists()


def test_a_users_file_with_dykes_letters_is_not_read_in_dykes_units(tmp_path):
    path = tmp_path / "mine.csv"
    t = np.arange(0.0, 2.0, 0.001)
    x = 0.01 * np.sin(2 * np.pi * t)
    path.write_text("t,D,V,F,Y\n" + "".join(f"{a:.4f},{b:.6g},{0.0628 * np.cos(6.283 * a):.6g},{1000 * b / 0.01:.6g},0.5\n"
                                            for a, b in zip(t, x)))
    with pytest.raises(InputError, match="unknown column 'd'.*Dyke records' names"):
        read_test(path)


def test_a_file_shorter_than_a_cycle_is_named_as_short_not_as_in_other_units(tmp_path):
    from damper.io.reader import require_samples
    path = _sine(tmp_path / "short.csv", "current", amp=0.0002, rate=1000.0, cycles=1)
    lines = path.read_text().splitlines()
    path.write_text("\n".join(lines[:12]) + "\n")  # 11 samples: 10 ms of a 1-Hz test
    with pytest.raises(InputError, match="reverses 0 time.*expected a test of at least one cycle"):
        require_samples(read_test(path), path)


def test_columns_read_as_si_for_want_of_a_unit_are_said_with_their_amplitudes(tmp_path, capsys):
    """A force in kN with no unit in the header reads as a 1-N device: plausible, so not
    refused, but the line with the amplitudes as read shows it (a review, 2026-11-26)."""
    from damper.io.screening import screening_lines
    path = tmp_path / "kn.csv"
    _sine(path, "current")
    lines = path.read_text().splitlines()
    rows = [r.split(",") for r in lines[1:]]
    path.write_text("time,displacement [m],velocity,force,current\n"
                    + "".join(",".join(r[:3] + [f"{float(r[3]) / 1e3:.6g}", r[4]]) + "\n" for r in rows))
    test = read_test(path)
    assert test.metadata["units_unstated"] == ["force"]
    line = next(ln for ln in screening_lines([test]) if "no unit in the header" in ln)
    assert "for force: read as SI" in line and "peak force 0.00" in line and "stroke" not in line



def test_percent_comment_lines_as_matlab_writes_them(tmp_path):
    """``%`` lines before the header are comments, as ``#`` lines are (their commas do not set
    the separator of a tab-separated file)."""
    path = _sine(tmp_path / "m.csv", "current")
    lines = path.read_text().splitlines()
    tabbed = [ln.replace(",", "\t") for ln in lines]
    path.write_text("% exported by the rig, 2024\n% operator: A\n" + "\n".join(tabbed) + "\n")
    test = read_test(path)
    assert test.n_samples == len(lines) - 1 and test.metadata.get("operator") == "A"
