"""A raw UTFSM logger export of one coil current (the campaign's validation sweeps,
``Validacion/MRDAMPER/15Hz1A.txt`` of the source repository: three channels, the current in the
file name) read as that current's test, and a one-sided sweep's strokes told from its drift
(:func:`damper.io.data.raw_current_from_name`, :func:`damper.io.screening.dominant_frequency`).

The real validation files are not in ``shared/``; these tests write exports of the same layout
(docs/diagnosis.md, "Other recordings of the UTFSM damper: the validation sweeps")."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.applications.cli import main
from benchmark.foundation.errors import InputError
from damper.io.data import raw_current_from_name
from damper.io.reader import read_test, read_tests
from damper.io.screening import dominant_frequency, screening_of, stroke_rate

FS = 1000.0


@pytest.mark.parametrize("name, current", [("15Hz1A", 1.0), ("15Hz0x5A", 0.5), ("15Hz0A", 0.0),
                                           ("15Hz1A_2", 1.0), ("sweep_0x75A", 0.75),
                                           ("ME10mm2Hz", None), ("ME25mm0x25Hz", None), ("DATA", None)])
def test_the_current_is_read_from_the_end_of_the_name(name, current):
    assert raw_current_from_name(f"/some/where/{name}.txt") == current


def _sweep(idle_before=4.0, idle_after=4.0, duration=30.0, f0=1.0, f1=12.0, amplitude=2e-3):
    """A one-sided sine sweep (0 to -2 amplitude, as the rig's validation sweeps run) between
    idle spans, and an MR-like force (yield force, viscous term, a lag of the plateau)."""
    n0, n1, n = int(idle_before * FS), int(duration * FS), int(idle_after * FS)
    ts = np.arange(n1) / FS
    phase = 2 * np.pi * (f0 * ts + 0.5 * (f1 - f0) / duration * ts ** 2)
    ramp = np.minimum(1.0, np.minimum(ts, duration - ts) / 1.0)  # a second in, a second out
    x = np.concatenate([np.zeros(n0), -amplitude * ramp * (1.0 - np.cos(phase)), np.zeros(n)])
    v = np.gradient(x, 1.0 / FS)
    force = 900.0 * np.tanh(v / 5e-3) + 3e3 * v
    return x, force


def _write_raw(path, x, force, command=True):
    """A raw logger export: seven header lines, CHANNEL0 displacement [x 10 mm], CHANNEL1 force
    [x 100 kgf] (the 1 kHz files' order), CHANNEL2 the commanded displacement."""
    rng = np.random.default_rng(3)
    ch0 = np.round(x * 1e3 / 10.0 + 2e-5 * rng.standard_normal(x.size), 4)
    ch1 = np.round(force / 980.665 + 2e-4 * rng.standard_normal(x.size), 4)
    ch2 = np.round(np.r_[x[5:], np.zeros(5)] * 1e3 / 10.0, 4)  # the command leads by 5 ms
    head = ["Header Size:  7", "Version:  2", "Sampling Interval:  0.001", "Sampling Rate:  1000",
            f"Sample Count:  {x.size}", "Device Serial Number:  0",
            "Sample Number, Date/Time, CHANNEL0, CHANNEL1" + (", CHANNEL2" if command else "") + ", Events"]
    rows = []
    for k in range(x.size):
        cells = [f"{k + 1:10d}", "  05/25/2022 05:48:06.092 PM", f"{ch0[k]:.4f}", f"{ch1[k]:.4f}"]
        if command:
            cells.append(f"{ch2[k]:.4f}")
        if k == 0:
            cells.append("DAQ Start")
        rows.append(", ".join(cells))
    path.write_text("\n".join(head + rows) + "\n")
    return path


def test_an_export_of_one_current_is_that_currents_test(tmp_path):
    x, force = _sweep()
    path = _write_raw(tmp_path / "15Hz0x5A.txt", x, force)
    tests = read_tests(path)
    assert len(tests) == 1
    test = tests[0]
    assert test.current is not None and np.all(test.current == 0.5)
    assert test.metadata["current_from"] == "the file name"
    assert "CHANNEL2 the commanded displacement" in test.metadata["units_in_file"]
    # channels, scales and units: the displacement in m, the force in N
    assert np.ptp(test.displacement) == pytest.approx(4e-3, rel=0.02)
    assert np.percentile(np.abs(test.force), 99) == pytest.approx(np.percentile(np.abs(force), 99), rel=0.02)
    assert read_test(path).current is not None  # read_test reads it the same


def test_the_idle_spans_at_both_ends_of_a_one_sided_sweep_are_found(tmp_path):
    # The sweep's mean position steps from 0 to -2 mm and back: the largest line of its spectrum
    # is that step's, at 1/40 Hz, and a "dominant period" of 40 s hid the 4-s idle spans (the
    # real 15Hz1A.txt: 4.7 s of rest at its end scored as data).
    x, force = _sweep()
    test = read_test(_write_raw(tmp_path / "15Hz1A.txt", x, force))
    idle = [f for f in screening_of(test).findings if f.kind == "idle"]
    assert len(idle) == 2
    assert idle[0].t_start == pytest.approx(0.0, abs=0.01) and idle[0].t_end > 3.0
    assert idle[1].t_end == pytest.approx(test.time[-1], abs=0.01) and idle[1].t_start < test.time[-1] - 3.0
    assert not test.usable[test.time < 3.0].any() and not test.usable[test.time > test.time[-1] - 3.0].any()
    assert test.usable[(test.time > 6.0) & (test.time < 30.0)].all()


def test_a_sweeps_dominant_frequency_is_in_its_band_not_its_drift():
    x, _ = _sweep(idle_before=0.5, idle_after=0.5)
    t = np.arange(x.size) / FS
    f = dominant_frequency(t, x)
    assert 1.0 <= f <= 12.0
    assert stroke_rate(t, x) > 3.0
    # a sinusoid keeps its own frequency, and a motion whose drift is slow but not far below its
    # strokes keeps its spectral peak (the Dyke recording's random motion: 0.97 Hz)
    t = np.arange(0.0, 20.0, 1e-3)
    assert dominant_frequency(t, 0.01 * np.sin(2 * np.pi * 1.5 * t)) == pytest.approx(1.5, abs=0.06)
    slow = 0.01 * np.sin(2 * np.pi * 1.0 * t) + 0.003 * np.sin(2 * np.pi * 9.0 * t)
    assert dominant_frequency(t, slow) == pytest.approx(1.0, abs=0.06)


def test_an_export_with_one_span_and_no_current_in_its_name_is_refused(tmp_path):
    x, force = _sweep()
    path = _write_raw(tmp_path / "sweep.txt", x, force, command=False)
    with pytest.raises(InputError, match=r"1 span\(s\) of motion.*names it at the end of the file name"):
        read_tests(path)


def test_diagnose_reads_a_named_export(tmp_path, capsys):
    x, force = _sweep()
    path = _write_raw(tmp_path / "15Hz1A.txt", x, force)
    rc = main(["diagnose", "--data", str(path), "--quiet", "--out", str(tmp_path / "out"),
               "--effects", "offset"])
    out = capsys.readouterr().out
    assert rc == 0
    assert "held-out relative RMS error" in out
    assert "idle" in (tmp_path / "out" / "report.md").read_text()
