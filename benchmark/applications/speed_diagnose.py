"""``sbib bench --only diagnose``: the residual loop's timing cases (issue 13, item 4; issue 24, item 6).

=====================  =====================================================  ============
case                   test                                                   target
=====================  =====================================================  ============
``diagnose-1khz``      40 s at 1 kHz, random motion, random voltage           <= 20 s
``diagnose-3khz``      25 s at 3 kHz (75 001 samples), the same protocol      <= 60 s
``diagnose-dyke``      the shared Dyke recording (60 096 samples at 3 kHz,    <= 60 s
                       random voltage), ``--model spencer``, 30 % held out
=====================  =====================================================  ============

The Dyke case is a real damper's measurement (``shared/hysteresis_data/
dyke_mr_damper_random_voltage/ransim_u_converted.csv``, read by :mod:`damper.io.dyke`); it is
reported as not measured when the shared data are absent. Its error is the loop's held-out
error on the recording as read (the samples the reader's screening flags, if any, left out).

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
from benchmark.foundation.errors import DataNotFoundError
from benchmark.foundation.paths import shared_dir

__all__ = ["bench_diagnose", "DIAGNOSE_CASES", "DYKE_CASE"]

#: name -> (duration [s], sample rate [Hz], target [s])
DIAGNOSE_CASES = {"diagnose-1khz": (40.0, 1000.0, 20.0), "diagnose-3khz": (25.0, 3000.0, 60.0)}
#: The real recording's case: path under the shared directory, target [s].
DYKE_CASE = ("diagnose-dyke", "hysteresis_data/dyke_mr_damper_random_voltage/ransim_u_converted.csv",
             60.0)

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
diagnose([warm], max_effects=1, model=args.get("model", "normalized"))
if args.get("file"):
    from damper.io.dyke import read_dyke
    test = read_dyke(args["file"])
else:
    test = random_voltage_test("virtual", duration=args["duration"], sample_rate=args["rate"], seed=1)
t0 = time.perf_counter(); c0 = time.process_time()
d = diagnose([test], model=args.get("model", "normalized"), holdout=args.get("holdout", 0.25))
wall, cpu = time.perf_counter() - t0, time.process_time() - c0
print("BENCH-JSON " + json.dumps({"wall": wall, "cpu": cpu, "samples": test.n_samples,
      "error_before": d.error_before, "error_after": d.error_after, "effects": d.effects}))
"""


def _run_one(duration: float, rate: float, timeout: float, **extra) -> dict:
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1",
               NUMBA_NUM_THREADS="1")
    args = {"duration": duration, "rate": rate, **extra}
    proc = subprocess.run([sys.executable, "-c", _SCRIPT, json.dumps(args)],
                          capture_output=True, text=True, timeout=timeout, env=env)
    for line in proc.stdout.splitlines():
        if line.startswith("BENCH-JSON "):
            return json.loads(line[len("BENCH-JSON "):])
    raise RuntimeError(f"diagnose benchmark failed (exit {proc.returncode}): "
                       f"{(proc.stderr or proc.stdout)[-1500:]}")


def bench_diagnose(timeout: float = 900.0, cases: dict | None = None,
                   real: bool = True) -> list[BenchCase]:
    """Time one diagnosis of each case of :data:`DIAGNOSE_CASES` (see the module docstring).

    Parameters
    ----------
    timeout : float
        Wall-clock limit of each case's process [s].
    cases : dict, optional
        Other cases, ``name -> (duration, rate, target)``.
    real : bool
        Time the loop on the shared Dyke recording too (:data:`DYKE_CASE`).

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
    if real:
        out.append(_bench_dyke(timeout))
    return out


def _bench_dyke(timeout: float) -> BenchCase:
    name, relative, target = DYKE_CASE
    target_text = f"<= {target:g} s (warm, one core)"
    try:
        path = shared_dir() / relative
    except DataNotFoundError as exc:
        return BenchCase(name, target=target_text, note=f"not measured: {exc}")
    if not path.is_file():
        return BenchCase(name, target=target_text, note=f"not measured: {path} not found")
    try:
        r = _run_one(0.0, 0.0, timeout, file=str(path), model="spencer", holdout=0.3)
    except (RuntimeError, subprocess.TimeoutExpired) as exc:
        return BenchCase(name, target=target_text, note=f"not measured: {str(exc)[:300]}")
    return BenchCase(
        name, project_s=r["wall"], target=target_text, met=r["cpu"] <= target,
        note=(f"one core: CPU {r['cpu']:.1f} s; the shared Dyke recording, {r['samples']} samples, "
              f"spencer base, last 30 % held out: error {r['error_before']:.3f} -> "
              f"{r['error_after']:.3f} ({', '.join(r['effects']) or 'no effect'})"),
        details=r)
