"""The controller protocol: what a controller is, what it is told, and how its outputs are checked.

A controller is a small object with a state:

* ``reset(context)`` — called once before a run with a :class:`ControlContext` (number of
  devices and measurements, control step, voltage limits and, for model-based designs, the
  :class:`DesignModel` the simulator hands over: the linearised plant and the devices); it
  (re)initialises the state;
* ``step(measurements) -> voltages`` — called at every control step with the measurement
  vector (noise added, layout of :mod:`controllers.measurements`: absolute accelerations of the
  base (3) and floors (24 on the benchmark's 8: ``context.slices`` gives the offsets of any
  height), base displacement (3), device displacements, device forces) and
  returning one coil voltage per device [V];
* ``compiled()`` — built-in controllers return their :class:`~controllers.compiled.CompiledController`
  so that the stepping kernel runs them inside numba; a user's controller returns ``None`` (the
  default) and is called from Python at every control step through :class:`ControllerSession`.

Both paths give the same voltages: a built-in's ``step`` calls the same kernel
(:func:`~controllers.compiled.controller_update`) the stepping loop calls.

Outputs are checked at every step (:func:`check_voltages`): a wrong number of voltages is an
:class:`~benchmark.foundation.errors.InputError`, a NaN or infinite voltage a
:class:`~benchmark.foundation.errors.NumericalError`; both name the controller and the time. The built-in
controllers' voltages are saturated to ``[0, v_max]`` and the slew limit applied, as the actuator
would; a user's controller (:mod:`controllers.user`) returning a command outside ``[0, v_max]``
is refused in one line naming the device and the time (a wrong scale is a bug to report, not to
hide by clipping).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Protocol, runtime_checkable

import numpy as np

from benchmark.foundation.registry import Registry
from benchmark.foundation.errors import InputError, NumericalError, ParameterError
from controllers.compiled import STATUS_OK, CompiledController, controller_update
from controllers.lqg import LinearPlant
from controllers.measurements import (N_ACCELERATIONS, N_FLOORS, MeasurementLayout, measurement_layout,
                                      measurement_slices, n_measurements)

__all__ = [
    "N_ACCELERATIONS",
    "MeasurementLayout",
    "measurement_layout",
    "measurement_slices",
    "n_measurements",
    "DesignModel",
    "ControlContext",
    "Controller",
    "CompiledBackedController",
    "FunctionController",
    "ControllerSession",
    "as_controller",
    "check_voltages",
    "CONTROLLERS",
    "register_controller",
]

@runtime_checkable
class DesignModel(Protocol):
    """What a model-based design may know of the building, handed over by the simulator.

    The simulator builds it (:func:`benchmark.simulator.control.design_model`) so that the
    controllers never import the simulator. One object per building: designs are cached on it.
    """

    #: Damper model of each device, in device order.
    device_models: tuple
    #: Plan position of each device relative to the base's centre of mass, (n_devices, 2) [m].
    device_positions: np.ndarray
    #: Direction of each device (0 = x, 1 = y), (n_devices,).
    device_directions: np.ndarray

    def linear_plant(self, isolation: str = "equivalent") -> LinearPlant:
        """The building's continuous linear plant with linearised isolation (``"equivalent"``:
        harmonic linearisation at 0.1 m and 3 s; ``"linear-part"``).

        Parameters
        ----------
        isolation : str, optional
            Linearisation of the bearings: ``"equivalent"`` (harmonic, at 0.1 m and 3 s) or ``"linear-part"``
            (the bearings' linear branch only).
        """
        ...


@dataclass(frozen=True)
class ControlContext:
    """What a controller is told before a run.

    Parameters
    ----------
    n_devices : int
        Number of MR dampers (one voltage each).
    control_step : float
        Control step [s]; ``step`` is called once per control step.
    voltage_max : ndarray, shape (n_devices,)
        Largest admissible coil voltage of each device [V] (the device's ``voltage_range[1]``).
    n_measurements : int, optional
        Length of the measurement vector (default ``6 + 3 n_floors + 2 n_devices``: ``30 + 2
        n_devices`` on the benchmark's 8 floors).
    design_model : DesignModel, optional
        The building as a model-based design sees it (clipped-optimal, Lyapunov, skyhook's
        device positions), supplied by the simulator. Pure measurement-driven controllers do not
        need it.
    slew_rate : float or ndarray
        Actuator slew limit [V/s] applied to every controller's output (``inf``: none).
    info : dict
        Free-form run information (record name, orientation, ...).
    n_floors : int
        Floors above the base (the benchmark's 8; a variant structure file may have others): the
        measurement vector has ``3 + 3 n_floors`` accelerations (:mod:`controllers.measurements`).
    """

    n_devices: int
    control_step: float
    voltage_max: np.ndarray
    n_measurements: int | None = None
    design_model: DesignModel | None = None
    slew_rate: float | np.ndarray = np.inf
    info: dict = field(default_factory=dict)
    n_floors: int = N_FLOORS

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        n_dev = int(self.n_devices)
        if n_dev < 1:
            raise ParameterError(f"ControlContext: n_devices must be >= 1, got {self.n_devices}")
        set_(self, "n_devices", n_dev)
        if not (np.isfinite(self.control_step) and self.control_step > 0):
            raise ParameterError(f"ControlContext: control_step must be > 0 s, got {self.control_step}")
        set_(self, "control_step", float(self.control_step))
        vmax = np.asarray(self.voltage_max, dtype=np.float64)
        vmax = np.full(n_dev, float(vmax)) if vmax.ndim == 0 else vmax.copy()
        if vmax.shape != (n_dev,) or np.any(~np.isfinite(vmax)) or np.any(vmax < 0):
            raise ParameterError(f"ControlContext: voltage_max must be {n_dev} finite values >= 0 V, "
                                 f"got {self.voltage_max!r}")
        set_(self, "voltage_max", vmax)
        floors = self.n_floors
        if isinstance(floors, bool) or not isinstance(floors, (int, np.integer)) or floors < 1:
            raise ParameterError(f"ControlContext: n_floors must be an integer >= 1, got {floors!r}")
        set_(self, "n_floors", int(floors))
        n_meas = n_measurements(n_dev, self.n_floors) if self.n_measurements is None else int(self.n_measurements)
        set_(self, "n_measurements", n_meas)
        slew = np.asarray(self.slew_rate, dtype=np.float64)
        slew = np.full(n_dev, float(slew)) if slew.ndim == 0 else slew.copy()
        if slew.shape != (n_dev,) or np.any(np.isnan(slew)) or np.any(slew <= 0):
            raise ParameterError(f"ControlContext: slew_rate must be > 0 V/s per device (inf for none), "
                                 f"got {self.slew_rate!r}")
        set_(self, "slew_rate", slew)

    @property
    def layout(self) -> MeasurementLayout:
        """The measurement vector's layout (:mod:`controllers.measurements`)."""
        return measurement_layout(self.n_devices, self.n_floors)

    @property
    def slices(self) -> dict[str, slice]:
        """Slices of the measurement vector (see :func:`measurement_slices`)."""
        return self.layout.slices()


@runtime_checkable
class ControllerProtocol(Protocol):
    """What the simulation calls on a controller: ``step``. ``reset(context)``, ``compiled()`` and
    ``name`` are optional (:class:`ControllerSession` uses them when present)."""

    def step(self, measurements: np.ndarray) -> np.ndarray:
        """Return the voltages [V] for the coming control step, one per device.

        Parameters
        ----------
        measurements : np.ndarray
            Measurement vector of this control step (:class:`controllers.measurements.MeasurementLayout`, SI).
        """


class Controller:
    """Base class of controllers: a name, a context after :meth:`reset`, and :meth:`step`.

    Subclass it (or write any object with ``step``) for a pure-Python controller::

        class MyController(Controller):
            name = "my-controller"
            def step(self, measurements):
                f = measurements[self.context.slices["device_force"]]
                return np.where(np.abs(f) < 1e5, self.context.voltage_max, 0.0)
    """

    name: str = "controller"

    def __init__(self) -> None:
        self.context: ControlContext | None = None

    def reset(self, context: ControlContext) -> None:
        """Store the context and reset the controller's state.

        Parameters
        ----------
        context : ControlContext
            The run's control context (:class:`controllers.base.ControlContext`: design model, device count,
            control step).
        """
        self.context = context

    def step(self, measurements: np.ndarray) -> np.ndarray:
        """Return the voltages [V] for the coming control step.

        Parameters
        ----------
        measurements : np.ndarray
            Measurement vector of this control step, laid out by
            :class:`controllers.measurements.MeasurementLayout` (SI: m/s², m, N).
        """
        raise NotImplementedError(f"controller {self.name!r} does not implement step(measurements)")

    def compiled(self) -> CompiledController | None:
        """The compiled representation (``None``: run from Python at every control step)."""
        return None

    def describe(self) -> dict:
        """Parameters worth recording with the results."""
        return {"name": self.name}


#: Registered controllers by name (filled by :func:`register_controller`; ``sbib --controller NAME``).
CONTROLLERS: Registry = Registry("controller", Controller)


def register_controller(cls):
    """Register a controller class under its ``name`` (a class decorator) and return it.

    A registered controller is built with no arguments (``cls()``) by
    :func:`controllers.registry.get_controller`, so its constructor's arguments need defaults.

    Parameters
    ----------
    cls : type
        A :class:`Controller` subclass with a class attribute ``name``.

    Returns
    -------
    type
        ``cls``.

    Raises
    ------
    InputError
        If ``cls`` is not a :class:`Controller` subclass, has no name, or its name is taken.
    """
    return CONTROLLERS.register(cls)


class CompiledBackedController(Controller):
    """A built-in controller: :meth:`reset` builds a :class:`CompiledController` (``build``), and
    :meth:`step` runs the same numba kernel the stepping loop runs, so both paths agree."""

    def build(self, context: ControlContext) -> CompiledController:
        """Return the compiled representation for ``context`` (subclasses implement it).

        Parameters
        ----------
        context : ControlContext
            The run's control context (:class:`controllers.base.ControlContext`: design model, device count,
            control step).
        """
        raise NotImplementedError

    def reset(self, context: ControlContext) -> None:
        super().reset(context)
        compiled = self.build(context)
        if compiled.n_devices != context.n_devices or compiled.n_meas != context.n_measurements:
            raise InputError(f"controller {self.name!r} was built for {compiled.n_devices} devices and "
                             f"{compiled.n_meas} measurements, the run has {context.n_devices} and "
                             f"{context.n_measurements}")
        self._compiled = compiled
        self._force_rows = context.slices["device_force"]
        self._xc, self._voltage = compiled.initial_state()
        self._desired = np.zeros(compiled.n_devices)
        self._steps = 0

    def compiled(self) -> CompiledController:
        if getattr(self, "_compiled", None) is None:
            raise InputError(f"controller {self.name!r}: call reset(context) before compiled()")
        return self._compiled

    def step(self, measurements: np.ndarray) -> np.ndarray:
        c = self.compiled()
        y = np.ascontiguousarray(measurements, dtype=np.float64)
        if y.shape != (c.n_meas,):
            raise InputError(f"controller {self.name!r}: measurement vector has shape {y.shape}, "
                             f"expected ({c.n_meas},)")
        f = np.ascontiguousarray(y[self._force_rows])
        status = controller_update(*c.kernel_arguments(), y, f, self._xc, self._voltage,  # type: ignore[call-arg]
                                   self._desired)
        if status != STATUS_OK:
            raise NumericalError(f"controller {self.name!r}: its state or desired force is not finite",
                                 time=self._steps * c.control_step,
                                 hint="check the measurements and the controller design")
        self._steps += 1
        return self._voltage.copy()

    @property
    def desired_force(self) -> np.ndarray:
        """Desired forces [N] (sign terms for Lyapunov) of the last :meth:`step`."""
        return self._desired.copy()


class FunctionController(Controller):
    """Wrap a plain function ``f(measurements) -> voltages`` (or ``f(t, measurements)``) as a controller.

    Parameters
    ----------
    function : Callable
        The control law, ``f(measurements) -> voltages`` [V], or ``f(t, measurements)`` with ``with_time``.
    name : str | None, optional
        Name shown in results and errors; default: the function's ``__name__``.
    with_time : bool, optional
        Pass the time [s] as first argument.
    """

    def __init__(self, function: Callable, name: str | None = None, with_time: bool = False) -> None:
        super().__init__()
        self.function = function
        self.with_time = with_time
        self.name = str(name or getattr(function, "__name__", "function"))
        self._steps = 0

    def reset(self, context: ControlContext) -> None:
        super().reset(context)
        self._steps = 0

    def step(self, measurements: np.ndarray) -> np.ndarray:
        if self.context is None:
            raise InputError(f"controller {self.name!r}: step() before reset(context)")
        t = self._steps * self.context.control_step
        self._steps += 1
        return self.function(t, measurements) if self.with_time else self.function(measurements)


def as_controller(obj: ControllerProtocol | Callable[..., Any]) -> ControllerProtocol:
    """Return ``obj`` as a controller: objects with ``step`` pass through, callables are wrapped.

    Parameters
    ----------
    obj : ControllerProtocol | Callable[..., Any]
        A controller (anything with ``step``) or a callable ``f(measurements) -> voltages``.

    Raises
    ------
    InputError
        If ``obj`` has no ``step`` method and is not callable.
    """
    if isinstance(obj, ControllerProtocol):
        return obj
    if callable(obj):
        return FunctionController(obj)
    raise InputError(f"controller {obj!r} has no step(measurements) method and is not callable; "
                     f"expected an object with step(measurements) -> voltages")


def _controller_name(controller: ControllerProtocol) -> str:
    return str(getattr(controller, "name", type(controller).__name__))


def check_voltages(voltages: Any, n_devices: int, name: str, time: float) -> np.ndarray:
    """Validate a controller's output and return it as a float array of shape ``(n_devices,)``.

    Parameters
    ----------
    voltages : Any
        The controller's output, one voltage [V] per device.
    n_devices : int
        Number of controlled devices (MR dampers) in the building.
    name : str
        Controller name, for the error message.
    time : float
        Time of the control step [s], for the error message.

    Raises
    ------
    InputError
        Wrong number of voltages (or not numeric); the message names the controller and time.
    NumericalError
        A NaN or infinite voltage (time and offending devices in the error).
    """
    try:
        v = np.asarray(voltages, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"controller {name!r} returned {type(voltages).__name__} at t = {time:.6g} s; "
                         f"expected {n_devices} voltages [V] ({exc})") from None
    if v.ndim == 0 or v.shape != (n_devices,):
        raise InputError(f"controller {name!r} returned voltages of shape {v.shape} at t = {time:.6g} s; "
                         f"expected ({n_devices},), one voltage per device")
    bad = np.flatnonzero(~np.isfinite(v))
    if bad.size:
        raise NumericalError(f"controller {name!r} returned non-finite voltage(s) for device(s) "
                             f"{bad.tolist()}", time=time,
                             state={f"v[{i}]": float(v[i]) for i in bad[:4]},
                             hint="fix the controller so that it returns finite voltages")
    return v


class ControllerSession:
    """Drive one controller through one run, from Python: reset, validated steps, actuator limits.

    The stepping loop uses it for controllers without a compiled form (``compiled`` is
    ``None``); for built-ins it exposes the compiled representation to run inside numba.

    Parameters
    ----------
    controller : object with ``step`` (or a callable)
    context : ControlContext
    """

    def __init__(self, controller: ControllerProtocol | Callable[..., Any], context: ControlContext) -> None:
        self.controller: ControllerProtocol = as_controller(controller)
        self.context = context
        self.name = _controller_name(self.controller)
        if hasattr(self.controller, "reset"):
            self.controller.reset(context)
        compiled_method = getattr(self.controller, "compiled", None)
        self.compiled: CompiledController | None = compiled_method() if callable(compiled_method) else None
        self._previous = np.zeros(context.n_devices)
        self._k = 0

    def step(self, measurements: np.ndarray, time: float | None = None) -> np.ndarray:
        """Call the controller, validate its voltages, saturate to ``[0, voltage_max]``, apply
        the slew limit, and return the voltages for the coming control step [V].

        Parameters
        ----------
        measurements : np.ndarray
            Measurement vector of this control step, laid out by
            :class:`controllers.measurements.MeasurementLayout` (SI: m/s², m, N).
        time : float | None, optional
            Time of the control step [s]; None: the session counts steps times the control step.
        """
        ctx = self.context
        t = self._k * ctx.control_step if time is None else float(time)
        raw = self.controller.step(np.array(measurements, dtype=np.float64))
        v = check_voltages(raw, ctx.n_devices, self.name, t)
        v = np.clip(v, 0.0, ctx.voltage_max)
        limit = ctx.slew_rate * ctx.control_step
        v = np.clip(v, self._previous - limit, self._previous + limit)
        self._previous = v
        self._k += 1
        return v.copy()
