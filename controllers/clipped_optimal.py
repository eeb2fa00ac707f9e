"""Clipped-optimal control (Dyke et al. 1996) with an H2/LQG design on a reduced building model.

Design (Nagarajaiah & Narasimhan 2006, Part II; :mod:`controllers.lqg` for the equations):

1. the building's linear model with linearised isolation (:mod:`benchmark.simulator.linear_model`),
   device forces as inputs, is reduced to its ``n_modes`` slowest modes (modal truncation with
   a static correction of the force feedthrough);
2. an LQR gain minimises :math:`\\int z^T W_z z + f^T W_f f\\,dt` with the regulated outputs

   .. math::

       z = \\left[\\frac{u_b}{d_0},\\ \\frac{\\dot u_b}{v_0},\\ \\frac{\\ddot u^a_{1..8}}{a_0}\\right],
       \\qquad W_z = \\operatorname{diag}(q_d I_3, q_v I_3, q_a I_{24}),
       \\qquad W_f = \\frac{r}{f_0^2} I,

   base displacement and velocity and absolute floor accelerations, rotations turned into
   displacements/accelerations at ``rotation_radius``; :math:`f_0` the device's force capacity;
3. a discrete Kalman filter at the control step estimates the reduced state from the
   absolute accelerations of the base and floors and the base drift, with the measured device
   forces as a known input; the ground acceleration is the process noise;
4. the desired force :math:`f_c = -K \\hat x[k|k]` is clipped by the bang-bang rule
   :math:`v_i = V_{max} H((f_{c,i} - f_i) f_i) H(|f_{c,i}| - p_i)` (law 1 of
   :mod:`controllers.compiled`) with the dead band :math:`p_i` = ``dead_band`` :math:`f_0`.

Switching before the earthquake: Dyke's rule looks only at signs, so it switches as often on a
desired force of 0.07 % of the capacity (a record's quiet lead-in, 0.002 m/s²) as in the strong
motion: 0.47 V mean and 9 switches/s before the Kobe motion arrives, without any sensor noise
(noise makes it ~90/s). The dead band (default :data:`DEFAULT_DEAD_BAND` = 2 % of :math:`f_0`,
the project's choice; the usual anti-chattering threshold of switching laws, Slotine & Li 1991,
ch. 7) keeps the devices off then; measured on all seven records, it changes no J by more than
0.001. Measurements and the choice: docs/switching.md.

Forces follow the measurement convention: ``f`` is the device's resisting force (it acts on
the base as ``-f``), so a positive desired force opposes positive base motion.

References
----------
Dyke S.J., Spencer B.F., Sain M.K., Carlson J.D. (1996) Modeling and control of
magnetorheological dampers for seismic response reduction. Smart Mater. Struct. 5:565–575.
Nagarajaiah S., Narasimhan S. (2006) Smart base-isolated benchmark building, Part II.
Struct. Control Health Monit. 13:589–604.
Slotine J.-J.E., Li W. (1991) Applied Nonlinear Control. Prentice Hall (ch. 7, chattering).
"""

from __future__ import annotations

import weakref
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from benchmark.foundation.errors import InputError, ParameterError
from controllers.base import CompiledBackedController, ControlContext, register_controller
from controllers.compiled import DEFAULT_DEAD_BAND, LAW_CLIPPED_OPTIMAL, CompiledController
from controllers.lqg import (LinearPlant, ReducedPlant, estimator_fit, kalman_design, lqr_design,
                             modal_reduction, observer_controller, simulate_linear)
from controllers.measurements import MeasurementLayout, layout_of
from controllers.plant import building_plant, device_force_capacity, device_models

__all__ = ["LQGWeights", "LQGDesign", "design_lqg", "regulated_outputs", "ClippedOptimal", "DEFAULT_DEAD_BAND"]



#: LQG designs per building (weakly keyed: an entry goes when its building does).
_DESIGN_CACHE: "weakref.WeakKeyDictionary[Any, dict]" = weakref.WeakKeyDictionary()


