"""Figures of the seed's claim: Fig. 11 as the seed drew it, and the closed loop's per-run ratios.

The seed paper's Fig. 11 shows, for the Kobe record (FP-y), the damper force error [kN] over
0-30 s of the "proposed" model (above) and of the "original method" (below), on axes of
±1000 kN. :func:`plot_seed_fig11` draws that pair on the same axes from a validated run;
:func:`plot_claim_ratios` draws the extended/normalized error ratio of each run for the seed's
pair and the closed loop's pair.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from benchmark.foundation.figures import save_figure  # noqa: E402

__all__ = ["SEED_NAMES", "seed_orientation_label", "plot_seed_fig11", "plot_claim_ratios"]

#: The seed's orientation names and the package's: FP-y is FN-x, FN-y is FP-x.
SEED_NAMES = {"FN-x": "FP-y", "FP-x": "FN-y"}


def seed_orientation_label(orientation: str) -> str:
    """``"FP-y (= FN-x)"`` for ``"FN-x"``: the seed's name with the package's in brackets.

    Parameters
    ----------
    orientation : str
        The package's orientation name (``FN-x`` or ``FP-x``).
    """
    seed = SEED_NAMES.get(orientation)
    return orientation if seed is None else f"{seed} (= {orientation})"


def plot_seed_fig11(run, path, proposed: str = "proposed", original: str = "original",
                    device: int | None = None, t_max: float = 30.0, limit_kN: float = 1000.0) -> Path:
    """Seed Fig. 11: damper force error [kN] against time [s], proposed (above), original (below).

    Parameters
    ----------
    run : RunValidation
        A validated run holding both models' replayed forces.
    path : path-like
        PNG file.
    proposed, original : str
        Model names in ``run.predicted``.
    device : int, optional
        Damper shown (default: the one with the largest peak force, as the seed shows one damper).
    t_max, limit_kN : float
        The seed's axes: 0 to ``t_max`` seconds, ±``limit_kN`` kN (widened if an error exceeds it).
    """
    if device is None:
        device = int(np.argmax(np.max(np.abs(run.force), axis=0)))
    keep = run.t <= t_max
    errs = {m: (run.force[keep, device] - run.predicted[m][keep, device]) * 1e-3 for m in (proposed, original)}
    top = max(limit_kN, 1.05 * max(float(np.max(np.abs(e))) for e in errs.values()))
    fig, axes = plt.subplots(2, 1, figsize=(7.5, 6.0), sharex=True)
    for ax, m, label in zip(axes, (proposed, original), ("proposed model", "original method [17]")):
        e = run.errors[m]
        ax.plot(run.t[keep], errs[m], "b-", lw=0.6)
        ax.set_xlim(0.0, t_max)
        ax.set_ylim(-top, top)
        ax.set_ylabel("Damper Force Error (kN)")
        ax.set_title(f"{label}: rel. RMS {100 * e['rel_rms_error']:.1f} %, peak {100 * e['peak_error']:.0f} %, "
                     f"energy {100 * e['energy_error']:.1f} % (all dampers, whole run)", fontsize=8.5)
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel("Time (s)")
    fig.suptitle(f"Damper force errors, {run.record} {seed_orientation_label(run.orientation)}, "
                 f"damper {device + 1} (seed Fig. 11: proposed above, original below)", fontsize=9.5)
    fig.tight_layout()
    return save_figure(fig, path, dpi=110)


def plot_claim_ratios(summary: dict, path) -> Path:
    """Extended/normalized relative RMS error ratio per run, for each pair of ``summary``
    (:func:`~benchmark.applications.identification_closed_loop.claim_summary`), with the targets 1 and 1/3.

    Parameters
    ----------
    summary : dict
        Result of :func:`benchmark.applications.identification_closed_loop.claim_summary`.
    path
        Image file to write (format from the suffix).
    """
    fig, ax = plt.subplots(figsize=(10, 4))
    colors = {"seed": "tab:gray", "closed_loop": "tab:red"}
    labels_done = None
    width = 0.38
    for k, (label, entry) in enumerate(summary.items()):
        runs = list(entry["ratio_by_run"])
        vals = [entry["ratio_by_run"][r] for r in runs]
        x = np.arange(len(runs)) + (k - 0.5) * width
        ax.bar(x, vals, width, color=colors.get(label, None),
               label=f"{entry['extended']} / {entry['normalized']} (mean {entry['ratio_mean']:.2f})")
        labels_done = runs
    if labels_done:
        ticks = [f"{r.split()[0]} {seed_orientation_label(r.split()[1])}" for r in labels_done]
        ax.set_xticks(np.arange(len(labels_done)))
        ax.set_xticklabels(ticks, rotation=45, ha="right", fontsize=7)
    ax.axhline(1.0, color="k", lw=0.8)
    ax.axhline(1.0 / 3.0, color="k", lw=0.8, ls="--", label="target mean 1/3")
    ax.set_ylabel("rel. RMS error ratio, extended / normalized")
    ax.set_title("The seed's claim per earthquake run (below 1: the extended form is better)")
    ax.legend(fontsize=8, loc="lower left", framealpha=0.95)
    ax.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    return save_figure(fig, path, dpi=110)
