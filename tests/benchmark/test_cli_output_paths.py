"""An output path that cannot be written is refused when the command is parsed, in one line,
before any work (found by probing: errno text after minutes of computation, or an atomic
writer's temporary name in the message)."""

from __future__ import annotations

import errno

import pytest

from benchmark.applications.cli import _os_error_line, main
from benchmark.foundation.atomic import check_output
from benchmark.foundation.errors import InputError


def test_check_output_cases(tmp_path):
    a_file = tmp_path / "afile"
    a_file.write_text("x")
    check_output(tmp_path / "new" / "deeper" / "run.h5")          # parents made later
    check_output(tmp_path / "newdir", directory=True)
    with pytest.raises(InputError, match="exists and is not a directory"):
        check_output(a_file, directory=True)
    with pytest.raises(InputError, match="is a directory; expected a file name"):
        check_output(tmp_path)
    with pytest.raises(InputError, match="is a file, not a directory"):
        check_output(a_file / "x" / "run.h5")


@pytest.mark.parametrize("argv, words", [
    (["diagnose", "--data", "whatever.csv", "--out", "{file}"], "exists and is not a directory"),
    (["run", "--record", "kobe", "--out", "{dir}"], "is a directory; expected a file name"),
    (["study", "--out", "{file}/results"], "is a file, not a directory"),
    (["hysteresis", "fit", "--data", "x.csv", "--out", "{dir}"], "is a directory"),
    # probed: a --plot folder that is a file was found after the whole run, its HDF5 written
    (["run", "--record", "kobe", "--plot", "{file}"], "exists and is not a directory"),
    (["compare", "--records", "kobe", "--plot", "{file}/sub"], "is a file, not a directory"),
    (["records", "show", "kobe", "--plot", "{dir}"], "is a directory; expected a file name"),
])
def test_commands_refuse_bad_outputs_at_once(tmp_path, capsys, argv, words):
    a_file = tmp_path / "afile"
    a_file.write_text("x")
    argv = [a.format(file=a_file, dir=tmp_path) for a in argv]
    with pytest.raises(SystemExit) as stop:  # an argparse error: exit status 2 at parse time
        main(argv)
    assert stop.value.code == 2
    err = capsys.readouterr().err.strip()
    option = "--plot" if "--plot" in argv else "--out"
    assert err.startswith("sbib: error:") and option in err and words in err and "\n" not in err, err


@pytest.mark.parametrize("argv, words", [
    # probed: `records generate kobe --out x.h5` wrote CSV text into x.h5, which `sbib run
    # --record x.h5` then read as HDF5
    (["records", "generate", "kobe", "--out", "{dir}/x.h5"], "writes CSV, not H5"),
    (["records", "resample", "kobe", "--step", "0.01", "--out", "{dir}/x.AT2"], "writes CSV, not AT2"),
    (["run", "--record", "kobe", "--out", "{dir}/kobe.csv"], "writes HDF5, not CSV"),
    (["hysteresis", "fit", "--data", "x.csv", "--out", "{dir}/model.h5"], "writes JSON, not H5"),
    (["damper", "test", "--out", "{dir}/t.json"], "writes CSV, not JSON"),
])
def test_outputs_named_for_another_format_are_refused(tmp_path, capsys, argv, words):
    with pytest.raises(SystemExit) as stop:
        main([a.format(dir=tmp_path) for a in argv])
    assert stop.value.code == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("sbib: error:") and words in err and "\n" not in err, err
    assert not any(tmp_path.iterdir())


@pytest.mark.parametrize("name", ["out.csv", "out.TXT", "out", "out.data"])
def test_csv_outputs_accept_their_own_or_unknown_suffixes(tmp_path, name):
    from benchmark.foundation.atomic import output_file_of
    assert output_file_of("csv")(str(tmp_path / name)) == str(tmp_path / name)


def test_os_error_line_names_the_destination_not_the_temporary_file():
    exc = OSError(errno.EISDIR, "Is a directory", "/x/.out.partial-abc", None, "/x/out")
    assert _os_error_line(exc) == "/x/out: is a directory"
    assert _os_error_line(OSError(errno.EEXIST, "File exists", "out/afile")) == "out/afile: file exists"


def test_a_cold_kernel_cache_is_announced_for_building_commands(monkeypatch, capsys):
    """A fresh checkout's first `sbib run` compiles for minutes: it says so first (only for the
    commands that run the building)."""
    import benchmark.applications.cli as cli
    monkeypatch.setattr(cli, "stepping_kernel_cached", lambda: False)
    assert main(["run", "--record", "no-such-record.csv"]) == 2
    assert "compiling the simulation kernels once" in capsys.readouterr().err
    main(["records", "list", "--json"])
    assert "compiling" not in capsys.readouterr().err


def test_a_writer_that_cannot_create_its_file_names_that_file(tmp_path):
    """The atomic writer's temporary name is not what the user asked for: a folder that cannot be
    made (here: under a file) is reported with the destination."""
    from benchmark.foundation.atomic import atomic_write_text
    a_file = tmp_path / "afile"
    a_file.write_text("x")
    with pytest.raises(InputError, match=r"afile/sub/out.json: cannot be written") as caught:
        atomic_write_text(a_file / "sub" / "out.json", "{}")
    assert ".partial" not in str(caught.value)



def test_a_device_is_refused_and_a_link_written_through(tmp_path):
    # '--out /dev/full' had replaced the device node by an HDF5 file (the atomic rename), and an
    # output that is a symbolic link had become a file beside its untouched target
    import os
    from benchmark.foundation.atomic import atomic_write_text
    fifo = tmp_path / "pipe.h5"
    os.mkfifo(fifo)
    with pytest.raises(InputError, match="not a regular file"):
        check_output(fifo)
    with pytest.raises(InputError, match="not a regular file"):
        atomic_write_text(fifo, "x")
    assert not fifo.is_file()
    target = tmp_path / "target.txt"
    target.write_text("old")
    link = tmp_path / "link.txt"
    link.symlink_to(target)
    atomic_write_text(link, "new")
    assert link.is_symlink() and target.read_text() == "new"