@dataclass(frozen=True)
class LQGWeights:
    """Design weights and scales of the H2/LQG design (SI units).

    Parameters
    ----------
    q_displacement, q_velocity, q_acceleration : float
        Weights on base displacement, base velocity and absolute floor accelerations (each
        normalised by its scale).
    r_force : float
        Weight on the device forces normalised by the force scale. The default 0.01 makes the
        LQR ask for about the devices' capacity when the base moves by ~0.3 m (a linear run of
        the design model: RMS desired force ≈ 0.25 f_0 at 0.07 m peak base displacement); with
        1.0 the desired forces stay near 1 % of the capacity and the controller is nearly passive.
    displacement_scale : float
        :math:`d_0` [m] (default 0.1 m).
    velocity_scale : float
        :math:`v_0` [m/s] (default 0.5 m/s).
    acceleration_scale : float
        :math:`a_0` [m/s²] (default 3 m/s² ≈ 0.3 g).
    force_scale : float, optional
        :math:`f_0` [N] per device; default: the device's peak force at maximum voltage
        (:func:`controllers.plant.device_force_capacity`).
    rotation_radius : float
        Radius [m] that turns rotations into displacements/accelerations in ``z`` and the
        sensor-noise RMS into rad units.
    n_modes : int
        Modes of the reduced design model (complex pairs count once). With 9 modes (18 states)
        the noise-free estimator fit of the full model is ~99.7 % (base displacement), ~96 %
        (base velocity), ~75 % (roof acceleration); 6 modes give 99/92/55 %.
    ground_rms : float
        RMS of the ground acceleration per direction assumed by the Kalman filter [m/s²].
    acceleration_noise_rms, displacement_noise_rms : float
        Sensor-noise RMS assumed by the Kalman filter [m/s², m].
    """

    q_displacement: float = 1.0
    q_velocity: float = 1.0
    q_acceleration: float = 1.0
    r_force: float = 0.01
    displacement_scale: float = 0.1
    velocity_scale: float = 0.5
    acceleration_scale: float = 3.0
    force_scale: float | None = None
    rotation_radius: float = 20.0
    n_modes: int = 9
    ground_rms: float = 3.0
    acceleration_noise_rms: float = 0.05
    displacement_noise_rms: float = 1e-3

    def __post_init__(self) -> None:
        for name, value in asdict(self).items():
            if name == "force_scale" and value is None:
                continue
            if name in ("q_displacement", "q_velocity", "q_acceleration"):
                ok = np.isfinite(value) and value >= 0
            else:
                ok = np.isfinite(value) and value > 0
            if not ok:
                raise ParameterError(f"LQGWeights.{name}: expected a finite number "
                                     f"{'>= 0' if name.startswith('q_') else '> 0'}, got {value!r}")
        if int(self.n_modes) != self.n_modes:
            raise ParameterError(f"LQGWeights.n_modes: expected an integer, got {self.n_modes!r}")


