"""Checks that report a record's flaws instead of hiding them.

* **identical components**: a span of samples where the two horizontal components are equal
  (not both zero). In the benchmark's ``erzikan.txt`` the last 105 samples of column 2 repeat
  column 1, a copying error.
* **baseline drift**: the velocity integrated from rest does not come back near zero at the
  end, so the displacement drifts (``jiji.txt``, column 2 of ``rinaldi.txt``: metres). The
  test is :math:`|v(T)| > r\\,\\mathrm{PGV}` and :math:`|v(T)| > v_{min}` (defaults r = 0.15,
  v_min = 0.02 m/s); on the seven benchmark files the flagged components have ratios 0.26–0.48
  and the others at most 0.09.
* **PGA far from the catalogue**: measured PGA differs from the expected one by more than a
  relative tolerance (default 5 %).
* **length far from the catalogue**: duration differs by more than one second.
* **physically implausible**: a PGA, PGV, displacement, time step or length that no recorded
  earthquake has had, the sign of wrong units or a wrong dt (:mod:`records.plausibility`).
* **clipped or stuck channel**: samples piled up at a component's extreme value (an
  accelerometer or digitiser at the end of its range) or a run of equal values longer than the
  component's own repeats explain (a frozen channel), by the rules of
  :func:`benchmark.foundation.channel_runs.stuck_spans`; runs of exact zeros (quiet padding
  before and after the motion) do not count.

Each check returns a list of :class:`Flaw` (empty when the record passes).
"""

from __future__ import annotations


from typing import Sequence

import numpy as np

from benchmark.foundation.channel_runs import spans_by_kind, stuck_spans
from benchmark.foundation.errors import InputError
from records.record import STANDARD_GRAVITY, Record
from records.flaws import Flaw
from records.plausibility import check_plausibility

__all__ = [
    "Flaw",
    "identical_spans",
    "check_identical_components",
    "check_baseline_drift",
    "check_stuck_channels",
    "check_pga",
    "check_duration",
    "check_record",
]


def identical_spans(acceleration: np.ndarray, min_length: int = 20) -> list[tuple[int, int]]:
    """Half-open sample ranges ``[start, stop)`` of at least ``min_length`` samples where all components are equal.

    Samples where every component is exactly zero (quiet padding) do not count as identical.

    Parameters
    ----------
    acceleration : ndarray, shape (n, m)
        The components (fewer than two: no spans).
    min_length : int
        Shortest span reported.
    """
    a = np.asarray(acceleration, dtype=float)
    if a.ndim != 2 or a.shape[1] < 2:
        return []
    equal = np.all(a == a[:, :1], axis=1) & np.any(a != 0.0, axis=1)
    padded = np.concatenate(([False], equal, [False])).astype(np.int8)
    edges = np.diff(padded)
    starts = np.flatnonzero(edges == 1)
    stops = np.flatnonzero(edges == -1)
    return [(int(s), int(e)) for s, e in zip(starts, stops) if e - s >= min_length]


def check_identical_components(record: Record, min_length: int = 20) -> list[Flaw]:
    """Flag spans where the components are identical (see :func:`identical_spans`).

    Parameters
    ----------
    record : Record
        The record.
    min_length : int
        Shortest span reported [samples].
    """
    flaws = []
    for start, stop in identical_spans(record.acceleration, min_length):
        n = stop - start
        where = "the last" if stop == record.n_samples else "a span of"
        flaws.append(Flaw(
            kind="identical_components",
            message=(f"{record.name}: {where} {n} samples ({start * record.dt:.3f}–{stop * record.dt:.3f} s, "
                     f"samples {start}–{stop - 1}) have {record.labels[1]} identical to {record.labels[0]}"),
            component=None,
            details={"start": start, "stop": stop, "n_samples": n},
        ))
    return flaws


def check_baseline_drift(record: Record, velocity_ratio: float = 0.15, min_velocity: float = 0.02) -> list[Flaw]:
    """Flag components whose final velocity is a large share of their PGV (see the module docstring).

    Parameters
    ----------
    record : Record
        The record.
    velocity_ratio : float
        Threshold on :math:`|v(T)|/\\mathrm{PGV}`.
    min_velocity : float
        Threshold on :math:`|v(T)|` [m/s].
    """
    if velocity_ratio <= 0 or min_velocity < 0:
        raise InputError(f"baseline drift thresholds velocity_ratio={velocity_ratio}, min_velocity={min_velocity}; "
                         "expected positive values")
    vel = record.velocity()
    disp = record.displacement()
    flaws = []
    for c in range(record.n_components):
        pgv = float(np.max(np.abs(vel[:, c])))
        v_end = float(vel[-1, c])
        if pgv > 0 and abs(v_end) > velocity_ratio * pgv and abs(v_end) > min_velocity:
            mean_acc = float(np.mean(record.acceleration[:, c]))
            flaws.append(Flaw(
                kind="baseline_drift",
                message=(f"{record.name} {record.labels[c]}: not baseline-corrected: velocity ends at "
                         f"{100 * v_end:.1f} cm/s ({abs(v_end) / pgv:.0%} of PGV), displacement drifts to "
                         f"{disp[-1, c]:.2f} m (mean acceleration {100 * mean_acc:.2f} cm/s²)"),
                component=c,
                details={"final_velocity_m_s": v_end, "final_displacement_m": float(disp[-1, c]),
                         "pgv_m_s": pgv, "mean_acceleration_m_s2": mean_acc},
            ))
    return flaws


