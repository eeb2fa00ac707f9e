"""A write interrupted at any point leaves the previous file or a complete new one.

A child process rewrites one destination in a loop (an HDF5 result of
:func:`benchmark.simulator.results.write_result`, a record CSV of :func:`records.readers.write_csv`, a
damper test CSV of :func:`damper.io.data.write_csv`), each generation filling every array with
its generation number. The parent kills it (SIGKILL: no clean-up at all; SIGINT: Ctrl-C) after
a delay from a fixed schedule, then reads the destination back: it must be readable, and
every value in it must be one generation's. After Ctrl-C no temporary file may remain (after
SIGKILL the hidden ``.<name>.partial-*`` file of the unfinished write may, by nature, remain;
the destination is still intact). Ensemble interruption and resume are tested in
``tests/benchmark/test_ensemble_interrupt.py``.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

CHILD = textwrap.dedent('''
    import sys
    import numpy as np

    kind, dest, n = sys.argv[1], sys.argv[2], int(sys.argv[3])

    def write(gen):
        if kind == "h5":
            from benchmark.simulator.results import write_result
            from benchmark.simulator.simulation import ENERGY_NAMES, SimulationResult
            g = float(gen)
            def full(*shape):
                return np.full(shape, g)
            result = SimulationResult(
                t=np.arange(n) * 0.005, base_displacement=full(n, 3), base_velocity=full(n, 3),
                base_acceleration=full(n, 3), base_acceleration_absolute=full(n, 3),
                floor_displacement=full(n, 8, 3), floor_acceleration_absolute=full(n, 8, 3),
                drift_ratio=full(n, 8, 2), isolation_force=full(n, 3), device_force_total=full(n, 3),
                base_shear=full(n, 3), structure_shear=full(n, 3), bearing_force=full(n, 92, 2),
                bearing_state=None, device_displacement=full(n, 16), device_velocity=full(n, 16),
                device_force=full(n, 16), voltage=full(n, 16),
                energy={k: full(n) for k in ENERGY_NAMES}, measurements=full(n, 62),
                desired_force=full(n, 16), iterations=np.full(n, gen), info={"generation": gen})
            write_result(result, dest, generation=str(gen))
        elif kind == "record":
            from records import Record
            from records.readers import write_csv
            write_csv(Record(f"gen{gen}", 0.01, np.full((n, 2), float(gen))), dest)
        else:
            from damper.io.data import DamperTest, write_csv
            t = np.arange(n) * 0.001
            write_csv(DamperTest(time=t, displacement=np.full(n, float(gen)), velocity=np.full(n, float(gen)),
                                 force=np.full(n, float(gen)), voltage=np.full(n, 0.5), name=f"gen{gen}"), dest)

    if len(sys.argv) > 4:          # write one generation and stop (the "previous file")
        write(int(sys.argv[4]))
        sys.exit(0)
    write(1)                       # warm up imports before announcing
    print("ready", flush=True)
    gen = 1
    while True:
        gen += 1
        write(gen)
''')

SIZES = {"h5": 2000, "record": 20000, "damper": 20000}
NAMES = {"h5": "result.h5", "record": "record.csv", "damper": "damper.csv"}


def _generation(kind: str, path: Path) -> int:
    """Read ``path`` back and return its single generation number (every value must agree)."""
    if kind == "h5":
        from benchmark.simulator.results import read_result

        stored = read_result(path)
        gen = int(stored.attrs["generation"])
        for name, arr in stored.arrays.items():
            if name not in ("t", "iterations"):
                assert np.all(arr == gen), f"{name} mixes generations"
        assert stored.info["generation"] == gen
        assert stored.arrays["t"].shape[0] == SIZES[kind]
        return gen
    if kind == "record":
        from records.readers import read_csv

        record = read_csv(path)
        values = np.unique(record.acceleration)
        assert values.size == 1 and record.n_samples == SIZES[kind]
        return int(values[0])
    from damper.io.data import read_csv

    test = read_csv(path)
    values = np.unique(test.force)
    assert values.size == 1 and test.n_samples == SIZES[kind]
    return int(values[0])


def _child(script: Path, kind: str, dest: Path, *extra: str) -> list[str]:
    return [sys.executable, str(script), kind, str(dest), str(SIZES[kind]), *extra]


def _interrupt(tmp_path: Path, kind: str, sig: int, delay: float,
               preexec_fn=None) -> tuple[int, list[Path]]:
    script = tmp_path / "writer.py"
    script.write_text(CHILD)
    dest = tmp_path / kind / NAMES[kind]
    dest.parent.mkdir(exist_ok=True)
    subprocess.run(_child(script, kind, dest, "0"), check=True, timeout=120)   # the previous file
    assert _generation(kind, dest) == 0
    proc = subprocess.Popen(_child(script, kind, dest), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            env=dict(os.environ, PYTHONUNBUFFERED="1"), preexec_fn=preexec_fn)
    try:
        assert proc.stdout.readline().strip() == b"ready", proc.stderr.read().decode()
        time.sleep(delay)
        proc.send_signal(sig)
        proc.wait(timeout=20)  # Ctrl-C must stop the writer, not be swallowed
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    gen = _generation(kind, dest)
    leftovers = [p for p in dest.parent.iterdir() if p != dest]
    return gen, leftovers


# (kind, signal, delay after the first completed write [s])
SCHEDULE = [("h5", signal.SIGKILL, 0.171), ("h5", signal.SIGINT, 0.057), ("record", signal.SIGKILL, 0.031),
            ("damper", signal.SIGINT, 0.109)]


@pytest.mark.parametrize("kind, sig, delay", SCHEDULE,
                         ids=[f"{k}-{signal.Signals(s).name}-{d}" for k, s, d in SCHEDULE])
def test_interrupted_write_leaves_a_complete_file(tmp_path, kind, sig, delay, sigint_default):
    gen, leftovers = _interrupt(tmp_path, kind, sig, delay, preexec_fn=sigint_default)
    assert gen >= 1  # the child completed at least its warm-up write before the signal
    if sig == signal.SIGINT:
        assert leftovers == [], f"Ctrl-C left temporary files: {leftovers}"
    else:
        assert all(p.name.startswith(f".{NAMES[kind]}.partial-") for p in leftovers), leftovers


@pytest.mark.slow
@pytest.mark.parametrize("trial", range(30))
def test_interrupted_writes_many_times(tmp_path, trial, sigint_default):
    """The same with many kill times spread over a write, for every writer (slow)."""
    sig = signal.SIGKILL if trial % 3 else signal.SIGINT
    kind = ("h5", "record", "damper")[trial % 5 % 3]
    gen, leftovers = _interrupt(tmp_path, kind, sig, 0.005 + 0.0137 * trial, preexec_fn=sigint_default)
    assert gen >= 1
    if sig == signal.SIGINT:
        assert leftovers == []


def test_atomic_path_keeps_the_previous_file_on_error(tmp_path):
    """An exception inside the ``with`` (here a failing writer) leaves the old file untouched."""
    from benchmark.foundation.atomic import atomic_path

    dest = tmp_path / "out.txt"
    dest.write_text("previous")
    with pytest.raises(RuntimeError):
        with atomic_path(dest) as tmp:
            tmp.write_text("half of the new")
            raise RuntimeError("disk full")
    assert dest.read_text() == "previous" and list(tmp_path.iterdir()) == [dest]


def test_ctrl_c_during_a_write_is_honoured_after_it(tmp_path, sigint_default):
    """Ctrl-C inside the writer is held back (h5py would swallow it), then raised; old file kept."""
    from benchmark.foundation.atomic import atomic_path

    dest = tmp_path / "out.txt"
    dest.write_text("previous")
    with pytest.raises(KeyboardInterrupt):
        with atomic_path(dest) as tmp:
            os.kill(os.getpid(), signal.SIGINT)
            tmp.write_text("new, complete")   # the writer still runs to its end
    assert dest.read_text() == "previous" and list(tmp_path.iterdir()) == [dest]
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


# Writers that may write in place: the ensemble journal is append-only with torn-line handling
# (benchmark/applications/ensemble_journal.py), the atomic module itself, and its docstring example.
_IN_PLACE_OK = {"benchmark/applications/ensemble_journal.py", "benchmark/foundation/atomic.py"}
_WRITE_CALL = ("savefig(", "h5py.File(", "write_text(", "write_bytes(", "np.save", "to_csv(", "json.dump(")


def test_every_result_writer_goes_through_atomic_path():
    """Static check: package code writes files only to the temporary path of ``atomic_path``.

    Every file-writing call must target the ``tmp`` path (or a handle opened on it); a new
    writer that writes in place fails here and should use :func:`benchmark.foundation.atomic.atomic_path`.
    """
    import re

    root = Path(__file__).resolve().parents[2]
    offenders = []
    for package in ("benchmark", "records", "damper", "controllers"):
        for path in sorted((root / package).rglob("*.py")):
            rel = path.relative_to(root).as_posix()
            if rel in _IN_PLACE_OK:
                continue
            for lineno, line in enumerate(path.read_text(encoding="utf-8").splitlines(), start=1):
                code = line.split("#", 1)[0].replace("atomic_write_text(", "").replace("json.dumps(", "")
                writes = any(call in code for call in _WRITE_CALL) or re.search(r"open\([^)]*['\"][wax]", code)
                if not writes or re.search(r"['\"]r['\"]", code):
                    continue
                if "tmp" not in code and not re.search(r"\bfh\b", code):
                    offenders.append(f"{rel}:{lineno}: {line.strip()}")
    assert not offenders, "writes outside atomic_path:\n" + "\n".join(offenders)
