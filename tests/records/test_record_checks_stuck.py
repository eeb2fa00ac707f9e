"""A record's component clipped at its range or frozen at one value is a flaw (found by probing
`sbib records show` with a clipped AT2 and a frozen CSV: only a baseline drift was reported,
and the frozen one was taken for a unit error)."""

from __future__ import annotations

import numpy as np

from records import Record, check_record, load_benchmark_record
from records.checks import check_stuck_channels


def _motion(n=6000, dt=0.005, seed=4):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    envelope = (t / 3.0) ** 2 * np.exp(-t / 3.0) * 4.0
    a = envelope * np.convolve(rng.standard_normal(n), np.hanning(15) / 7.5, mode="same")
    return np.round(a, 4)           # a file's four decimals: repeats of its own


def test_clipped_and_frozen_components_are_flagged():
    a = _motion()
    clipped = np.clip(a, -0.6 * np.abs(a).max(), 0.6 * np.abs(a).max())
    frozen = a.copy()
    frozen[3000:3400] = frozen[3000]
    padded = a.copy()
    padded[:800] = 0.0              # quiet padding: exact zeros are not a frozen channel
    rec = Record("r", 0.005, np.column_stack([a, clipped, frozen, padded]), labels=("ok", "clip", "frz", "pad"))
    flaws = check_stuck_channels(rec)
    assert sorted((f.kind, f.component) for f in flaws) == [("clipped_channel", 1), ("stuck_channel", 2)]
    clip = next(f for f in flaws if f.component == 1)
    assert clip.details["samples"] == int(np.sum(np.abs(clipped) == np.abs(clipped).max()))
    frz = next(f for f in flaws if f.component == 2)
    assert frz.details["spans"] == [[3000, 3400]] and "frozen at" in frz.message
    assert any(f.kind == "stuck_channel" for f in check_record(rec))


def test_benchmark_records_have_no_stuck_or_clipped_component(shared_dir):
    for name in ("newhall", "sylmar", "elcentro", "rinaldi", "kobe", "jiji", "erzikan"):
        rec = load_benchmark_record(name, records_dir=shared_dir / "records" / "raw" / "FDZ")
        assert check_stuck_channels(rec) == [], name