def check_stuck_channels(record: Record) -> list[Flaw]:
    """Flag components clipped at their range or frozen at one value (module docstring).

    Parameters
    ----------
    record : Record
        The record.
    """
    flaws = []
    t = record.time
    for c in range(record.n_components):
        a = record.acceleration[:, c]
        spans = [(kind, i, j, level) for kind, i, j, level in stuck_spans(a) if level != 0.0]
        for kind, hits in spans_by_kind(spans).items():
            n = sum(j - i for i, j, _ in hits)
            levels = sorted({level for _, _, level in hits})
            values = " and ".join(f"{v:.4g}" for v in levels[:3]) + (" ..." if len(levels) > 3 else "")
            what = (f"clipped at its range ({values} m/s²)" if kind == "clipped"
                    else f"frozen at {values} m/s²")
            i, j, _ = hits[0]
            flaws.append(Flaw(
                kind=f"{kind}_channel",
                message=(f"{record.name} {record.labels[c]}: {what} in {len(hits)} span"
                         f"{'s' if len(hits) > 1 else ''} ({n} samples, the first at "
                         f"{t[i]:.4g}-{t[j - 1]:.4g} s): the ground motion there is not the recorded one"),
                component=c,
                details={"spans": [[int(i), int(j)] for i, j, _ in hits], "samples": int(n),
                         "levels_m_s2": [float(v) for v in levels]},
            ))
    return flaws


def check_pga(record: Record, expected_pga_g: Sequence[float], rtol: float = 0.05) -> list[Flaw]:
    """Flag components whose PGA differs from the expected one by more than a relative tolerance.

    Parameters
    ----------
    record : Record
        The record.
    expected_pga_g : sequence of float
        Expected PGA per component [g].
    rtol : float
        Relative tolerance.
    """
    expected = np.asarray(expected_pga_g, dtype=float)
    if expected.shape != (record.n_components,):
        raise InputError(f"{record.name}: {expected.size} expected PGAs for {record.n_components} components")
    flaws = []
    for c, (measured, target) in enumerate(zip(record.pga / STANDARD_GRAVITY, expected)):
        if abs(measured - target) > rtol * target:
            flaws.append(Flaw(
                kind="pga_mismatch",
                message=(f"{record.name} {record.labels[c]}: PGA {measured:.3f} g differs from the catalogue's "
                         f"{target:.3f} g by {abs(measured - target) / target:.0%}"),
                component=c,
                details={"pga_g": float(measured), "expected_pga_g": float(target)},
            ))
    return flaws


def check_duration(record: Record, expected_duration: float, atol: float = 1.0) -> list[Flaw]:
    """Flag a record whose duration differs from the expected one.

    Parameters
    ----------
    record : Record
        The record.
    expected_duration : float
        Expected length n·dt [s].
    atol : float
        Tolerance [s].
    """
    if abs(record.duration - expected_duration) > atol:
        return [Flaw(kind="duration_mismatch",
                     message=(f"{record.name}: duration {record.duration:.2f} s differs from the catalogue's "
                              f"{expected_duration:.2f} s"),
                     details={"duration_s": record.duration, "expected_duration_s": expected_duration})]
    return []


def check_record(record: Record, expected_pga_g: Sequence[float] | None = None,
                 expected_duration: float | None = None, pga_rtol: float = 0.05) -> list[Flaw]:
    """Run every check that applies and return all flaws found.

    Parameters
    ----------
    record : Record
        The record.
    expected_pga_g : sequence of float, optional
        Expected PGA per component [g] (no PGA check if None).
    expected_duration : float, optional
        Expected length [s] (no length check if None).
    pga_rtol : float
        Relative tolerance of the PGA check.
    """

    flaws = (check_identical_components(record) + check_stuck_channels(record) + check_baseline_drift(record)
             + check_plausibility(record))
    if expected_pga_g is not None:
        flaws += check_pga(record, expected_pga_g, pga_rtol)
    if expected_duration is not None:
        flaws += check_duration(record, expected_duration)
    return flaws
