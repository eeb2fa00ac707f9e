"""``sbib identify --data`` / ``sbib diagnose --data`` on files too short or emptied by the screening:
exit status 2, one ``sbib: error:`` line naming the file, no traceback, no output folder left."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.applications.cli import main


def _frozen(tmp_path):
    # the displacement never moves while the force does: the screening flags every sample
    t = np.arange(0.0, 2.0, 0.005)
    path = tmp_path / "frozen.csv"
    path.write_text("time,displacement,force\n" + "".join(f"{a:.3f},0,{300 * np.sin(6 * a):.3f}\n" for a in t))
    return path


def _two_samples(tmp_path):
    path = tmp_path / "two.csv"
    path.write_text("time,displacement,force\n0,0,0\n0.01,0.001,1\n")
    return path


@pytest.mark.parametrize("make, words", [(_frozen, "the screening leaves 0 of"), (_two_samples, "2 samples")])
@pytest.mark.parametrize("command", [["identify", "--bootstrap", "0", "--no-plots"], ["diagnose", "--quiet"]])
def test_one_line_and_no_output_folder(tmp_path, capsys, make, words, command):
    data = make(tmp_path)
    out = tmp_path / "out"
    assert main([*command, "--data", str(data), "--out", str(out)]) == 2
    err = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    assert len(err) == 1 and err[0].startswith("sbib: error: ") and str(data) in err[0] and words in err[0], err
    assert not out.exists()


def test_diagnose_validation_file_too_short(tmp_path, capsys):
    good, bad = _frozen(tmp_path), _two_samples(tmp_path)
    assert main(["diagnose", "--quiet", "--data", str(good), "--validate", str(bad)]) == 2
    assert "Traceback" not in capsys.readouterr().err


def test_identify_with_nothing_identified_leaves_no_folder(tmp_path, capsys):
    # a ramp without one complete cycle: read and screened fine, not identifiable
    t = np.arange(0.0, 1.0, 0.01)
    data = tmp_path / "ramp.csv"
    data.write_text("time,displacement,force\n" + "".join(f"{a:.2f},{0.01 * a:.5f},{100 * a:.3f}\n" for a in t))
    out = tmp_path / "out"
    status = main(["identify", "--bootstrap", "0", "--no-plots", "--model", "normalized",
                   "--data", str(data), "--out", str(out)])
    err = [line for line in capsys.readouterr().err.splitlines() if line.startswith("sbib: error:")]
    assert status == 2 and len(err) == 1 and f"no test identified: {data} [normalized]:" in err[0], err
    assert not out.exists()


def test_identify_on_a_changing_command_says_once_where_to_go(tmp_path, capsys):
    # a random-voltage recording (the Dyke files) fails every model form for the same reason:
    # one entry naming the forms, and the command that fits such a recording
    t = np.arange(0.0, 4.0, 0.002)
    x = 0.01 * np.sin(2 * np.pi * 1.0 * t)
    v = 0.5 + 0.4 * np.sign(np.sin(2 * np.pi * 0.7 * t))
    f = 800.0 * np.tanh(np.gradient(x, t) / 0.01) * (0.5 + v)
    data = tmp_path / "random_voltage.csv"
    data.write_text("time,displacement,force,voltage\n"
                    + "".join(f"{a:.3f},{b:.6f},{c:.3f},{d:.2f}\n" for a, b, c, d in zip(t, x, f, v)))
    status = main(["identify", "--bootstrap", "0", "--no-plots", "--data", str(data), "--out", str(tmp_path / "o")])
    err = [line for line in capsys.readouterr().err.splitlines() if line.startswith("sbib: error:")]
    assert status == 2 and len(err) == 1, err
    assert err[0].count("varies over the test") == 1 and "[normalized, extended]" in err[0], err
    assert "sbib diagnose" in err[0]


def test_a_test_sampled_at_random_instants_is_refused_as_such(tmp_path, capsys):
    # stamps drawn at random (mean step 1 ms): refused before as '0 of 4000 samples usable
    # (settling: ... gap: 758 spans ...)', which did not say what was wrong
    rng = np.random.default_rng(4)
    t = np.sort(rng.uniform(0.0, 4.0, 4000))
    data = tmp_path / "random_times.csv"
    data.write_text("time,displacement,force\n" + "".join(
        f"{a:.6f},{0.005 * np.sin(2 * np.pi * 2 * a):.6g},{500 * np.cos(2 * np.pi * 2 * a):.5g}\n" for a in t))
    assert main(["diagnose", "--quiet", "--data", str(data)]) == 2
    err = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    assert len(err) == 1 and "the sampling is not uniform" in err[0] and "resample" in err[0], err
