"""A raw UTFSM logger export (five coil currents back to back) read as one test per current
(:func:`damper.io.data.split_utfsm_raw`, :func:`damper.io.reader.read_tests`)."""

from __future__ import annotations


import numpy as np
import pytest

from benchmark.applications.cli import main
from benchmark.foundation.errors import InputError
from damper.io.data import UTFSM_RAW_CURRENTS, is_utfsm_raw_file, read_utfsm_raw, split_utfsm_raw
from damper.io.reader import read_test, read_tests
from damper.io.screening import screened

RAW = "hysteresis_data/quiroz_utfsm_mr_damper_sinusoidal/Datos_crudos"


def test_each_raw_export_gives_its_five_currents_in_order(shared_dir):
    files = sorted((shared_dir / RAW).glob("ME*.txt"))
    assert len(files) == 6
    for path in files:
        assert is_utfsm_raw_file(path)
        levels = read_tests(path)
        assert [float(t.current[0]) for t in levels] == list(UTFSM_RAW_CURRENTS)
        whole = read_test(path)  # the whole file, its current not recorded
        assert whole.current is None and whole.voltage is None
        # the levels lie between the idle spans, in time order, and the force rises with the current
        starts = [t.time[0] for t in levels]
        assert starts == sorted(starts)
        peaks = [np.percentile(np.abs(t.force), 95) for t in levels]
        assert all(b > a for a, b in zip(peaks, peaks[1:]))
        for t in levels:
            assert np.ptp(t.current) == 0.0 and t.name.startswith(path.stem)
            assert t.usable.mean() > 0.95  # the idle spans stay out
            assert t.metadata["screening"] is not None


def _levels_file(tmp_path, shared_dir, drop=None, swap=False):
    """A raw export written back with a level dropped or two levels swapped."""
    path = sorted((shared_dir / RAW).glob("ME5mm4Hz.txt"))[0]
    lines = path.read_text().splitlines()
    head, body = lines[:7], lines[7:]
    whole = read_test(path)
    spans = [t.metadata["span_s"] for t in read_tests(path)]
    t = whole.time
    index = [(int(np.searchsorted(t, a)), int(np.searchsorted(t, b)) + 1) for a, b in spans]
    rows = list(range(len(body)))
    if drop is not None:
        a, b = index[drop]
        rows = [r for r in rows if not a <= r < b]
    if swap:
        (a1, b1), (a2, b2) = index[1], index[3]
        rows = rows[:a1] + rows[a2:b2] + rows[b1:a2] + rows[a1:b1] + rows[b2:]
    out = tmp_path / "ME5mm4Hz.txt"
    # the sample numbers stay those of the file: the time base runs on
    out.write_text("\n".join(head + [f"{k + 1},{body[r].split(',', 1)[1]}" for k, r in enumerate(rows)]) + "\n")
    return out


def test_a_level_missing_or_out_of_order_is_refused_in_one_line(tmp_path, shared_dir):
    with pytest.raises(InputError, match="4 span\\(s\\) of motion") as info:
        read_tests(_levels_file(tmp_path, shared_dir, drop=2))
    assert "\n" not in str(info.value)
    with pytest.raises(InputError, match="does not rise with"):
        read_tests(_levels_file(tmp_path, shared_dir, swap=True))


def test_a_levels_filled_samples_stay_out_of_it(tmp_path, shared_dir):
    """A raw export with a spike and a lost row inside its third level: the level read from it
    leaves both samples out (they carry no measurement), with their findings; before, the level
    was screened afresh and scored the interpolated samples as data."""
    path = shared_dir / RAW / "ME5mm4Hz.txt"
    lines = path.read_text().splitlines()
    head, body = lines[:7], lines[7:]
    a, b = read_tests(path)[2].metadata["span_s"]
    t_whole = read_test(path).time
    middle = int(np.searchsorted(t_whole, 0.5 * (a + b)))
    cells = body[middle].split(",")
    cells[2] = f" {8.0 * float(cells[2]) + 5.0:.4f}"  # the first channel (the force) jumps and comes back
    body[middle] = ",".join(cells)
    del body[middle + 100]  # a row the logger never wrote (its sample number missing)
    out = tmp_path / "ME5mm4Hz.txt"
    out.write_text("\n".join(head + body) + "\n")
    level = read_tests(out)[2]
    kinds = {f.kind for f in level.metadata["screening"].findings}
    assert {"spike", "lost"} <= kinds
    missing = level.time[~level.usable & (np.abs(level.time - t_whole[middle]) < 0.2)]
    assert np.isclose(missing, t_whole[middle]).any() and np.isclose(missing, t_whole[middle + 100]).any()
    assert missing.size == 2


def test_split_refuses_a_file_with_no_idle_span():
    t = np.arange(0.0, 10.0, 0.005)
    x = 0.01 * np.sin(2 * np.pi * t)
    from damper.io.data import DamperTest

    test = screened(DamperTest(time=t, displacement=x, velocity=np.gradient(x, t), force=1e3 * np.cos(2 * np.pi * t),
                               name="one", source="one.txt"))
    with pytest.raises(InputError, match="1 span"):
        split_utfsm_raw(test)
    assert len(split_utfsm_raw(test, currents=(0.5,))) == 1


def test_sbib_diagnose_reads_a_raw_export_as_five_currents(shared_dir, capsys):
    path = shared_dir / RAW / "ME2mm5Hz.txt"
    assert main(["diagnose", "--data", str(path), "--quiet", "--json", "--effects", "offset"]) == 0
    import json

    doc = json.loads(capsys.readouterr().out)
    assert len(doc["screening"]) == 5  # one entry per level, not one overwritten five times
    assert sorted(float(k) for k in doc["errors_by_input"]) == list(UTFSM_RAW_CURRENTS)
    assert doc["error_after"] < 0.2


def test_sbib_identify_data_fits_each_current_of_a_raw_export(shared_dir, tmp_path, capsys):
    path = shared_dir / RAW / "ME2mm5Hz.txt"
    assert main(["identify", "--data", str(path), "--model", "normalized", "--bootstrap", "0", "--no-plots",
                 "--json", "--out", str(tmp_path / "id")]) == 0
    import json

    doc = json.loads(capsys.readouterr().out)
    assert len(doc["tests"]) == 5 and len(doc["screening"]) == 5
    assert sorted(t["file"] for t in doc["tests"]) == sorted(f"ME2mm5Hz {c:g} A" for c in UTFSM_RAW_CURRENTS)
