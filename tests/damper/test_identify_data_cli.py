"""``sbib identify --data`` output (issue #16 item 9): progress on stderr, parameters with units,
JSON on stdout only with ``--json``."""

from __future__ import annotations

import json

import pytest

from benchmark.applications.cli import main
from damper.io.data import write_csv
from damper.lab.laboratory import periodic_test


@pytest.fixture(scope="module")
def csv_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("idata") / "virtual_0V.csv"
    write_csv(periodic_test("virtual", 0.02, 1.0, 0.0, cycles=3, sample_rate=200.0, noise=0.01, seed=4), path)
    return str(path)


def _is_json(text: str) -> bool:
    try:
        json.loads(text)
    except ValueError:
        return False
    return True


def test_text_output_has_units_and_no_json(csv_file, tmp_path, capsys):
    assert main(["identify", "--data", csv_file, "--model", "extended", "--bootstrap", "0",
                 "--out", str(tmp_path)]) == 0
    captured = capsys.readouterr()
    out = captured.out
    assert not _is_json(out) and "{" not in out, out
    assert "kappa_x = " in out and " N/m" in out and " N s/m" in out and " 1/m" in out
    assert "kappa_w = " in out and " kN" not in out.split("kappa_w = ")[1].split(",")[0]
    # progress on stderr: a line when it starts and one per identification
    assert "identify" in captured.err and "1/1" in captured.err


def test_json_only_with_the_option(csv_file, tmp_path, capsys):
    assert main(["identify", "--data", csv_file, "--model", "extended", "--bootstrap", "0",
                 "--out", str(tmp_path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["tests"][0]["units"]["kappa_x"] == "N/m"


def test_nested_summaries_print_as_text(capsys):
    from benchmark.applications.cli_identify import _print_tree

    _print_tree({"extended": {"mean_rel_rms_error": 0.0123, "runs": [1, {"a": 2.0}]}, "n": 3}, "  ")
    out = capsys.readouterr().out
    assert "{" not in out and "mean_rel_rms_error: 0.0123" in out and "  n: 3" in out
