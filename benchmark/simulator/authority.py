"""Can the controller act? Whether the devices' force depends on the commanded voltage.

A semi-active controller acts only through the command of the devices. A damper model whose
parameters do not depend on the voltage (constant numbers where voltage laws were meant, an
identification that found no voltage effect) gives the same response under every controller
as under ``passive-off``, and the evaluation criteria would say nothing about why.
:func:`controller_authority_warnings` finds such devices before a run by probing each distinct
device model with the building's own compiled kernels (:func:`damper.simulate`): the force
under a test motion at the lowest and at the highest admissible command. It needs no knowledge
of how a model packs its voltage laws, so it covers any registered model.

The test motion is a sine of :data:`PROBE_AMPLITUDE` at :data:`PROBE_FREQUENCY` (a stroke
and a frequency of the isolation level's motion) over :data:`PROBE_CYCLES` cycles, sampled
at :data:`PROBE_STEP`. A model is command-independent when the two forces differ by no more
than :data:`PROBE_RTOL` of the larger force (round-off of the same equations).
"""

from __future__ import annotations

import numpy as np

from benchmark.foundation.errors import NumericalError
from damper.models.response import simulate as simulate_damper

__all__ = ["command_changes_force", "controller_authority_warnings", "PROBE_AMPLITUDE", "PROBE_FREQUENCY",
           "PROBE_CYCLES", "PROBE_STEP", "PROBE_RTOL"]

#: Test motion: amplitude [m], frequency [Hz], cycles, sampling step [s].
PROBE_AMPLITUDE = 0.02
PROBE_FREQUENCY = 1.0
PROBE_CYCLES = 1.5
PROBE_STEP = 0.002
#: Forces closer than this (relative to the larger peak force) are the same force.
PROBE_RTOL = 1e-9

_PROBED: dict[tuple, bool] = {}


def _model_key(model) -> tuple:
    params = np.ascontiguousarray(model.to_array(), dtype=np.float64)
    return (type(model).__module__, type(model).__qualname__, params.tobytes(),
            tuple(float(v) for v in model.voltage_range))


def command_changes_force(model) -> bool:
    """True when the force of ``model`` under the test motion (module docstring) differs
    between its lowest and highest admissible voltage (memoised per model parameters).

    Parameters
    ----------
    model : damper.models.base.DamperModel
        A registered damper model.

    Returns
    -------
    bool
        Also True when the probe itself fails (a model too stiff for the test motion): the run
        then reports the failure with the building's state.
    """
    key = _model_key(model)
    hit = _PROBED.get(key)
    if hit is not None:
        return hit
    lo, hi = (float(v) for v in model.voltage_range)
    t = np.arange(int(round(PROBE_CYCLES / PROBE_FREQUENCY / PROBE_STEP)) + 1) * PROBE_STEP
    x = PROBE_AMPLITUDE * np.sin(2 * np.pi * PROBE_FREQUENCY * t)
    xdot = 2 * np.pi * PROBE_FREQUENCY * PROBE_AMPLITUDE * np.cos(2 * np.pi * PROBE_FREQUENCY * t)
    try:
        f_lo = simulate_damper(model, t, x, xdot, v=lo).force
        f_hi = simulate_damper(model, t, x, xdot, v=hi).force
    except NumericalError:  # cannot tell; the run itself reports the model's failure
        return True
    scale = max(float(np.max(np.abs(f_lo))), float(np.max(np.abs(f_hi))))
    changes = bool(hi > lo and float(np.max(np.abs(f_hi - f_lo))) > PROBE_RTOL * scale)
    if len(_PROBED) > 64:
        _PROBED.clear()
    _PROBED[key] = changes
    return changes


def controller_authority_warnings(devices, controller_name: str) -> list[str]:
    """Warning lines (``"warning: ..."``) when the command changes the force of none, or of only
    some, of the devices; an empty list when every device responds to it.

    Parameters
    ----------
    devices : benchmark.simulator.devices.DeviceLayout
        The building's devices.
    controller_name : str
        The controller's name, for the message.

    Returns
    -------
    list of str
        At most one line.
    """
    models = list(devices.models)
    if not models:
        return []
    deaf = [m for m in models if not command_changes_force(m)]
    if not deaf:
        return []
    names = sorted({getattr(m, "name", type(m).__name__) for m in deaf})
    lo_hi = sorted({tuple(float(v) for v in m.voltage_range) for m in deaf})
    # the models' input is a voltage or a coil current (a model file says which; the building
    # only sees the range), so the ends are named without a unit
    span = ", ".join(f"{lo:g} and {hi:g}" for lo, hi in lo_hi)
    why = (f"the force of damper model {', '.join(names)} does not depend on the command (the same force at "
           f"the ends of its input range, {span}, on a {100 * PROBE_AMPLITUDE:g}-cm, {PROBE_FREQUENCY:g}-Hz "
           "test motion)")
    if len(deaf) == len(models):
        return [f"warning: controller {controller_name!r} cannot act: {why}, so every controller gives the "
                "response of passive-off; give a damper model whose parameters depend on its input (voltage "
                "or current)"]
    return [f"warning: controller {controller_name!r} cannot act on {len(deaf)} of {len(models)} devices: {why}"]
