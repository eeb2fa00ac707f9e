"""Fuzz: malformed record files, damper test files, configurations and CLI options.

Hypothesis mutates valid files (truncation, tokens replaced by text/NaN/inf/empty, rows made
ragged, duplicated or swapped so that time goes backwards, headers and units garbled, random
bytes) and drives every reader and the ``sbib`` command line in-process with them. The only
outcomes allowed are a valid object or a *clear error*: an ``InputError`` (or subclass) whose
message is one line and names the file or field; from the CLI, exit status 2 and exactly one
``sbib: error: ...`` line. Anything else (a traceback, a ``ValueError`` from numpy, a record
with NaN in it) fails the test.

The examples are derandomized (same inputs on every run, so a failure reproduces) and small;
1850 are generated in total (see ``N_EXAMPLES``), in about ten seconds.
"""

from __future__ import annotations

import contextlib
import io
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from benchmark.foundation.errors import InputError

# examples per test; their sum is the total number of generated malformed inputs
N_EXAMPLES = {
    "record_readers": 500,
    "record_bytes": 150,
    "damper_csv": 250,
    "utfsm": 150,
    "isolation_json": 150,
    "ensemble_toml": 150,
    "damper_parameters": 150,
    "cli_record_files": 150,
    "cli_options": 150,
}


def _settings(name: str):
    return settings(max_examples=N_EXAMPLES[name], deadline=None, derandomize=True, database=None,
                    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow,
                                           HealthCheck.data_too_large])


def test_the_fuzz_generates_at_least_1000_inputs():
    assert sum(N_EXAMPLES.values()) >= 1000


# --------------------------------------------------------------------------------------------
# Mutations of valid files
# --------------------------------------------------------------------------------------------
BAD_TOKENS = ["nan", "NaN", "inf", "-inf", "1e999", "-1e400", "abc", "", "1,5", "0x1A", "--1", "1.2.3",
              "1e", "e5", "+-3", "∞", "１２", "None", "true", "1_000", "  ", "\t", "%", "#", ";", ",",
              "9" * 400, "1e-400", "0", "-0", "-1", "1e308"]


@st.composite
def mutated(draw, lines: list[str]) -> str:
    """A valid file's ``lines`` with 1-4 random mutations applied."""
    lines = list(lines)
    for _ in range(draw(st.integers(1, 4))):
        op = draw(st.sampled_from(["token", "token", "drop_token", "add_token", "dup_line", "swap_lines",
                                   "drop_line", "insert_text", "truncate", "empty", "crlf", "header"]))
        if not lines:
            lines = [""]
        i = draw(st.integers(0, len(lines) - 1))
        if op == "token":
            tokens = lines[i].replace(",", " , ").split(" ")
            j = draw(st.integers(0, max(len(tokens) - 1, 0)))
            tokens[j] = draw(st.sampled_from(BAD_TOKENS) | st.text(max_size=6))
            lines[i] = " ".join(tokens).replace(" , ", ",")
        elif op == "drop_token":
            tokens = lines[i].split()
            if tokens:
                del tokens[draw(st.integers(0, len(tokens) - 1))]
            lines[i] = " ".join(tokens)
        elif op == "add_token":
            lines[i] = lines[i] + draw(st.sampled_from([" ", ",", "\t"])) + draw(
                st.sampled_from(["1.0", "2", "x", "nan"]))
        elif op == "dup_line":
            lines.insert(i, lines[i])
        elif op == "swap_lines":
            j = draw(st.integers(0, len(lines) - 1))
            lines[i], lines[j] = lines[j], lines[i]
        elif op == "drop_line":
            del lines[i]
        elif op == "insert_text":
            lines.insert(i, draw(st.text(max_size=20)))
        elif op == "truncate":
            text = "\n".join(lines)
            cut = draw(st.integers(0, len(text)))
            lines = text[:cut].split("\n")
        elif op == "empty":
            lines = []
        elif op == "crlf":
            lines = [line + "\r" for line in lines]
        elif op == "header":
            lines.insert(0, draw(st.sampled_from(["%", "#", ""])) + draw(st.text(max_size=30)))
    return "\n".join(lines)


def _write(path: Path, content: str | bytes) -> Path:
    path.write_bytes(content.encode("utf-8", "surrogatepass") if isinstance(content, str) else content)
    return path


def _outcome(func, path: Path, *args, **kwargs):
    """Call ``func``; return its value, or check that it raised a clear error naming ``path``."""
    try:
        return func(path, *args, **kwargs)
    except InputError as exc:
        message = str(exc)
        assert "\n" not in message and "\r" not in message, f"multi-line message: {message!r}"
        assert str(path) in message or path.name in message, f"file not named: {message!r}"
        return None


