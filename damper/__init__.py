"""MR damper models, the virtual benchmark damper, its virtual laboratory and identification.

Quick start::

    import numpy as np
    import damper
    model = damper.ExtendedBoucWen(kappa_x=207e3, kappa_xdot=100e3, kappa_w=50e3,
                                   rho=40.0, sigma=1.0, n=1.5)
    t = np.linspace(0.0, 5.0, 5001)
    response = damper.simulate(model, t, 0.1 * np.sin(2 * np.pi * t), v=0.0)
    response.force  # [N]
"""


# The kernels here call kernels of other modules; numba's cache would not see edits there.

from damper.bouc_wen import ExtendedBoucWen, NormalizedBoucWen, StandardBoucWen, limit_cycle_peak
from damper.data import DamperTest, read_csv, read_utfsm, write_csv
from damper.laboratory import general_test, periodic_test
from damper.registry import MODELS, device_force, device_step, get_model_class
from damper.simulate import DamperResponse, simulate
from damper.voltage_laws import Constant, Exponential, Polynomial, SeedKappaW, Tabulated

__all__ = [
    "NormalizedBoucWen", "ExtendedBoucWen", "StandardBoucWen", "limit_cycle_peak",
    "DamperTest", "read_csv", "write_csv", "read_utfsm",
    "MODELS", "get_model_class", "device_step", "device_force",
    "DamperResponse", "simulate", "periodic_test", "general_test",
    "Constant", "Polynomial", "Exponential", "SeedKappaW", "Tabulated",
]