def regulated_outputs(plant: LinearPlant, n_devices: int, weights: LQGWeights) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Return ``(C_z, D_z, W_z)`` of the regulated outputs (module docstring) for a plant whose
    outputs are the benchmark's measurement vector.

    Parameters
    ----------
    plant : LinearPlant
        Full linear model whose outputs are the measurement vector.
    n_devices : int
        Number of controlled devices (MR dampers) in the building.
    weights : LQGWeights
        Weights of the regulated outputs (drifts, accelerations, base displacement).
    """
    lay = layout_of(plant.C.shape[0], n_devices)
    s = lay.slices()
    rot = np.ones(3)
    rot[2] = weights.rotation_radius
    Cd = plant.C[s["base_displacement"]] * rot[:, None]
    Dd = plant.D[s["base_displacement"]] * rot[:, None]
    Cv = Cd @ plant.A          # d/dt of the displacement rows (their force feedthrough is zero)
    Dv = Cd @ plant.B
    rot_floor = np.tile(rot, lay.n_accelerations // 3 - 1)
    Ca = plant.C[s["floor_acceleration"]] * rot_floor[:, None]
    Da = plant.D[s["floor_acceleration"]] * rot_floor[:, None]
    Cz = np.vstack([Cd / weights.displacement_scale, Cv / weights.velocity_scale, Ca / weights.acceleration_scale])
    Dz = np.vstack([Dd / weights.displacement_scale, Dv / weights.velocity_scale, Da / weights.acceleration_scale])
    Wz = np.diag(np.concatenate([np.full(3, weights.q_displacement), np.full(3, weights.q_velocity),
                                 np.full(lay.n_accelerations - 3, weights.q_acceleration)]))
    return Cz, Dz, Wz


@dataclass
class LQGDesign:
    """Result of :func:`design_lqg`: reduced plant, gains, estimator, compiled matrices, checks.

    Parameters
    ----------
    reduced : ReducedPlant
        The modally reduced design plant.
    weights : LQGWeights
        The weights the design used.
    control_step : float
        Control (sampling) step [s].
    force_scale : np.ndarray
        Force scale f₀ per device [N] (``W_f = r / f_0²``).
    lqr : dict
        Result of :func:`controllers.lqg.lqr_design` (gain ``K``, Riccati solution, closed-loop poles,
        residual).
    kalman : dict
        Result of :func:`controllers.lqg.kalman_design` (filter gains, covariance, poles, residual).
    sensor_rows : np.ndarray
        Rows of the measurement vector the estimator reads (the noisy sensors).
    force_rows : np.ndarray
        Rows of the measurement vector holding the device forces [N].
    n_meas : int
        Length of the measurement vector (``30 + 2 n_devices``).
    gain : np.ndarray
        Gain G of the desired forces ``f_c = G x̂[k|k]`` [N per state unit].
    matrices : tuple
        ``(Ac, Bc, Cc, Dc)``: the compiled discrete observer-controller.
    fit : dict, optional
        Estimator fit per state [%] (:func:`controllers.lqg.estimator_fit`), empty without ``check_fit``.
    """

    reduced: ReducedPlant
    weights: LQGWeights
    control_step: float
    force_scale: np.ndarray
    lqr: dict
    kalman: dict
    sensor_rows: np.ndarray
    force_rows: np.ndarray
    n_meas: int
    gain: np.ndarray                      # G: f_c = G x̂[k|k]
    matrices: tuple                        # (Ac, Bc, Cc, Dc)
    fit: dict = field(default_factory=dict)

    @property
    def riccati_residuals(self) -> dict[str, float]:
        """Relative residuals of the LQR and Kalman Riccati equations."""
        return {"lqr": self.lqr["riccati_residual"], "kalman": self.kalman["riccati_residual"]}

    def report(self) -> str:
        """A text report: reduced model, closed-loop and estimator poles, residuals, estimator fit."""
        modes = self.reduced.eigenvalues.size or self.weights.n_modes
        lines = [f"H2/LQG design: {self.reduced.plant.n_states} states ({modes} modes), "
                 f"control step {self.control_step:g} s",
                 "weights: " + ", ".join(f"{k}={v}" for k, v in asdict(self.weights).items()),
                 f"force scale per device: {np.unique(np.round(self.force_scale)).tolist()} N",
                 f"Riccati residuals (relative): LQR {self.lqr['riccati_residual']:.2e}, "
                 f"Kalman {self.kalman['riccati_residual']:.2e}",
                 "open-loop modes of the design model (period s, damping %):"]
        lines += _pole_lines(self.reduced.eigenvalues)
        lines.append("LQR closed-loop poles (period s, damping %):")
        lines += _pole_lines(self.lqr["closed_loop_poles"])
        est = np.log(self.kalman["poles"].astype(complex)) / self.control_step
        lines.append("Kalman estimator poles, continuous equivalents (period s, damping %):")
        lines += _pole_lines(est)
        if self.fit:
            lines.append("estimator fit on a noise-free linear run of the full model [%]:")
            lines += [f"  {name}: {value:.2f}" for name, value in self.fit.items()]
        return "\n".join(lines)


def _pole_lines(poles: np.ndarray) -> list[str]:
    poles = np.asarray(poles, dtype=complex)
    poles = poles[poles.imag >= -1e-12]
    poles = poles[np.argsort(np.abs(poles))]
    out = []
    for p in poles:
        wn = abs(p)
        zeta = -p.real / wn if wn > 0 else 1.0
        period = 2 * np.pi / abs(p.imag) if abs(p.imag) > 1e-12 else np.inf
        out.append(f"  {p.real:+.4g}{p.imag:+.4g}j  T={period:.3f}  zeta={100 * zeta:.1f}")
    return out


def _sensor_noise(lay: MeasurementLayout, weights: LQGWeights) -> tuple[np.ndarray, np.ndarray]:
    s = lay.slices()
    rows = np.arange(s["base_acceleration"].start, s["base_displacement"].stop)
    rms = np.concatenate([np.full(lay.n_accelerations, weights.acceleration_noise_rms),
                          np.full(3, weights.displacement_noise_rms)])
    rms[2::3] /= weights.rotation_radius  # θ entries
    return rows, rms


def design_lqg(plant: LinearPlant, n_devices: int, control_step: float, weights: LQGWeights,
               force_scale: float | np.ndarray, check_fit: bool = True, seed: int = 0) -> LQGDesign:
    """H2/LQG design on ``plant`` (outputs = measurement vector), discretised at ``control_step``.

    Parameters
    ----------
    plant : LinearPlant
        Full linear model of the building (:func:`controllers.plant.building_plant`).
    n_devices : int
    control_step : float
        [s]
    weights : LQGWeights
    force_scale : float or ndarray
        Force scale per device [N] (``W_f = r / f_0²``).
    check_fit : bool
        Run the estimator on a noise-free linear simulation of the full model driven by a
        seeded broadband ground motion and random device forces, and store the fit of the
        estimated base displacement, base velocity and roof acceleration.
    seed : int, optional
        Seed of the random ground motion and device forces of the estimator-fit check.
    """
    try:
        lay = layout_of(plant.C.shape[0], n_devices)
    except InputError:
        lay = None
    if lay is None or plant.B.shape[1] != n_devices:
        raise ParameterError(f"design_lqg: plant has {plant.C.shape[0]} outputs and {plant.B.shape[1]} "
                             f"inputs, expected 6 + 3 n_floors + 2 n_devices measurements and {n_devices} "
                             "devices")
    n_meas = lay.n_measurements
    f0 = np.broadcast_to(np.asarray(force_scale, dtype=float), (n_devices,)).copy()
    if np.any(~np.isfinite(f0)) or np.any(f0 <= 0):
        raise ParameterError(f"design_lqg: force_scale must be positive, got {force_scale!r}")
    # a building reduced by --n-modes below the design's order: its modes are all the design has
    reduced = modal_reduction(plant, int(weights.n_modes), at_most=True)
    p = reduced.plant
    Cz, Dz, Wz = regulated_outputs(p, n_devices, weights)
    Wf = np.diag(weights.r_force / f0 ** 2)
    lqr = lqr_design(p.A, p.B, Cz, Dz, Wz, Wf)
    Ad, Bd, Ed = p.discretise(control_step)
    sensor_rows, rms = _sensor_noise(lay, weights)
    force_rows = np.arange(n_meas)[lay.slices()["device_force"]]
    Cs, Ds = p.C[sensor_rows], p.D[sensor_rows]
    kf = kalman_design(Ad, Ed, Cs, np.eye(p.E.shape[1]) * weights.ground_rms ** 2, np.diag(rms ** 2))
    G = -lqr["K"]
    matrices = observer_controller(Ad, Bd, Cs, Ds, kf["M"], G, sensor_rows, force_rows, n_meas)
    design = LQGDesign(reduced=reduced, weights=weights, control_step=float(control_step), force_scale=f0,
                       lqr=lqr, kalman=kf, sensor_rows=sensor_rows, force_rows=force_rows, n_meas=n_meas,
                       gain=G, matrices=matrices)
    if check_fit:
        design.fit = _estimator_fit(plant, design, seed)
    return design


def _estimator_fit(plant: LinearPlant, design: LQGDesign, seed: int, duration: float = 20.0) -> dict:
    """Fit of the estimate on a noise-free run of the *full* linear model (module docstring)."""
    dt = design.control_step
    n = int(round(duration / dt))
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    envelope = np.minimum(1.0, t / 2.0) * np.exp(-np.maximum(0.0, t - 10.0) / 5.0)
    kernel = np.ones(8) / 8  # smooths the white noise to below ~25 Hz
    ground = np.column_stack([np.convolve(rng.standard_normal(n), kernel, "same") for _ in range(plant.E.shape[1])])
    ground *= 2.0 * envelope[:, None]
    n_dev = plant.B.shape[1]
    scale = design.force_scale
    forces = np.column_stack([scale[i] * 0.5 * np.sin(2 * np.pi * (0.3 + 0.05 * i) * t + i) for i in range(n_dev)])
    x, y = simulate_linear(plant, dt, ground, forces)
    Ac, Bc, Cc, Dc = design.matrices
    p = design.reduced.plant
    M, Cs, Ds = design.kalman["M"], p.C[design.sensor_rows], p.D[design.sensor_rows]
    xc = np.zeros(p.n_states)
    est = np.empty((n, p.n_states))
    for k in range(n):
        # filtered estimate x̂[k|k], then the controller-state update xc = x̂[k+1|k]
        innovation = y[k, design.sensor_rows] - Cs @ xc - Ds @ forces[k]
        est[k] = xc + M @ innovation
        xc = Ac @ xc + Bc @ y[k]
    s = layout_of(plant.C.shape[0], n_dev).slices()
    disp_true = y[:, s["base_displacement"]]
    disp_est = est @ p.C[s["base_displacement"]].T
    vel_true = x @ (plant.C[s["base_displacement"]] @ plant.A).T
    vel_est = est @ (p.C[s["base_displacement"]] @ p.A).T
    roof = slice(s["floor_acceleration"].stop - 3, s["floor_acceleration"].stop)
    acc_true = y[:, roof]
    acc_est = est @ p.C[roof].T + forces @ p.D[roof].T
    fit = {}
    for label, true, est_ in (("base displacement", disp_true, disp_est), ("base velocity", vel_true, vel_est),
                              ("roof absolute acceleration", acc_true, acc_est)):
        values = estimator_fit(true, est_)
        for axis, value in zip("xyθ", values):
            fit[f"{label} {axis}"] = float(value)
    return fit


@register_controller
class ClippedOptimal(CompiledBackedController):
    """Clipped-optimal controller with an H2/LQG design (module docstring).

    Parameters
    ----------
    weights : LQGWeights, optional
        Design weights (defaults documented in :class:`LQGWeights`).
    plant : LinearPlant, optional
        Design model; default: :func:`controllers.plant.building_plant` of the run's building.
    voltage : float, optional
        Commanded "on" voltage [V]; default: each device's maximum.
    check_fit : bool
        Compute the estimator fit at design time (shown in :meth:`LQGDesign.report`).
    dead_band : float
        Dead band on the desired force as a fraction of the design's force scale :math:`f_0`
        (the device's capacity): a device is switched on only while
        :math:`|f_{c,i}|` > ``dead_band`` :math:`f_0` (default :data:`DEFAULT_DEAD_BAND`; 0 gives
        Dyke's law unchanged). See the module docstring, "Switching before the earthquake".
    """

    name = "clipped-optimal"
    law_id = LAW_CLIPPED_OPTIMAL

    def __init__(self, weights: LQGWeights | None = None, plant: LinearPlant | None = None,
                 voltage: float | None = None, check_fit: bool = False,
                 dead_band: float | None = None) -> None:
        super().__init__()
        self.dead_band = DEFAULT_DEAD_BAND if dead_band is None else float(dead_band)
        if not np.isfinite(self.dead_band) or not 0.0 <= self.dead_band < 1.0:
            raise ParameterError(f"controller {self.name!r}: dead_band must be a fraction of the force "
                                 f"capacity in [0, 1), got {dead_band}")
        self.weights = weights or LQGWeights()
        self.plant = plant
        self.voltage = voltage
        self.check_fit = check_fit
        self.design: LQGDesign | None = None

    def _force_scale(self, context: ControlContext) -> np.ndarray:
        if self.weights.force_scale is not None:
            return np.full(context.n_devices, float(self.weights.force_scale))
        models = device_models(context.design_model)
        return np.array([device_force_capacity(m, v) for m, v in zip(models, self._v_on(context))])

    def _v_on(self, context: ControlContext) -> np.ndarray:
        if self.voltage is None:
            return context.voltage_max.copy()
        if np.any(self.voltage > context.voltage_max) or self.voltage < 0:
            raise ParameterError(f"controller {self.name!r}: voltage {self.voltage} V outside "
                                 f"[0, {context.voltage_max.min():g}] V")
        return np.full(context.n_devices, float(self.voltage))

    def make_design(self, context: ControlContext) -> LQGDesign:
        """Run the design for ``context`` (building, device count, control step).

        Parameters
        ----------
        context : ControlContext
            The run's control context (:class:`controllers.base.ControlContext`: design model, device count,
            control step).
        """
        plant = self.plant if self.plant is not None else building_plant(context.design_model)
        return design_lqg(plant, context.n_devices, context.control_step, self.weights,
                          self._force_scale(context), check_fit=self.check_fit)

    def _cached_design(self, context: ControlContext) -> LQGDesign:
        # A comparison or ensemble makes a new controller object per run on the same building:
        # share the design (about 50 ms) between them. Only designs derived from the building
        # itself are shared; the cache entry dies with the design model (one per building).
        if self.plant is not None or context.design_model is None:
            return self.make_design(context)
        key = (type(self).make_design, self.weights, None if self.voltage is None else float(self.voltage),
               self.check_fit, context.n_devices, context.control_step,
               tuple(np.asarray(context.voltage_max, dtype=float)))
        designs = _DESIGN_CACHE.setdefault(context.design_model, {})
        if key not in designs:
            designs[key] = self.make_design(context)
        return designs[key]

    def law_parameters(self, design: LQGDesign, context: ControlContext) -> np.ndarray:
        """``law_params`` of the compiled controller: the dead band [N] of the bang-bang law,
        ``dead_band`` times the force scale :math:`f_0` of each device.

        Parameters
        ----------
        design : LQGDesign
            The LQG design this controller made (:meth:`make_design`).
        context : ControlContext
            The run's control context (:class:`controllers.base.ControlContext`: design model, device count,
            control step).
        """
        return self.dead_band * self._force_scale(context)

    def controller_matrices(self, design: LQGDesign) -> tuple:
        """``(Ac, Bc, Cc, Dc)`` of the compiled controller (the LQG observer with f_c = −K x̂).

        Parameters
        ----------
        design : LQGDesign
            The LQG design this controller made (:meth:`make_design`).
        """
        return design.matrices

    def build(self, context: ControlContext) -> CompiledController:
        key = (id(context.design_model), context.n_devices, context.control_step)
        if self.design is None or getattr(self, "_design_key", None) != key:
            self.design = self._cached_design(context)
            self._design_key = key
        d = self.design
        Ac, Bc, Cc, Dc = self.controller_matrices(d)
        return CompiledController(name=self.name, n_meas=context.n_measurements, n_devices=context.n_devices,
                                  control_step=context.control_step, law_id=self.law_id,
                                  law_params=self.law_parameters(d, context), v_max=self._v_on(context),
                                  slew_rate=context.slew_rate, Ac=Ac, Bc=Bc, Cc=Cc, Dc=Dc)

    def describe(self) -> dict[str, Any]:
        return {"name": self.name, **{k: v for k, v in asdict(self.weights).items() if v is not None},
                "dead_band": self.dead_band}
