"""Every ``sbib`` command rejects bad input with exit status 2 and one ``sbib: error: ...`` line.

The table below holds, for each command, options and files a user gets wrong (missing or
empty files, ragged rows, time going backwards, unknown names, non-positive steps, NaN,
values outside the device range, inadmissible model parameters, a record shorter than one
control step, an output path that cannot be created). Each case runs ``benchmark.applications.cli.main``
in-process and checks the exit status, that stderr holds exactly one line, that it starts
with ``sbib: error: `` and that it names what is wrong. Two cases also run the installed
console script in a subprocess, to check the real exit status and that no traceback leaks.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent


@pytest.fixture
def files(tmp_path: Path) -> dict[str, Path]:
    """Small malformed (and a few valid) input files."""
    content = {
        "empty.txt": "",
        "ragged.txt": "% dt=0.005\n1 2\n3\n",
        "text.txt": "% dt=0.005\n1 2\n3 abc\n",
        "nan.txt": "% dt=0.005\n1 2\n3 nan\n",
        "two.txt": "% dt=0.005 cm/s^2\n1 2\n3 4\n",
        "backwards.csv": "time [s],ax [g]\n0,0.1\n0.01,0.2\n0.005,0.1\n",
        "unequal.csv": "time [s],ax [g]\n0,0.1\n0.01,0.2\n0.03,0.1\n0.04,0.0\n",
        "zerostep.csv": "time [s],ax [g]\n0,0.1\n0,0.2\n0.01,0.1\n",
        "furlongs.csv": "time [s],ax [furlong/s2]\n0,0.1\n0.01,0.2\n0.02,0.1\n",
        "single.dat": "0.01\n0.02\n-0.01\n0.0\n",
        "damper_short.csv": "time,displacement,force\n0,0,1\n",
        "damper_back.csv": "time,displacement,force\n0,0,1\n0.1,0.1,2\n0.05,0.2,3\n",
        "damper_units.csv": "time,displacement [mm],force\n0,0,1\n0.1,0.1,2\n0.2,0.2,3\n",
        "damper_cols.csv": "t,x,F\n0,0,1\n0.1,0.1,2\n",
        "damper_nan.csv": "time,displacement,force\n0,0,1\n0.1,nan,2\n0.2,0.2,3\n",
        "bad_iso.json": '{"groups": [{"type": "lead-rubber", "bearings": "1-92", '
                        '"parameters": {"k_initial": -1, "alpha": 0.1, "yield_force": 1e5}}]}',
        "broken.json": '{"groups": [',
        "broken.toml": 'controllers = ["passive-on"\n',
        "unknown_field.toml": 'controllers = ["passive-on"]\nrecords = ["kobe"]\nbogus = 1\n',
        "negative_pga.toml": 'controllers = ["passive-on"]\nrecords = ["kobe"]\npga = [-1.0]\n',
        "no_motions.toml": 'controllers = ["passive-on"]\n',
        "plain_file": "not a directory\n",
    }
    out = {}
    for name, text in content.items():
        path = tmp_path / name
        path.write_text(text, encoding="utf-8")
        out[name] = path
    out["missing"] = tmp_path / "does_not_exist.txt"
    out["tmp"] = tmp_path
    return out


def _argv(template: list[str], files: dict[str, Path]) -> list[str]:
    return [str(files[a[1:]]) if a.startswith("@") else a for a in template]


# (argv with @name for a file of the fixture, text the message must contain)
CASES = {
    # --- sbib warm-up (no options: an unknown one is refused before anything is compiled)
    "warm-up: unknown option": (["warm-up", "--jobs", "2"], "--jobs"),
    # --- sbib records
    "records show: unknown name": (["records", "show", "nosuch"], "nosuch"),
    "records show: empty file": (["records", "show", "@empty.txt"], "empty.txt"),
    "records show: missing file": (["records", "show", "@missing"], "does_not_exist"),
    "records show: ragged rows": (["records", "show", "@ragged.txt"], "ragged.txt:3"),
    "records show: text in a number": (["records", "show", "@text.txt"], "text.txt:3"),
    "records show: NaN": (["records", "show", "@nan.txt"], "nan.txt:3"),
    "records show: time backwards": (["records", "show", "@backwards.csv"], "backwards.csv:4"),
    "records show: non-uniform step": (["records", "show", "@unequal.csv"], "unequal.csv:4"),
    "records show: zero step": (["records", "show", "@zerostep.csv"], "zerostep.csv:3"),
    "records show: unknown unit": (["records", "show", "@furlongs.csv"], "furlong"),
    "records show: single column without dt": (["records", "show", "@single.dat", "--format", "single"], "dt"),
    "records show: negative dt": (["records", "show", "@single.dat", "--format", "single", "--dt", "-0.01"], "dt"),
    "records show: unknown --units": (["records", "show", "@single.dat", "--dt", "0.01", "--units", "kN"], "kN"),
    "records show: --damping 1.5": (["records", "show", "kobe", "--damping", "1.5"], "--damping"),
    "records show: orientation": (["records", "show", "kobe", "--orientation", "NS-x"], "NS-x"),
    "records show: records dir": (["records", "show", "kobe", "--records-dir", "@missing"], "does_not_exist"),
    "records show: --dt text": (["records", "show", "kobe", "--dt", "fast"], "--dt"),
    "records generate: unknown name": (["records", "generate", "nosuch", "--out", "@missing"], "nosuch"),
    # --- sbib run
    "run: no --record": (["run"], "--record"),
    "run: unknown record": (["run", "--record", "nosuch", "--json"], "nosuch"),
    "run: empty record file": (["run", "--record", "@empty.txt", "--json"], "empty.txt"),
    "run: missing record file": (["run", "--record", "@missing", "--json"], "does_not_exist"),
    "run: ragged record file": (["run", "--record", "@ragged.txt", "--json"], "ragged.txt:3"),
    "run: control step 0": (["run", "--record", "kobe", "--control-step", "0", "--json"], "--control-step"),
    "run: control step NaN": (["run", "--record", "kobe", "--control-step", "nan", "--json"], "--control-step"),
    "run: control step text": (["run", "--record", "kobe", "--control-step", "abc"], "--control-step"),
    # any positive control step fits a record (issue 22); the integration step must be positive
    "run: integration step negative": (["run", "--record", "kobe", "--integration-step", "-0.005", "--json"],
                                       "--integration-step"),
    "run: record shorter than a control step": (["run", "--record", "@two.txt", "--control-step", "0.01",
                                                 "--json"], "shorter than one control step"),
    "run: n-modes 0": (["run", "--record", "kobe", "--n-modes", "0", "--json"], "n_modes"),
    "run: n-modes 25": (["run", "--record", "kobe", "--n-modes", "25", "--json"], "n_modes"),
    "run: unknown isolation": (["run", "--record", "kobe", "--isolation", "rubber-duck", "--json"], "rubber-duck"),
    "run: isolation file, bad parameter": (["run", "--record", "kobe", "--isolation", "@bad_iso.json", "--json"],
                                           "bad_iso.json"),
    "run: isolation file, broken JSON": (["run", "--record", "kobe", "--isolation", "@broken.json", "--json"],
                                         "broken.json"),
    "run: unknown controller": (["run", "--record", "kobe", "--controller", "psychic", "--json"], "psychic"),
    "run: substep tolerance NaN": (["run", "--record", "kobe", "--substep-tolerance", "nan", "--json"],
                                   "substep_tolerance"),
    "run: substep tolerance negative": (["run", "--record", "kobe", "--substep-tolerance", "-1", "--json"],
                                        "substep_tolerance"),
    "run: orientation": (["run", "--record", "kobe", "--orientation", "sideways"], "--orientation"),
    # --- sbib compare
    "compare: unknown record": (["compare", "--records", "nosuch"], "nosuch"),
    "compare: unknown controller": (["compare", "--controllers", "psychic"], "psychic"),
    "compare: jobs 0": (["compare", "--jobs", "0"], "--jobs"),
    "compare: orientation": (["compare", "--orientations", "sideways"], "sideways"),
    "compare: control step": (["compare", "--control-step", "-1"], "--control-step"),
    "compare: unknown isolation": (["compare", "--isolation", "rubber-duck"], "rubber-duck"),
    # --- sbib ensemble
    "ensemble: missing config": (["ensemble", "--config", "@missing"], "does_not_exist"),
    "ensemble: broken TOML": (["ensemble", "--config", "@broken.toml"], "broken.toml"),
    "ensemble: unknown field": (["ensemble", "--config", "@unknown_field.toml"], "bogus"),
    "ensemble: negative PGA": (["ensemble", "--config", "@negative_pga.toml"], "pga"),
    "ensemble: no motions": (["ensemble", "--config", "@no_motions.toml"], "no_motions.toml"),
    "ensemble: jobs 0": (["ensemble", "--config", "@unknown_field.toml", "--jobs", "0"], ""),
    # --- sbib bench
    "bench: unknown section": (["bench", "--only", "everything"], "everything"),
    "bench: jobs": (["bench", "--jobs", "-3"], "--jobs"),
    # --- sbib damper test
    "damper test: voltage out of range": (["damper", "test", "--model", "virtual", "--amplitude", "0.1",
                                           "--frequency", "1", "--voltage", "5", "--out", "@missing"], "voltage"),
    "damper test: negative amplitude": (["damper", "test", "--model", "virtual", "--amplitude", "-0.1",
                                         "--frequency", "1", "--voltage", "0", "--out", "@missing"], "amplitude"),
    "damper test: NaN frequency": (["damper", "test", "--model", "virtual", "--amplitude", "0.1",
                                    "--frequency", "nan", "--voltage", "0", "--out", "@missing"], "frequency"),
    "damper test: unknown model": (["damper", "test", "--model", "magic", "--amplitude", "0.1",
                                    "--frequency", "1", "--voltage", "0", "--out", "@missing"], "magic"),
    "damper test: inadmissible parameter": (["damper", "test", "--model", "virtual", "--amplitude", "0.1",
                                             "--frequency", "1", "--voltage", "0", "--param", "rho=-1",
                                             "--out", "@missing"], "rho"),
    "damper test: malformed --param": (["damper", "test", "--model", "virtual", "--amplitude", "0.1",
                                        "--frequency", "1", "--voltage", "0", "--param", "rho",
                                        "--out", "@missing"], "--param"),
    "damper test: too few samples per period": (["damper", "test", "--model", "virtual", "--amplitude", "0.1",
                                                 "--frequency", "10", "--voltage", "0", "--sample-rate", "20",
                                                 "--out", "@missing"], "sample_rate"),
    "damper test: output under a file": (["damper", "test", "--model", "virtual", "--amplitude", "0.1",
                                          "--frequency", "1", "--voltage", "0", "--cycles", "1",
                                          "--out", "@plain_file"], "plain_file"),
    # --- sbib diagnose
    "diagnose: missing file": (["diagnose", "--data", "@missing", "--quiet"], "does_not_exist"),
    "diagnose: empty file": (["diagnose", "--data", "@empty.txt", "--quiet"], "empty.txt"),
    "diagnose: one data line": (["diagnose", "--data", "@damper_short.csv", "--quiet"], "damper_short.csv"),
    "diagnose: time backwards": (["diagnose", "--data", "@damper_back.csv", "--quiet"], "damper_back.csv:4"),
    "diagnose: non-SI unit": (["diagnose", "--data", "@damper_units.csv", "--quiet"], "damper_units.csv"),
    "diagnose: wrong column names": (["diagnose", "--data", "@damper_cols.csv", "--quiet"], "damper_cols.csv"),
    "diagnose: NaN": (["diagnose", "--data", "@damper_nan.csv", "--quiet"], "damper_nan.csv:3"),
    "diagnose: holdout 2": (["diagnose", "--data", "@damper_back.csv", "--holdout", "2"], "--holdout"),
    "diagnose: unknown model": (["diagnose", "--data", "@damper_back.csv", "--model", "magic"], "--model"),
    # --- sbib identify (measured data)
    "identify: missing file": (["identify", "--data", "@missing", "--out", "@tmp"], "does_not_exist"),
    "identify: empty file": (["identify", "--data", "@empty.txt", "--out", "@tmp"], "empty.txt"),
    "identify: time backwards": (["identify", "--data", "@damper_back.csv", "--out", "@tmp"], "damper_back.csv:4"),
    "identify: NaN": (["identify", "--data", "@damper_nan.csv", "--out", "@tmp"], "damper_nan.csv:3"),
    "identify: bootstrap text": (["identify", "--data", "@damper_back.csv", "--bootstrap", "many"], "--bootstrap"),
    "identify: unknown model": (["identify", "--data", "@damper_back.csv", "--model", "magic"], "--model"),
    # --jobs had no check of its own here: 0 and -2 reached the study's pool (the other commands
    # refused them; benchmark.foundation.arguments.positive_int is now every command's check)
    "identify: jobs 0": (["identify", "--jobs", "0"], "--jobs"),
    "identify: jobs negative": (["identify", "--jobs", "-2", "--out", "@tmp"], "--jobs"),
    "compare: jobs 1.5": (["compare", "--jobs", "1.5"], "--jobs"),
    # --- sbib hysteresis
    "hysteresis fit: missing file": (["hysteresis", "fit", "--data", "@missing", "--out", "@missing"],
                                     "does_not_exist"),
    "hysteresis fit: empty file": (["hysteresis", "fit", "--data", "@empty.txt", "--out", "@missing"],
                                   "empty.txt"),
    "hysteresis fit: time backwards": (["hysteresis", "fit", "--data", "@damper_back.csv", "--out",
                                        "@missing"], "damper_back.csv:4"),
    "hysteresis fit: non-SI unit": (["hysteresis", "fit", "--data", "@damper_units.csv", "--out",
                                     "@missing"], "damper_units.csv"),
    "hysteresis fit: wrong columns": (["hysteresis", "fit", "--data", "@damper_cols.csv", "--out",
                                       "@missing"], "damper_cols.csv"),
    "hysteresis fit: NaN": (["hysteresis", "fit", "--data", "@damper_nan.csv", "--out", "@missing"],
                            "damper_nan.csv:3"),
    "hysteresis fit: holdout 2": (["hysteresis", "fit", "--data", "@damper_back.csv", "--out", "@missing",
                                   "--holdout", "2"], "--holdout"),
    "hysteresis predict: missing model": (["hysteresis", "predict", "--model", "@missing", "--input",
                                           "@damper_back.csv", "--out", "@missing"], "does_not_exist"),
    # --- the dispatcher
    "unknown command": (["teleport"], "teleport"),
    "unknown option": (["records", "show", "kobe", "--colour"], "--colour"),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_cli_rejects_bad_input_with_one_line(case, files, cli, cli_error):
    template, expected = CASES[case]
    if template[0] == "damper" and template[-1] == "@plain_file":
        template = template[:-1] + [str(files["plain_file"] / "out.csv")]
    rc, _, err = cli(_argv(template, files))
    line = cli_error(rc, err)
    assert expected in line, f"{case}: {line!r} does not mention {expected!r}"


def test_every_command_is_covered():
    """A new command must come with its bad-input cases in the table above."""
    from benchmark.applications.cli import build_parser

    parser = build_parser()
    commands = set(parser._subparsers._group_actions[0].choices)  # noqa: SLF001 - argparse has no public API
    covered = {argv[0] for argv, _ in CASES.values()}
    uncovered = commands - covered - {"study"}  # study runs everything; its options are those above
    assert not uncovered, f"commands without bad-input cases: {sorted(uncovered)}"


def _console(args: list[str], env_extra: dict[str, str] | None = None) -> subprocess.CompletedProcess:
    env = dict(os.environ, **(env_extra or {}))
    return subprocess.run([sys.executable, "-m", "benchmark", *args], capture_output=True, text=True,
                          env=env, timeout=120)


def test_console_script_exit_status_and_no_traceback(files):
    proc = _console(["records", "show", str(files["ragged.txt"])])
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines() == [proc.stderr.strip()]
    assert proc.stderr.startswith("sbib: error: ") and "ragged.txt:3" in proc.stderr
    assert "Traceback" not in proc.stderr and proc.stdout == ""


def test_console_script_argparse_error_is_one_line():
    proc = _console(["run", "--record", "kobe", "--control-step", "abc"])
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("sbib: error: ") and "--control-step" in lines[0]
