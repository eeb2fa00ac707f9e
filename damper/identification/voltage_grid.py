"""Identification over a voltage grid and the voltage laws fitted to the parameter table.

At each voltage of a grid (default 0, 0.1, …, 1 V, the seed paper's Table 1) a periodic test
is run on the device through :func:`damper.lab.laboratory.periodic_test` and identified with
:func:`~damper.identification.identify.identify`. The resulting table (parameters per model
and voltage) is then fitted with

* the seed paper's laws (Bahar et al. 2009, eq. 5–10): :math:`\\kappa_x` constant (5),
  :math:`\\kappa_{\\dot x} = a + b v` (6), :math:`n = a + b e^{-13 v}` (7),
  :math:`\\rho = a + b e^{-14 v}` (8), :math:`\\sigma = a + b e^{-14 v}` (9) and the three-region
  :math:`\\kappa_w` law (10) (:class:`~damper.models.voltage_laws.SeedKappaW`), each by linear least
  squares (the exponents 13 and 14 are the paper's, fixed);
* the generic law of :mod:`damper.models.voltage_laws`: the shape-preserving cubic through the table
  (:class:`~damper.models.voltage_laws.Tabulated`); it interpolates, so its error is reported by
  leave-one-out cross-validation.

Fit errors: RMS and maximum of the relative residual at the grid voltages. A seed law that
leaves the admissible class somewhere in [0, 1] V (e.g. :math:`\\sigma < 1/2`) is replaced by
the generic law in the voltage-dependent model, and the replacement is reported.

The extended model's :math:`\\kappa_x`
------------------------------------------
The seed paper reads :math:`\\kappa_x` once, in its step (a), from the average inclination of
a large-amplitude force–displacement loop at 0 V (its Fig. 2: 82.8 kN over 0.4 m, 207 kN/m),
identifies the rest on :math:`F - \\kappa_x x`, and its voltage law is :math:`\\kappa_x(v) =
\\kappa_x` (eq. 5). :func:`identify_voltage_grid` does the same by default
(``kappa_x="large-loop"``: :func:`estimate_kappa_x` on :data:`LARGE_LOOP_PROTOCOL`, then
:math:`\\kappa_x` held fixed in every closed-form step and refinement of the grid). Options:
``"joint"``, one :math:`\\kappa_x` refined jointly with every voltage's other parameters
(:func:`~damper.identification.refine.refine_shared`, started from the large-loop value);
a number, a given :math:`\\kappa_x`; and ``"per-voltage"``, :math:`\\kappa_x` free at each
voltage (not the seed's method: a voltage-dependent :math:`\\kappa_x(v)` multiplies the total
displacement, so every voltage switch changes the force by :math:`\\Delta\\kappa_x x`; kept for
comparison).

The grid's voltages are independent tasks and run in a process pool (``jobs``); the results
do not depend on the number of workers.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

from benchmark.foundation.errors import InputError, ParameterError
from benchmark.foundation.pools import stop_pool
from damper.models.bouc_wen import ExtendedBoucWen, NormalizedBoucWen
from damper.identification.closed_form import MODEL_FORMS, PARAMETER_NAMES, closed_form
from damper.identification.cycles import average_branches, detect_cycles, steady_cycles
from damper.identification.identify import Identification, identify
from benchmark.foundation.pools import make_executor, run_tasks, worker_count
from damper.identification.refine import free_parameters, parameters_at_bounds, refine_shared
from damper.models.voltage_laws import (Constant, Exponential, Polynomial, SeedKappaW, Tabulated,
                                 VoltageLaw, check_law)
from damper.lab.laboratory import periodic_test

__all__ = ["TestProtocol", "LawFit", "VoltageGridResult", "KappaXEstimate", "identify_voltage_grid",
           "estimate_kappa_x", "fit_voltage_laws", "voltage_model", "inadmissible", "DEFAULT_VOLTAGES",
           "LARGE_LOOP_PROTOCOL", "KAPPA_X_MODES"]

#: The seed paper's grid (Table 1): 0, 0.1, ..., 1 V.
DEFAULT_VOLTAGES = tuple(np.round(np.linspace(0.0, 1.0, 11), 10))


@dataclass(frozen=True)
class TestProtocol:
    """A constant-voltage periodic test (arguments of :func:`damper.lab.laboratory.periodic_test`).

    The default drives the device with ±0.1 m at 0.5 Hz (±0.31 m/s): the displacements and
    velocities the dampers see in the benchmark's earthquake runs (peaks 0.1–0.3 m and up to
    1 m/s, RMS a few cm), with :math:`\\rho(X_{max} - X_{min})` well above the plastic threshold
    for a device whose transition length is a centimetre; three cycles (the first is
    discarded as transient), 1 kHz sampling. The seed paper's large loop (±0.4 m, 0.8 Hz,
    Fig. 1–3) is :data:`benchmark.applications.identification_study.LARGE_LOOP_PROTOCOL`; identified on it the
    models reproduce that loop better and the earthquake runs worse (see the study's report).

    Parameters
    ----------
    amplitude : float, optional
        Displacement amplitude [m].
    frequency : float, optional
        Frequency of the motion [Hz].
    cycles : float, optional
        Number of periods.
    sample_rate : float, optional
        Samples per second [Hz].
    noise : float, optional
        Relative RMS measurement noise on the force (0: none).
    seed : int, optional
        Seed of the random generator (the same seed gives the same result).
    """

    __test__ = False  # not a pytest class

    amplitude: float = 0.1
    frequency: float = 0.5
    cycles: float = 3.0
    sample_rate: float = 1000.0
    noise: float = 0.0
    seed: int = 0

    def run(self, device, voltage: float):
        """Run the test on ``device`` at ``voltage`` [V] through the virtual laboratory.

        Parameters
        ----------
        device
            The damper tested: a model instance, or the name of a parameterless model
            (:func:`damper.lab.laboratory.resolve_device`).
        voltage : float
            Constant voltage [V].
        """
        return periodic_test(device, self.amplitude, self.frequency, voltage, cycles=self.cycles,
                             sample_rate=self.sample_rate, noise=self.noise, seed=self.seed)


#: The seed paper's large loop (Fig. 1-3): ±0.4 m at 0.8 Hz (±2 m/s), at 0 V; kappa_x is read from it.
LARGE_LOOP_PROTOCOL = TestProtocol(amplitude=0.4, frequency=0.8, cycles=3.0, sample_rate=1000.0)
#: How the extended model's kappa_x is obtained (besides a given number).
KAPPA_X_MODES = ("large-loop", "joint", "per-voltage")


@dataclass(frozen=True)
class KappaXEstimate:
    """The extended model's :math:`\\kappa_x` and how it was obtained.

    Attributes
    ----------
    mode : str
        ``"large-loop"`` (seed step a), ``"joint"`` (shared over the grid), ``"given"`` or
        ``"per-voltage"`` (free at each voltage: ``value`` is NaN).
    value, standard_error : float
        [N/m] (standard error: Jacobian of the joint fit; NaN otherwise).
    inclination, regression : float
        The large loop's average inclination (seed step a) and the joint plastic regression's
        :math:`\\kappa_x` on the same loop [N/m] (NaN when no loop was run).
    rho_stroke : float
        :math:`\\rho(X_{max} - X_{min})` of the large loop (closed-form :math:`\\rho`).
    protocol : dict
        The large loop's test (amplitude [m], frequency [Hz], voltage [V], ...).
    notes : tuple of str
    """

    mode: str
    value: float
    standard_error: float = float("nan")
    inclination: float = float("nan")
    regression: float = float("nan")
    rho_stroke: float = float("nan")
    protocol: dict = field(default_factory=dict)
    notes: tuple = ()

    def to_dict(self) -> dict:
        """JSON-ready (NaN as None)."""
        out = {}
        for k, v in self.__dict__.items():
            if isinstance(v, float) and v != v:
                v = None
            out[k] = list(v) if isinstance(v, tuple) else v
        return out


def estimate_kappa_x(device, protocol: TestProtocol = LARGE_LOOP_PROTOCOL,
                     voltage: float = 0.0) -> tuple[KappaXEstimate, object]:
    """The seed paper's step (a): :math:`\\kappa_x` from the average inclination of a large loop.

    Runs ``protocol`` on ``device`` at ``voltage`` [V] (the seed: ±0.4 m at 0 V, Fig. 2), waits
    for the limit cycle and takes the slope of the loop's mid-line over the displacements
    where both branches are plastic (:func:`~damper.identification.closed_form.closed_form`,
    ``kappa_x_inclination``); if that slope leaves no dry friction the joint plastic
    regression's value is used instead and a note says so.

    Parameters
    ----------
    device
        The damper tested: a model instance, or the name of a parameterless model
        (:func:`damper.lab.laboratory.resolve_device`).
    protocol : TestProtocol, optional
        The large-stroke test.
    voltage : float, optional
        Voltage of the test [V].

    Returns
    -------
    (KappaXEstimate, DamperTest)
        The estimate and the test it was read from.
    """
    test = protocol.run(device, float(voltage))
    x, f = np.asarray(test.displacement), np.asarray(test.force)
    xdot = np.asarray(test.velocity) if getattr(test, "velocity", None) is not None \
        else np.gradient(x, test.time, edge_order=2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        cycles = detect_cycles(x)
        kept, _ = steady_cycles(x, f, cycles)
        if len(cycles) >= 3 and len(kept) == len(cycles):
            kept = kept[1:]
        cf = closed_form(average_branches(x, xdot, f, kept), model="extended", strict=False, check=False)
    value = cf.kappa_x_inclination if cf.kappa_x_method == "inclination" else cf.kappa_x
    est = KappaXEstimate(mode="large-loop", value=float(value), inclination=float(cf.kappa_x_inclination),
                         regression=float(cf.kappa_x_regression), rho_stroke=float(cf.rho_stroke),
                         protocol=dict(protocol.__dict__, voltage=float(voltage)), notes=tuple(cf.notes))
    return est, test


@dataclass(frozen=True)
class LawFit:
    """A voltage law fitted to one parameter column.

    Attributes
    ----------
    parameter : str
    family : str
        ``"seed"`` (eq. 5–10) or ``"generic"`` (PCHIP table).
    law : VoltageLaw
    formula : str
        Human-readable law.
    coefficients : list of float
    rms_error, max_error : float
        Relative residuals at the grid voltages (leave-one-out for the generic law).
    """

    parameter: str
    family: str
    law: VoltageLaw = field(repr=False)
    formula: str
    coefficients: list
    rms_error: float
    max_error: float

    def to_dict(self) -> dict:
        """The fit as a JSON-ready dict: family, formula, coefficients, RMS and largest error."""
        return {"family": self.family, "formula": self.formula, "coefficients": self.coefficients,
                "rms_error": self.rms_error, "max_error": self.max_error}


@dataclass
class VoltageGridResult:
    """Identification results over the voltage grid.

    Attributes
    ----------
    voltages : ndarray
        Grid [V].
    identifications : dict
        ``model -> list of Identification`` (one per voltage).
    laws : dict
        ``model -> {"seed": {param: LawFit}, "generic": {param: LawFit}}``.
    models : dict
        ``model -> {"seed": model object, "generic": model object}``: the voltage-dependent
        identified models (seed laws, with generic replacements noted in ``notes``).
    notes : list of str
    protocol : TestProtocol
    kappa_x : KappaXEstimate or None
        How the extended model's :math:`\\kappa_x` was obtained (None without that model).
    """

    voltages: np.ndarray
    identifications: dict
    laws: dict
    models: dict
    notes: list
    protocol: TestProtocol
    kappa_x: KappaXEstimate | None = None

    def table(self, model: str) -> np.ndarray:
        """Parameters per voltage, shape (n_voltages, 6), columns :data:`PARAMETER_NAMES`.

        Parameters
        ----------
        model : str
            ``"normalized"`` or ``"extended"``.
        """
        return np.array([[ident.parameters[k] for k in PARAMETER_NAMES]
                         for ident in self.identifications[model]])

    def standard_errors(self, model: str) -> np.ndarray:
        """Jacobian standard errors, same shape as :meth:`table`.

        Parameters
        ----------
        model : str
            ``"normalized"`` or ``"extended"``.
        """
        return np.array([[ident.fit.standard_error[k] for k in PARAMETER_NAMES]
                         for ident in self.identifications[model]])

    def rows(self) -> list[dict]:
        """One dict per (model, voltage): parameters, standard errors, fit errors (for CSV)."""
        out = []
        for model, idents in self.identifications.items():
            for v, ident in zip(self.voltages, idents):
                row = {"model": model, "voltage": float(v),
                       "kappa_x_mode": (self.kappa_x.mode if self.kappa_x is not None else "")
                       if model == "extended" else "none"}
                row.update({k: ident.parameters[k] for k in PARAMETER_NAMES})
                row.update({f"{k}_std": ident.fit.standard_error[k] for k in PARAMETER_NAMES})
                row.update({k: ident.errors[k] for k in ("rel_rms_error", "peak_error", "energy_error")})
                row["rho_stroke"] = ident.summary()["rho_stroke"]
                # a parameter the data left at its bound was not identified (the --data path says so too)
                row["at_bounds"] = "; ".join(f"{k} {where}" for k, where in parameters_at_bounds(
                    ident.fit.parameters, ident.fit.start, ident.fit.free).items())
                out.append(row)
        return out

    def laws_json(self) -> dict:
        """The fitted laws and their errors, JSON-ready."""
        out = {model: {family: {p: fit.to_dict() for p, fit in fits.items()}
                       for family, fits in families.items()}
               for model, families in self.laws.items()} | {"notes": list(self.notes)}
        if self.kappa_x is not None:
            out["kappa_x"] = self.kappa_x.to_dict()
        return out


def _relative_residuals(values: np.ndarray, fitted: np.ndarray) -> np.ndarray:
    scale = np.maximum(np.abs(values), 1e-12 * max(np.max(np.abs(values)), 1e-300))
    return (fitted - values) / scale


def _lsq(columns: list[np.ndarray], values: np.ndarray) -> np.ndarray:
    return np.linalg.lstsq(np.column_stack(columns), values, rcond=None)[0]


def _seed_fit(name: str, v: np.ndarray, y: np.ndarray) -> tuple[VoltageLaw, str, list]:
    """Seed law (eq. 5–10) for parameter ``name`` by linear least squares."""
    if name == "kappa_x":
        c = float(np.mean(y))
        return Constant(c), "kappa_x(v) = c", [c]
    if name == "kappa_xdot":
        a, b = _lsq([np.ones_like(v), v], y)
        return Polynomial((a, b)), "kappa_xdot(v) = a + b v", [float(a), float(b)]
    if name in ("n", "rho", "sigma"):
        rate = 13.0 if name == "n" else 14.0
        a, b = _lsq([np.ones_like(v), np.exp(-rate * v)], y)
        return (Exponential(a, b, rate), f"{name}(v) = a + b exp(-{rate:g} v)",
                [float(a), float(b), rate])
    if name == "kappa_w":
        k = np.zeros(9)
        regions = [(v <= 0.3 + 1e-9, [lambda u: np.ones_like(u), lambda u: u ** 1.15], slice(0, 2)),
                   ((v >= 0.3 - 1e-9) & (v <= 0.7 + 1e-9),
                    [lambda u: np.ones_like(u), lambda u: np.sin(np.pi * (u - 0.3) / 0.8),
                     lambda u: np.sin(3 * np.pi * (u - 0.3) / 0.8)], slice(2, 5)),
                   (v >= 0.7 - 1e-9, [lambda u: np.ones_like(u), lambda u: u, lambda u: u ** 3,
                                      lambda u: u ** 5], slice(5, 9))]
        for mask, basis, sl in regions:
            if np.count_nonzero(mask) == 0:
                raise InputError("voltage grid: the seed's kappa_w law needs voltages in each of "
                                 "[0, 0.3], [0.3, 0.7] and [0.7, 1] V")
            k[sl] = _lsq([b(v[mask]) for b in basis], y[mask])
        return (SeedKappaW(tuple(float(c) for c in k)),
                "kappa_w(v) = k1 + k2 v^1.15 (v<=0.3); k3 + k4 sin(pi(v-0.3)/0.8) + "
                "k5 sin(3pi(v-0.3)/0.8) (0.3-0.7); k6 + k7 v + k8 v^3 + k9 v^5 (v>=0.7)",
                [float(c) for c in k])
    raise InputError(f"parameter: unknown name {name!r}")


def fit_voltage_laws(voltages: Sequence[float], table: np.ndarray,
                     parameters: Sequence[str] = PARAMETER_NAMES) -> dict[str, dict[str, LawFit]]:
    """Fit the seed laws (eq. 5–10) and the generic tabulated law to a parameter table.

    Parameters
    ----------
    voltages : sequence of float
        Grid [V], strictly increasing, at least 3 values.
    table : ndarray, shape (n_voltages, len(parameters))
        Identified parameter values (SI).
    parameters : sequence of str
        Column names (from :data:`PARAMETER_NAMES`).

    Returns
    -------
    dict
        ``{"seed": {name: LawFit}, "generic": {name: LawFit}}``.
    """
    v = np.asarray(voltages, dtype=float)
    table = np.asarray(table, dtype=float)
    if v.ndim != 1 or v.size < 3 or np.any(np.diff(v) <= 0):
        raise InputError(f"voltages: expected at least 3 strictly increasing values, got {v}")
    if table.shape != (v.size, len(parameters)):
        raise InputError(f"table: expected shape {(v.size, len(parameters))}, got {table.shape}")
    out: dict[str, dict[str, LawFit]] = {"seed": {}, "generic": {}}
    for j, name in enumerate(parameters):
        y = table[:, j]
        law, formula, coef = _seed_fit(name, v, y)
        res = _relative_residuals(y, law(v))
        out["seed"][name] = LawFit(name, "seed", law, formula, coef,
                                   float(np.sqrt(np.mean(res ** 2))), float(np.max(np.abs(res))))
        # Generic: PCHIP through the table; leave-one-out error at the interior nodes.
        loo = []
        for i in range(1, v.size - 1):
            keep = np.arange(v.size) != i
            loo.append(float(Tabulated(tuple(v[keep]), tuple(y[keep]))(v[i])))
        res = _relative_residuals(y[1:-1], np.array(loo))
        out["generic"][name] = LawFit(name, "generic", Tabulated(tuple(v), tuple(y)),
                                      "PCHIP through the identified values", [float(c) for c in y],
                                      float(np.sqrt(np.mean(res ** 2))), float(np.max(np.abs(res))))
    return out


_ADMISSIBLE = {"kappa_x": (0.0, False), "kappa_xdot": (0.0, True), "kappa_w": (0.0, True),
               "rho": (0.0, True), "sigma": (0.5, False), "n": (1.0, False)}


def inadmissible(name: str, law: VoltageLaw, voltage_range: tuple[float, float] = (0.0, 1.0)) -> str | None:
    """Why ``law`` for parameter ``name`` leaves the admissible class over ``voltage_range``
    (for example ``n < 1`` near 0 V), or None when it stays inside.

    Parameters
    ----------
    name : str
        A Bouc-Wen parameter (:data:`damper.identification.closed_form.PARAMETER_NAMES`).
    law : VoltageLaw
        Its law of the coil input.
    voltage_range : tuple[float, float], optional
        The coil inputs over which it must hold [V] (or [A]).
    """
    lower, strict = _ADMISSIBLE[name]
    try:
        check_law(law, name, voltage_range, lower=lower, strict=strict)
    except ParameterError as exc:
        return str(exc)
    return None


def voltage_model(model: str, laws: dict[str, LawFit], fallback: dict[str, LawFit] | None = None,
                  notes: list | None = None, voltage_range: tuple[float, float] = (0.0, 1.0)):
    """The voltage-dependent :class:`ExtendedBoucWen`/:class:`NormalizedBoucWen` from fitted laws.

    A law that leaves the admissible class somewhere in ``voltage_range`` (checked with
    :func:`damper.models.voltage_laws.check_law`) is replaced by the same parameter's ``fallback`` law,
    and a note is appended to ``notes``.

    Parameters
    ----------
    model : str
        ``"normalized"`` or ``"extended"``.
    laws : dict[str, LawFit]
        Fitted law of each parameter.
    fallback : dict[str, LawFit] | None, optional
        Laws used where ``laws`` has none; None: none.
    notes : list | None, optional
        List that receives a note for each fallback used; None: none.
    voltage_range : tuple[float, float], optional
        Admissible coil inputs ``(min, max)`` [V] (or [A]); the voltage laws are checked over it.
    """
    names = free_parameters(model)
    chosen = {}
    for k in names:
        law = laws[k].law
        why = inadmissible(k, law, voltage_range)
        if why is not None:
            if fallback is None:
                raise ParameterError(why)
            law = fallback[k].law
            if notes is not None:
                notes.append(f"{model}: the {laws[k].family} law for {k} leaves the admissible class "
                             f"({why}); the {fallback[k].family} law is used for it")
        chosen[k] = law
    cls = ExtendedBoucWen if model == "extended" else NormalizedBoucWen
    return cls(*(chosen[k] for k in names), voltage_range=voltage_range)


def _identify_at_voltage(device, voltage: float, models: tuple, protocol: TestProtocol,
                         n_bootstrap: int, kappa_x: float | None,
                         starts: dict | None = None) -> list[Identification]:
    """One grid voltage: run the test, identify each model (a pool task)."""
    test = protocol.run(device, float(voltage))
    out = []
    for m in models:
        options = {"n_bootstrap": n_bootstrap}
        if m == "extended" and kappa_x is not None:
            options["kappa_x"] = kappa_x
        if starts and m in starts:
            options["start"] = starts[m]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # kept in Identification.warnings
            out.append(identify(test, model=m, **options))
    return out


def identify_voltage_grid(device, voltages: Sequence[float] = DEFAULT_VOLTAGES,
                          models: Sequence[str] = MODEL_FORMS, protocol: TestProtocol = TestProtocol(),
                          progress: Callable[[str], None] | None = None,
                          n_bootstrap: int = 0, kappa_x: str | float = "large-loop",
                          kappa_x_protocol: TestProtocol = LARGE_LOOP_PROTOCOL,
                          jobs: int | None = 1, executor=None) -> VoltageGridResult:
    """Identify each model at each voltage of the grid and fit the voltage laws.

    Parameters
    ----------
    device : damper model or str
        The device under test, handed to :func:`damper.lab.laboratory.periodic_test` (e.g.
        ``"virtual"``); the identification never looks inside it.
    voltages : sequence of float
        Grid [V].
    models : sequence of {"normalized", "extended"}
    protocol : TestProtocol
        The periodic test run at each voltage.
    progress : callable, optional
        Called with a short label after each identification (progress bars).
    n_bootstrap : int
        Cycle-bootstrap refits per identification.
    kappa_x : {"large-loop", "joint", "per-voltage"} or float
        The extended model's :math:`\\kappa_x` (see the module docstring): read once from the
        large loop and held fixed (default, the seed's method), refined jointly over the grid,
        free at each voltage, or this value [N/m] held fixed.
    kappa_x_protocol : TestProtocol
        The large loop of ``"large-loop"`` and ``"joint"`` (run at 0 V).
    jobs : int, optional
        Worker processes (``None`` or 0: all cores; 1: this process). Ignored with ``executor``.
    executor : concurrent.futures.Executor, optional
        A pool to run the voltages on (e.g. the study's).

    Returns
    -------
    VoltageGridResult
    """
    v = np.asarray(voltages, dtype=float)
    models = tuple(models)
    for m in models:
        if m not in MODEL_FORMS:
            raise InputError(f"models: expected names from {MODEL_FORMS}, got {m!r}")
    if isinstance(kappa_x, str):
        if kappa_x not in KAPPA_X_MODES:
            raise InputError(f"kappa_x: expected one of {KAPPA_X_MODES} or a number [N/m], got {kappa_x!r}")
    elif not (isinstance(kappa_x, (int, float)) and np.isfinite(kappa_x) and kappa_x >= 0):
        raise InputError(f"kappa_x: expected one of {KAPPA_X_MODES} or a number >= 0 [N/m], got {kappa_x!r}")
    worker_count(jobs)  # validates jobs
    estimate = None
    fixed = None
    if "extended" in models:
        if isinstance(kappa_x, str) and kappa_x in ("large-loop", "joint"):
            estimate, _ = estimate_kappa_x(device, kappa_x_protocol)
            fixed = estimate.value
        elif isinstance(kappa_x, str):
            estimate = KappaXEstimate(mode="per-voltage", value=float("nan"))
        else:
            fixed = float(kappa_x)
            estimate = KappaXEstimate(mode="given", value=fixed)

    own = executor is None and worker_count(jobs, v.size) > 1
    pool = make_executor(min(worker_count(jobs), v.size)) if own else executor

    def tick(idents: list) -> None:
        if progress is not None:
            for ident in idents:
                progress(f"{ident.model_name} {ident.level:.2f} V")

    try:
        per_voltage = run_tasks(_identify_at_voltage,
                                [(device, float(x), models, protocol, n_bootstrap, fixed) for x in v],
                                pool, tick)
        if kappa_x == "joint":
            j = models.index("extended")
            ext = [row[j] for row in per_voltage]
            shared = refine_shared([(i.t, i.x, i.xdot, i.force, i.cycles) for i in ext],
                                   [i.parameters for i in ext], shared="kappa_x", model="extended")
            estimate = KappaXEstimate(
                mode="joint", value=shared.value, standard_error=shared.standard_error,
                inclination=estimate.inclination, regression=estimate.regression,
                rho_stroke=estimate.rho_stroke, protocol=estimate.protocol,
                notes=estimate.notes + (f"joint refinement over {v.size} voltages from the large-loop "
                                        f"value {shared.start:.6g} N/m: {shared.nfev} evaluations, "
                                        f"{shared.message}",))
            # Re-identify each voltage with the joint kappa_x, started at the joint optimum, so
            # that every per-voltage result (closed form, uncertainty, errors) is consistent.
            again = run_tasks(_identify_at_voltage,
                              [(device, float(x), ("extended",), protocol, n_bootstrap, shared.value,
                                {"extended": prm}) for x, prm in zip(v, shared.parameters)], pool)
            for row, new in zip(per_voltage, again):
                row[j] = new[0]
    except BaseException:  # Ctrl-C or a failed task: stop the workers now, wait for nothing
        if own:
            stop_pool(pool)
        raise
    finally:
        if own and pool is not None:
            pool.shutdown()
    identifications: dict[str, list[Identification]] = {m: [row[k] for row in per_voltage]
                                                       for k, m in enumerate(models)}
    notes: list[str] = []
    laws, fitted_models = {}, {}
    for m in models:
        table = np.array([[ident.parameters[k] for k in free_parameters(m)]
                          for ident in identifications[m]])
        laws[m] = fit_voltage_laws(v, table, free_parameters(m))
        fitted_models[m] = {"seed": voltage_model(m, laws[m]["seed"], laws[m]["generic"], notes),
                            "generic": voltage_model(m, laws[m]["generic"])}
    return VoltageGridResult(v, identifications, laws, fitted_models, notes, protocol, estimate)
