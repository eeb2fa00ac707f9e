"""Shared fixtures: paths to the shared benchmark data (skip with a clear message when absent)."""

from __future__ import annotations

import os
from pathlib import Path

# One BLAS thread, as every `sbib` process has (benchmark/applications/cli.py sets it before numpy
# is imported), and set here before any test module imports numpy: the fixture below imports the
# command line, which sets it for the processes the tests start, and a test process on
# OpenBLAS's default threads would then compute an LQG design that differs from a subprocess's
# in the last digits (tests/reliability/test_reproducible_runs.py compares them bit for bit).
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import pytest  # noqa: E402

from benchmark.foundation.kernel_cache import ensure_fresh  # noqa: E402

_DEFAULT_SHARED = Path(__file__).resolve().parent.parent.parent / "shared"


def _shared_path() -> Path:
    return Path(os.environ.get("SBIB_SHARED") or _DEFAULT_SHARED)


@pytest.fixture(scope="session")
def shared_dir() -> Path:
    """The shared data directory (SBIB_SHARED or ../shared); skips the test when absent."""
    path = _shared_path()
    if not path.is_dir():
        pytest.skip(f"shared data not found at {path}; set SBIB_SHARED to run this test")
    return path


@pytest.fixture(scope="session")
def records_dir(shared_dir: Path) -> Path:
    """The benchmark's two-column record files (SBIB_RECORDS_DIR or <shared>/records/raw/FDZ)."""
    path = Path(os.environ.get("SBIB_RECORDS_DIR") or shared_dir / "records" / "raw" / "FDZ")
    if not path.is_dir():
        pytest.skip(f"benchmark records not found at {path}; set SBIB_RECORDS_DIR")
    return path


def _default_sigint_in_child() -> None:
    """``preexec_fn`` of a child that is sent Ctrl-C: SIGINT back to its default action."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.fixture
def sigint_default():
    """For tests that send SIGINT: Ctrl-C works even if the suite runs with SIGINT ignored.

    A background job of a shell (``nohup make test &``) starts with SIGINT ignored; children
    inherit the ignore and Python then installs no ``KeyboardInterrupt`` handler. This fixture
    restores Python's handler in the test process for the test's duration and returns a
    ``preexec_fn`` that gives a child the default action (so that Python installs its handler).
    """
    import signal

    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield _default_sigint_in_child
    finally:
        signal.signal(signal.SIGINT, previous)


class _FigureTexts:
    """Axis labels and titles of every figure saved during a test (see ``figures``)."""

    #: a unit at the end of a label: "force [kN]", "Force (kN)"
    _UNIT = r"[\[(]([^\[\]()]*)[\])]\s*$"

    def __init__(self) -> None:
        self.seen: list[list[tuple[str, str]]] = []

    def record(self, fig) -> None:
        texts = []
        for ax in fig.axes:
            for where, text in (("xlabel", ax.get_xlabel()), ("ylabel", ax.get_ylabel()),
                                ("title", ax.get_title())):
                if text:
                    texts.append((where, text))
        self.seen.append(texts)

    def check(self) -> None:
        """Every unit shown is a display unit of ``benchmark.foundation.display_units`` (or %, V/s, A/s)."""
        import re

        from benchmark.foundation.display_units import DISPLAY_UNITS

        allowed = {u for u, _ in DISPLAY_UNITS.values()} | {"V/s", "A/s", "%"}
        assert self.seen, "no figure was saved"
        for texts in self.seen:
            for where, text in texts:
                m = re.search(self._UNIT, text)
                if m is None or not re.fullmatch(r"[-\w./·²$\\{}^]*", m.group(1).strip()):
                    continue   # no unit, or words in parentheses ("cf. seed Fig. 2")
                unit = m.group(1).strip()
                assert unit in allowed, f"{where} {text!r}: unit {unit!r} is not a display unit"


@pytest.fixture
def figures(monkeypatch):
    """Records the axis labels and titles of every figure saved during the test (units check)."""
    from matplotlib.figure import Figure

    recorder = _FigureTexts()
    original = Figure.savefig

    def savefig(self, *args, **kwargs):
        recorder.record(self)
        return original(self, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", savefig)
    return recorder


def pytest_configure(config):
    """Clear numba caches made stale by an edit of a kernel another kernel calls (before any
    test loads one): see benchmark/foundation/kernel_cache.py."""
    ensure_fresh()


@pytest.fixture(autouse=True)
def _warm_kernel_cache_assumed(monkeypatch):
    """In-process ``sbib`` calls see the kernel cache as warm, as ``make test`` leaves it.

    ``make test`` compiles every kernel at set-up (``sbib warm-up``) before the suite runs. A
    suite run on a cold cache (``pytest`` straight after a clone, on another CPU) would otherwise
    print the command line's compile notice before the first building command's one-line
    error, and the tests that hold an error to one line would fail on the notice, not on the
    error (seen on an Intel Xeon with numba 0.68.0, 2026-11-26). The notice itself is tested
    in ``tests/benchmark/test_cli_output_paths.py``, which sets the cache cold again.
    """
    import benchmark.applications.cli as cli

    monkeypatch.setattr(cli, "stepping_kernel_cached", lambda: True)
