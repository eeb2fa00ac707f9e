"""Figures of the identification study, regenerating the seed paper's for this project.

* :func:`plot_loops` — Fig. 1: force–displacement and force–velocity loops of the device under
  test (dashed) and of the identified models (solid).
* :func:`plot_inclination` — Fig. 2: the force–displacement loop and its average inclination
  :math:`\\kappa_x`.
* :func:`plot_elastic_removed` — Fig. 3: force–velocity loop of :math:`F` and of
  :math:`F - \\kappa_x x`.
* :func:`plot_test_signals` — Fig. 6: displacement and force of constant-voltage tests.
* :func:`plot_parameters_vs_voltage` — Fig. 8: identified parameters over the voltage grid with
  the fitted laws.
* :func:`plot_force_errors` — Fig. 11: force-error histories of one earthquake run, extended
  (above) versus normalized (below).
* :func:`plot_error_anatomy` — the validation error split by field regime, and the identified
  models against the best their form reaches on each run's motion (constant 0 V and 1 V).
* :func:`plot_fit` — a measured test, the fitted model and the force error (one per file).

All figures use the Agg backend and are written atomically as PNG.
"""

from __future__ import annotations

from pathlib import Path
from typing import Sequence

import matplotlib
from records.catalogue import SEED_ORIENTATION_NAMES

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from benchmark.foundation.figures import display_envelope, fixed_layout, save_figure  # noqa: E402
from benchmark.foundation.display_units import display_unit, parameter_kind, to_display  # noqa: E402
from damper.identification.closed_form import PARAMETER_NAMES  # noqa: E402
from damper.identification.metrics import relative_rms_error  # noqa: E402
from damper.lab.plots import draw_loops  # noqa: E402
from damper.identification.voltage_grid import inadmissible  # noqa: E402

#: The admissible class's lower bounds drawn where a seed law crosses them (sigma >= 1/2, n >= 1).
_ADMISSIBLE_LOWER = {"sigma": 0.5, "n": 1.0}

__all__ = ["plot_identified_loops", "plot_inclination", "plot_elastic_removed", "plot_test_signals",
           "plot_parameters_vs_voltage", "plot_force_errors", "plot_fit", "plot_parameters_vs_level",
           "plot_error_anatomy"]

_COLORS = {"normalized": "tab:blue", "extended": "tab:red"}
#: parameter -> (display unit, factor from SI), from benchmark.foundation.display_units
_UNITS = {name: (display_unit(parameter_kind(name)), float(to_display(1.0, parameter_kind(name))))
          for name in PARAMETER_NAMES}
_SYMBOLS = {"kappa_x": r"$\kappa_x$", "kappa_xdot": r"$\kappa_{\dot x}$", "kappa_w": r"$\kappa_w$",
            "rho": r"$\rho$", "sigma": r"$\sigma$", "n": r"$n$"}


def _save(fig, path) -> Path:
    return save_figure(fig, path, dpi=110)


def plot_identified_loops(identifications: dict, path, title: str = "") -> Path:
    """Fig. 1: loops of the test (dashed) and of each identified model (solid), kN vs m, m/s.

    ``identifications``: ``model name -> Identification`` of the same test.

    Parameters
    ----------
    identifications : dict
        Identifications by model key.
    path
        Image file to write (format from the suffix).
    title : str, optional
        Figure title.
    """
    first = next(iter(identifications.values()))
    w = first.window
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2))
    curves = [(first.force[w] * 1e-3, "device under test", {"color": "k", "ls": "--", "lw": 1.4})]
    curves += [(ident.fit.force[w] * 1e-3, f"{m} Bouc-Wen (err {100 * ident.errors['rel_rms_error']:.2f} %)",
                {"color": _COLORS.get(m), "lw": 1.0}) for m, ident in identifications.items()]
    draw_loops((a1, a2), first.x[w], first.xdot[w], curves)
    a1.legend(fontsize=8, loc="upper left")
    fig.suptitle(title or f"Loops at {first.level:g} {first.level_unit} (cf. seed Fig. 1)")
    fig.tight_layout()
    return _save(fig, path)


