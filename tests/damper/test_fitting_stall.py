"""``least_squares_fit(stall=...)``: a fit crawling along an ill-conditioned valley stops once its
cost stops falling, and says so; without ``stall`` the same fit runs on to its tolerance."""

from __future__ import annotations

import numpy as np
import pytest

from damper.fitting import least_squares_fit


def _valley(q):
    # Rosenbrock's valley in least-squares form: trust-region steps crawl along the curved floor
    return np.array([10.0 * (q[1] - q[0] ** 2), 1.0 - q[0]])


LOWER, UPPER = np.array([-5.0, -5.0]), np.array([5.0, 5.0])
START = np.array([-1.9, 2.0])


def test_without_stall_the_fit_reaches_the_minimum():
    sol = least_squares_fit(_valley, START, LOWER, UPPER, tolerance=1e-12)
    assert sol.status > 0 and sol.success
    assert np.allclose(sol.x, [1.0, 1.0], atol=1e-6)


def test_a_stall_stops_the_crawl_and_says_so():
    full = least_squares_fit(_valley, START, LOWER, UPPER, tolerance=1e-12)
    # a generous rule (the cost must halve every 3 iterations) stops it on the valley's floor
    sol = least_squares_fit(_valley, START, LOWER, UPPER, tolerance=1e-12, stall=(3, 0.5))
    assert sol.status == -2 and not sol.success
    assert sol.message.startswith("stalled")
    assert sol.nfev < full.nfev
    # the last iterate, not the start: the cost has fallen
    assert 0.5 * np.sum(_valley(sol.x) ** 2) < 0.5 * np.sum(_valley(START) ** 2)


def test_a_converging_fit_is_not_stopped():
    # a linear problem converges in one or two iterations, before any window of 5 fills
    sol = least_squares_fit(lambda q: q - np.array([0.3, -0.2]), np.zeros(2), LOWER, UPPER,
                            tolerance=1e-12, stall=(5, 1e-3))
    assert sol.success and np.allclose(sol.x, [0.3, -0.2])


@pytest.mark.parametrize("stall", [(0, 1e-3), (5, 0.0), (5, -1.0)])
def test_bad_stall_is_refused(stall):
    with pytest.raises(ValueError, match="stall"):
        least_squares_fit(_valley, START, LOWER, UPPER, stall=stall)
