"""A velocity column that cannot drive the model is replaced by the displacement's central
difference, with a finding (:func:`damper.io.screening.velocity_scale`): a dead (mostly NaN) column,
one scaled by a unit or gain error, one of inverted sign. Before, the dead column refused the file
('expected a finite number, got nan'), a 1.2 gain drove the fit unnoticed (the shear-thinning
coefficient of a UTFSM test fell 9 %), and an inverted one refused the file as 'velocity: 27 spans'."""

from __future__ import annotations

import numpy as np
import pytest

from damper.io.data import read_csv
from damper.io.screening import VELOCITY_GAIN_TOLERANCE, screening_of


def _file(tmp_path, scale: float = 1.0, dead: bool = False, noise: float = 0.0):
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 3.0, 1e-3)
    x = 0.005 * np.sin(2 * np.pi * 2.0 * t) + noise * rng.standard_normal(t.size)
    v = scale * 0.005 * 2 * np.pi * 2.0 * np.cos(2 * np.pi * 2.0 * t)
    f = 500.0 * np.tanh(v / scale / 0.01) if scale else 0 * t
    rows = [f"{a:.4f},{b:.7g},{'nan' if dead else format(c, '.7g')},{d:.5g}\n" for a, b, c, d in zip(t, x, v, f)]
    path = tmp_path / "test.csv"
    path.write_text("time [s],displacement [m],velocity [m/s],force [N]\n" + "".join(rows))
    return path, np.gradient(x, t, edge_order=2)


def _velocity_findings(test):
    return [f.message for f in screening_of(test).findings if f.channel == "velocity"]


@pytest.mark.parametrize("scale, words", [(1.2, "a unit or gain error"), (-1.0, "its sign inverted"),
                                          (1e3, "a unit or gain error")])
def test_a_scaled_or_inverted_column_is_replaced(tmp_path, scale, words):
    path, deriv = _file(tmp_path, scale)
    test = read_csv(path)
    found = [m for m in _velocity_findings(test) if words in m and "replaced by the central difference" in m]
    assert len(found) == 1, _velocity_findings(test)
    # the scale named, within the smoothed derivative's 0.1 %
    assert float(found[0].split("column is ")[1].split(" times")[0]) == pytest.approx(scale, rel=2e-3)
    np.testing.assert_allclose(test.velocity, deriv, atol=1e-6)  # the file keeps 7 digits
    assert test.usable.all()


def test_a_dead_column_is_dropped(tmp_path):
    path, deriv = _file(tmp_path, dead=True)
    test = read_csv(path)
    assert any("missing in 3000 of 3000 samples" in m for m in _velocity_findings(test))
    np.testing.assert_allclose(test.velocity, deriv, rtol=1e-6, atol=1e-6)


@pytest.mark.parametrize("scale", [1.0, 1.0 + 0.5 * VELOCITY_GAIN_TOLERANCE])
def test_a_column_within_the_tolerance_is_kept(tmp_path, scale):
    # also with displacement noise (the derivative's, amplified by differentiation)
    path, _ = _file(tmp_path, scale, noise=2e-6)
    test = read_csv(path)
    assert not any("replaced" in m for m in _velocity_findings(test))
    assert np.ptp(test.velocity) == pytest.approx(scale * 2 * 0.005 * 2 * np.pi * 2.0, rel=1e-3)
