"""The virtual benchmark damper: the "black box" large-scale MR damper of the virtual laboratory.

The seed paper identifies the benchmark building's MR damper without knowing its model, using
the benchmark as a virtual laboratory. This module is that device: a ~1000 kN class MR damper
whose internal model is richer than the extended Bouc-Wen model the identification fits
(series stiffness and dashpot, an accumulator spring, a low-velocity roll-off, first-order field
dynamics under voltage changes, smoothly saturating voltage dependence). Identification code
must reach it only through :mod:`damper.lab.laboratory` (a test checks that it does not import this
module). The test bench (this module's tests, the plots) may know everything below.

Model (Spencer-type, Spencer et al. 1997, with a normalized hysteretic variable)
------------------------------------------------------------------------------------

.. math::

   F &= c_1(u)\\,\\dot y + k_1 (x - x_0) \\\\
   \\dot y &= \\frac{F_w(u)\\,w + c_0(u)\\,\\dot x + k_0 (x - y)}{c_0(u) + c_1(u)} \\\\
   \\dot w &= \\rho\\left(\\dot r - \\sigma|\\dot r||w|^{n-1}w + (\\sigma-1)\\dot r|w|^n\\right),
      \\quad \\dot r = \\dot x - \\dot y \\\\
   \\dot u &= -\\eta\\,(u - v)

A Bouc-Wen element (force :math:`F_w w`) in parallel with a dashpot :math:`c_0` and a spring
:math:`k_0`, in series with the dashpot :math:`c_1`, all in parallel with the accumulator
spring :math:`k_1`. ``v`` is the commanded voltage, ``u`` the field the fluid sees.

Voltage laws (all saturating smoothly, :class:`~damper.models.voltage_laws.Saturating`,
:math:`p(u) = a + b\\tanh((u/c)^e)`):

=============  =============================  ===========  ===========  ==========
parameter      meaning                        a            b            c, e
=============  =============================  ===========  ===========  ==========
``F_w``        yield ("dry friction") force   58 kN        (*)          0.55 V, 1.3
``c0``         viscous coefficient            100 kN·s/m   150 kN·s/m   0.5 V, 1.0
``c1``         low-velocity roll-off dashpot  5 MN·s/m     25 MN·s/m    0.5 V, 1.0
=============  =============================  ===========  ===========  ==========

(*) ``b`` chosen so that ``F_w(1 V) = 1010 kN``.

Constants: ``k0 = 40 kN/m``, ``k1 = 170 kN/m``, ``x0 = 0``, ``rho = 120 1/m``,
``sigma = 0.9``, ``n = 1.4``, ``eta = 30 1/s`` (field time constant 33 ms), voltage range
[0, 1] V.

Calibration targets (Bahar et al. 2009: the seed's Fig. 1-3 and 6), checked by the tests from loops
produced by :mod:`damper.lab.laboratory`:

* 0 V, ±0.4 m at 0.8 Hz (±2 m/s): inclined loop, average slope ≈ 207 kN/m (82.8 kN over 0.4 m);
* 0 V, ±0.03 m at 1 Hz (10 s test, Fig. 6): force about ±80 kN (the seed does not state the
  frequency; 1 Hz is chosen);
* 0 V, ±2 m/s: after removing the elastic part, force spans about ±250 kN;
* the force-velocity plastic branch is wider than a Bouc-Wen loop's;
* the dry-friction force grows from ≈50 kN (0 V) to ≈1000 kN (1 V).

References
----------
Bahar A., Pozo F., Acho L., Rodellar J., Barbat A. (2009), the seed paper, Fig. 1-3, 6.
Spencer B.F. Jr., Dyke S.J., Sain M.K., Carlson J.D. (1997), J. Eng. Mech. 123(3):230-238.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import ClassVar

import numpy as np

from damper.models.base import register_model
from benchmark.foundation.errors import ParameterError
from damper.models.bouc_wen import DEFAULT_SUBSTEP_TOLERANCE, _check_voltage_range
from damper.models.spencer import SpencerTypeModel
from damper.models.voltage_laws import ParameterLike, Saturating, VoltageLaw, as_law, check_law

__all__ = ["VirtualBenchmarkDamper"]


_FW_SHAPE = (0.55, 1.3)
_FW0 = 58.0e3
_FW1 = 1010.0e3


def _default_yield_force() -> Saturating:
    c, e = _FW_SHAPE
    return Saturating(_FW0, (_FW1 - _FW0) / math.tanh((1.0 / c) ** e), c, e)


@register_model
@dataclass(frozen=True)
class VirtualBenchmarkDamper(SpencerTypeModel):
    """The virtual benchmark MR damper (equations and values in the module docstring).

    Every field has the calibrated default; pass other values to build variants (e.g. a
    device without field lag, ``eta=1e4``).

    Parameters
    ----------
    yield_force : float or VoltageLaw
        Force scale ``F_w(u)`` of the normalized Bouc-Wen element [N].
    c0, c1 : float or VoltageLaw
        Dashpots [N·s/m].
    k0, k1 : float
        Series-branch and accumulator stiffness [N/m].
    x0 : float
        Accumulator spring offset [m].
    rho, sigma, n : float
        Normalized Bouc-Wen shape (ρ [1/m] > 0, σ >= 1/2, n >= 1).
    eta : float
        Field rate [1/s].
    voltage_range : tuple of float
        [0, 1] V.
    substep_tolerance : float
        RK4 sub-step size as ``lambda * h``.
    """

    yield_force: ParameterLike = None  # type: ignore[assignment]
    c0: ParameterLike = Saturating(100.0e3, 150.0e3, 0.5, 1.0)
    c1: ParameterLike = Saturating(5.0e6, 25.0e6, 0.5, 1.0)
    k0: float = 40.0e3
    k1: float = 170.0e3
    x0: float = 0.0
    rho: float = 120.0
    sigma: float = 0.9
    n: float = 1.4
    eta: float = 30.0
    voltage_range: tuple[float, float] = (0.0, 1.0)
    substep_tolerance: float = DEFAULT_SUBSTEP_TOLERANCE

    name: ClassVar[str] = "virtual"
    n_states: ClassVar[int] = 3
    state_names: ClassVar[tuple[str, ...]] = ("y", "w", "u")

    def __post_init__(self) -> None:
        if self.yield_force is None:
            object.__setattr__(self, "yield_force", _default_yield_force())
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name == "voltage_range":
                object.__setattr__(self, f.name, _check_voltage_range(value))
            elif f.name in ("yield_force", "c0", "c1"):
                if not isinstance(value, VoltageLaw):
                    object.__setattr__(self, f.name, float(as_law(value, f.name)(0.0)))
            else:
                try:
                    value = float(value)
                except (TypeError, ValueError):
                    raise ParameterError(f"VirtualBenchmarkDamper.{f.name}: expected a number, "
                                         f"got {value!r}") from None
                if not math.isfinite(value):
                    raise ParameterError(f"VirtualBenchmarkDamper.{f.name}: expected a finite "
                                         f"number, got {value}")
                object.__setattr__(self, f.name, value)
        rng = self.voltage_range
        for name in ("yield_force", "c0", "c1"):
            check_law(as_law(getattr(self, name), name), name, rng, lower=0.0)
        checks = [("k0", self.k0 >= 0, "k0 >= 0"), ("k1", self.k1 >= 0, "k1 >= 0"),
                  ("rho", self.rho > 0, "rho > 0"), ("sigma", self.sigma >= 0.5, "sigma >= 1/2"),
                  ("n", self.n >= 1, "n >= 1"), ("eta", self.eta > 0, "eta > 0"),
                  ("substep_tolerance", 0 < self.substep_tolerance <= 1, "0 < tol <= 1")]
        for name, ok, expected in checks:
            if not ok:
                raise ParameterError(f"VirtualBenchmarkDamper.{name}: expected {expected}, "
                                     f"got {getattr(self, name):g}")

    def _kernel_parameters(self) -> dict:
        return dict(k0=self.k0, k1=self.k1, x0=self.x0, eta=self.eta, rho=self.rho,
                    sigma=self.sigma, n=self.n, alpha_w=as_law(self.yield_force),
                    c0=as_law(self.c0), c1=as_law(self.c1))