def _check_record(record) -> None:
    if record is None:
        return
    acc = np.asarray(record.acceleration)
    assert acc.ndim == 2 and acc.shape[0] >= 2 and np.all(np.isfinite(acc))
    assert math.isfinite(record.dt) and record.dt > 0


# --------------------------------------------------------------------------------------------
# Record readers
# --------------------------------------------------------------------------------------------
BENCHMARK_LINES = ["%1995 Kobe, Japan Earthquake. First column contains FN Component",
                   "%component (JMA Station - E-W). Acc. in cm/sec^2 and dt=0.005 sec.",
                   "0.00E+00\t\t0.00E+00", "-1.05E-01\t\t-2.04E-01", "-1.12E-01\t\t-1.96E-01",
                   "3.5E+01\t\t-2.2E+01"]
AT2_LINES = ["PEER NGA STRONG MOTION DATABASE RECORD", "Kobe 1995-01-16, KJMA, 000",
             "ACCELERATION TIME HISTORY IN UNITS OF G", "NPTS=    6, DT=   .0100 SEC",
             "  .1234E-02  .2345E-02 -.3456E-02", "  .1000E-01 -.2000E-01  .0000E+00"]
SINGLE_LINES = ["0.0012", "-0.0034", "0.0100", "0.0200", "-0.0150"]
CSV_LINES = ["# units: g", "time [s],ax [g],ay [g]", "0.00,0.001,0.002", "0.01,0.003,-0.004",
             "0.02,-0.010,0.020", "0.03,0.000,0.010"]

KNET_LINES = ["Origin Time       2011/03/11 14:46:00", "Lat.              38.103", "Long.             142.860",
              "Depth. (km)       24", "Mag.              9.0", "Station Code      MYG004",
              "Station Lat.      38.7291", "Station Long.     141.0217", "Station Height(m) 230",
              "Record Time       2011/03/11 14:46:24", "Sampling Freq(Hz) 100Hz", "Duration Time(s)  0.16",
              "Dir.              E-W", "Scale Factor      3920(gal)/6182761", "Max. Acc. (gal)   11.689",
              "Last Correction   2011/03/11 14:46:09", "Memo.",
              "  1000  1010  -9000  1020  20000  1000  990  1005", "  1001  1000  1000  999  1000  1002  998  1000"]
ESM_LINES = ["EVENT_NAME: TEST", "EVENT_ID: X", "NETWORK: IT", "STATION_CODE: NRC", "SAMPLING_INTERVAL_S: 0.010000",
             "NDATA: 5", "STREAM: HGE", "UNITS: cm/s^2", "PGA_CM/S^2: 20.0", "DATA_TYPE: ACCELERATION", "USER5:",
             "1.0E+00", "-2.0E+01", "3.0E+00", "5.0E+00", "-1.0E+00"]

def _cosmos_lines() -> list[str]:
    """A valid COSMOS v1.20 block of 16 values (layout of records.station_files.read_cosmos)."""
    ints, reals = [-999] * 100, [-999.0] * 100
    ints[53], reals[61], reals[62], reals[63] = 90, 10.0, 0.16, -12.5
    values = [0.5, -1.25, 3.0, -12.5, 7.0, 2.0, -4.0, 1.0, 0.0, 0.25, -0.5, 1.5, 2.5, -3.5, 4.5, -0.75]
    return (["Corrected acceleration    (Format v01.20 with 13 text lines)"] + [f"text {k}" for k in range(2, 14)]
            + [" 100 Integer-header values follow on  10 lines, Format= (10I8)"]
            + ["".join(f"{v:8d}" for v in ints[k:k + 10]) for k in range(0, 100, 10)]
            + [" 100 Real-header values follow on  20 lines, Format= (5F15.6)"]
            + ["".join(f"{v:15.6f}" for v in reals[k:k + 5]) for k in range(0, 100, 5)]
            + ["  0 Comment line(s) follow, each starting with a \"|\":",
               "      16  acceleration pts, approx    0 secs, units=cm/sec2(04),Format=(8F10.5)"]
            + ["".join(f"{v:10.5f}" for v in values[k:k + 8]) for k in range(0, 16, 8)])


COSMOS_LINES = _cosmos_lines()

RECORD_CASES = {
    "benchmark": ("quake.txt", BENCHMARK_LINES, lambda p: __import__("records.readers").readers.read_benchmark(p)),
    "at2": ("quake.AT2", AT2_LINES, lambda p: __import__("records.readers").readers.read_at2(p)),
    "single": ("quake.dat", SINGLE_LINES,
               lambda p: __import__("records.readers").readers.read_single_column(p, dt=0.01)),
    "csv": ("quake.csv", CSV_LINES, lambda p: __import__("records.readers").readers.read_csv(p)),
    "knet": ("MYG0041103111446.EW", KNET_LINES, lambda p: __import__("records.station_files").station_files.read_knet(p)),
    "esm": ("IT.NRC..HGE.ASC", ESM_LINES, lambda p: __import__("records.station_files").station_files.read_esm(p)),
    "cosmos": ("CE1.V2", COSMOS_LINES, lambda p: __import__("records.station_files").station_files.read_cosmos(p)),
}


