"""A shared-data path the user set that does not exist is an error naming it (issue #16, item 4)."""

from __future__ import annotations

import pytest

from benchmark.foundation.errors import DataNotFoundError


def test_missing_sbib_shared_is_an_error(monkeypatch, tmp_path):
    from benchmark.foundation.paths import shared_dir

    missing = tmp_path / "nonexistent"
    monkeypatch.setenv("SBIB_SHARED", str(missing))
    with pytest.raises(DataNotFoundError, match="SBIB_SHARED") as info:
        shared_dir()
    assert str(missing) in str(info.value)


def test_missing_explicit_shared_is_an_error(monkeypatch, tmp_path):
    from benchmark.foundation.paths import shared_dir

    monkeypatch.delenv("SBIB_SHARED", raising=False)
    with pytest.raises(DataNotFoundError, match="nowhere"):
        shared_dir(tmp_path / "nowhere")


@pytest.mark.parametrize("argv", [["run", "--record", "kobe"], ["records", "list"],
                                  ["records", "show", "kobe"]])
def test_cli_names_the_missing_shared_path(monkeypatch, tmp_path, capsys, argv):
    from benchmark.applications.cli import main

    missing = tmp_path / "nonexistent"
    monkeypatch.setenv("SBIB_SHARED", str(missing))
    monkeypatch.delenv("SBIB_RECORDS_DIR", raising=False)
    status = main(argv)
    out, err = capsys.readouterr()
    assert status == 2
    assert str(missing) in err and "SBIB_SHARED" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("argv", [["run", "--record", "kobe"], ["records", "list"]])
def test_cli_names_the_missing_records_dir(monkeypatch, tmp_path, capsys, argv):
    from benchmark.applications.cli import main

    missing = tmp_path / "norecords"
    monkeypatch.setenv("SBIB_RECORDS_DIR", str(missing))
    status = main(argv)
    out, err = capsys.readouterr()
    assert status == 2 and str(missing) in err and "SBIB_RECORDS_DIR" in err
