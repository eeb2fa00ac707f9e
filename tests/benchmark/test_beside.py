"""benchmark.foundation.beside: a function run in a forked child while the caller goes on."""

from __future__ import annotations

import os
import sys
import threading

import pytest

from benchmark.foundation.beside import run_beside
from benchmark.foundation.errors import SbibError

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="fork")


def _pid_and_count(items):
    return os.getpid(), len(items)


def test_the_value_comes_back_and_the_work_ran_in_another_process():
    pid, count = run_beside(_pid_and_count, list(range(1000))).result()
    assert count == 1000
    assert pid != os.getpid()


def test_inputs_are_inherited_not_pickled():
    lock = threading.Lock()  # cannot be pickled

    def uses_the_lock(n):
        with lock:
            return n * 2

    assert run_beside(uses_the_lock, 21).result() == 42


def _fails():
    raise ValueError("bad figure data")


def test_an_error_in_the_child_is_raised_with_its_traceback():
    with pytest.raises(SbibError, match="bad figure data"):
        run_beside(_fails).result()


def _dies():
    os._exit(3)


def test_a_child_that_dies_without_an_answer_is_an_error():
    with pytest.raises(SbibError, match="exit code 3"):
        run_beside(_dies).result()


@pytest.mark.parametrize("n_cases", [1, 5, 14])
def test_comparison_figures_split_into_shares_that_cover_them_once(monkeypatch, tmp_path, n_cases):
    from types import SimpleNamespace

    import benchmark.applications.comparison_plots as cp
    monkeypatch.setattr(cp, "plot_J_by_record", lambda r, p: p)
    monkeypatch.setattr(cp, "plot_J_summary", lambda r, p: p)
    monkeypatch.setattr(cp, "plot_histories", lambda r, rec, o, p: p)
    result = SimpleNamespace(cases=[(f"r{k}", "FN-x") for k in range(n_cases)])
    whole = cp.plot_all(result, tmp_path)
    shares = [cp.plot_all(result, tmp_path, (i, 2)) for i in range(2)]
    assert sorted(shares[0] + shares[1]) == sorted(whole)
    assert not set(shares[0]) & set(shares[1])
    assert len(whole) == n_cases + 2
