"""Compiled controllers: the one representation every built-in controller compiles to.

The building's stepping kernel runs a controller without leaving numba. Every built-in
controller (passive, clipped-optimal, modulated, skyhook, Lyapunov) is reduced to

1. a discrete linear system from the measurement vector :math:`y` to desired device
   forces (or, for the Lyapunov law, to a sign term),

   .. math::

       x_c[k+1] = A_c x_c[k] + B_c y[k], \\qquad
       f_c[k] = C_c x_c[k] + D_c y[k],

   discretised at the control step (passive controllers have all four matrices empty);
2. a voltage law (``law_id``) with its parameters (``law_params``), applied per device
   with the measured device force :math:`f_i`:

   ======  ==========================  ================================================
   id      law                         voltage of device *i*
   ======  ==========================  ================================================
   0       constant                    :math:`v_i = p_i` (``law_params[i]``)
   1       clipped-optimal             :math:`v_i = V_{max,i} H((f_{c,i} - f_i) f_i)
           (Dyke et al. 1996)          H(|f_{c,i}| - p_i)`, :math:`p_i \\ge 0` a dead band on
                                       the desired force [N] (0: Dyke's law unchanged)
   2       modulated clipped-optimal   :math:`v_i = V_{max,i} \\min(1, |f_{c,i}| / p_i)
           (Yoshida & Dyke 2004)       H((f_{c,i} - f_i) f_i)`, :math:`p_i` the device's
                                       force capacity at :math:`V_{max,i}` [N]
   3       Lyapunov                    :math:`v_i = V_{max,i} H(-f_{c,i} f_i)`, where
           (Jansen & Dyke 2000)        :math:`f_{c,i}` carries the sign term
                                       :math:`x^T P B_i` (built by :mod:`controllers.lyapunov`)
   ======  ==========================  ================================================

   with :math:`H` the Heaviside step (:math:`H(0) = 0`). The dead band of law 1 exists because
   the bang-bang rule only looks at signs: it switches as often under a ground acceleration of
   1e-3 m/s² as under a strong motion (see :mod:`controllers.clipped_optimal`);
3. actuator limits: saturation to :math:`[0, V_{max,i}]` and a slew limit
   :math:`|v_i[k] - v_i[k-1]| \\le r_i \\Delta t` (``slew_rate`` [V/s], ``inf`` for none).

The kernel :func:`controller_update` is what the stepping loop calls once per control
step; :class:`CompiledController` holds the arrays and validates them on construction.

References
----------
Dyke, Spencer, Sain, Carlson (1996), Modeling and control of magnetorheological dampers
for seismic response reduction, Smart Mater. Struct. 5:565-575.
Yoshida, Dyke (2004), Seismic control of a nonlinear, asymmetric building with
magnetorheological dampers, J. Eng. Mech. 130(4) (modulated clipped-optimal).
Jansen, Dyke (2000), Semiactive control strategies for MR dampers: comparative study,
J. Eng. Mech. 126(8):795-803.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba
import numpy as np

from benchmark.foundation.errors import ParameterError
from benchmark.foundation.errors import NumericalError

__all__ = [
    "LAW_CONSTANT",
    "LAW_CLIPPED_OPTIMAL",
    "LAW_MODULATED",
    "LAW_LYAPUNOV",
    "LAW_NAMES",
    "DEFAULT_DEAD_BAND",
    "STATUS_OK",
    "STATUS_NONFINITE",
    "CompiledController",
    "constant_voltage",
    "controller_update",
    "run_compiled",
]

LAW_CONSTANT = 0
LAW_CLIPPED_OPTIMAL = 1
LAW_MODULATED = 2
LAW_LYAPUNOV = 3
#: Default dead band of law 1 on the desired force, as a fraction of a device's force capacity
#: (docs/switching.md: the project's choice, 2 %; controllers pass it in ``law_params`` [N]).
DEFAULT_DEAD_BAND = 0.02
LAW_NAMES = {LAW_CONSTANT: "constant", LAW_CLIPPED_OPTIMAL: "clipped-optimal",
             LAW_MODULATED: "modulated clipped-optimal", LAW_LYAPUNOV: "Lyapunov"}

#: :func:`controller_update` return codes.
STATUS_OK = 0
STATUS_NONFINITE = 1  # the controller state or a desired force became NaN/inf


@numba.njit(cache=True)
def controller_update(Ac, Bc, Cc, Dc, law_id, law_params, v_max, slew_rate, dt,
                      y, device_force, xc, voltage, desired_force):
    """Advance a compiled controller by one control step and write the new voltages.

    Signature (all arrays ``float64``, C-contiguous)::

        status = controller_update(Ac, Bc, Cc, Dc, law_id, law_params, v_max, slew_rate, dt,
                                   y, device_force, xc, voltage, desired_force)

    Parameters
    ----------
    Ac, Bc, Cc, Dc : ndarray
        Discrete controller system, shapes ``(n_c, n_c)``, ``(n_c, n_meas)``,
        ``(n_dev, n_c)``, ``(n_dev, n_meas)``. For passive controllers ``n_c = 0`` and
        ``Cc``, ``Dc`` have shapes ``(n_dev, 0)`` and ``(n_dev, n_meas)`` of zeros.
    law_id : int
        Voltage law: 0 constant, 1 clipped-optimal, 2 modulated clipped-optimal,
        3 Lyapunov (see the module docstring).
    law_params : ndarray, shape (n_dev,)
        Law 0: the constant voltages [V]; law 1: dead band on the desired force [N] (0 for
        none); law 2: force capacity at ``v_max`` [N]; law 3: unused (any values).
    v_max : ndarray, shape (n_dev,)
        Upper voltage limit of each device [V] (the lower limit is 0 V).
    slew_rate : ndarray, shape (n_dev,)
        Largest voltage change per second [V/s]; ``inf`` for none.
    dt : float
        Control step [s] (the step ``Ac``, ``Bc`` were discretised at).
    y : ndarray, shape (n_meas,)
        Measurement vector at this control step, noise already added, in the order of
        :mod:`benchmark.simulator.sensors` (absolute accelerations of the base and floors, base
        displacement, device displacements, device forces).
    device_force : ndarray, shape (n_dev,)
        Measured device forces [N] the voltage law compares with (normally the last
        ``n_dev`` entries of ``y``).
    xc : ndarray, shape (n_c,)
        Controller state; updated in place from :math:`x_c[k]` to :math:`x_c[k+1]`.
    voltage : ndarray, shape (n_dev,)
        On entry the voltages of the previous control step (for the slew limit); on exit
        the commanded voltages for the coming control step [V], held until the next call.
    desired_force : ndarray, shape (n_dev,)
        Output: :math:`f_c[k] = C_c x_c[k] + D_c y[k]` [N] (the sign term for law 3).

    Returns
    -------
    int
        0 (``STATUS_OK``); 1 (``STATUS_NONFINITE``) if the controller state or a desired
        force is NaN or infinite; the voltages are then left unchanged and the caller must
        stop the run with a :class:`benchmark.foundation.errors.NumericalError`.
    """
    n_c = xc.shape[0]
    n_dev = voltage.shape[0]
    n_meas = y.shape[0]
    # Output equation with the state *before* the update.
    for i in range(n_dev):
        s = 0.0
        for j in range(n_c):
            s += Cc[i, j] * xc[j]
        for j in range(n_meas):
            s += Dc[i, j] * y[j]
        desired_force[i] = s
    if n_c > 0:
        x_new = np.empty(n_c)
        for i in range(n_c):
            s = 0.0
            for j in range(n_c):
                s += Ac[i, j] * xc[j]
            for j in range(n_meas):
                s += Bc[i, j] * y[j]
            x_new[i] = s
        for i in range(n_c):
            if not math.isfinite(x_new[i]):
                return STATUS_NONFINITE
            xc[i] = x_new[i]
    for i in range(n_dev):
        if not math.isfinite(desired_force[i]):
            return STATUS_NONFINITE

    for i in range(n_dev):
        fc = desired_force[i]
        f = device_force[i]
        vm = v_max[i]
        if law_id == 0:
            v = law_params[i]
        elif law_id == 1:
            v = vm if (fc - f) * f > 0.0 and abs(fc) > law_params[i] else 0.0
        elif law_id == 2:
            if (fc - f) * f > 0.0:
                ratio = abs(fc) / law_params[i]
                v = vm * (ratio if ratio < 1.0 else 1.0)
            else:
                v = 0.0
        elif law_id == 3:
            v = vm if -fc * f > 0.0 else 0.0
        else:
            v = 0.0
        # Saturation, then slew limit relative to the previous command.
        if v > vm:
            v = vm
        if v < 0.0:
            v = 0.0
        rate = slew_rate[i]
        if math.isfinite(rate):
            step = rate * dt
            v_prev = voltage[i]
            if v > v_prev + step:
                v = v_prev + step
            elif v < v_prev - step:
                v = v_prev - step
        voltage[i] = v
    return STATUS_OK


def _as_matrix(value, shape: tuple[int, int], name: str, controller: str) -> np.ndarray:
    array = np.asarray(value, dtype=np.float64)
    if array.size == 0 and shape[0] * shape[1] == 0:
        array = array.reshape(shape)  # empty matrices of any listed shape are equivalent
    array = np.ascontiguousarray(array)
    if array.shape != shape:
        raise ParameterError(f"controller {controller!r}: {name} has shape {array.shape}, expected {shape}")
    if not np.all(np.isfinite(array)):
        raise ParameterError(f"controller {controller!r}: {name} contains NaN or inf")
    return array


@dataclass(frozen=True)
class CompiledController:
    """Arrays of a compiled controller, validated on construction (SI units).

    Parameters
    ----------
    name : str
        Controller name (used in error messages and results).
    n_meas : int
        Length of the measurement vector the controller was built for.
    n_devices : int
        Number of devices it commands.
    control_step : float
        Control step [s]; the discrete system was designed for it, so the simulation must
        call the kernel at exactly this step.
    Ac, Bc, Cc, Dc : ndarray
        Discrete system (see :func:`controller_update`); ``None`` means "no dynamics":
        ``n_c = 0`` and a zero ``Dc``.
    law_id : int
        Voltage law (0 constant, 1 clipped-optimal, 2 modulated, 3 Lyapunov).
    law_params : ndarray, shape (n_devices,)
        Law parameters (constant voltages [V] for law 0, the desired-force dead band [N] for
        law 1, force capacities [N] for law 2).
    v_max : ndarray or float
        Upper voltage limit per device [V].
    slew_rate : ndarray or float
        Voltage slew limit per device [V/s] (``inf`` for none).
    xc0 : ndarray, shape (n_c,), optional
        Initial controller state (zeros by default).
    v0 : ndarray or float, optional
        Voltage before the first control step [V] (0 V by default); matters only with a
        finite slew rate.
    """

    name: str
    n_meas: int
    n_devices: int
    control_step: float
    law_id: int
    law_params: np.ndarray
    v_max: np.ndarray
    slew_rate: np.ndarray
    Ac: np.ndarray = field(default=None)
    Bc: np.ndarray = field(default=None)
    Cc: np.ndarray = field(default=None)
    Dc: np.ndarray = field(default=None)
    xc0: np.ndarray = field(default=None)
    v0: np.ndarray = field(default=None)

    def __post_init__(self) -> None:
        name = self.name
        n_meas, n_dev = int(self.n_meas), int(self.n_devices)
        if n_meas < 0 or n_dev < 1:
            raise ParameterError(f"controller {name!r}: needs n_meas >= 0 and n_devices >= 1, "
                                 f"got n_meas={n_meas}, n_devices={n_dev}")
        if not (np.isfinite(self.control_step) and self.control_step > 0):
            raise ParameterError(f"controller {name!r}: control_step must be a positive number of "
                                 f"seconds, got {self.control_step!r}")
        if self.law_id not in LAW_NAMES:
            raise ParameterError(f"controller {name!r}: law_id {self.law_id!r} unknown; expected one "
                                 f"of {sorted(LAW_NAMES)} ({', '.join(LAW_NAMES.values())})")
        set_ = object.__setattr__
        set_(self, "n_meas", n_meas)
        set_(self, "n_devices", n_dev)
        set_(self, "control_step", float(self.control_step))
        set_(self, "law_id", int(self.law_id))
        if self.Ac is None:
            n_c = 0
        else:
            n_c = int(np.shape(self.Ac)[0]) if np.ndim(self.Ac) == 2 else -1
            if n_c < 0:
                raise ParameterError(f"controller {name!r}: Ac must be a square matrix, "
                                     f"got shape {np.shape(self.Ac)}")
        set_(self, "Ac", _as_matrix(np.zeros((0, 0)) if self.Ac is None else self.Ac, (n_c, n_c), "Ac", name))
        set_(self, "Bc", _as_matrix(np.zeros((0, n_meas)) if self.Bc is None else self.Bc, (n_c, n_meas), "Bc", name))
        set_(self, "Cc", _as_matrix(np.zeros((n_dev, 0)) if self.Cc is None else self.Cc, (n_dev, n_c), "Cc", name))
        set_(self, "Dc", _as_matrix(np.zeros((n_dev, n_meas)) if self.Dc is None else self.Dc,
                                    (n_dev, n_meas), "Dc", name))
        for attr, default in (("law_params", 0.0), ("v_max", None), ("slew_rate", np.inf), ("v0", 0.0)):
            value = getattr(self, attr)
            if value is None:
                value = default
            if value is None:
                raise ParameterError(f"controller {name!r}: {attr} is required")
            array = np.ascontiguousarray(np.broadcast_to(np.asarray(value, dtype=np.float64), (n_dev,))
                                         if np.ndim(value) == 0 else np.asarray(value, dtype=np.float64))
            if array.shape != (n_dev,):
                raise ParameterError(f"controller {name!r}: {attr} has shape {array.shape}, "
                                     f"expected ({n_dev},) (one value per device)")
            if np.any(np.isnan(array)):
                raise ParameterError(f"controller {name!r}: {attr} contains NaN")
            set_(self, attr, array.copy())
        if np.any(~np.isfinite(self.v_max)) or np.any(self.v_max < 0):
            raise ParameterError(f"controller {name!r}: v_max must be finite and >= 0 V, got {self.v_max}")
        if np.any(self.slew_rate <= 0):
            raise ParameterError(f"controller {name!r}: slew_rate must be > 0 V/s (inf for none), "
                                 f"got {self.slew_rate}")
        if np.any(self.v0 < 0) or np.any(self.v0 > self.v_max) or np.any(~np.isfinite(self.v0)):
            raise ParameterError(f"controller {name!r}: v0 must lie in [0, v_max], got {self.v0}")
        if self.law_id == LAW_CONSTANT:
            if np.any(~np.isfinite(self.law_params)) or np.any(self.law_params < 0) \
                    or np.any(self.law_params > self.v_max):
                raise ParameterError(f"controller {name!r}: constant voltages must lie in [0, v_max] = "
                                     f"[0, {self.v_max.max():g}] V, got {self.law_params}")
        if self.law_id == LAW_CLIPPED_OPTIMAL and (np.any(~np.isfinite(self.law_params))
                                                   or np.any(self.law_params < 0)):
            raise ParameterError(f"controller {name!r}: the clipped-optimal law's dead band (law_params) "
                                 f"must be finite and >= 0 N, got {self.law_params}")
        if self.law_id == LAW_MODULATED and (np.any(~np.isfinite(self.law_params))
                                             or np.any(self.law_params <= 0)):
            raise ParameterError(f"controller {name!r}: the modulated law needs a positive force capacity "
                                 f"per device in law_params [N], got {self.law_params}")
        xc0 = np.zeros(n_c) if self.xc0 is None else np.asarray(self.xc0, dtype=np.float64)
        if xc0.shape != (n_c,) or not np.all(np.isfinite(xc0)):
            raise ParameterError(f"controller {name!r}: xc0 must be a finite vector of length {n_c}, "
                                 f"got shape {xc0.shape}")
        set_(self, "xc0", np.ascontiguousarray(xc0.copy()))
        for attr in ("Ac", "Bc", "Cc", "Dc", "law_params", "v_max", "slew_rate", "xc0", "v0"):
            getattr(self, attr).setflags(write=False)

    @property
    def n_states(self) -> int:
        """Number of controller states ``n_c``."""
        return self.Ac.shape[0]

    def initial_state(self) -> tuple[np.ndarray, np.ndarray]:
        """Return fresh writable copies ``(xc, voltage)`` of the initial controller state and voltages."""
        return self.xc0.copy(), self.v0.copy()

    def kernel_arguments(self) -> tuple:
        """Return ``(Ac, Bc, Cc, Dc, law_id, law_params, v_max, slew_rate, dt)``, the leading
        arguments of :func:`controller_update` in order."""
        return (self.Ac, self.Bc, self.Cc, self.Dc, self.law_id, self.law_params,
                self.v_max, self.slew_rate, self.control_step)


def constant_voltage(n_devices: int, v: float | np.ndarray, n_meas: int = 0,
                     control_step: float = 0.005, v_max: float | np.ndarray | None = None,
                     slew_rate: float | np.ndarray = np.inf, name: str | None = None) -> CompiledController:
    """Build the compiled form of a passive controller: constant voltages, no dynamics.

    Parameters
    ----------
    n_devices : int
        Number of devices.
    v : float or ndarray
        Voltage of every device (or one per device) [V].
    n_meas : int
        Length of the measurement vector (the compiled ``Dc`` is ``(n_devices, n_meas)`` zeros).
    control_step : float
        Control step [s].
    v_max : float or ndarray, optional
        Upper voltage limit [V]; defaults to ``max(v)``.
    slew_rate : float or ndarray
        Slew limit [V/s] (``inf`` for none); with a finite rate the voltage ramps up from 0 V.
    name : str, optional
        Controller name (``"constant-<v>V"`` by default).
    """
    v_array = np.asarray(v, dtype=np.float64)
    if v_max is None:
        v_max = float(np.max(v_array)) if v_array.size else 0.0
    return CompiledController(
        name=name or f"constant-{float(np.max(v_array)):g}V", n_meas=n_meas, n_devices=n_devices,
        control_step=control_step, law_id=LAW_CONSTANT, law_params=v_array, v_max=v_max,
        slew_rate=slew_rate)


def run_compiled(compiled: CompiledController, measurements: np.ndarray,
                 device_force: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Run a compiled controller over a sequence of measurements (open loop), in Python.

    Parameters
    ----------
    compiled : CompiledController
    measurements : ndarray, shape (n_steps, n_meas)
        Measurement vectors, one per control step.
    device_force : ndarray, shape (n_steps, n_devices), optional
        Measured device forces [N]; default: the last ``n_devices`` columns of ``measurements``.

    Returns
    -------
    voltage, desired_force : ndarray, shape (n_steps, n_devices)
    states : ndarray, shape (n_steps + 1, n_c)
        Controller state before each step and after the last.
    """
    y = np.ascontiguousarray(measurements, dtype=np.float64)
    if y.ndim != 2 or y.shape[1] != compiled.n_meas:
        raise ParameterError(f"controller {compiled.name!r}: measurements have shape {y.shape}, "
                             f"expected (n_steps, {compiled.n_meas})")
    n_dev = compiled.n_devices
    if device_force is None:
        f = np.ascontiguousarray(y[:, y.shape[1] - n_dev:])
    else:
        f = np.ascontiguousarray(device_force, dtype=np.float64)
    if f.shape != (y.shape[0], n_dev):
        raise ParameterError(f"controller {compiled.name!r}: device_force has shape {f.shape}, "
                             f"expected ({y.shape[0]}, {n_dev})")
    xc, v = compiled.initial_state()
    voltage = np.empty((y.shape[0], n_dev))
    desired = np.empty((y.shape[0], n_dev))
    states = np.empty((y.shape[0] + 1, compiled.n_states))
    states[0] = xc
    fd = np.empty(n_dev)
    args = compiled.kernel_arguments()
    for k in range(y.shape[0]):
        status = controller_update(*args, y[k], f[k], xc, v, fd)
        if status != STATUS_OK:
            raise NumericalError(f"controller {compiled.name!r}: state or desired force is not finite",
                                 time=k * compiled.control_step,
                                 hint="check the controller design (unstable estimator?) and the measurements")
        voltage[k] = v
        desired[k] = fd
        states[k + 1] = xc
    return voltage, desired, states
