"""The isolation layer: bearing types (one module each), their registry and dispatch kernel,
and isolation configurations (groups of bearings, named configurations).

>>> from benchmark.simulator.isolation import get_isolation
>>> layer = get_isolation("linear")
>>> layer.pack().params[:, 0].sum()  # total linear stiffness [N/m]  # doctest: +SKIP
"""


# The kernels here call kernels of other modules; numba's cache would not see edits there.

from benchmark.simulator.isolation.configurations import (DEFAULT_NONLINEAR, ISOLATION_NAMES, BearingGroup,
                                                IsolationLayer, PackedIsolation, get_isolation,
                                                isolation_from_dict, load_isolation)
from benchmark.simulator.isolation.friction_pendulum import FrictionPendulumBearing
from benchmark.simulator.isolation.lead_rubber import LeadRubberBearing
from benchmark.simulator.isolation.linear import LinearBearing
from benchmark.simulator.isolation.registry import (BEARING_NAMES, MAX_PARAMS, MAX_STATES, bearing_step,
                                          bearing_total_force, bearing_type, linear_part)

__all__ = [
    "BearingGroup", "IsolationLayer", "PackedIsolation", "get_isolation", "isolation_from_dict",
    "load_isolation", "ISOLATION_NAMES", "DEFAULT_NONLINEAR", "LinearBearing", "LeadRubberBearing",
    "FrictionPendulumBearing", "BEARING_NAMES", "MAX_PARAMS", "MAX_STATES", "bearing_step",
    "bearing_total_force", "bearing_type", "linear_part",
]
