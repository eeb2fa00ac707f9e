"""The display envelope keeps what a line plot of a long history shows: every column's extremes."""

from __future__ import annotations

import numpy as np

from benchmark.foundation.figures import display_envelope


def test_long_history_keeps_each_columns_extremes_in_time_order():
    rng = np.random.default_rng(3)
    t = np.arange(12_000) * 0.005
    y = np.cumsum(rng.normal(size=t.size)) + 50.0 * (rng.random(t.size) > 0.999)  # spikes
    te, ye = display_envelope(t, y, bins=1000)
    assert te.size <= 2 * 1000 + 12 + 2 and te.size < t.size / 5
    assert np.all(np.diff(te) > 0)  # a subset of the samples, in time order
    assert np.array_equal(ye, y[np.searchsorted(t, te)])
    assert te[0] == t[0] and te[-1] == t[-1]
    # every column of 12 samples keeps its lowest and highest sample (the peaks a plot shows)
    for c in range(0, 12_000, 12):
        col = slice(c, c + 12)
        kept = (te >= t[col][0]) & (te <= t[col][-1])
        assert ye[kept].max() == y[col].max() and ye[kept].min() == y[col].min()


def test_short_or_gapped_histories_are_left_alone():
    t = np.arange(3000.0)
    y = np.sin(t)
    assert display_envelope(t, y, bins=1500)[0].size == t.size
    # a 30-s benchmark record at 5 ms (6000 samples) is drawn through 2 samples per column
    t6 = np.arange(6000) * 0.005
    assert display_envelope(t6, np.sin(7 * t6), bins=1500)[0].size <= 3002
    y_gap = np.sin(np.arange(20_000.0))
    y_gap[100] = np.nan
    assert display_envelope(np.arange(20_000.0), y_gap)[1].size == 20_000
