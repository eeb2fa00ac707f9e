"""Measure the dead band of the bang-bang laws (docs/switching.md): voltage and switching on a
record's quiet lead-in, and the J's, for several dead bands.

    python examples/dead_band.py --records kobe,jiji --bands 0,0.02 [--controller skyhook]

The quiet lead-in is the part before the ground acceleration first exceeds 1 % of its peak.
Prints one JSON line per record and dead band (SI units; J's from benchmark.simulator.evaluation).
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from benchmark.simulator.building import Building
from benchmark.simulator.evaluation import evaluate
from benchmark.simulator.simulation import simulate
from controllers.clipped_optimal import ClippedOptimal
from controllers.skyhook import Skyhook
from records.catalogue import load_benchmark_record

CONTROLLERS = {"clipped-optimal": ClippedOptimal, "skyhook": Skyhook}


def measure(building, record, controller, reference) -> dict:
    """Quiet-part voltage and switching rate, whole-record voltage and switching, J1–J9."""
    result = simulate(building, record, controller=controller, control_step=0.005)
    t, v = np.asarray(result.t), np.asarray(result.voltage)
    ag = np.abs(np.asarray(record.acceleration)).max(axis=1)
    t_quiet = float(np.argmax(ag > 0.01 * ag.max()) * record.dt)
    quiet = t < t_quiet
    switches = np.abs(np.diff(v, axis=0)) > 0
    row = {"quiet_s": t_quiet,
           "mean_voltage_quiet": float(v[quiet].mean()) if quiet.any() else None,
           "switches_per_s_quiet": float(switches[quiet[1:]].sum(axis=0).mean() / t_quiet) if t_quiet else None,
           "mean_voltage": float(v.mean()),
           "switches_per_s": float(switches.sum(axis=0).mean() / (t[-1] - t[0]))}
    row.update({k: None if x is None else round(x, 4) for k, x in evaluate(result, reference).items()})
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--records", default="kobe,jiji")
    parser.add_argument("--orientation", default="FN-x")
    parser.add_argument("--bands", default="0,0.02", help="dead bands, fractions of the device capacity")
    parser.add_argument("--controller", choices=sorted(CONTROLLERS), default="clipped-optimal")
    args = parser.parse_args()
    building = Building.default()
    for name in args.records.split(","):
        record = load_benchmark_record(name, args.orientation)
        reference = simulate(building, record, controller=None)
        for band in (float(b) for b in args.bands.split(",")):
            row = measure(building, record, CONTROLLERS[args.controller](dead_band=band), reference)
            print(json.dumps({"record": name, "controller": args.controller, "dead_band": band, **row}))


if __name__ == "__main__":
    main()
