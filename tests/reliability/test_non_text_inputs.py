"""Non-text and non-UTF-8 input files give the usual one-line error, never a traceback (issue #16, item 16).

Every reader of a text file (records, damper tests, isolation JSON, ensemble TOML, the
structure file) is fed a binary file (PNG-like bytes with a NUL) and a Latin-1 file (a
byte 0xB0 that is not UTF-8), through the Python API and through ``sbib``.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from benchmark.foundation.errors import InputError

BINARY = b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\x00\x00\x01\x00" + bytes(range(256))
# valid-looking content whose one non-ASCII byte is Latin-1 (a degree sign), not UTF-8
LATIN1 = {
    "record.txt": "% Sylmar 360\xb0 = FN\n1.0 2.0\n3.0 4.0\n",
    "record.csv": "time,ax [g]\n0,0.1\n0.01,0.2\n0.02,0.1\n# 360\xb0\n",
    "damper.csv": "# name: test at 20\xb0C\ntime,displacement,force\n0,0,1\n0.1,0.1,2\n0.2,0.2,3\n",
    "25mm0x1Hz0x75A.txt": "0.0 0.0 0.0 1.0\n0.005 0.1 0.1 2.0 \xb0\n",
    "isolation.json": '{"name": "caf\xe9", "groups": []}',
    "ensemble.toml": 'name = "caf\xe9"\ncontrollers = ["passive-on"]\nrecords = ["kobe"]\n',
}


def _readers():
    from benchmark.applications.ensemble import EnsembleConfig
    from benchmark.simulator.isolation.configurations import load_isolation as load_isolation_file
    from damper.io.data import read_csv as read_damper_csv
    from damper.io.data import read_utfsm
    from records import load_record

    return {
        "record.txt": lambda p: load_record(p),
        "record.csv": lambda p: load_record(p),
        "damper.csv": read_damper_csv,
        "25mm0x1Hz0x75A.txt": read_utfsm,
        "isolation.json": load_isolation_file,
        "ensemble.toml": EnsembleConfig.from_toml,
    }


@pytest.mark.parametrize("name", sorted(LATIN1))
@pytest.mark.parametrize("kind", ["binary", "latin-1"])
def test_readers_reject_non_text_with_one_line(tmp_path, name, kind):
    path = tmp_path / name
    path.write_bytes(BINARY if kind == "binary" else LATIN1[name].encode("latin-1"))
    with pytest.raises(InputError) as info:
        _readers()[name](path)
    message = str(info.value)
    assert str(path) in message and "\n" not in message
    assert ("binary" in message) if kind == "binary" else ("UTF-8" in message)


@pytest.mark.parametrize("name", sorted(LATIN1))
def test_readers_name_utf16(tmp_path, name):
    """A spreadsheet's "Unicode text" export (UTF-16 with its byte-order mark) is named as such,
    not as a binary file."""
    path = tmp_path / name
    path.write_bytes(LATIN1[name].encode("utf-16"))
    with pytest.raises(InputError, match="UTF-16 text; expected UTF-8"):
        _readers()[name](path)


def test_structure_file_rejects_non_text(tmp_path):
    from benchmark.simulator.structure import load_superstructure

    path = tmp_path / "structure.json"
    path.write_bytes(BINARY)
    with pytest.raises(InputError, match="binary"):
        load_superstructure(path)


@pytest.mark.parametrize("argv", [
    ["identify", "--data", "{bin}"],
    ["diagnose", "--data", "{bin}"],
    ["run", "--record", "{bin}"],
    ["records", "show", "{bin}"],
    ["run", "--record", "kobe", "--isolation", "{json}"],
    ["ensemble", "--config", "{toml}"],
])
def test_cli_rejects_non_text_in_one_line(tmp_path, capsys, argv):
    from benchmark.applications.cli import main

    paths = {"bin": tmp_path / "data.csv", "json": tmp_path / "iso.json", "toml": tmp_path / "e.toml"}
    paths["bin"].write_bytes(BINARY)
    paths["json"].write_bytes(LATIN1["isolation.json"].encode("latin-1"))
    paths["toml"].write_bytes(LATIN1["ensemble.toml"].encode("latin-1"))
    argv = [a.format(**{k: str(v) for k, v in paths.items()}) for a in argv]
    status = main(argv)
    out, err = capsys.readouterr()
    assert status == 2, err
    assert err.startswith("sbib: error: ") and len(err.strip().splitlines()) == 1, err
    assert "Traceback" not in err


def test_identify_binary_file_no_traceback_in_a_real_process(tmp_path):
    path = tmp_path / "data.bin"
    path.write_bytes(BINARY)
    proc = subprocess.run([sys.executable, "-m", "benchmark", "identify", "--data", str(path)],
                          capture_output=True, text=True, timeout=120,
                          cwd=Path(__file__).resolve().parents[2])
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr and len(proc.stderr.strip().splitlines()) == 1
