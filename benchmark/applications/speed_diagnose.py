"""``sbib bench --only diagnose``: the residual loop's two timing cases (issue 13, item 4).

=====================  =====================================================  ============
case                   test                                                   target
=====================  =====================================================  ============
``diagnose-1khz``      40 s at 1 kHz, random motion, random voltage           <= 20 s
``diagnose-3khz``      25 s at 3 kHz (75 001 samples), the same protocol      <= 60 s
=====================  =====================================================  ============

Both tests come from the virtual laboratory (:func:`damper.lab.protocols.random_voltage_test`
on the virtual benchmark damper, 1 % force noise, voltage levels held 0.3 s on average). Each is
timed *warm* (the compiled kernels cached; a short diagnosis runs first in the same process) on
*one core*: a fresh Python process pinned to one CPU with the BLAS, OpenMP and numba thread pools
at one thread, so that the figure does not depend on how many cores the machine lends or on
thread pools fighting over them (on a loaded machine a multi-threaded BLAS made each small
least-squares step 70 times slower). The target is judged on the CPU time of that single-threaded,
pinned process, which is its time on a dedicated core; the wall time is reported too (on a
shared machine it includes the time the process waited for its core). The held-out errors before
and after the loop are reported beside the time.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

from benchmark.applications.bench_case import BenchCase

__all__ = ["bench_diagnose", "DIAGNOSE_CASES"]

#: name -> (duration [s], sample rate [Hz], target [s])
DIAGNOSE_CASES = {"diagnose-1khz": (40.0, 1000.0, 20.0), "diagnose-3khz": (25.0, 3000.0, 60.0)}

_SCRIPT = r"""
import json, os, sys, time
try:
    os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})
except (AttributeError, OSError):
    pass
from damper.diagnosis import diagnose
from damper.lab.protocols import random_voltage_test
args = json.loads(sys.argv[1])
warm = random_voltage_test("virtual", duration=4.0, sample_rate=500.0, seed=99)
diagnose([warm], max_effects=1)
test = random_voltage_test("virtual", duration=args["duration"], sample_rate=args["rate"], seed=1)
t0 = time.perf_counter(); c0 = time.process_time()
d = diagnose([test])
wall, cpu = time.perf_counter() - t0, time.process_time() - c0
print("BENCH-JSON " + json.dumps({"wall": wall, "cpu": cpu, "samples": test.n_samples,
      "error_before": d.error_before, "error_after": d.error_after, "effects": d.effects}))
"""


def _run_one(duration: float, rate: float, timeout: float) -> dict:
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1",
               NUMBA_NUM_THREADS="1")
    proc = subprocess.run([sys.executable, "-c", _SCRIPT, json.dumps({"duration": duration, "rate": rate})],
                          capture_output=True, text=True, timeout=timeout, env=env)
    for line in proc.stdout.splitlines():
        if line.startswith("BENCH-JSON "):
            return json.loads(line[len("BENCH-JSON "):])
    raise RuntimeError(f"diagnose benchmark failed (exit {proc.returncode}): "
                       f"{(proc.stderr or proc.stdout)[-1500:]}")


def bench_diagnose(timeout: float = 900.0, cases: dict | None = None) -> list[BenchCase]:
    """Time one diagnosis of each case of :data:`DIAGNOSE_CASES` (see the module docstring).

    Parameters
    ----------
    timeout : float
        Wall-clock limit of each case's process [s].
    cases : dict, optional
        Other cases, ``name -> (duration, rate, target)``.

    Returns
    -------
    list of BenchCase
    """
    out = []
    for name, (duration, rate, target) in (cases or DIAGNOSE_CASES).items():
        try:
            r = _run_one(duration, rate, timeout)
        except (RuntimeError, subprocess.TimeoutExpired) as exc:
            out.append(BenchCase(name, target=f"<= {target:g} s (warm, one core)",
                                 note=f"not measured: {str(exc)[:300]}"))
            continue
        out.append(BenchCase(
            name, project_s=r["wall"], target=f"<= {target:g} s (warm, one core)",
            met=r["cpu"] <= target,
            note=(f"one core: CPU {r['cpu']:.1f} s (wall above; it includes waiting for the core on "
                  f"a shared machine); {r['samples']} samples, random voltage; held-out error "
                  f"{r['error_before']:.3f} -> {r['error_after']:.3f} "
                  f"({', '.join(r['effects']) or 'no effect'})"),
            details=r))
    return out
