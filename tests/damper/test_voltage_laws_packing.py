"""Voltage laws: the numba evaluation of the packed array equals the numpy one; PCHIP law."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import PchipInterpolator

from benchmark.foundation.errors import ParameterError
from damper.models.voltage_laws import (Constant, Exponential, Polynomial, Saturating, SeedKappaW, Tabulated,
                                 as_law, law_length, law_value)

LAWS = [
    Constant(3.5),
    Polynomial((1e5, 5e4)),
    Polynomial((1.0, -2.0, 0.5, 3.0)),
    Exponential(1.2, 0.8, 13.0),
    SeedKappaW((5e4, 2e5, 1.6e5, 3e5, -2e4, 2e5, 5e5, 2e5, 1e5)),
    Tabulated((0.0, 0.1, 0.3, 0.6, 1.0), (5e4, 9e4, 3e5, 7e5, 1e6)),
    Saturating(5e4, 9.5e5, 0.55, 1.3),
]


@pytest.mark.parametrize("law", LAWS, ids=lambda law: type(law).__name__)
def test_packed_kernel_equals_numpy(law):
    packed = np.concatenate((np.array([7.0, 8.0]), law.to_array(), np.array([9.0])))
    assert law_length(packed, 2) == law.to_array().size
    v = np.linspace(-0.1, 1.2, 131)
    expected = law(v)
    got = np.array([law_value(packed, 2, vi) for vi in v])
    assert np.allclose(got, expected, rtol=1e-13, atol=1e-9)


def test_polynomial_and_exponential_values():
    assert Polynomial((1.0, 2.0, 3.0))(2.0) == pytest.approx(17.0)
    assert Exponential(1.0, 2.0, 14.0)(0.1) == pytest.approx(1.0 + 2.0 * np.exp(-1.4))


def test_seed_kappa_w_regions():
    k = (1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0)
    law = SeedKappaW(k)
    assert law(0.2) == pytest.approx(1.0 + 2.0 * 0.2 ** 1.15)
    s = np.pi * (0.5 - 0.3) / 0.8
    assert law(0.5) == pytest.approx(3.0 + 4.0 * np.sin(s) + 5.0 * np.sin(3 * s))
    assert law(0.9) == pytest.approx(6.0 + 7.0 * 0.9 + 8.0 * 0.9 ** 3 + 9.0 * 0.9 ** 5)


def test_tabulated_is_pchip_monotone_and_clamped():
    vg = np.array([0.0, 0.1, 0.2, 0.5, 1.0])
    vals = np.array([50.0, 60.0, 200.0, 210.0, 1000.0])
    law = Tabulated(vg, vals)
    v = np.linspace(0.0, 1.0, 1001)
    assert np.allclose(law(v), PchipInterpolator(vg, vals)(v), rtol=1e-12)
    assert np.all(np.diff(law(v)) >= -1e-9)  # monotone data -> monotone law
    assert law(-0.5) == 50.0 and law(2.0) == 1000.0
    assert np.allclose(law(vg), vals)


def test_bad_laws_raise():
    with pytest.raises(ParameterError, match="strictly increasing"):
        Tabulated((0.0, 0.5, 0.5), (1.0, 2.0, 3.0))
    with pytest.raises(ParameterError, match="equal length"):
        Tabulated((0.0, 0.5), (1.0, 2.0, 3.0))
    with pytest.raises(ParameterError, match="9 coefficients"):
        SeedKappaW((1.0, 2.0))
    with pytest.raises(ParameterError, match="finite"):
        Constant(float("inf"))
    with pytest.raises(ParameterError, match="number or a VoltageLaw"):
        as_law("3", "rho")
    with pytest.raises(ParameterError, match="c > 0"):
        Saturating(1.0, 1.0, 0.0)
