"""Measurements on steady hysteresis loops from periodic tests (what one reads off a loop plot).

* :func:`last_cycles` -- the last whole periods of a periodic test (the limit cycle);
* :func:`midline_slope` -- the loop's average inclination: the slope of the mean of the loading
  and unloading branches at equal displacement (viscous and hysteretic parts cancel), over the
  central part of the stroke (the seed paper's step (a), Fig. 2: 82.8 kN over 0.4 m);
* :func:`plastic_branch_fit` -- least squares :math:`F - \\kappa_x x = c\\,\\dot x + f\\,\\mathrm{sgn}\\,\\dot x`
  on the plastic part of both branches (past the centre of the stroke in the direction of
  motion): the viscous coefficient ``c`` and the dry-friction force ``f`` (Rodríguez et al. 2009);
* :func:`dissipated_energy` -- loop area :math:`\\oint F\\,dx` per cycle [J].
"""

from __future__ import annotations

import numpy as np

from benchmark.foundation.errors import InputError
from damper.io.data import DamperTest

__all__ = ["last_cycles", "midline_slope", "plastic_branch_fit", "dissipated_energy"]


def last_cycles(test: DamperTest, cycles: float = 1.0, frequency: float | None = None) -> DamperTest:
    """The last ``cycles`` periods of ``test`` (frequency [Hz] from its metadata unless given).

    Parameters
    ----------
    test : DamperTest
        The test.
    cycles : float, optional
        Number of periods kept.
    frequency : float | None, optional
        Frequency [Hz]; None: from the test's metadata.
    """
    frequency = frequency if frequency is not None else test.metadata.get("frequency")
    if frequency is None:
        raise InputError(f"{test.name}: frequency unknown; pass frequency=<Hz>")
    end = test.time[-1]
    return test.select(end - cycles / float(frequency) - 1e-9 / float(frequency), end)


def _branch(x, f, mask):
    xs, fs = x[mask], f[mask]
    order = np.argsort(xs)
    return xs[order], fs[order]


def midline_slope(test: DamperTest, fraction: float = 0.8) -> float:
    """Average inclination [N/m] of a steady loop (use :func:`last_cycles` first).

    The loading (ẋ > 0) and unloading (ẋ < 0) branches are interpolated on a common
    displacement grid covering ``fraction`` of the stroke about its centre; their mean (the
    loop's mid-line, where the odd-in-velocity viscous and hysteretic forces cancel) is fitted
    with a straight line.

    Parameters
    ----------
    test : DamperTest
        A steady loop.
    fraction : float, optional
        Central fraction of the stroke used.
    """
    x, f, xd = test.displacement, test.force, test.velocity
    centre, half = 0.5 * (x.max() + x.min()), 0.5 * np.ptp(x)
    if half <= 0:
        raise InputError(f"{test.name}: midline_slope needs a moving displacement")
    xl, fl = _branch(x, f, xd > 0)
    xu, fu = _branch(x, f, xd < 0)
    if xl.size < 4 or xu.size < 4:
        raise InputError(f"{test.name}: midline_slope needs both loading and unloading branches")
    grid = np.linspace(centre - fraction * half, centre + fraction * half, 201)
    mid = 0.5 * (np.interp(grid, xl, fl) + np.interp(grid, xu, fu))
    return float(np.polyfit(grid, mid, 1)[0])


def plastic_branch_fit(test: DamperTest, kappa_x: float = 0.0) -> tuple[float, float]:
    """Viscous coefficient [N·s/m] and dry-friction force [N] from the plastic branches.

    Samples past the centre of the stroke in the direction of motion (where the hysteretic
    variable has saturated in a large-amplitude test) are fitted with
    :math:`F - \\kappa_x x = c\\,\\dot x + f\\,\\mathrm{sgn}(\\dot x)` by least squares.

    Parameters
    ----------
    test : DamperTest
        A steady loop.
    kappa_x : float, optional
        Elastic coefficient [N/m] removed first.
    """
    x, xd = test.displacement, test.velocity
    centre = 0.5 * (x.max() + x.min())
    sel = ((xd > 0) & (x >= centre)) | ((xd < 0) & (x <= centre))
    if sel.sum() < 4:
        raise InputError(f"{test.name}: plastic_branch_fit found too few plastic samples")
    design = np.column_stack([xd[sel], np.sign(xd[sel])])
    c, f = np.linalg.lstsq(design, test.force[sel] - kappa_x * x[sel], rcond=None)[0]
    return float(c), float(f)


def dissipated_energy(test: DamperTest) -> float:
    """Energy dissipated over the record, :math:`\\int F\\,\\dot x\\,dt` [J] (trapezoidal).

    Parameters
    ----------
    test : DamperTest
        The test.
    """
    power = test.force * test.velocity
    return float(np.sum(0.5 * (power[1:] + power[:-1]) * np.diff(test.time)))
