"""A command a hair past the model's range (:func:`damper.models.response.prepare_motion`).

A probe (2026-11-28) replayed a run's stored commands through its model: the HDF5 keeps them in
single precision, the top command came back as 2.70560002 V against a range ending at 2.7056 V,
and the model refused it with "expected voltages in [-0.44144, 2.7056] V, got 2.7056 V". Within
a millionth of the range a command is the range's edge; beyond it, it is refused with the digits
that show by how much."""

from __future__ import annotations

import numpy as np
import pytest

from benchmark.foundation.errors import InputError
from damper.models.bouc_wen import NormalizedBoucWen
from damper.models.response import simulate
from damper.models.voltage_laws import Polynomial

MODEL = NormalizedBoucWen(Polynomial((1000.0, 300.0)), Polynomial((200.0, 150.0)), 400.0, 1.0, 1.5,
                          voltage_range=(-0.44144, 2.7056))
T = np.linspace(0.0, 1.0, 201)
X = 0.01 * np.sin(2 * np.pi * T)


def test_a_single_precision_edge_command_is_the_edge():
    stored = np.full(T.size, np.float32(2.7056), dtype=np.float32).astype(float)
    assert stored[0] > 2.7056  # 2.70560002: the float32 round trip
    f = simulate(MODEL, T, X, v=stored).force
    assert np.array_equal(f, simulate(MODEL, T, X, v=np.full(T.size, 2.7056)).force)


def test_a_command_past_the_tolerance_is_refused_with_its_digits():
    with pytest.raises(InputError, match=r"got 2\.7066 V at sample 0"):
        simulate(MODEL, T, X, v=np.full(T.size, 2.7066))
