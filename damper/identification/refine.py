"""Joint nonlinear least-squares refinement of all Bouc-Wen parameters, with their uncertainty.

Starting from the closed-form values, minimise over :math:`p = (\\kappa_x, \\kappa_{\\dot x},
\\kappa_w, \\rho, \\sigma, n)` (without :math:`\\kappa_x` for the normalized model)

.. math:: \\sum_{k \\in \\mathcal{W}} c_k \\left(\\hat F_k(p) - F_k\\right)^2 / F_{rms}^2,

where :math:`\\hat F(p)` is the model force simulated with :func:`damper.simulate` (the same
compiled kernels the building runs) over the whole test from rest, :math:`\\mathcal W` the
samples of the steady cycles and :math:`c_k` the multiplicity of sample :math:`k`'s cycle (1,
or a bootstrap count). The search runs on :math:`p/p_0` with the admissible class as bounds
(:math:`\\kappa > 0`, :math:`\\kappa_x \\ge 0`, :math:`\\sigma \\ge 1/2`, :math:`n \\ge 1`).

Uncertainty
-----------
* ``standard_error``: from the Jacobian at the optimum, :math:`\\mathrm{cov} = s^2 (J^T J)^{-1}`,
  :math:`s^2 = \\mathrm{RSS}/(m - p)`. It assumes independent residuals, which sampled, filtered
  signals are not: read it as a lower bound.
* ``bootstrap_std`` (``n_bootstrap > 0``): the cycles are resampled with replacement and the fit
  repeated from the optimum; the spread of the refits is the bootstrap standard deviation,
  which includes cycle-to-cycle variation and correlated noise.
* ``correlation``: parameter correlation matrix; entries near ±1 flag the near-equivalent
  parameter sets that give almost the same loop.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from damper.fitting import jacobian_covariance, least_squares_fit
from benchmark.foundation.errors import InputError, NumericalError, ParameterError
from damper.models.bouc_wen import ExtendedBoucWen, NormalizedBoucWen
from damper.identification.closed_form import MODEL_FORMS, PARAMETER_NAMES
from damper.identification.cycles import Cycle
from damper.identification.metrics import relative_rms_error
from damper.models.response import simulate

__all__ = ["RefinedFit", "refine", "SharedFit", "refine_shared", "make_model",
           "free_parameters", "fit_scaled", "CommonFit", "refine_common", "parameters_at_bounds",
           "BOUND_TOLERANCE"]

_UPPER = {"sigma": 50.0, "n": 20.0}
_LOWER = {"kappa_x": 0.0, "sigma": 0.5, "n": 1.0}


def free_parameters(model: str) -> tuple[str, ...]:
    """Names of the parameters identified for ``model`` ("normalized": no ``kappa_x``).

    Parameters
    ----------
    model : str
        ``"normalized"`` or ``"extended"``.
    """
    if model not in MODEL_FORMS:
        raise InputError(f"model: expected one of {MODEL_FORMS}, got {model!r}")
    return PARAMETER_NAMES if model == "extended" else PARAMETER_NAMES[1:]


def make_model(model: str, parameters: dict[str, float], **options):
    """The :class:`~damper.models.bouc_wen.ExtendedBoucWen` or :class:`~damper.models.bouc_wen.NormalizedBoucWen`
    with constant ``parameters`` (SI); ``options`` go to the class (e.g. ``substep_tolerance``).

    Parameters
    ----------
    model : str
        ``"normalized"`` or ``"extended"``.
    parameters : dict[str, float]
        Parameter values by name (SI).
    **options
        Further model fields (e.g. ``voltage_range``, ``substep_tolerance``).
    """
    if model == "extended":
        return ExtendedBoucWen(*(parameters[k] for k in PARAMETER_NAMES), **options)
    if model == "normalized":
        return NormalizedBoucWen(*(parameters[k] for k in PARAMETER_NAMES[1:]), **options)
    raise InputError(f"model: expected one of {MODEL_FORMS}, got {model!r}")


@dataclass(frozen=True)
class RefinedFit:
    """Result of :func:`refine`.

    Attributes
    ----------
    model_name : str
        ``"normalized"`` or ``"extended"``.
    model : NormalizedBoucWen or ExtendedBoucWen
        The fitted model (constant parameters), ready for :func:`damper.simulate`.
    parameters, start : dict
        Fitted and starting values of the six parameters (SI; ``kappa_x`` = 0 for normalized).
    standard_error : dict
        Jacobian-based standard errors (0 for fixed parameters).
    correlation : ndarray
        Correlation matrix of the free parameters (order of ``free``).
    free : tuple of str
        The parameters fitted.
    bootstrap_std : dict or None
        Standard deviation over the cycle bootstrap.
    bootstrap : ndarray or None
        The bootstrap refits, shape (n_bootstrap, len(free)).
    force : ndarray
        The fitted model's force over the whole test [N].
    rel_rms_error : float
        Relative RMS force error over the fit window.
    nfev : int
        Model simulations used by the main fit.
    success : bool
    message : str
    """

    model_name: str
    model: object = field(repr=False)
    parameters: dict
    start: dict
    standard_error: dict
    correlation: np.ndarray = field(repr=False)
    free: tuple
    bootstrap_std: dict | None
    bootstrap: np.ndarray | None = field(repr=False)
    force: np.ndarray = field(repr=False)
    rel_rms_error: float
    nfev: int
    success: bool
    message: str


class _Problem:
    """Residuals of one test for one model, on scaled parameters q = p / p0."""

    def __init__(self, model: str, t, x, xdot, force, window: np.ndarray, start: dict,
                 substep_tolerance: float, fixed: dict | None = None):
        self.model = model
        self.options = {"substep_tolerance": substep_tolerance}
        self.fixed = {k: float(v) for k, v in (fixed or {}).items()}
        self.free = tuple(k for k in free_parameters(model) if k not in self.fixed)
        self.t, self.x, self.xdot, self.force = t, x, xdot, force
        self.window = window
        scale = float(np.sqrt(np.mean(force[window] ** 2)))
        if not scale > 0:
            raise InputError("force: identically zero over the steady cycles")
        self.scale = scale
        p0 = np.array([float(start[k]) for k in self.free])
        # A zero start (kappa_x of a device without stiffness) still needs a scale.
        for j, k in enumerate(self.free):
            if p0[j] <= 0 and k == "kappa_x":
                p0[j] = 1e-3 * start["kappa_w"] / max(np.ptp(x), 1e-12)
        self.p0 = p0
        self.lower = np.array([_LOWER.get(k, 1e-9 * p) / p for k, p in zip(self.free, p0)])
        self.upper = np.array([_UPPER.get(k, math.inf) / p for k, p in zip(self.free, p0)])
        self.weights = np.ones(window.size)
        self.nsim = 0
        self._held: tuple | None = None  # (state parameters, response, its force read off)

    def parameters(self, q: np.ndarray) -> dict[str, float]:
        p = dict(zip(self.free, q * self.p0))
        p.update(self.fixed)
        p.setdefault("kappa_x", 0.0)
        return {k: float(p[k]) for k in PARAMETER_NAMES}

    def simulate(self, q: np.ndarray) -> np.ndarray:
        self.nsim += 1
        try:
            m = make_model(self.model, self.parameters(q), **self.options)
        except ParameterError:
            return np.full(self.t.size, np.nan)
        # κ_x, κ_ẋ, κ_w only read the force off w (NormalizedBoucWen.state_parameters): a point
        # that differs from the last simulated one only in them (the Jacobian's κ columns) reads
        # its force off that w history, equal to a simulation to rounding
        key = m.state_parameters().tobytes()
        if self._held is not None and self._held[0] == key:
            _, response, read = self._held
            return response.force + (m.force_history(self.x, self.xdot, response.voltage, response.states) - read)
        response = simulate(m, self.t, self.x, self.xdot, 0.0)
        self._held = (key, response, m.force_history(self.x, self.xdot, response.voltage, response.states))
        return response.force

    def residuals(self, q: np.ndarray) -> np.ndarray:
        f = self.simulate(q)
        r = (f[self.window] - self.force[self.window]) / self.scale
        if not np.all(np.isfinite(r)):
            return np.full(self.window.size, 1e3)  # pushes the trust region back
        return r * self.weights


def _usable_index(window: np.ndarray, mask, n: int) -> np.ndarray:
    """Which entries of ``window`` the mask keeps (all without a mask)."""
    if mask is None:
        return np.ones(window.size, dtype=bool)
    mask = np.asarray(mask, dtype=bool)
    if mask.shape != (n,):
        raise InputError(f"mask: expected {n} booleans, got shape {mask.shape}")
    keep = mask[window]
    if keep.sum() < 10:
        raise InputError(f"the screening leaves {int(keep.sum())} usable samples in the steady "
                         "cycles; at least 10 are needed")
    return keep


def _usable(window: np.ndarray, mask, n: int) -> np.ndarray:
    """The samples of ``window`` the mask keeps."""
    return window[_usable_index(window, mask, n)]


def _fit(problem: _Problem, q0: np.ndarray, max_nfev: int | None):
    q0 = np.clip(q0, problem.lower + 1e-12, problem.upper - 1e-12)
    return least_squares_fit(problem.residuals, q0, problem.lower, problem.upper, max_nfev=max_nfev)


def fit_scaled(problem, q0: np.ndarray, max_nfev: int | None):
    """The fitting engine of :func:`refine`, for any problem on scaled parameters.

    Bounded trust-region least squares (:func:`scipy.optimize.least_squares`, ``trf``, 2-point
    finite-difference Jacobian with relative step 1e-5, tolerances 1e-10) of
    ``problem.residuals(q)`` within ``problem.lower <= q <= problem.upper``, where ``q`` is the
    parameter vector scaled to order one. Used by :mod:`damper.hysteresis.identification` as well.

    Parameters
    ----------
    problem
        The fitting problem (residuals of scaled parameters, bounds).
    q0 : np.ndarray
        Start, scaled parameters.
    max_nfev : int | None
        Most function evaluations; None: the optimiser's default.
    """
    return _fit(problem, q0, max_nfev)


def refine(t: np.ndarray, x: np.ndarray, xdot: np.ndarray, force: np.ndarray,
           cycles: list[Cycle], start: dict[str, float], model: str = "extended",
           n_bootstrap: int = 0, seed: int = 0, max_nfev: int = 200,
           substep_tolerance: float = 0.25, fixed: dict[str, float] | None = None,
           mask: np.ndarray | None = None) -> RefinedFit:
    """Refine the parameters of ``model`` jointly by nonlinear least squares.

    Parameters
    ----------
    t, x, xdot, force : ndarray, shape (n,)
        Test histories [s, m, m/s, N] (the whole test: the model is simulated from rest).
    cycles : list of Cycle
        Steady cycles: their samples form the fit window and the bootstrap units.
    start : dict
        Starting values of the six parameters (SI), e.g. ``ClosedFormResult.parameters()``.
    model : {"extended", "normalized"}
    n_bootstrap : int
        Number of cycle-bootstrap refits (0: none).
    seed : int
        Seed of the bootstrap resampling.
    max_nfev : int
        Cap on the residual evaluations of the main fit.
    substep_tolerance : float
        Sub-step size of the model's integrator during the search (see
        :class:`~damper.models.bouc_wen.NormalizedBoucWen`). The default 0.25 is 2–3 times faster
        than the model default 0.05 and changes the force by about 2e-7 relative on the
        virtual damper's tests; the returned model and ``force`` use the model default.
    fixed : dict, optional
        Parameters held at the given values (SI) instead of fitted, e.g. ``{"kappa_x": 2.07e5}``
        for the seed paper's extended model, whose :math:`\\kappa_x` is read once and is the
        same at every voltage (eq. 5). Their standard errors are reported as 0.
    mask : ndarray of bool, optional
        Usable samples (:attr:`damper.io.data.DamperTest.mask`): the others are simulated but
        left out of the residuals and the error.

    Returns
    -------
    RefinedFit

    Raises
    ------
    InputError
        Inconsistent inputs or no steady cycle.
    NumericalError
        The least-squares search could not evaluate the model at its start.
    """
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    xdot = np.asarray(xdot, dtype=float)
    force = np.asarray(force, dtype=float)
    if not (t.shape == x.shape == xdot.shape == force.shape) or t.ndim != 1:
        raise InputError("refine: t, x, xdot and force must be 1-D arrays of equal length")
    if not cycles:
        raise InputError("refine: at least one steady cycle is needed")
    # Fit window: every sample of the steady cycles once (consecutive cycles share an end point).
    window = np.arange(cycles[0].start, cycles[-1].end + 1)
    owner = np.full(window.size, -1)
    for j, c in enumerate(cycles):
        owner[c.start - window[0]: c.end - window[0] + 1] = j
    window, owner = _usable(window, mask, t.size), owner[_usable_index(window, mask, t.size)]
    allowed = free_parameters(model)
    for k, v in (fixed or {}).items():
        if k not in allowed:
            raise InputError(f"fixed: {k!r} is not a parameter of the {model} model {allowed}")
        if not math.isfinite(float(v)):
            raise InputError(f"fixed: {k} must be finite, got {v!r}")
    problem = _Problem(model, t, x, xdot, force, window, start, substep_tolerance, fixed)
    q_start = np.ones(len(problem.free))
    r0 = problem.residuals(q_start)
    if np.all(r0 == 1e3):
        raise NumericalError(f"refine: the {model} model cannot be simulated at the starting values",
                             state=start, hint="check the closed-form start")
    sol = _fit(problem, q_start, max_nfev)
    nfev = problem.nsim
    q = sol.x
    params = problem.parameters(q)
    fitted = make_model(model, params)
    f_fit = simulate(fitted, t, x, xdot, 0.0).force

    # Jacobian-based covariance in physical units.
    cov = jacobian_covariance(sol.jac, sol.fun, problem.p0)  # r already divided by scale
    std = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(std, std)
    standard_error = {k: 0.0 for k in PARAMETER_NAMES}
    standard_error.update({k: float(s) for k, s in zip(problem.free, std)})

    boot = None
    boot_std = None
    if n_bootstrap > 0 and len(cycles) >= 2:
        rng = np.random.default_rng(seed)
        samples = []
        for _ in range(n_bootstrap):
            counts = np.bincount(rng.integers(0, len(cycles), len(cycles)), minlength=len(cycles))
            problem.weights = np.sqrt(counts[owner].astype(float))
            refit = _fit(problem, q, max_nfev=60)
            samples.append(refit.x * problem.p0)
        problem.weights = np.ones(window.size)
        boot = np.array(samples)
        boot_std = {k: 0.0 for k in PARAMETER_NAMES}
        boot_std.update({k: float(s) for k, s in zip(problem.free, boot.std(axis=0, ddof=1))})

    rel = relative_rms_error(force[window], f_fit[window])
    start_values = {k: float(start.get(k, 0.0)) for k in PARAMETER_NAMES}
    start_values.update(problem.fixed)
    return RefinedFit(model_name=model, model=fitted, parameters=params,
                      start=start_values,
                      standard_error=standard_error, correlation=corr, free=problem.free,
                      bootstrap_std=boot_std, bootstrap=boot, force=f_fit, rel_rms_error=rel,
                      nfev=nfev, success=bool(sol.success), message=str(sol.message))


@dataclass(frozen=True)
class SharedFit:
    """Result of :func:`refine_shared`.

    Attributes
    ----------
    name : str
        The shared parameter.
    value, standard_error : float
        Its joint estimate and Jacobian standard error (SI).
    start : float
        Its starting value.
    parameters : list of dict
        Per test: the six parameters at the joint optimum (the shared one included).
    rel_rms_errors : list of float
        Per test: relative RMS force error over its fit window at the optimum.
    nfev : int
        Residual evaluations (each simulates every test).
    success : bool
    message : str
    """

    name: str
    value: float
    standard_error: float
    start: float
    parameters: list
    rel_rms_errors: list
    nfev: int
    success: bool
    message: str


def refine_shared(tests: list[tuple], starts: list[dict], shared: str = "kappa_x",
                  model: str = "extended", max_nfev: int = 60,
                  substep_tolerance: float = 0.25) -> SharedFit:
    """Refine several tests jointly with one parameter shared by all of them.

    Minimises :math:`\\sum_i \\sum_{k \\in \\mathcal W_i} (\\hat F_{i,k}(s, p_i) - F_{i,k})^2 / F_{i,rms}^2`
    over the shared parameter :math:`s` (e.g. the extended model's :math:`\\kappa_x`, constant
    over voltage in the seed paper's eq. 5) and each test's other parameters :math:`p_i`; each
    test is weighted by its own force RMS, so low-voltage tests count as much as high-voltage
    ones. The Jacobian is block-sparse (test :math:`i` depends on :math:`s` and :math:`p_i`
    only), which the finite differences exploit.

    Parameters
    ----------
    tests : list of (t, x, xdot, force, cycles)
        Test histories [s, m, m/s, N] and their steady cycles.
    starts : list of dict
        Starting parameters per test (SI); the shared start is the mean of theirs.
    shared : str
        Name of the shared parameter.
    model : {"extended", "normalized"}
    max_nfev : int
        Cap on the joint residual evaluations.
    substep_tolerance : float
        As in :func:`refine`.

    Returns
    -------
    SharedFit
    """
    from scipy.sparse import lil_matrix

    if len(tests) != len(starts) or not tests:
        raise InputError("refine_shared: expected one start per test and at least one test")
    if shared not in free_parameters(model):
        raise InputError(f"refine_shared: {shared!r} is not a parameter of the {model} model")
    s0 = float(np.mean([float(st[shared]) for st in starts]))
    if not s0 > 0:
        raise InputError(f"refine_shared: the start of {shared} must be > 0, got {s0}")
    problems = []
    for (t, x, xdot, force, cycles), st in zip(tests, starts):
        window = np.arange(cycles[0].start, cycles[-1].end + 1)
        problems.append(_Problem(model, np.asarray(t, float), np.asarray(x, float),
                                 np.asarray(xdot, float), np.asarray(force, float), window, st,
                                 substep_tolerance, fixed={shared: s0}))
    sizes = [len(p.free) for p in problems]
    rows = [p.window.size for p in problems]
    n_q = 1 + sum(sizes)
    sparsity = lil_matrix((sum(rows), n_q), dtype=int)
    r0, c0 = 0, 1
    for m, k in zip(rows, sizes):
        sparsity[r0:r0 + m, 0] = 1
        sparsity[r0:r0 + m, c0:c0 + k] = 1
        r0, c0 = r0 + m, c0 + k
    lower = np.concatenate([[_LOWER.get(shared, 0.0) / s0 + 1e-9]] + [p.lower for p in problems])
    upper = np.concatenate([[_UPPER.get(shared, math.inf) / s0]] + [p.upper for p in problems])
    counter = [0]

    def split(q: np.ndarray) -> list[np.ndarray]:
        out, c = [], 1
        for k in sizes:
            out.append(q[c:c + k])
            c += k
        return out

    def residuals(q: np.ndarray) -> np.ndarray:
        counter[0] += 1
        parts = []
        for p, qi in zip(problems, split(q)):
            p.fixed[shared] = float(q[0] * s0)
            parts.append(p.residuals(qi))
        return np.concatenate(parts)

    q0 = np.clip(np.ones(n_q), lower + 1e-12, upper - 1e-12)
    sol = least_squares_fit(residuals, q0, lower, upper, jac_sparsity=sparsity, max_nfev=max_nfev)
    value = float(sol.x[0] * s0)
    jac = sol.jac.toarray() if hasattr(sol.jac, "toarray") else np.asarray(sol.jac)
    s2 = float(np.sum(sol.fun ** 2)) / max(jac.shape[0] - n_q, 1)
    try:
        cov = np.linalg.pinv(jac.T @ jac) * s2
        std = float(np.sqrt(max(cov[0, 0], 0.0))) * s0
    except np.linalg.LinAlgError:
        std = math.nan
    params, errors = [], []
    for p, qi in zip(problems, split(sol.x)):
        p.fixed[shared] = value
        params.append(p.parameters(qi))
        r = p.residuals(qi)
        errors.append(float(np.linalg.norm(r) * p.scale / np.linalg.norm(p.force[p.window])))
    return SharedFit(name=shared, value=value, standard_error=std, start=s0, parameters=params,
                     rel_rms_errors=errors, nfev=counter[0], success=bool(sol.success),
                     message=str(sol.message))


#: A parameter within this fraction of a bound (of the bound itself, or of its start for a
#: zero bound) is reported at the bound.
BOUND_TOLERANCE = 1e-3


def parameters_at_bounds(parameters: dict, start: dict, free: tuple | list,
                         tolerance: float = BOUND_TOLERANCE) -> dict[str, str]:
    """The free parameters the refinement left at (or within ``tolerance`` of) a bound.

    A parameter at a bound was not identified by the data: the fit would have moved it further
    (e.g. :math:`\\sigma` at its upper bound 50 means the transition is sharper than the model
    may express). Returns ``{name: "lower 0.5" | "upper 50" ...}``.

    Parameters
    ----------
    parameters : dict
        The fitted parameters by name (SI).
    start : dict
        The start of the refinement (the bounds of the refinement are set around it).
    free : tuple or list
        Names of the parameters that were fitted.
    tolerance : float
        Relative distance to a bound below which a parameter counts as at it.
    """
    out = {}
    for k in free:
        p = float(parameters[k])
        scale = max(abs(float(start.get(k, 0.0))), abs(p), 1e-300)
        for side, bound in (("lower", _LOWER.get(k, 0.0)), ("upper", _UPPER.get(k, math.inf))):
            if not math.isfinite(bound):
                continue
            tol = tolerance * (abs(bound) if bound != 0 else scale)
            if abs(p - bound) <= tol:
                out[k] = f"{side} {bound:g}"
    return out


@dataclass(frozen=True)
class CommonFit:
    """Result of :func:`refine_common`: one model for several tests.

    Attributes
    ----------
    model_name : str
    model : NormalizedBoucWen or ExtendedBoucWen
    parameters, start : dict
        Fitted and starting values (SI).
    standard_error : dict
        Jacobian-based standard errors (a lower bound, as in :func:`refine`).
    rel_rms_errors : list of float
        Per test: relative RMS force error over its usable steady-cycle samples.
    at_bounds : dict
        :func:`parameters_at_bounds` of the optimum.
    nfev : int
    success : bool
    message : str
    """

    model_name: str
    model: object = field(repr=False)
    parameters: dict
    start: dict
    standard_error: dict
    rel_rms_errors: list
    at_bounds: dict
    nfev: int
    success: bool
    message: str


def refine_common(tests: list[tuple], start: dict, model: str = "extended", max_nfev: int = 100,
                  substep_tolerance: float = 0.25) -> CommonFit:
    """Refine ONE parameter set over several tests (e.g. every test at one coil current).

    Minimises :math:`\\sum_i \\sum_{k \\in \\mathcal W_i} (\\hat F_{i,k}(p) - F_{i,k})^2 / F_{i,rms}^2`
    over one :math:`p` for all tests :math:`i` (the seed's method per voltage: the parameters
    are those of the device at that input, whatever the amplitude and frequency of the test);
    each test weighted by its own force RMS so that a small-stroke test counts as much as a
    large one. The same engine as :func:`refine` (:func:`damper.fitting.least_squares_fit`).

    Parameters
    ----------
    tests : list of (t, x, xdot, force, cycles, mask)
        Test histories [s, m, m/s, N], their steady cycles and usable samples (``None``: all).
    start : dict
        Starting parameters (SI).
    model : {"extended", "normalized"}
    max_nfev : int
        Cap on the joint residual evaluations (each simulates every test).
    substep_tolerance : float
        As in :func:`refine`; the returned model uses the model default.

    Returns
    -------
    CommonFit
    """
    if not tests:
        raise InputError("refine_common: expected at least one test")
    problems = []
    for t, x, xdot, force, cycles, mask in tests:
        if not cycles:
            raise InputError("refine_common: every test needs at least one steady cycle")
        t = np.asarray(t, float)
        window = _usable(np.arange(cycles[0].start, cycles[-1].end + 1), mask, t.size)
        problems.append(_Problem(model, t, np.asarray(x, float), np.asarray(xdot, float),
                                 np.asarray(force, float), window, start, substep_tolerance))
    first = problems[0]
    for p in problems[1:]:  # one scaling for all: q means the same parameters in every test
        p.p0, p.lower, p.upper = first.p0, first.lower, first.upper
    counter = [0]

    def residuals(q: np.ndarray) -> np.ndarray:
        counter[0] += 1
        return np.concatenate([p.residuals(q) for p in problems])

    q0 = np.clip(np.ones(first.p0.size), first.lower + 1e-12, first.upper - 1e-12)
    sol = least_squares_fit(residuals, q0, first.lower, first.upper, max_nfev=max_nfev)
    params = first.parameters(sol.x)
    cov = jacobian_covariance(sol.jac, sol.fun, first.p0)
    std = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    standard_error = {k: 0.0 for k in PARAMETER_NAMES}
    standard_error.update({k: float(s) for k, s in zip(first.free, std)})
    fitted = make_model(model, params)
    errors = []
    for p in problems:
        f = simulate(fitted, p.t, p.x, p.xdot, 0.0).force
        errors.append(relative_rms_error(p.force[p.window], f[p.window]))
    start_values = {k: float(start.get(k, 0.0)) for k in PARAMETER_NAMES}
    return CommonFit(model_name=model, model=fitted, parameters=params, start=start_values,
                     standard_error=standard_error, rel_rms_errors=errors,
                     at_bounds=parameters_at_bounds(params, start_values, first.free),
                     nfev=counter[0], success=bool(sol.success), message=str(sol.message))
