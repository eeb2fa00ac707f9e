"""MR damper models, their laboratory, identification and diagnosis.

The façade (names load on first use, :mod:`benchmark.foundation.facade`)::

    import numpy as np
    import damper
    model = damper.ExtendedBoucWen(kappa_x=207e3, kappa_xdot=100e3, kappa_w=50e3,
                                   rho=40.0, sigma=1.0, n=1.5)
    t = np.linspace(0.0, 5.0, 5001)
    response = damper.simulate(model, t, 0.1 * np.sin(2 * np.pi * t), v=0.0)
    response.force  # [N]
    test = damper.periodic_test("virtual", amplitude=0.1, frequency=1.0, voltage=0.5)
    fit = damper.identify(test, model="extended")

The package by concern:

- :mod:`damper.models`: the model contract and registry, the models, voltage laws, and
  :func:`damper.models.response.simulate` (a model driven by a displacement history);
- :mod:`damper.io`: measured test data (:class:`DamperTest`, CSV, UTFSM and Dyke files);
- :mod:`damper.lab`: the virtual laboratory, its protocols, loop measurements and figures;
- :mod:`damper.fitting`: the one least-squares engine;
- :mod:`damper.identification`: the seed paper's identification steps;
- :mod:`damper.diagnosis`: the residual loop, with its effects and augmented model;
- :mod:`damper.hysteresis`: the force-driven Bouc-Wen oscillator and its benchmark.
"""

from benchmark.foundation.facade import lazy_exports

#: Public name -> the module that defines it.
EXPORTS = {
    "register_model": "damper.models.base",
    "DamperModel": "damper.models.base",
    "NormalizedBoucWen": "damper.models.bouc_wen",
    "ExtendedBoucWen": "damper.models.bouc_wen",
    "StandardBoucWen": "damper.models.bouc_wen",
    "limit_cycle_peak": "damper.models.bouc_wen",
    "Spencer": "damper.models.spencer",
    "VirtualBenchmarkDamper": "damper.models.virtual",
    "MODELS": "damper.models.registry",
    "get_model_class": "damper.models.registry",
    "device_step": "damper.models.registry",
    "device_force": "damper.models.registry",
    "DamperResponse": "damper.models.response",
    "simulate": "damper.models.response",
    "Constant": "damper.models.voltage_laws",
    "Polynomial": "damper.models.voltage_laws",
    "Exponential": "damper.models.voltage_laws",
    "SeedKappaW": "damper.models.voltage_laws",
    "Tabulated": "damper.models.voltage_laws",
    "DamperTest": "damper.io.data",
    "read_csv": "damper.io.data",
    "write_csv": "damper.io.data",
    "read_utfsm": "damper.io.data",
    "read_test": "damper.io.reader",
    "read_model_file": "damper.io.model_file",
    "write_model_file": "damper.io.model_file",
    "ModelFile": "damper.io.model_file",
    "random_voltage_test": "damper.lab.protocols",
    "periodic_test": "damper.lab.laboratory",
    "general_test": "damper.lab.laboratory",
    "identify": "damper.identification.identify",
    "Identification": "damper.identification.identify",
    "diagnose": "damper.diagnosis.loop",
    "Diagnosis": "damper.diagnosis.loop",
    "AugmentedModel": "damper.diagnosis.augmented",
    "register_effect": "damper.diagnosis.effects",
}

__all__ = list(EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, EXPORTS, globals())