@pytest.mark.parametrize("fmt", sorted(RECORD_CASES))
def test_valid_templates_are_read(tmp_path, fmt):
    """The templates the fuzz mutates are valid files (so the mutations are what fails)."""
    name, lines, reader = RECORD_CASES[fmt]
    record = reader(_write(tmp_path / name, "\n".join(lines)))
    _check_record(record)


@_settings("record_readers")
@given(data=st.data(), fmt=st.sampled_from(sorted(RECORD_CASES)), auto=st.booleans())
def test_record_readers_give_records_or_clear_errors(tmp_path, data, fmt, auto):
    from records.readers import load_record

    name, lines, reader = RECORD_CASES[fmt]
    path = _write(tmp_path / name, data.draw(mutated(lines)))
    if auto:
        _check_record(_outcome(load_record, path, dt=0.01 if fmt == "single" else None))
    else:
        _check_record(_outcome(reader, path))


@_settings("record_bytes")
@given(content=st.binary(max_size=300), suffix=st.sampled_from([".txt", ".AT2", ".csv", ".dat"]))
def test_record_reader_on_random_bytes(tmp_path, content, suffix):
    from records.readers import load_record

    path = _write(tmp_path / f"bytes{suffix}", content)
    _check_record(_outcome(load_record, path, dt=0.01))


# --------------------------------------------------------------------------------------------
# Damper test readers
# --------------------------------------------------------------------------------------------
DAMPER_CSV_LINES = ["# name: virtual test", "time,displacement,force,velocity,voltage",
                    "0.0,0.0,-1234.5,2.01,0.5", "0.005,0.01,-1000.0,2.0,0.5", "0.01,0.02,-500,1.9,0.5",
                    "0.015,0.029,10,1.8,0.5"]
UTFSM_LINES = ["   0.0000000e+00  -2.6156111e-02  -1.2000000e+00  -9.0296201e+01",
               "   5.0000000e-03  -3.5156111e-02  -1.8000000e+00  -1.1498444e+02",
               "   1.0000000e-02  -4.6406111e-02  -2.2500000e+00  -1.2398204e+02",
               "   1.5000000e-02  -5.0000000e-02  -2.0000000e+00  -1.3000000e+02"]


def _check_damper_test(test) -> None:
    if test is None:
        return
    for name in ("time", "displacement", "velocity", "force"):
        assert np.all(np.isfinite(getattr(test, name))), name
    assert np.all(np.diff(test.time) > 0)


def test_valid_damper_templates_are_read(tmp_path):
    from damper.io.data import read_csv, read_utfsm

    _check_damper_test(read_csv(_write(tmp_path / "t.csv", "\n".join(DAMPER_CSV_LINES))))
    _check_damper_test(read_utfsm(_write(tmp_path / "2mm5Hz0x5A.txt", "\n".join(UTFSM_LINES))))


@_settings("damper_csv")
@given(data=st.data())
def test_damper_csv_reader(tmp_path, data):
    from damper.io.data import read_csv

    path = _write(tmp_path / "damper_test.csv", data.draw(mutated(DAMPER_CSV_LINES)))
    _check_damper_test(_outcome(read_csv, path))


@_settings("utfsm")
@given(data=st.data(), raw=st.booleans())
def test_utfsm_reader(tmp_path, data, raw):
    from damper.io.data import read_utfsm

    content = data.draw(st.binary(max_size=200)) if raw else data.draw(mutated(UTFSM_LINES))
    path = _write(tmp_path / "2mm5Hz0x5A.txt", content)
    _check_damper_test(_outcome(read_utfsm, path))


# --------------------------------------------------------------------------------------------
# Configuration files: isolation JSON, ensemble TOML
# --------------------------------------------------------------------------------------------
ISOLATION_LINES = ['{"name": "my-layer", "groups": [',
                   '  {"type": "friction-pendulum", "bearings": "1-61",',
                   '   "parameters": {"weight": 2.2e6, "radius": 2.24, "mu_max": 0.06, "mu_min": 0.03,',
                   '                  "rate_parameter": 20}},',
                   '  {"type": "lead-rubber", "bearings": "62-92",',
                   '   "parameters": {"k_initial": 9.86e6, "alpha": 0.1, "yield_force": 1.2e5}}]}']
