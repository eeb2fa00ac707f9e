"""The ensemble machinery with the cheap deterministic probe run function: expansion, seeds,
journal (torn lines, damage, headers), resume, failures, process counts, CLI."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from benchmark.applications.cli import main
from benchmark.applications.ensemble import (EnsembleConfig, derive_seed, journal_path, read_ensemble,
                                run_ensemble)
from benchmark.applications.ensemble_journal import Journal, JournalEntry
from benchmark.foundation.errors import DataNotFoundError, InputError

PROBE_TOML = """
name = "probe-test"
base_seed = 7
run = "probe"
controllers = ["passive-off", "clipped-optimal"]
records = ["kobe", "elcentro"]
orientations = ["FN-x", "FP-x"]
pga = [1.0, 2.5]

[synthetic]
templates = ["kobe"]
realisations = 2

[grid]
"damper.scale" = [0.5, 1.0]
"""


def _config(tmp_path: Path, text: str = PROBE_TOML) -> EnsembleConfig:
    path = tmp_path / "ens.toml"
    path.write_text(text)
    return EnsembleConfig.from_toml(path)


def _same_results(a, b) -> None:
    assert list(a.cases["key"]) == list(b.cases["key"])
    assert list(a.cases["status"]) == list(b.cases["status"])
    assert set(a.results) == set(b.results)
    for name in a.results:
        # bit for bit, NaN where NaN
        assert a.results[name].tobytes() == b.results[name].tobytes(), name


def test_derive_seed_is_deterministic_and_key_dependent():
    assert derive_seed(1, "a") == derive_seed(1, "a")
    assert derive_seed(1, "a") != derive_seed(1, "b")
    assert derive_seed(1, "a") != derive_seed(2, "a")
    assert 0 <= derive_seed(123, "x") < 2 ** 63


def test_expansion_counts_keys_and_shared_motion_seeds(tmp_path):
    cfg = _config(tmp_path)
    cases = cfg.cases()
    # motions: 2 records x 2 orientations x 2 pga + 1 template x 2 orient x 2 real x 2 pga = 16
    assert len(cfg.motions()) == 16
    assert len(cases) == 16 * 2 * 2
    assert len({c.key for c in cases}) == len(cases)
    assert [c.index for c in cases] == list(range(len(cases)))
    # every controller/parameter set sees the same motion; PGA scaling does not change the motion
    by_motion: dict[tuple, set[int]] = {}
    for c in cases:
        by_motion.setdefault((c.record, c.synthetic, c.realisation), set()).add(c.motion_seed)
    assert all(len(s) == 1 for s in by_motion.values())
    assert len({next(iter(s)) for s in by_motion.values()}) == len(by_motion)
    assert len({c.seed for c in cases}) == len(cases)
    syn = [c for c in cases if c.synthetic]
    assert syn and all(c.realisation in (0, 1) for c in syn)
    assert all(c.realisation == -1 for c in cases if not c.synthetic)


@pytest.mark.parametrize("text, field", [
    ('controllers = ["a"]\nrecords = ["kobe"]\ncolour = 3\n', "colour"),
    ('records = ["kobe"]\n', "controllers"),
    ('controllers = "a"\nrecords = ["kobe"]\norientations = ["NS"]\n', "orientations"),
    ('controllers = ["a"]\nrecords = ["kobe"]\npga = [1.0, -2.0]\n', "pga"),
    ('controllers = ["a"]\nrecords = ["kobe"]\nbase_seed = -1\n', "base_seed"),
    ('controllers = ["a"]\nrecords = ["kobe"]\nrun = "nonsense"\n', "run"),
    ('controllers = ["a"]\n[synthetic]\ntemplates = ["kobe"]\nrealisations = 0\n', "synthetic.realisations"),
    ('controllers = ["a"]\n[synthetic]\ntemplates = ["kobe"]\nseeds = 3\n', "synthetic.seeds"),
    ('controllers = ["a"]\nrecords = ["kobe"]\n[grid]\n"damper.x" = ["big"]\n', "grid.damper.x"),
    ('controllers = ["a", "a"]\nrecords = ["kobe"]\n', "controllers"),
    ('controllers = ["a"]\n', "no motions"),
])
def test_config_errors_name_the_field(tmp_path, text, field):
    with pytest.raises(InputError, match=None) as info:
        _config(tmp_path, text)
    assert field in str(info.value)
    assert "ens.toml" in str(info.value)


def test_config_syntax_error_and_missing_file(tmp_path):
    with pytest.raises(InputError, match="invalid TOML.*line 2"):
        _config(tmp_path, 'controllers = ["a"]\nrecords = [1,,2]\n')
    with pytest.raises(DataNotFoundError, match="nowhere.toml"):
        EnsembleConfig.from_toml(tmp_path / "nowhere.toml")


def test_nested_grid_tables_flatten(tmp_path):
    cfg = _config(tmp_path, 'run = "probe"\ncontrollers = ["passive-on"]\nrecords = ["kobe"]\n[grid.damper]\n'
                            'kappa_w = [1.0, 2.0]\n')
    assert cfg.parameter_names == ("damper.kappa_w",)
    assert {c.parameter_dict["damper.kappa_w"] for c in cfg.cases()} == {1.0, 2.0}


def test_journal_round_trip_is_bit_exact_and_torn_line_ignored(tmp_path):
    path = tmp_path / "j.journal"
    values = {"a": 0.1 + 0.2, "nan": math.nan, "arr": np.array([[1e-300, -0.0], [np.inf, 3.0]]),
              "i": 3, "f32": np.arange(3, dtype=np.float32)}
    with Journal(path, {"base_seed": 1, "run": "probe"}) as j:
        j.append(JournalEntry("k1", "ok", values, elapsed_s=0.5))
        j.append(JournalEntry("k2", "failed", error="boom"))
    with open(path, "ab") as fh:  # a process died while writing the next line
        fh.write(b'deadbeef {"key": "k3", "sta')
    j2 = Journal(path, {"base_seed": 1, "run": "probe"})
    assert j2.torn_line_ignored and set(j2.entries) == {"k1", "k2"}
    got = j2.entries["k1"].result
    assert got["a"] == values["a"] and math.isnan(got["nan"]) and got["i"] == 3
    assert got["arr"].tobytes() == values["arr"].tobytes() and got["arr"].shape == (2, 2)
    assert got["f32"].dtype == np.float32
    assert j2.entries["k2"].status == "failed" and j2.entries["k2"].error == "boom"
    with j2:  # appending cuts the torn tail off first
        j2.append(JournalEntry("k3", "ok", {"a": 1.0}))
    j3 = Journal(path, {"base_seed": 1, "run": "probe"})
    assert not j3.torn_line_ignored and set(j3.entries) == {"k1", "k2", "k3"}


def test_journal_damage_and_foreign_header_are_input_errors(tmp_path):
    path = tmp_path / "j.journal"
    with Journal(path, {"base_seed": 1, "run": "probe"}) as j:
        j.append(JournalEntry("k1", "ok", {"a": 1.0}))
        j.append(JournalEntry("k2", "ok", {"a": 2.0}))
    with pytest.raises(InputError, match="base_seed"):
        Journal(path, {"base_seed": 2, "run": "probe"})
    lines = path.read_bytes().split(b"\n")
    lines[1] = lines[1].replace(b'"a":1.0', b'"a":9.0')  # checksum no longer matches
    path.write_bytes(b"\n".join(lines))
    with pytest.raises(InputError, match=r"j\.journal:2: damaged"):
        Journal(path, {"base_seed": 1, "run": "probe"})


def test_resume_runs_only_missing_cases_and_matches_a_full_run(tmp_path):
    cfg = _config(tmp_path)
    n = len(cfg.cases())
    full = run_ensemble(cfg, tmp_path / "full.h5", progress=False)
    assert full.complete and full.n_run == n and full.n_resumed == 0
    part = run_ensemble(cfg, tmp_path / "part.h5", progress=False, max_cases=5)
    assert not part.complete and part.n_run == 5
    partial = read_ensemble(tmp_path / "part.h5")
    assert partial.attrs["complete"] in (False, np.False_) and partial.attrs["n_done"] == 5
    assert np.isnan(partial.results["draw"][5:]).all() and not np.isnan(partial.results["draw"][:5]).any()
    rest = run_ensemble(cfg, tmp_path / "part.h5", progress=False)
    assert rest.n_resumed == 5 and rest.n_run == n - 5 and rest.complete
    _same_results(read_ensemble(tmp_path / "full.h5"), read_ensemble(tmp_path / "part.h5"))
    again = run_ensemble(cfg, tmp_path / "part.h5", progress=False)
    assert again.n_run == 0 and again.n_resumed == n


def test_results_do_not_depend_on_process_count(tmp_path):
    cfg = _config(tmp_path)
    run_ensemble(cfg, tmp_path / "one.h5", jobs=1, progress=False)
    run_ensemble(cfg, tmp_path / "two.h5", jobs=2, progress=False)
    a, b = read_ensemble(tmp_path / "one.h5"), read_ensemble(tmp_path / "two.h5")
    _same_results(a, b)
    assert (a.cases["seed"] == b.cases["seed"]).all()
    # the probe really depends on the case: draws differ between cases
    assert len(np.unique(a.results["draw"])) == a.n_cases
    assert a.results["samples"].shape == (a.n_cases, 4)
    assert (a.parameters["damper.scale"] == a.results["parameter_sum"]).all()
    import h5py  # a user's metrics say that their units are the run function's own
    with h5py.File(tmp_path / "one.h5") as f:
        assert f["results/draw"].attrs["units"] == "as returned by the run function"


def test_failed_runs_are_recorded_not_redone(tmp_path):
    cfg = _config(tmp_path, 'run = "probe"\ncontrollers = ["a", "b", "c"]\nrecords = ["kobe", "elcentro"]\n'
                            '[grid]\n"probe.fail_above" = [0.5]\n')
    s = run_ensemble(cfg, tmp_path / "f.h5", progress=False)
    res = read_ensemble(tmp_path / "f.h5")
    failed = res.cases["status"] == "failed"
    assert s.n_failed == failed.sum() and 0 < failed.sum() < res.n_cases
    assert np.isnan(res.results["draw"][failed]).all()
    assert (res.results["draw"][~failed] <= 0.5).all()
    assert all("probe.fail_above" in e for e in res.cases["error"][failed])
    assert run_ensemble(cfg, tmp_path / "f.h5", progress=False).n_run == 0


def test_changed_base_seed_refuses_old_journal(tmp_path):
    cfg = _config(tmp_path)
    run_ensemble(cfg, tmp_path / "a.h5", progress=False, max_cases=2)
    other = _config(tmp_path, PROBE_TOML.replace("base_seed = 7", "base_seed = 8"))
    with pytest.raises(InputError, match="base_seed"):
        run_ensemble(other, tmp_path / "a.h5", progress=False)


def test_extending_the_grid_reuses_finished_runs(tmp_path):
    small = _config(tmp_path)
    run_ensemble(small, tmp_path / "g.h5", progress=False)
    big = _config(tmp_path, PROBE_TOML.replace('"damper.scale" = [0.5, 1.0]', '"damper.scale" = [0.5, 1.0, 2.0]'))
    s = run_ensemble(big, tmp_path / "g.h5", progress=False)
    assert s.n_resumed == len(small.cases()) and s.n_run == len(big.cases()) - len(small.cases())


def test_cli_runs_and_reports_errors(tmp_path, capsys):
    cfg = tmp_path / "e.toml"
    cfg.write_text('run = "probe"\ncontrollers = ["a"]\nrecords = ["kobe"]\n')
    assert main(["ensemble", "--config", str(cfg), "--jobs", "1", "--no-progress"]) == 0
    assert (tmp_path / "e.h5").is_file() and journal_path(tmp_path / "e.h5").is_file()
    assert '"n_run": 2' in capsys.readouterr().out
    bad = tmp_path / "bad.toml"
    bad.write_text('controllers = ["a"]\nrecords = ["kobe"]\njobs = 3\n')
    assert main(["ensemble", "--config", str(bad)]) == 2
    assert "unknown field(s) ['jobs']" in capsys.readouterr().err


def test_example_config_parses_with_the_documented_size():
    example = Path(__file__).resolve().parents[2] / "examples" / "ensemble.toml"
    cfg = EnsembleConfig.from_toml(example)
    # (2 records x 2 orientations + 2 templates x 2 orientations x 5 realisations) x 3 controllers x 2
    assert len(cfg.motions()) == 24 and len(cfg.cases()) == 144
    assert cfg.run == "simulation" and cfg.parameter_names == ("control_step",)


def test_a_case_the_simulation_refuses_is_named(tmp_path):
    """Probed: a grid value refused inside the run (n_modes = 30) named only the model field."""
    from benchmark.applications.ensemble import _execute

    def refuse(case):
        raise InputError("n_modes: expected an integer in 1..24, got 30")

    case = _config(tmp_path).cases()[0]
    with pytest.raises(InputError) as err:
        _execute(refuse, case)
    assert str(err.value) == f"case {case.key}: n_modes: expected an integer in 1..24, got 30"


def test_a_resume_after_an_edited_record_or_structure_file_is_refused(tmp_path, monkeypatch):
    # the case keys name the files, not their content: a probe doubled a record file, and raised
    # a --structure file's damping to 10 %, and both ensembles resumed with the old numbers
    import json
    from benchmark.foundation.paths import structure_file
    record = tmp_path / "rec.csv"
    record.write_text("time [s],ax [m/s2]\n" + "".join(f"{0.005 * k:.3f},{np.sin(0.05 * k):.4f}\n"
                                                      for k in range(400)))
    structure = tmp_path / "structure.json"
    structure.write_text(structure_file().read_text())
    monkeypatch.setenv("SBIB_STRUCTURE", str(structure))
    toml = tmp_path / "e.toml"
    toml.write_text(f'controllers = ["none"]\nrecords = ["{record}"]\n')
    out = tmp_path / "e.h5"
    run_ensemble(EnsembleConfig.from_toml(toml), out, max_cases=0, progress=False)
    run_ensemble(EnsembleConfig.from_toml(toml), out, max_cases=0, progress=False)  # unchanged: resumes
    record.write_text(record.read_text().replace("ax [m/s2]", "ax [g]"))
    with pytest.raises(InputError, match="input_files_sha256.*do not belong to this ensemble"):
        run_ensemble(EnsembleConfig.from_toml(toml), out, max_cases=0, progress=False)
    journal_path(out).unlink()
    run_ensemble(EnsembleConfig.from_toml(toml), out, max_cases=0, progress=False)
    doc = json.loads(structure.read_text())
    doc["modal_damping_ratio"] = 0.10
    structure.write_text(json.dumps(doc))
    with pytest.raises(InputError, match="input_files_sha256.*do not belong to this ensemble"):
        run_ensemble(EnsembleConfig.from_toml(toml), out, max_cases=0, progress=False)


def _user_run_raising(case):
    if case.index % 2:
        raise ValueError("boom in user run")
    return {"x": 1.0, "y": [1.0, 2.0]}  # a list is an array


def _user_run_text(case):
    return {"x": "high"}


def test_a_user_run_function_failing_on_a_case_fails_that_case(tmp_path):
    # it had ended the ensemble in a traceback; a list metric had failed to encode (TypeError)
    cfg = _config(tmp_path)
    summary = run_ensemble(cfg, tmp_path / "u.h5", run=_user_run_raising, progress=False)
    n = len(cfg.cases())
    assert summary.complete and summary.n_failed == n // 2
    res = read_ensemble(tmp_path / "u.h5")
    ok = ~np.isnan(res.results["x"])
    assert ok.sum() == n - n // 2 and np.all(res.results["y"][ok] == [1.0, 2.0])
    entries = Journal(journal_path(tmp_path / "u.h5"), {}).entries
    assert any("raised ValueError: boom in user run" in e.error for e in entries.values())
    with pytest.raises(InputError, match="metric 'x' .* is str; expected a number or an array"):
        run_ensemble(cfg, tmp_path / "t.h5", run=_user_run_text, progress=False)


@pytest.mark.parametrize("body, words", [
    ('controllers = ["passive-on"]\nrecords = ["kobe", "kobee"]\n', "'kobee' is neither a benchmark record"),
    ('controllers = ["pasive-on"]\nrecords = ["kobe"]\n', "unknown controller 'pasive-on'"),
    ('controllers = ["passive-on"]\nrecords = ["kobe"]\n[grid]\n"probe.a" = ' + str(list(range(1000)))
     + '\n"probe.b" = ' + str(list(range(1000))) + '\n', "2,000,000 cases"),
    # a grid value the simulation refuses had stopped the ensemble only when its case came up
    ('controllers = ["passive-on"]\nrecords = ["kobe"]\n[grid]\n"isolation.mu_max" = [0.1, -0.1]\n',
     r"grid parameter isolation.mu_max = -0.1: FrictionPendulumBearing.mu_max = -0.1: expected in \[0.0, 1.0\)"),
    ('controllers = ["passive-on"]\nrecords = ["kobe"]\n[grid]\n"device.eta" = [0.0]\n', "device.eta = 0.0"),
    ('controllers = ["passive-on"]\nrecords = ["kobe"]\n[grid]\nn_modes = [3, 2.5]\n', "n_modes = 2.5"),
    ('controllers = ["passive-on"]\nrecords = ["kobe"]\n[grid]\ncontrol_step = [0.005, 1e-6]\n',
     "control_step = 1e-06"),
    ('controllers = ["passive-on"]\nrecords = ["kobe"]\n[grid]\nn_mode = [3]\n', "'n_mode' unknown to the simulation"),
])
def test_names_and_the_case_count_are_checked_before_any_run(tmp_path, body, words):
    # a misspelt record had failed after 12 runs of the others; a 9-million grid took 3.7 GB and
    # 90 s of silence before its first run
    toml = tmp_path / "e.toml"
    toml.write_text(body)
    with pytest.raises(InputError, match=words):
        run_ensemble(EnsembleConfig.from_toml(toml), tmp_path / "e.h5", progress=False)
    assert not journal_path(tmp_path / "e.h5").exists()


def test_grid_fields_are_checked_together_at_every_point(tmp_path):
    """A review: mu_max = [0.02, 0.05] with mu_min = [0.01, 0.015] is valid at every point, but each
    value checked alone against the default bearing (mu_min 0.03) had refused mu_max = 0.02."""
    from benchmark.applications.ensemble_simulation import check_grid_values
    check_grid_values((("isolation.mu_max", (0.02, 0.05)), ("isolation.mu_min", (0.01, 0.015))))
    with pytest.raises(InputError, match=r"grid point isolation.mu_max = 0.02, isolation.mu_min = 0.03"):
        check_grid_values((("isolation.mu_max", (0.02, 0.05)), ("isolation.mu_min", (0.01, 0.03))))


def test_a_mask_on_a_value_no_case_has_is_refused(tmp_path):
    # controller="passive-onn" had selected nothing without a word
    cfg = _config(tmp_path)
    run_ensemble(cfg, tmp_path / "m.h5", progress=False, max_cases=2)
    res = read_ensemble(tmp_path / "m.h5")
    name = str(res.cases["controller"][0])
    assert res.mask(controller=name).any()
    with pytest.raises(InputError, match=f"no case has controller = '{name}x'; the values are"):
        res.mask(controller=name + "x")
    assert res.mask(status="failed").sum() == 0  # a status nobody has is a count, not a typo
