"""Runs of equal samples in a sampled channel: a sensor stuck at one value or clipped at its range.

A measuring chain that freezes repeats its last value; one that saturates piles its samples up
at the end of its range. Both show as runs of exactly equal consecutive samples, which a healthy
quantised channel also has, only shorter: :func:`stuck_threshold` learns how long the channel's
own repeats get and :func:`stuck_spans` reports the runs beyond that and the piles at the
extremes. Used by the damper tests' screening (:mod:`damper.io.screening`), the hysteresis
data's (:func:`damper.hysteresis.files.data_flaws`) and the earthquake records' checks
(:func:`records.checks.check_stuck_channels`).
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["runs", "repeat_runs", "stuck_threshold", "stuck_spans", "spans_by_kind", "MIN_STUCK_RUN"]

#: A run of identical values shorter than this is never called stuck.
MIN_STUCK_RUN = 8


def runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """``[(start, end_exclusive)]`` of the runs of True in ``mask``.

    Parameters
    ----------
    mask : np.ndarray
        Booleans.
    """
    m = np.asarray(mask, dtype=bool)
    if not m.any():
        return []
    d = np.diff(np.r_[0, m.astype(np.int8), 0])
    return list(zip(np.flatnonzero(d == 1).tolist(), np.flatnonzero(d == -1).tolist()))


def repeat_runs(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Starts and lengths of the runs of exactly equal consecutive values.

    Parameters
    ----------
    values : np.ndarray
        The channel's samples.
    """
    change = np.flatnonzero(np.diff(values) != 0) + 1
    starts = np.r_[0, change]
    ends = np.r_[change, values.size]
    return starts, ends - starts


def stuck_threshold(lengths: np.ndarray) -> int:
    """Shortest run of equal values the channel's own repeats do not explain.

    Repeats of a sampled, quantised channel cluster (it stalls at its reversals and plateaus),
    so the runs of two or more are modelled as geometric: a run that has lasted ``k`` samples
    goes on with probability ``r`` (maximum-likelihood estimate from the channel's own runs).
    Of ``N_2`` such runs about ``N_2 r^(L-2)`` last ``L`` or more; a length expected less than
    once in a thousand recordings is not chance but a stuck or saturated sensor.

    Parameters
    ----------
    lengths : np.ndarray
        Lengths of the channel's runs of equal values (:func:`repeat_runs`).
    """
    long = lengths[lengths >= 2].astype(float)
    if long.size == 0:
        return MIN_STUCK_RUN

    def threshold_below(cap: float) -> int:
        # r from the runs shorter than ``cap``: the candidates themselves would inflate it
        trimmed = long[long < cap]
        if trimmed.size == 0:
            return MIN_STUCK_RUN
        r = float(np.sum(trimmed - 2) / max(np.sum(trimmed - 1), 1.0))
        if not r > 0:
            return MIN_STUCK_RUN
        r = min(r, 0.95)
        k = 2 + math.log(1e-3 / trimmed.size) / math.log(r)
        return max(MIN_STUCK_RUN, int(math.ceil(k)))

    # The threshold consistent with the runs below it, from above (the 99th percentile) and
    # from below (twice the shortest threshold): a channel pinned in more than 1 % of its runs
    # (a sensor stuck at every cycle) would otherwise set the percentile itself; a channel
    # whose own repeats are long raises the lower start until it holds them.
    best = None
    for cap in (max(MIN_STUCK_RUN, float(np.percentile(long, 99))), 2.0 * MIN_STUCK_RUN):
        for _ in range(20):
            k = threshold_below(cap)
            if k <= cap or k == best:
                break
            cap = float(k)
        best = k if best is None else min(best, k)
    return int(best)


def stuck_spans(values: np.ndarray) -> list[tuple[str, int, int, float]]:
    """``[(kind, start, end_exclusive, level)]`` of the stuck or clipped runs of one channel.

    Stuck: a run of equal values longer than :func:`stuck_threshold`. Clipped: the samples at
    an extreme value when the channel piles up there (visited in at least two separate runs,
    or in one stuck run, with ten times more samples than the mean of the five levels just
    inside it: a smooth quantised peak holds about three times more), and held there for two
    consecutive samples at least once (a sine sampled exactly at its amplitude only touches
    it). Fewer than 8 samples: none.

    Parameters
    ----------
    values : np.ndarray
        The channel's samples (finite).
    """
    values = np.asarray(values, dtype=float)
    if values.size < 8:
        return []
    out = []
    starts, lengths = repeat_runs(values)
    threshold = stuck_threshold(lengths)
    hi, lo = float(values.max()), float(values.min())
    levels, counts = np.unique(values, return_counts=True)
    clip_levels = set()
    for level in {hi, lo}:
        if hi == lo:
            break
        k = int(np.searchsorted(levels, level))
        count = int(counts[k])
        at_runs = lengths[values[starts] == level]
        near = counts[max(k - 5, 0):k] if level == hi else counts[k + 1:k + 6]
        pile = count > 10 * max(float(np.mean(near)) if near.size else 1.0, 1.0)
        # a clipped channel *stays* at its limit for consecutive samples somewhere; a smooth
        # signal sampled exactly at its peak value (a synthetic sine sweep) only touches it
        if count >= 3 and pile and at_runs.max() >= 2 and (at_runs.size >= 2 or at_runs.max() >= threshold):
            clip_levels.add(level)
    # only the runs that are findings reach Python (a continuous channel has a run per sample)
    clipped = np.isin(values[starts], np.array(sorted(clip_levels), dtype=float))
    hit = clipped | (lengths >= threshold)
    for s, n_run, is_clipped in zip(starts[hit], lengths[hit], clipped[hit]):
        out.append(("clipped" if is_clipped else "stuck", int(s), int(s + n_run), float(values[s])))
    return out


def spans_by_kind(spans) -> dict[str, list[tuple[int, int, float]]]:
    """:func:`stuck_spans`'s findings as ``{"clipped": [(start, end, level), ...], "stuck": [...]}``
    (only the kinds found, clipped first), for a report of one line per kind.

    Parameters
    ----------
    spans : iterable of (kind, start, end_exclusive, level)
        What :func:`stuck_spans` returns (filtered or not).
    """
    out: dict[str, list[tuple[int, int, float]]] = {}
    for kind in ("clipped", "stuck"):
        hits = [(a, b, level) for k, a, b, level in spans if k == kind]
        if hits:
            out[kind] = hits
    return out
