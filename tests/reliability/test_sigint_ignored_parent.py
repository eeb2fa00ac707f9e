"""The Ctrl-C tests also pass when the suite itself runs with SIGINT ignored.

A shell starts a background job (``nohup make test &``) with SIGINT ignored, and children
inherit the ignore: Python then installs no ``KeyboardInterrupt`` handler, and a test that sends
SIGINT to its child (or to itself) sees nothing happen. Those tests restore the default handler
(``tests/sigint.py``); this test runs them under a parent that ignores SIGINT.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

#: fast Ctrl-C tests (the ensemble one takes ~10 s and is covered by the same helper)
CTRL_C_TESTS = [
    "tests/reliability/test_interrupted_writes.py::test_ctrl_c_during_a_write_is_honoured_after_it",
    "tests/reliability/test_interrupted_writes.py::test_interrupted_write_leaves_a_complete_file"
    "[damper-SIGINT-0.109]",
]


def _ignore_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def test_ctrl_c_tests_pass_when_sigint_is_ignored_by_the_parent():
    proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", *CTRL_C_TESTS],
                          cwd=ROOT, capture_output=True, text=True, timeout=300,
                          preexec_fn=_ignore_sigint, env=dict(os.environ, PYTHONUNBUFFERED="1"))
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-2000:]
    assert "2 passed" in proc.stdout, proc.stdout[-2000:]
