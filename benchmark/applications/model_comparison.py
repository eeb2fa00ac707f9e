"""Several damper models in the same runs: J differences and force differences (the seed's Fig. 11).

``sbib compare --dampers A.json,B.json[,...]`` runs every model with the same records,
orientations and controllers (:func:`benchmark.applications.comparison.compare`). For each run
(record, orientation, controller) the first model is the reference: each other model's J's are
reported with their differences ``J[model] - J[first]``, and the device-force difference history
``F_model(t) - F_first(t)`` of the device with the largest peak force in the reference run
(both runs closed-loop: the difference includes the change of the motion and of the commands the
model causes, i.e. what the model difference does to the building). The figure
``force_difference_<record>_<orientation>_<controller>.png`` follows the seed's Fig. 11 layout:
one panel per compared model with the force difference [kN], and a bottom panel with the
device's force in every run and the reference run's command.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from benchmark.applications.damper_choice import command_unit
from benchmark.foundation.figures import save_figure
from benchmark.foundation.paths import file_label
from benchmark.simulator.criteria import J_NAMES
from damper.models.response import simulate

__all__ = ["differences", "force_difference", "table_lines", "plot_force_differences", "add_replays"]


def add_replays(runs: list, buildings: dict, units: dict | None = None) -> None:
    """For each run of a model other than the first: the force of its model, at the reference
    run's most loaded device, under that device's motion and commands in the first model's run
    (``histories["replay_force"]``; the seed's Fig. 11 compares models under the same motion).

    Parameters
    ----------
    runs : list of ComparisonRun
        The runs of every model; those of the first model need full device histories
        (``device_displacement`` [m], ``device_velocity`` [m/s], ``voltage_full``, ``t_full`` [s]).
        The others get ``histories["replay_force"]`` [N], in place.
    buildings : dict
        ``{damper label: Building}`` in the comparison's model order (first: the reference).
    units : dict, optional
        ``{damper label: input unit}`` (``"V"``, ``"A"``). Models in one unit get the same
        physical commands (clipped to each model's range: the same volts are the same coil
        input). A model read in another unit than the reference's, between which no physical
        conversion exists without the coil's resistance, gets the reference's commands mapped by
        their share of the top of each model's range, as the controllers command each device
        (from 0 to the top of its own model's range): 2.7 V of a model up to 2.7 V is 1 A of one
        up to 1 A, never 2.7 A clipped to 1 A.
    """
    order = list(buildings)
    groups: dict[tuple, list] = {}
    for r in runs:
        groups.setdefault(r.key, []).append(r)
    for members in groups.values():
        members = sorted(members, key=lambda r: order.index(r.damper))
        first = members[0]
        h = first.histories
        if "device_displacement" not in h:
            continue
        device = int(np.argmax(np.max(np.abs(np.asarray(h["device_force"])), axis=0)))
        t = np.asarray(h["t_full"])
        reference_model = buildings[first.damper].devices.models[device]
        for r in members[1:]:
            model = buildings[r.damper].devices.models[device]
            lo, hi = model.voltage_range
            v = np.asarray(h["voltage_full"])[:, device]
            if units and units.get(r.damper, "V") != units.get(first.damper, "V"):
                # the controllers command u in [0, top of the model's range] (damper_choice's input mapping)
                hi0 = reference_model.voltage_range[1]
                v = (np.clip(v / hi0, 0.0, 1.0) if hi0 > 0 else np.zeros_like(v)) * hi
            v = np.clip(v, lo, hi)
            r.histories["replay_force"] = simulate(model, t, np.asarray(h["device_displacement"])[:, device],
                                                   np.asarray(h["device_velocity"])[:, device], v).force


def _groups(result: Any) -> list[tuple[tuple, list]]:
    order = result.dampers
    groups: dict[tuple, list] = {}
    for r in result.runs:
        groups.setdefault(r.key, []).append(r)
    return [(k, sorted(v, key=lambda r: order.index(r.damper))) for k, v in groups.items()]


def force_difference(reference: Any, other: Any) -> dict:
    """Force-difference history of the reference run's most loaded device (SI).

    Parameters
    ----------
    reference : ComparisonRun
        The first model's run; its device with the largest peak force is compared.
    other : ComparisonRun
        Another model's run of the same record, orientation and controller.

    Returns
    -------
    dict
        ``{"device", "t", "reference", "other", "difference", "peak", "rms", "relative_rms"}``
        (time [s], forces [N]; ``relative_rms``: RMS of the difference over the RMS of the
        reference force), with ``replay_*`` entries when ``other`` has a replay force, or ``{}``
        when the runs kept no full device histories.
    """
    ha, hb = reference.histories, other.histories
    if "device_force" not in ha or "device_force" not in hb:
        return {}
    fa, fb = np.asarray(ha["device_force"]), np.asarray(hb["device_force"])
    n = min(fa.shape[0], fb.shape[0])
    device = int(np.argmax(np.max(np.abs(fa[:n]), axis=0)))
    diff = fb[:n, device] - fa[:n, device]
    rms_ref = float(np.sqrt(np.mean(fa[:n, device] ** 2)))
    rms = float(np.sqrt(np.mean(diff ** 2)))
    out = {"device": device, "t": np.asarray(ha["t_full"])[:n], "reference": fa[:n, device],
           "other": fb[:n, device], "difference": diff, "peak": float(np.max(np.abs(diff))), "rms": rms,
           "relative_rms": rms / rms_ref if rms_ref > 0 else float("nan")}
    if "replay_force" in hb:
        replay = np.asarray(hb["replay_force"])[:n] - fa[:n, device]
        rms_replay = float(np.sqrt(np.mean(replay ** 2)))
        out.update(replay_difference=replay, replay_peak=float(np.max(np.abs(replay))), replay_rms=rms_replay,
                   replay_relative_rms=rms_replay / rms_ref if rms_ref > 0 else float("nan"))
    return out


def differences(result: Any) -> list[dict]:
    """One entry per run: ``record, orientation, controller, reference`` (first model), ``models``
    (``{model: {"J": {...}, "dJ": {...}, "force_difference": {device, peak [N], rms [N], relative_rms}}}``).

    Parameters
    ----------
    result : ComparisonResult
        A comparison of several dampers (``result.dampers`` in order, the first the reference).
    """
    out = []
    for (record, orientation, controller), runs in _groups(result):
        first = runs[0]
        entry: dict = {"record": record, "orientation": orientation, "controller": controller,
                       "reference": first.damper, "models": {}}
        for r in runs:
            dJ = {j: (None if r.J.get(j) is None or first.J.get(j) is None else float(r.J[j] - first.J[j]))
                  for j in J_NAMES}
            fd = force_difference(first, r) if r is not first else {}
            entry["models"][r.damper] = {
                "J": {j: r.J.get(j) for j in J_NAMES}, "dJ": dJ,
                "force_difference": {k: fd[k] for k in ("device", "peak", "rms", "relative_rms", "replay_peak",
                                                        "replay_rms", "replay_relative_rms") if k in fd} if fd else None}
        out.append(entry)
    return out


def table_lines(result: Any) -> list[str]:
    """Text: per run, each model's J's and the differences from the first model, and the force difference.

    Parameters
    ----------
    result : ComparisonResult
        A comparison of several dampers (:func:`differences`); forces printed in kN.
    """
    lines = [f"model comparison (reference: the first model, {result.dampers[0]}); dJ = J[model] - J[reference]"]
    for entry in differences(result):
        lines.append(f"{entry['record']} {entry['orientation']} {entry['controller']}:")
        for name, m in entry["models"].items():
            js = " ".join(f"{j} {m['J'][j]:.3f}" for j in J_NAMES if m["J"].get(j) is not None)
            lines.append(f"  {name}: {js}")
            if name != entry["reference"]:
                ds = " ".join(f"{j} {m['dJ'][j]:+.3f}" for j in J_NAMES if m["dJ"].get(j) is not None)
                lines.append(f"    dJ: {ds}")
                fd = m["force_difference"]
                if fd:
                    lines.append(f"    force difference, device {fd['device'] + 1}, in its own run: peak "
                                 f"{fd['peak'] / 1e3:.4g} kN, RMS {fd['rms'] / 1e3:.4g} kN ({100 * fd['relative_rms']:.1f} % "
                                 "of the reference force RMS)")
                if fd and "replay_rms" in fd:
                    unit_ref, unit = (command_unit(_damper_summary(result), label)
                                      for label in (entry["reference"], name))
                    mapped = (f" (commands mapped by their share of each model's top, {unit_ref} to {unit})"
                              if unit != unit_ref else "")
                    lines.append(f"    under the reference run's motion and commands{mapped}: peak "
                                 f"{fd['replay_peak'] / 1e3:.4g} kN, "
                                 f"RMS {fd['replay_rms'] / 1e3:.4g} kN ({100 * fd['replay_relative_rms']:.1f} %)")
    return lines


def _damper_summary(result: Any) -> dict | None:
    summary = getattr(result, "settings", {}).get("damper")
    return summary if isinstance(summary, dict) else None


def _pyplot():
    import matplotlib  # heavy optional dependency: loaded only when drawing

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_force_differences(result: Any, directory: Path) -> list[Path]:
    """One figure per run (module docstring); returns the paths.

    Parameters
    ----------
    result : ComparisonResult
        A comparison of several dampers whose runs kept full device histories.
    directory : Path
        Folder the PNG figures are written into.
    """
    plt = _pyplot()
    directory = Path(directory)
    paths = []
    for (record, orientation, controller), runs in _groups(result):
        first, others = runs[0], runs[1:]
        diffs = [(r, force_difference(first, r)) for r in others]
        diffs = [(r, d) for r, d in diffs if d]
        if not diffs:
            continue
        device = diffs[0][1]["device"]
        fig, axes = plt.subplots(len(diffs) + 1, 1, figsize=(10, 2.6 * (len(diffs) + 1)), sharex=True)
        limit = max(max(d["peak"], d.get("replay_peak", 0.0)) for _, d in diffs) * 1e-3
        for ax, (r, d) in zip(axes, diffs):
            ax.plot(d["t"], d["difference"] * 1e-3, color="tab:red", lw=0.6, alpha=0.7,
                    label="in its own run (closed loop)")
            if "replay_difference" in d:
                ax.plot(d["t"], d["replay_difference"] * 1e-3, color="k", lw=0.7,
                        label=f"same motion and commands as {first.damper} (as the seed)")
            ax.legend(fontsize=7, loc="upper right")
            dj = " ".join(f"{j} {r.J[j] - first.J[j]:+.3f}" for j in ("J1", "J3", "J5")
                          if r.J.get(j) is not None and first.J.get(j) is not None)
            title = (f"{r.damper} − {first.damper}: closed loop RMS {d['rms'] / 1e3:.3g} kN "
                     f"({100 * d['relative_rms']:.0f} % of force RMS)")
            if "replay_rms" in d:
                title += f", same motion RMS {d['replay_rms'] / 1e3:.3g} kN ({100 * d['replay_relative_rms']:.0f} %)"
            ax.set_title(f"{title}; {dj}", fontsize=8.5)
            ax.set_ylabel("Force difference (kN)")
            ax.set_ylim(-1.1 * limit, 1.1 * limit)
            ax.grid(alpha=0.3)
        ax = axes[-1]
        t = diffs[0][1]["t"]
        for r in runs:
            f = np.asarray(r.histories["device_force"])[: t.size, device]
            ax.plot(t, f * 1e-3, lw=0.7, label=r.damper)
        ax.set_ylabel("Device force (kN)")
        ax.set_xlabel("Time (s)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper right")
        v = np.asarray(first.histories.get("voltage_full", np.zeros((t.size, device + 1))))[: t.size, device]
        ax2 = ax.twinx()
        ax2.plot(t, v, color="tab:green", lw=0.4, alpha=0.5)
        unit = _input_unit(result, first.damper)
        ax2.set_ylabel(f"Command ({unit}), {first.damper}", color="tab:green")
        fig.suptitle(f"Device force difference between damper models, {record} {orientation}, {controller}, "
                     f"damper {device + 1} (cf. seed Fig. 11)", fontsize=10)
        fig.tight_layout()
        name = f"force_difference_{file_label(record)}_{file_label(orientation)}_{file_label(controller)}.png"
        paths.append(save_figure(fig, directory / name, dpi=110))
    return paths


def _input_unit(result: Any, damper: str) -> str:
    for d in (result.settings.get("damper") or {}).get("dampers", []):
        if d.get("damper") == damper:
            return d.get("input", {}).get("unit", "V")
    return "V"
