"""Semi-active controllers that turn the benchmark's measurements into coil voltages.

The façade (names load on first use, :mod:`benchmark.foundation.facade`)::

    import controllers
    controllers.controller_names()                 # ('passive-off', 'passive-on', 'clipped-optimal', ...)
    law = controllers.get_controller("skyhook")    # a registered controller
    class MyLaw(controllers.Controller): ...       # the interface a user's controller implements

The interface (measurements in, voltages out) is :class:`controllers.base.Controller`; the
measurement vector's layout is :class:`controllers.measurements.MeasurementLayout`.
"""

from benchmark.foundation.facade import lazy_exports

#: Public name -> the module that defines it.
EXPORTS = {
    "register_controller": "controllers.base",
    "Controller": "controllers.base",
    "CompiledBackedController": "controllers.base",
    "FunctionController": "controllers.base",
    "ControlContext": "controllers.base",
    "ControllerProtocol": "controllers.base",
    "DesignModel": "controllers.base",
    "as_controller": "controllers.base",
    "check_voltages": "controllers.base",
    "MeasurementLayout": "controllers.base",
    "measurement_layout": "controllers.base",
    "CONTROLLERS": "controllers.registry",
    "controller_names": "controllers.registry",
    "get_controller": "controllers.registry",
}

__all__ = list(EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, EXPORTS, globals())
