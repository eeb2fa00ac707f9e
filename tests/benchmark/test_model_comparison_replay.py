"""``sbib compare --dampers``: each model replayed under the first model's motion and commands
(:func:`benchmark.applications.model_comparison.add_replays`).

A probe (2026-11-28) compared a model read in volts (0-2.7 V) with one read in amperes (0-1 A):
the replay fed the volts to the ampere model, clipped at 1 A, so a command of 2.7 V (full field)
and one of 1 V (a third) both became 1 A; the line it printed was 68 % RMS off the replay that
maps each command by its share of the model's top. The controllers command each device from 0
to the top of its own model's range, so that mapping is the replay of the same commands."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from benchmark.applications.model_comparison import add_replays
from damper.models.bouc_wen import NormalizedBoucWen
from damper.models.response import simulate
from damper.models.voltage_laws import Polynomial


def _model(top: float) -> NormalizedBoucWen:
    # the same device read on two inputs: its laws in the command's share of the top
    return NormalizedBoucWen(Polynomial((1000.0, 3000.0 / top)), Polynomial((200.0, 1500.0 / top)), 400.0, 1.0, 1.5,
                             voltage_range=(0.0, top))


def _runs(units):
    t = np.linspace(0.0, 2.0, 801)
    x = 0.01 * np.sin(2 * np.pi * t)
    xd = 0.01 * 2 * np.pi * np.cos(2 * np.pi * t)
    volts = np.where(np.sin(4 * np.pi * t) > 0, 2.7, 0.9)  # full and a third of a 0-2.7 V model's top
    first = SimpleNamespace(key=("kobe", "FN-x", "c"), damper="volts.json", histories={
        "device_displacement": x[:, None], "device_velocity": xd[:, None], "voltage_full": volts[:, None],
        "t_full": t, "device_force": np.ones((t.size, 1))})
    other = SimpleNamespace(key=("kobe", "FN-x", "c"), damper="amperes.json", histories={})
    buildings = {"volts.json": SimpleNamespace(devices=SimpleNamespace(models=[_model(2.7)])),
                 "amperes.json": SimpleNamespace(devices=SimpleNamespace(models=[_model(1.0)]))}
    add_replays([first, other], buildings, units)
    return t, x, xd, volts, other.histories["replay_force"]


def test_a_model_read_in_another_unit_is_replayed_with_the_commands_share_of_its_top():
    t, x, xd, volts, replay = _runs({"volts.json": "V", "amperes.json": "A"})
    mapped = simulate(_model(1.0), t, x, xd, volts / 2.7).force
    assert np.allclose(replay, mapped, rtol=1e-12, atol=1e-9)
    # the same device: the replay is the reference model's own force under its commands
    assert np.allclose(replay, simulate(_model(2.7), t, x, xd, volts).force, rtol=1e-9, atol=1e-6)


def test_models_in_one_unit_keep_the_commands_values():
    t, x, xd, volts, replay = _runs({"volts.json": "V", "amperes.json": "V"})
    assert np.allclose(replay, simulate(_model(1.0), t, x, xd, np.clip(volts, 0.0, 1.0)).force, rtol=1e-12)
    assert not np.allclose(replay, simulate(_model(1.0), t, x, xd, volts / 2.7).force, rtol=1e-3)
