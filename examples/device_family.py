"""The seed's claim across black boxes: the identification study on a family of virtual devices.

    python examples/device_family.py --out results/device-family [--variants default,no-roll-off,...]

For each variant of the virtual benchmark damper (``damper/models/virtual.py``; the default device is
not changed) it runs the identification study with its closed loop
(:func:`benchmark.applications.identification_study.run_identify_study`, no ceiling, no
free-κ_x variant, no figures) and collects the claim test: the extended form's relative RMS force
error over the normalized form's in the 14 earthquake runs, for the seed's pair (proposed /
original) and the closed loop's pair. Writes ``<out>/<variant>/`` (the study's files),
``<out>/family.json`` and prints the Markdown table of docs/identification.md. About two minutes
per variant on 2 cores.

Variants:

* ``default``: the device as calibrated;
* ``no-roll-off``: the series dashpot c1 ×100 (roll-off velocity F_w/c1 from 10–30 mm/s to
  0.1–0.3 mm/s);
* ``no-field-lag``: field rate η = 10⁴ 1/s (time constant 0.1 ms instead of 33 ms);
* ``no-roll-off-no-lag``: both;
* ``accumulator-0`` and ``accumulator-x2``: accumulator spring k1 = 0 and 340 kN/m (default 170).
"""

from __future__ import annotations

import argparse
import json
import time
from dataclasses import replace
from pathlib import Path

from benchmark.applications.identification_study import run_identify_study
from benchmark.foundation.atomic import atomic_write_text
from damper.models.virtual import VirtualBenchmarkDamper
from damper.models.voltage_laws import Saturating

NO_ROLL_OFF = {"c1": Saturating(5.0e8, 25.0e8, 0.5, 1.0)}
NO_LAG = {"eta": 1.0e4}
VARIANTS = {
    "default": {},
    "no-roll-off": NO_ROLL_OFF,
    "no-field-lag": NO_LAG,
    "no-roll-off-no-lag": {**NO_ROLL_OFF, **NO_LAG},
    "accumulator-0": {"k1": 0.0},
    "accumulator-x2": {"k1": 340.0e3},
}
DESCRIPTION = {
    "default": "as calibrated (roll-off 10–30 mm/s, field lag 33 ms, k1 = 170 kN/m)",
    "no-roll-off": "series dashpot c1 ×100 (roll-off 0.1–0.3 mm/s)",
    "no-field-lag": "field lag 0.1 ms",
    "no-roll-off-no-lag": "both",
    "accumulator-0": "k1 = 0",
    "accumulator-x2": "k1 = 340 kN/m",
}


def run_variant(name: str, out: Path) -> dict:
    """The study on one variant; returns its row (claim test, time)."""
    device = replace(VirtualBenchmarkDamper(), **VARIANTS[name])
    t0 = time.perf_counter()
    summary = run_identify_study(out / name, device=device, progress=False, plots=False,
                                 compare_free_kappa_x=False, ceiling=False, close_loop=True)
    return {"variant": name, "description": DESCRIPTION[name], "claim_test": summary.get("claim_test"),
            "elapsed_s": time.perf_counter() - t0}


def table(rows: list[dict]) -> str:
    """Markdown table: per variant and pair, mean and range of extended/normalized, runs below 1."""
    lines = ["| device | seed pair: proposed / original, mean (range) | below 1 | closed loop: extended / normalized, "
             "mean (range) | below 1 |", "|---|---|---|---|---|"]
    for row in rows:
        cells = [f"`{row['variant']}`: {row['description']}"]
        for pair in ("seed", "closed_loop"):
            c = (row.get("claim_test") or {}).get(pair)
            if not c:
                cells += ["—", "—"]
                continue
            ratios = list(c["ratio_by_run"].values())
            below = sum(r < 1.0 for r in ratios)
            cells += [f"{c['ratio_mean']:.2f} ({min(ratios):.2f}–{max(ratios):.2f})", f"{below}/{len(ratios)}"]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", default="results/device-family")
    parser.add_argument("--variants", default=",".join(VARIANTS), help="comma list of " + ", ".join(VARIANTS))
    parser.add_argument("--table-only", action="store_true", help="print the table of <out>/family.json")
    args = parser.parse_args()
    out = Path(args.out)
    if args.table_only:
        print(table(json.loads((out / "family.json").read_text())))
        return
    rows = [run_variant(v.strip(), out) for v in args.variants.split(",") if v.strip()]
    atomic_write_text(out / "family.json", json.dumps(rows, indent=2, default=float))
    print(table(rows))


if __name__ == "__main__":
    main()