def plot_inclination(ident, path) -> Path:
    """Fig. 2: force–displacement loop and its average inclination (the closed-form :math:`\\kappa_x`).

    Parameters
    ----------
    ident
        One identification (:class:`damper.identification.identify.Identification`).
    path
        Image file to write (format from the suffix).
    """
    w = ident.window
    cf = ident.closed_form
    x = ident.x[w]
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    ax.plot(x, ident.force[w] * 1e-3, "k-", lw=1.0, label="device under test")
    xs = np.array([x.min(), x.max()])
    k = cf.kappa_x_inclination
    offset = cf.force_offset
    ax.plot(xs, (k * xs + offset) * 1e-3, "r-", lw=2,
            label=fr"average inclination $\kappa_x$ = {k * 1e-3:.1f} kN/m")
    rise = k * x.max()
    ax.annotate(f"{rise * 1e-3:.1f} kN over {x.max():.2g} m", (x.max() * 0.55, (k * x.max() * 0.55 + offset) * 1e-3),
                xytext=(x.max() * 0.05, (k * x.max() + 0.6 * cf.kappa_w_plastic) * 1e-3),
                arrowprops=dict(arrowstyle="->"), fontsize=9)
    ax.set_xlabel("Displacement (m)")
    ax.set_ylabel("Force (kN)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="lower right")
    ax.set_title(f"Average inclination at {ident.level:g} {ident.level_unit} (cf. seed Fig. 2)")
    fig.tight_layout()
    return _save(fig, path)


def plot_elastic_removed(ident, path) -> Path:
    """Fig. 3: force–velocity loop of :math:`F` (dashed) and :math:`F - \\kappa_x x` (solid).

    Parameters
    ----------
    ident
        One identification (:class:`damper.identification.identify.Identification`).
    path
        Image file to write (format from the suffix).
    """
    w = ident.window
    kx = ident.parameters["kappa_x"]
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    ax.plot(ident.xdot[w], ident.force[w] * 1e-3, "k--", lw=1.0, label=r"$F$")
    ax.plot(ident.xdot[w], (ident.force[w] - kx * ident.x[w]) * 1e-3, "b-", lw=1.2,
            label=fr"$F - \kappa_x x$ ($\kappa_x$ = {kx * 1e-3:.1f} kN/m)")
    ax.set_xlabel("Velocity (m/s)")
    ax.set_ylabel("Force (kN)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    ax.set_title(f"Elastic part removed at {ident.level:g} {ident.level_unit} (cf. seed Fig. 3)")
    fig.tight_layout()
    return _save(fig, path)


def plot_test_signals(tests: Sequence, path, title: str = "Test signals (cf. seed Fig. 6)") -> Path:
    """Fig. 6: force (left) and displacement (right) against time for each test.

    Parameters
    ----------
    tests : Sequence
        The tests (:class:`damper.io.data.DamperTest`).
    path
        Image file to write (format from the suffix).
    title : str, optional
        Figure title.
    """
    fig, axes = plt.subplots(len(tests), 2, figsize=(11, 3.0 * len(tests)), squeeze=False)
    for (a_f, a_x), test in zip(axes, tests):
        a_f.plot(test.time, test.force * 1e-3, "k-", lw=0.8)
        a_x.plot(test.time, test.displacement, "k-", lw=0.8)
        a_f.set_ylabel("Force (kN)")
        a_x.set_ylabel("Displacement (m)")
        for a in (a_f, a_x):
            a.set_xlabel("Time (s)")
            a.grid(alpha=0.3)
        a_f.set_title(test.name, fontsize=9)
    fig.suptitle(title)
    fig.tight_layout()
    return _save(fig, path)


def plot_parameters_vs_voltage(grid, path, comparison=None) -> Path:
    """Fig. 8: parameters against voltage (markers, with standard errors) and the fitted laws.

    ``comparison``: another grid (e.g. the extended model with :math:`\\kappa_x` free at each
    voltage), drawn as open grey markers.

    Parameters
    ----------
    grid
        The voltage-grid result (:class:`damper.identification.voltage_grid.VoltageGridResult`).
    path
        Image file to write (format from the suffix).
    comparison : dict, optional
        Reference parameters to draw beside; None: none.
    """
    v = grid.voltages
    vf = np.linspace(v.min(), v.max(), 301)
    fig, axes = plt.subplots(2, 3, figsize=(13, 7))
    for ax, name in zip(axes.ravel(), PARAMETER_NAMES):
        unit, scale = _UNITS[name]
        for m in grid.identifications:
            j = PARAMETER_NAMES.index(name)
            if name == "kappa_x" and m == "normalized":
                continue
            vals = grid.table(m)[:, j] * scale
            errs = grid.standard_errors(m)[:, j] * scale
            c = _COLORS.get(m)
            ax.errorbar(v, vals, yerr=errs, fmt="o", color=c, ms=4, capsize=2, label=f"{m}")
            laws = grid.laws[m]
            if name in laws["seed"]:
                # a seed law leaving the admissible class (n < 1 near 0 V) is not the one the
                # models use (voltage_model falls back to PCHIP): draw it so, and say which is used
                why = inadmissible(name, laws["seed"][name].law, (float(v.min()), float(v.max())))
                ax.plot(vf, laws["seed"][name].law(vf) * scale, "-" if why is None else "--",
                        color=c if why is None else "0.6", lw=1.2,
                        label=f"seed law (rms {100 * laws['seed'][name].rms_error:.1f} %)"
                              + ("" if why is None else "; leaves the admissible class, not used"))
                ax.plot(vf, laws["generic"][name].law(vf) * scale, ":" if why is None else "-", color=c, lw=1.2,
                        label=f"PCHIP (LOO {100 * laws['generic'][name].rms_error:.1f} %)"
                              + ("" if why is None else "; used"))
                if why is not None and name in _ADMISSIBLE_LOWER:
                    ax.axhline(_ADMISSIBLE_LOWER[name] * scale, color="0.6", lw=0.8, ls=":")
        if comparison is not None:
            for m in comparison.identifications:
                if name == "kappa_x" and m == "normalized":
                    continue
                mode = getattr(getattr(comparison, "kappa_x", None), "mode", "")
                ax.plot(comparison.voltages, comparison.table(m)[:, PARAMETER_NAMES.index(name)] * scale,
                        "s", mfc="none", color="0.4", ms=5,
                        label=f"{m}, kappa_x {mode}" if mode else m)
        ax.set_title(f"{_SYMBOLS[name]} [{unit}]")
        ax.set_xlabel("Voltage (V)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=6.5)
    fig.suptitle("Identified parameters versus voltage and fitted laws (cf. seed Fig. 8, eq. 5-10)")
    fig.tight_layout()
    return _save(fig, path)


def plot_force_errors(run, path, device: int | None = None) -> Path:
    """Fig. 11: force error of one damper, extended model (above) and normalized model (below).

    ``device`` defaults to the damper with the largest peak force in the run. The histories are
    drawn through their per-column envelope (:func:`benchmark.foundation.figures.display_envelope`).

    Parameters
    ----------
    run
        A closed-loop run with the forces of both models.
    path
        Image file to write (format from the suffix).
    device : int | None, optional
        Damper index; None: the one with the largest displacement.
    """
    if device is None:
        device = int(np.argmax(np.max(np.abs(run.force), axis=0)))
    models = [m for m in ("extended", "normalized") if m in run.predicted]
    lagged = {m: m + "+lag" for m in models if m + "+lag" in run.predicted}
    fig, axes = plt.subplots(len(models) + 1, 1, figsize=(10, 2.6 * (len(models) + 1)), sharex=True)
    limit = 0.0
    for ax, m in zip(axes, models):
        err = (run.force[:, device] - run.predicted[m][:, device]) * 1e-3
        limit = max(limit, float(np.max(np.abs(err))))
        e = run.errors[m]
        ax.plot(*display_envelope(run.t, err), color=_COLORS[m], lw=0.7, label="commanded voltage (as the seed)")
        title = (f"{m}: rel. RMS {100 * e['rel_rms_error']:.1f} %, peak {100 * e['peak_error']:.0f} %, "
                 f"energy {100 * e['energy_error']:.1f} %")
        if m in lagged:
            err_l = (run.force[:, device] - run.predicted[lagged[m]][:, device]) * 1e-3
            el = run.errors[lagged[m]]
            ax.plot(*display_envelope(run.t, err_l), color="k", lw=0.6, alpha=0.8, label="with identified field lag")
            title += (f"  |  +lag: {100 * el['rel_rms_error']:.1f} %, {100 * el['peak_error']:.0f} %, "
                      f"{100 * el['energy_error']:.1f} %")
            ax.legend(fontsize=7, loc="upper right")
        ax.set_ylabel("Force error (kN)")
        ax.set_title(title + " (all dampers)", fontsize=8.5)
        ax.grid(alpha=0.3)
    for ax in axes[:-1]:
        ax.set_ylim(-1.1 * limit, 1.1 * limit)
    ax = axes[-1]
    ax.plot(*display_envelope(run.t, run.force[:, device] * 1e-3), "k-", lw=0.7, label="force (kN)")
    ax2 = ax.twinx()
    ax2.plot(*display_envelope(run.t, run.voltage[:, device]), color="tab:green", lw=0.4, alpha=0.6)
    ax2.set_ylabel("Voltage (V)", color="tab:green")
    ax.set_ylabel("Device force (kN)")
    ax.set_xlabel("Time (s)")
    ax.grid(alpha=0.3)

    seed_name = SEED_ORIENTATION_NAMES.get(run.orientation)  # the seed's Fig. 11 is "Kobe (FP-y)"
    orientation = f"{run.orientation} (seed: {seed_name})" if seed_name else run.orientation
    fig.suptitle(f"Damper force errors, {run.record} {orientation}, damper {device + 1} "
                 "(cf. seed Fig. 11)")
    # one per run of the validation: fixed margins, not tight_layout (a third of the figure's cost)
    fixed_layout(fig, left=0.8, right=0.75, top=0.75, bottom=0.6, hgap=0.45)
    return _save(fig, path)


def plot_fit(ident, path, held_out: Sequence = ()) -> Path:
    """A test, the fitted model and the force error; ``held_out``: (name, t, force, predicted) tuples.

    Parameters
    ----------
    ident
        One identification (:class:`damper.identification.identify.Identification`).
    path
        Image file to write (format from the suffix).
    held_out : Sequence, optional
        ``(name, t, force, predicted)`` tuples of held-out tests.
    """
    w = ident.window
    rows = 2 if not held_out else 3
    fig = plt.figure(figsize=(12, 3.4 * rows))
    a1 = fig.add_subplot(rows, 2, 1)
    a2 = fig.add_subplot(rows, 2, 2)
    kN = _UNITS["kappa_w"][1]   # force display factor (kN)
    a1.plot(ident.x[w], ident.force[w] * kN, "k--", lw=1.0, label="measured")
    a1.plot(ident.x[w], ident.fit.force[w] * kN, color=_COLORS.get(ident.model_name), lw=1.0,
            label=f"{ident.model_name} Bouc-Wen")
    a2.plot(ident.xdot[w], ident.force[w] * kN, "k--", lw=1.0)
    a2.plot(ident.xdot[w], ident.fit.force[w] * kN, color=_COLORS.get(ident.model_name), lw=1.0)
    a1.set_xlabel(f"Displacement ({display_unit('displacement')})")
    a2.set_xlabel(f"Velocity ({display_unit('velocity')})")
    for a in (a1, a2):
        a.set_ylabel(f"Force ({display_unit('force')})")
        a.grid(alpha=0.3)
    a1.legend(fontsize=8)
    a3 = fig.add_subplot(rows, 1, 2)
    a3.plot(ident.t, (ident.force - ident.fit.force) * kN, "k-", lw=0.6)
    a3.axvspan(ident.t[w.start], ident.t[w.stop - 1], color="tab:orange", alpha=0.1, label="fit window")
    e = ident.errors
    a3.set_title(f"force error: rel. RMS {100 * e['rel_rms_error']:.2f} %, peak {100 * e['peak_error']:.1f} %",
                 fontsize=9)
    a3.set_xlabel("Time (s)")
    a3.set_ylabel(f"Error ({display_unit('force')})")
    a3.grid(alpha=0.3)
    a3.legend(fontsize=8)
    if held_out:
        a4 = fig.add_subplot(rows, 1, 3)
        for name, t, f, g in held_out:
            rel = relative_rms_error(f, g)
            a4.plot(t, (f - g) * kN, lw=0.6, label=f"{name} (held out, rel. RMS {100 * rel:.1f} %)")
        a4.set_xlabel("Time (s)")
        a4.set_ylabel(f"Error ({display_unit('force')})")
        a4.grid(alpha=0.3)
        a4.legend(fontsize=7)
    fig.suptitle(f"{ident.name}: {ident.model_name} model at {ident.level:g} {ident.level_unit}")
    fig.tight_layout()
    return _save(fig, path)


def plot_parameters_vs_level(summaries: Sequence[dict], path, unit: str = "A") -> Path:
    """Parameters of many tests against their current/voltage (``Identification.summary()`` dicts).

    Parameters
    ----------
    summaries : Sequence[dict]
        ``Identification.summary()`` dicts.
    path
        Image file to write (format from the suffix).
    unit : str, optional
        Unit of the level: ``"A"`` or ``"V"``.
    """
    level_unit = unit  # the loop below names each parameter's own unit
    fig, axes = plt.subplots(2, 3, figsize=(13, 7))
    for ax, name in zip(axes.ravel(), PARAMETER_NAMES):
        unit, scale = _UNITS[name]
        for m in ("normalized", "extended"):
            pts = [(s["level"], s["parameters"][name], s["standard_error"][name]) for s in summaries
                   if s["model"] == m and s["level"] is not None]
            if not pts or (name == "kappa_x" and m == "normalized"):
                continue
            lv, val, err = map(np.array, zip(*pts))
            ax.errorbar(lv, val * scale, yerr=err * scale, fmt="o", color=_COLORS[m], ms=4, alpha=0.7,
                        capsize=2, label=m)
        ax.set_title(f"{_SYMBOLS[name]} [{unit}]")
        ax.set_xlabel(f"Current ({level_unit})" if level_unit == "A" else f"Voltage ({level_unit})")
        ax.grid(alpha=0.3)
        if ax.get_legend_handles_labels()[0]:  # a panel with no fitted model (kappa_x, normalized only)
            ax.legend(fontsize=7)
    fig.suptitle("Identified parameters per test")
    fig.tight_layout()
    return _save(fig, path)


def plot_error_anatomy(validation_json: dict, ceiling_entries: Sequence, path,
                       pair: tuple[str, str] = ("normalized+lag", "extended+lag")) -> Path:
    """Where the force error of each model comes from, run by run (this project's addition to Fig. 11).

    Left: relative RMS force error of the two models (``pair``) over the low-field, high-field
    and transition samples of each earthquake run (from ``validation_json["regimes"]``). Right:
    at constant 0 V and 1 V on each run's most-moving damper, the identified models' error
    (filled) against the best the same model form reaches when fitted to that very motion
    (hollow; :mod:`~benchmark.applications.identification_ceiling`).

    Parameters
    ----------
    validation_json : dict
        A validation document as a dict.
    ceiling_entries : Sequence
        The ceiling entries of the runs.
    path
        Image file to write (format from the suffix).
    pair : tuple[str, str], optional
        The two model keys compared.
    """
    nor, ext = pair
    regimes = validation_json.get("regimes", {})
    runs = [(r, o) for r in regimes for o in regimes[r]]
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.2), gridspec_kw={"width_ratios": [3, 2]})
    ax = axes[0]
    labels = [f"{r} {o}" for r, o in runs]
    y = np.arange(len(runs))
    styles = {"low": ("tab:green", "low field"), "high": ("tab:purple", "high field"),
              "transition": ("tab:gray", "transition")}
    for k, (g, (color, name)) in enumerate(styles.items()):
        off = (k - 1) * 0.27
        en = [100 * regimes[r][o][nor][g]["rel_rms_error"] for r, o in runs]
        ee = [100 * regimes[r][o][ext][g]["rel_rms_error"] for r, o in runs]
        ax.scatter(en, y + off, marker="o", facecolors="none", edgecolors=color, s=30,
                   label=f"{name}: {nor}")
        ax.scatter(ee, y + off, marker="s", color=color, s=22, label=f"{name}: {ext}")
        for a, b, yy in zip(en, ee, y + off):
            ax.plot([a, b], [yy, yy], color=color, lw=0.8, alpha=0.6)
    ax.set_yticks(y)
    ax.set_yticklabels(labels, fontsize=8)
    ax.invert_yaxis()
    ax.set_xlabel("Relative RMS force error over the regime's samples (%)")
    ax.set_title("By estimated field (circle: normalized, square: extended)", fontsize=10)
    ax.grid(True, axis="x", alpha=0.3)
    ax.legend(fontsize=7, loc="lower right")

    ax = axes[1]
    entries = list(ceiling_entries)
    volts = sorted({e.voltage for e in entries})
    forms = ("normalized", "extended")
    xs = np.arange(len(volts))
    for j, m in enumerate(forms):
        for k, (kind, fill) in enumerate((("identified_error", True), ("best_error", False))):
            vals = [[100 * getattr(e, kind) for e in entries if e.voltage == v and e.model == m] for v in volts]
            pos = xs + (j - 0.5) * 0.4 + (k - 0.5) * 0.16
            for p, vv in zip(pos, vals):
                if not vv:
                    continue
                ax.scatter(np.full(len(vv), p), vv, s=14, color=_COLORS[m] if fill else "none",
                           edgecolors=_COLORS[m], alpha=0.8)
                ax.plot([p - 0.06, p + 0.06], [np.mean(vv)] * 2, color=_COLORS[m], lw=2)
            ax.scatter([], [], color=_COLORS[m] if fill else "none", edgecolors=_COLORS[m],
                       label=f"{m}: {'identified' if fill else 'best fit on the motion'}")
    ax.set_xticks(xs)
    ax.set_xticklabels([f"{v:g} V" for v in volts])
    ax.set_ylabel("Relative RMS force error (%)")
    ax.set_title("Constant voltage on each run's damper motion:\nidentified vs the form's ceiling",
                 fontsize=10)
    ax.set_ylim(bottom=0)
    ax.grid(True, axis="y", alpha=0.3)
    ax.legend(fontsize=7)
    fig.suptitle(f"Anatomy of the validation error ({validation_json.get('controller', '')})")
    fig.tight_layout()
    return _save(fig, path)