ENSEMBLE_LINES = ['name = "fuzz"', "base_seed = 7", 'run = "probe"', 'controllers = ["passive-off", "passive-on"]',
                  'records = ["kobe", "sylmar"]', 'orientations = ["FN-x"]', "pga = [2.0, 4.0]",
                  "[synthetic]", 'templates = ["newhall"]', "realisations = 2", "[grid]",
                  "control_step = [0.005, 0.01]"]


def test_valid_config_templates_are_read(tmp_path):
    from benchmark.applications.ensemble import EnsembleConfig
    from benchmark.simulator.isolation.configurations import load_isolation

    assert load_isolation(_write(tmp_path / "iso.json", "\n".join(ISOLATION_LINES))).n_bearings == 92
    assert len(EnsembleConfig.from_toml(_write(tmp_path / "e.toml", "\n".join(ENSEMBLE_LINES))).cases()) > 0


@_settings("isolation_json")
@given(data=st.data())
def test_isolation_json_reader(tmp_path, data):
    from benchmark.simulator.isolation.configurations import load_isolation

    path = _write(tmp_path / "isolation.json", data.draw(mutated(ISOLATION_LINES)))
    layer = _outcome(load_isolation, path)
    if layer is not None:
        packed = layer.pack()
        assert np.all(np.isfinite(packed.params))


@_settings("ensemble_toml")
@given(data=st.data())
def test_ensemble_toml_reader(tmp_path, data):
    from benchmark.applications.ensemble import EnsembleConfig

    path = _write(tmp_path / "ensemble.toml", data.draw(mutated(ENSEMBLE_LINES)))
    config = _outcome(EnsembleConfig.from_toml, path)
    if config is not None:
        for case in config.cases():
            assert case.key and case.seed >= 0


# --------------------------------------------------------------------------------------------
# Model parameters (the Python API)
# --------------------------------------------------------------------------------------------
ANY_FLOAT = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.sampled_from([0.0, -1.0, 0.5, 1.0]))


@_settings("damper_parameters")
@given(kappa_x=ANY_FLOAT, kappa_xdot=ANY_FLOAT, kappa_w=ANY_FLOAT, rho=ANY_FLOAT, sigma=ANY_FLOAT, n=ANY_FLOAT)
def test_extended_bouc_wen_parameters(kappa_x, kappa_xdot, kappa_w, rho, sigma, n):
    """Any float is either an admissible parameter set (finite packed array) or a ParameterError."""
    from benchmark.foundation.errors import ParameterError
    from damper import ExtendedBoucWen

    try:
        model = ExtendedBoucWen(kappa_x=kappa_x, kappa_xdot=kappa_xdot, kappa_w=kappa_w, rho=rho,
                                sigma=sigma, n=n)
    except ParameterError as exc:
        message = str(exc)
        assert "\n" not in message
        return
    assert np.all(np.isfinite(model.to_array()))
    assert model.rho > 0 and model.sigma >= 0.5 and model.n >= 1


# --------------------------------------------------------------------------------------------
# The command line
# --------------------------------------------------------------------------------------------
def _cli(argv: list[str]) -> tuple[int, str, str]:
    from benchmark.applications.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            rc = main(argv)
        except SystemExit as exc:
            rc = exc.code if isinstance(exc.code, int) else 2
    return int(rc), out.getvalue(), err.getvalue()


def _check_cli(rc: int, err: str, names=()) -> None:
    assert rc in (0, 2), f"exit status {rc}: {err!r}"
    if rc == 2:
        lines = [line for line in err.splitlines() if line.strip()]
        assert len(lines) == 1 and lines[0].startswith("sbib: error: "), err
        if names:
            assert any(n in lines[0] for n in names), lines[0]


@_settings("cli_record_files")
@given(data=st.data(), fmt=st.sampled_from(["benchmark", "at2", "csv"]))
def test_cli_records_show_on_malformed_files(tmp_path, data, fmt):
    name, lines, _ = RECORD_CASES[fmt]
    path = _write(tmp_path / name, data.draw(mutated(lines)))
    rc, _, err = _cli(["records", "show", str(path), "--json"])
    _check_cli(rc, err, names=(str(path), path.name))


BAD_NUMBERS = st.one_of(st.sampled_from(["nan", "inf", "-inf", "0", "-1", "-0.005", "abc", "", "1e999", "--"]),
                        st.text(max_size=8).filter(lambda s: not s.startswith("-") or s == "-"))


@_settings("cli_options")
@given(option=st.sampled_from(["--dt", "--units", "--damping", "--format", "--seed"]), value=BAD_NUMBERS)
def test_cli_options_of_records_show(tmp_path, option, value):
    path = _write(tmp_path / "quake.dat", "\n".join(SINGLE_LINES))
    argv = ["records", "show", str(path), "--json", "--format", "single", "--dt", "0.01"]
    argv += [f"{option}={value}"]
    rc, _, err = _cli(argv)
    _check_cli(rc, err)
