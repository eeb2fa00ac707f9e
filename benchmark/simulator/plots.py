"""Figures of a run: base displacement orbit, floor response envelopes, bearing and device loops.

Figures are drawn with matplotlib's object-oriented API on the Agg canvas (no pyplot, no
window, no global backend change) and saved atomically (:func:`benchmark.foundation.atomic.atomic_path`)
as PNG (or PDF/SVG from the file extension). Every function takes a
:class:`benchmark.simulator.simulation.SimulationResult` (or a :class:`benchmark.simulator.results.StoredResult`),
optionally the uncontrolled reference run drawn in grey for comparison, and returns the path
written. Axes are labelled in display units (cm, kN, MN, m/s², %) converted from SI here.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from benchmark.foundation.errors import InputError
from benchmark.foundation.figures import save_figure
from benchmark.simulator.structure import load_superstructure
from benchmark.foundation.display_units import axis_label, to_display


def _disp(a):
    """Displacement in its display unit (benchmark.foundation.display_units)."""
    return to_display(a, "displacement")


__all__ = ["plot_base_orbit", "plot_floor_envelopes", "plot_bearing_hysteresis",
           "plot_device_hysteresis", "plot_run"]

_REF_STYLE = dict(color="0.6", lw=0.8, label="uncontrolled")
_RUN_COLOR = "C0"


def _figure(width: float, height: float):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height), layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _save(fig, path: str | os.PathLike) -> Path:
    return save_figure(fig, path, dpi=120)


def _title(result: Any) -> str:
    info = getattr(result, "info", {}) or {}
    parts = [str(info[k]) for k in ("record", "orientation", "isolation", "controller") if k in info]
    return ", ".join(parts)


def _label(result: Any, default: str = "run") -> str:
    info = getattr(result, "info", {}) or {}
    return str(info.get("controller", default))


def _get(result: Any, name: str) -> np.ndarray:
    value = getattr(result, name, None)
    if value is None:
        raise InputError(f"result has no field {name!r}; expected a SimulationResult")
    return np.asarray(value, dtype=float)


def _bearing_xy(result: Any, bearing_xy: np.ndarray | None) -> np.ndarray:
    if bearing_xy is not None:
        return np.asarray(bearing_xy, dtype=float)

    return load_superstructure().bearing_xy


def plot_base_orbit(result: Any, path: str | os.PathLike, reference: Any = None,
                    corners: np.ndarray | None = None) -> Path:
    """Orbit of the base displacement in plan (x vs y, cm) at the centre of mass.

    Parameters
    ----------
    result : SimulationResult
    path : path-like
        Output file (``.png``).
    reference : SimulationResult, optional
        The uncontrolled run, drawn in grey.
    corners : (n_c, 2) array, optional
        Plan corners [m]; the orbit of the corner with the largest displacement is drawn dashed.
    """
    fig = _figure(5.5, 5.2)
    ax = fig.add_subplot()
    runs = ([(reference, _REF_STYLE)] if reference is not None else []) + \
        [(result, dict(color=_RUN_COLOR, lw=0.9, label=_label(result)))]
    for run, style in runs:
        ub = _get(run, "base_displacement")
        ax.plot(_disp(ub[:, 0]), _disp(ub[:, 1]), **style)
        if corners is not None:
            c = np.asarray(corners, dtype=float).reshape(-1, 2)
            cx = ub[:, 0:1] - ub[:, 2:3] * c[:, 1]
            cy = ub[:, 1:2] + ub[:, 2:3] * c[:, 0]
            j = int(np.argmax(np.max(np.hypot(cx, cy), axis=0)))
            ax.plot(_disp(cx[:, j]), _disp(cy[:, j]), ls="--", lw=0.6, color=style["color"],
                    label=f"{style['label']}, corner ({c[j, 0]:.1f}, {c[j, 1]:.1f}) m")
    ax.set_aspect("equal", adjustable="datalim")
    ax.axhline(0, color="k", lw=0.4)
    ax.axvline(0, color="k", lw=0.4)
    ax.set_xlabel(axis_label("base displacement x", "displacement"))
    ax.set_ylabel(axis_label("base displacement y", "displacement"))
    ax.set_title("Base orbit (centre of mass)\n" + _title(result), fontsize=9)
    ax.legend(fontsize=7, loc="best")
    ax.grid(alpha=0.3)
    return _save(fig, path)


def _envelopes(run: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    ub = _get(run, "base_displacement")
    us = _get(run, "floor_displacement")
    drift = _get(run, "drift_ratio")
    acc = _get(run, "floor_acceleration_absolute")
    # displacement relative to the ground: base + floor relative to base (centre of mass)
    total = us[:, :, :2] + ub[:, None, :2]
    disp = np.concatenate([[np.max(np.hypot(ub[:, 0], ub[:, 1]))],
                           np.max(np.hypot(total[..., 0], total[..., 1]), axis=0)])
    drift_peak = np.max(np.hypot(drift[..., 0], drift[..., 1]), axis=0)
    acc_floors = np.max(np.hypot(acc[..., 0], acc[..., 1]), axis=0)
    base_acc = getattr(run, "base_acceleration_absolute", None)
    if base_acc is not None:
        base_acc = np.asarray(base_acc, dtype=float)
        acc_env = np.concatenate([[np.max(np.hypot(base_acc[:, 0], base_acc[:, 1]))], acc_floors])
    else:
        acc_env = np.concatenate([[np.nan], acc_floors])
    return disp, drift_peak, acc_env


def plot_floor_envelopes(result: Any, path: str | os.PathLike, reference: Any = None) -> Path:
    """Peak responses over height: displacement (relative to the ground), drift ratio, absolute
    acceleration, each the x–y resultant at the centre of mass; level 0 is the base.

    Parameters
    ----------
    result : SimulationResult
    path : path-like
        Output file (``.png``, or ``.pdf``/``.svg``).
    reference : SimulationResult, optional
        The uncontrolled run, drawn in grey.
    """
    fig = _figure(9.0, 4.2)
    axes = fig.subplots(1, 3, sharey=True)
    runs = ([(reference, _REF_STYLE)] if reference is not None else []) + \
        [(result, dict(color=_RUN_COLOR, lw=1.2, label=_label(result)))]
    for run, style in runs:
        disp, drift, acc = _envelopes(run)
        levels = np.arange(disp.size)
        axes[0].plot(_disp(disp), levels, marker="o", ms=3, **style)
        # storey i spans levels i-1 .. i: draw each drift as a vertical segment over its storey
        axes[1].plot(np.repeat(100 * drift, 2), np.repeat(np.arange(drift.size + 1), 2)[1:-1], **style)
        axes[2].plot(acc, levels, marker="o", ms=3, **style)
    axes[0].set_xlabel(axis_label("peak displacement", "displacement"))
    axes[1].set_xlabel("peak inter-storey drift ratio [%]")
    axes[2].set_xlabel("peak absolute acceleration [m/s²]")
    axes[0].set_ylabel("level (0 = base)")
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.set_xlim(left=0)
    axes[0].legend(fontsize=7)
    fig.suptitle("Response envelopes — " + _title(result), fontsize=9)
    return _save(fig, path)


def plot_bearing_hysteresis(result: Any, path: str | os.PathLike, bearings: Sequence[int] | None = None,
                            bearing_xy: np.ndarray | None = None) -> Path:
    """Force–displacement loops of selected bearings (x and y), kN vs cm.

    Parameters
    ----------
    result : SimulationResult
        Needs ``bearing_force`` (n, n_bearings, 2) and ``base_displacement``.
    path : path-like
    bearings : sequence of int, optional
        0-based bearing indices (default the first and the last bearing of the plan: 0 and 91 on
        the benchmark's, one of each default group).
    bearing_xy : (n_bearings, 2) array, optional
        Plan positions [m]; default from the structure file. The bearing displacement is
        :math:`T_i u_b` unless the result carries ``bearing_displacement``.
    """
    force = _get(result, "bearing_force")
    ub = _get(result, "base_displacement")
    disp = getattr(result, "bearing_displacement", None)
    if disp is None:
        xy = _bearing_xy(result, bearing_xy)
        disp = np.stack([ub[:, 0:1] - ub[:, 2:3] * xy[:, 1], ub[:, 1:2] + ub[:, 2:3] * xy[:, 0]], axis=2)
    disp = np.asarray(disp, dtype=float)
    bearings = [0, force.shape[1] - 1] if bearings is None else [int(b) for b in bearings]
    for b in bearings:
        if not 0 <= b < force.shape[1]:
            raise InputError(f"plot_bearing_hysteresis: bearing index {b} outside 0..{force.shape[1] - 1}")
    fig = _figure(4.2 * len(bearings), 6.4)
    axes = np.atleast_2d(fig.subplots(2, len(bearings), squeeze=False))
    for j, b in enumerate(bearings):
        for d, name in enumerate("xy"):
            ax = axes[d, j]
            ax.plot(_disp(disp[:, b, d]), to_display(force[:, b, d], "force"), lw=0.7, color=_RUN_COLOR)
            ax.set_xlabel(axis_label(f"bearing {b + 1} displacement {name}", "displacement"))
            ax.set_ylabel(axis_label(f"force {name}", "force"))
            ax.grid(alpha=0.3)
    fig.suptitle("Bearing hysteresis — " + _title(result), fontsize=9)
    return _save(fig, path)


def plot_device_hysteresis(result: Any, path: str | os.PathLike,
                           devices: Sequence[int] | None = None, command_unit: str = "V") -> Path:
    """Force–displacement and force–velocity loops of selected devices (kN vs cm, m/s).

    Parameters
    ----------
    result : SimulationResult
        Needs ``device_force``, ``device_displacement``, ``device_velocity`` (n, n_devices).
    path : path-like
    devices : sequence of int, optional
        0-based device indices (default up to four spread over the layout).
    command_unit : str, optional
        Unit of the devices' commands in the titles: the damper models' input unit (``"V"``, or
        ``"A"`` for a model identified on the coil current).

    Raises
    ------
    InputError
        If the run has no devices.
    """
    force = _get(result, "device_force")
    if force.ndim != 2 or force.shape[1] == 0:
        raise InputError("plot_device_hysteresis: the run has no devices")
    x = _get(result, "device_displacement")
    v = _get(result, "device_velocity")
    n_dev = force.shape[1]
    if devices is None:
        devices = sorted(set(np.linspace(0, n_dev - 1, min(4, n_dev)).round().astype(int).tolist()))
    devices = [int(d) for d in devices]
    for d in devices:
        if not 0 <= d < n_dev:
            raise InputError(f"plot_device_hysteresis: device index {d} outside 0..{n_dev - 1}")
    fig = _figure(3.6 * len(devices), 6.4)
    axes = fig.subplots(2, len(devices), squeeze=False)
    volt = getattr(result, "voltage", None)
    for j, d in enumerate(devices):
        vmax = f", max {np.max(volt[:, d]):.2f} {command_unit}" if volt is not None and np.size(volt) else ""
        axes[0, j].plot(_disp(x[:, d]), to_display(force[:, d], "force"), lw=0.7, color="C3")
        axes[0, j].set_xlabel(axis_label(f"device {d + 1} displacement", "displacement"))
        axes[0, j].set_title(f"device {d + 1}{vmax}", fontsize=8)
        axes[1, j].plot(to_display(v[:, d], "velocity"), to_display(force[:, d], "force"), lw=0.7, color="C3")
        axes[1, j].set_xlabel(axis_label(f"device {d + 1} velocity", "velocity"))
        for ax in axes[:, j]:
            ax.set_ylabel(axis_label("force", "force"))
            ax.grid(alpha=0.3)
    fig.suptitle("Device hysteresis — " + _title(result), fontsize=9)
    return _save(fig, path)


def plot_run(result: Any, directory: str | os.PathLike, reference: Any = None,
             prefix: str | None = None, bearing_xy: np.ndarray | None = None,
             corners: np.ndarray | None = None, command_unit: str = "V") -> list[Path]:
    """Write every figure of a run into ``directory``; return the paths.

    Files: ``<prefix>_orbit.png``, ``<prefix>_envelopes.png``, ``<prefix>_bearings.png`` and,
    with devices, ``<prefix>_devices.png``. ``prefix`` defaults to
    ``record_orientation_isolation_controller`` from the run's ``info``.

    Parameters
    ----------
    result : SimulationResult
    directory : path-like
    reference : SimulationResult, optional
        The uncontrolled run (grey in the orbit and envelope figures).
    prefix : str, optional
    bearing_xy : (n_bearings, 2) array, optional
        Bearing plan positions [m] (default from the structure file).
    corners : (n_c, 2) array, optional
        Plan corners for the orbit figure.
    command_unit : str, optional
        Unit of the devices' commands (:func:`plot_device_hysteresis`).
    """
    directory = Path(directory)
    if prefix is None:
        info = getattr(result, "info", {}) or {}
        prefix = "_".join(str(info.get(k, "run")) for k in ("record", "orientation", "isolation", "controller"))
        prefix = "".join(ch if ch.isalnum() or ch in "-_." else "-" for ch in prefix)
    paths = [plot_base_orbit(result, directory / f"{prefix}_orbit.png", reference, corners),
             plot_floor_envelopes(result, directory / f"{prefix}_envelopes.png", reference),
             plot_bearing_hysteresis(result, directory / f"{prefix}_bearings.png", bearing_xy=bearing_xy)]
    force = getattr(result, "device_force", None)
    if force is not None and np.ndim(force) == 2 and np.shape(force)[1] > 0:
        paths.append(plot_device_hysteresis(result, directory / f"{prefix}_devices.png",
                                            command_unit=command_unit))
    return paths
