"""The damper model file (``model.json``): one format, one writer, one loader.

Every command that fits a damper model writes this file (``sbib identify --data``, one per model
form; ``sbib diagnose``, ``base_model.json`` and ``final_model.json``; ``sbib hysteresis fit``),
and every command that runs a damper in the building reads it (``sbib run --damper``, ``sbib
compare --damper/--dampers``, ensembles). Layout (SI throughout; units are written beside each
value and checked when read)::

    {"format": "sbib-damper-model", "format_version": 1,
     "model": "normalized_bouc_wen",                 # a name of damper.models.registry (or "hysteretic_oscillator")
     "input": {"quantity": "current", "unit": "A",   # or "voltage", "V"
               "range": [0.0, 1.0],                  # admissible input, the laws are checked over it
               "levels": [0.0, 0.25, 0.5, 0.75, 1.0]},   # input levels of the tests it was fitted on
     "parameters": {"rho": {"value": 812.0, "unit": "1/m"},
                    "kappa_w": {"law": "tabulated", "unit": "N", "inputs": [...], "values": [...]},
                    ...},                            # every field of the model class, no more, no less
     "effects": [{"name": "roll_off", "parameter": "velocity", "value": 0.0059, "unit": "m/s"}],
     "quality": {...},                               # errors, standard errors (free form, SI)
     "provenance": {"inputs": [{"path", "sha256"}], "command", "package_version", ...},
     "notes": ["..."]}

Voltage laws (:mod:`damper.models.voltage_laws`) are written as ``{"law": KIND, ...}`` with the fields
of :data:`LAW_FIELDS` (``constant``: ``value``; ``polynomial``: ``coefficients`` in ascending
powers of the input; ``exponential``: ``a, b, c``; ``seed_kappa_w``: ``k`` (9); ``tabulated``:
``inputs, values`` (PCHIP through them, held outside); ``saturating``: ``a, b, c, e``); the
law's ``unit`` is the parameter's, its variable is the input in ``input.unit``. ``effects`` are
the terms of an augmented model (:mod:`damper.diagnosis.augmented`, :mod:`damper.diagnosis.effects`) on top of the
registered base model.

:func:`read_model_file` refuses a bad file in one line (:class:`~benchmark.foundation.errors.InputError`
naming the file and the field): not JSON, another format, an unknown model or effect, a missing
or extra parameter, a wrong unit, a malformed law, or a parameter (law) that leaves its
admissible class over the input range, a law node outside the input range.
:func:`write_model_file` writes atomically.

In the building (:meth:`ModelFile.building_model`, which is
:meth:`damper.diagnosis.augmented.AugmentedModel.building_model`) the effects that a registered kernel
carries are folded into the model (``stiffness`` into κ_x, ``roll_off`` into the series dashpot of
:class:`~damper.models.series_dashpot.SeriesDashpotBoucWen`, ``voltage_lag`` into its field lag when
there is a roll-off, the memoryless terms into :class:`~damper.models.force_terms.WithForceTerms`);
the others are listed as not run, with their values and why.
:meth:`ModelFile.scaled` applies a force similitude (every parameter whose unit is a force
unit, N..., and every effect in N or kg, times the factor; displacements, velocities and times
unchanged).
"""

from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from benchmark.foundation.atomic import atomic_write_text
from benchmark.foundation.errors import DataNotFoundError, InputError, NumericalError, ParameterError
from benchmark.foundation.provenance import provenance as base_provenance, sha256_of
from benchmark.foundation.textfile import read_text
from damper.diagnosis.augmented import BASE_MODELS, AugmentedModel
from damper.models.base import DamperModel
from damper.diagnosis.effects import EFFECTS, Effect
from damper.hysteresis.oscillator import PARAMETER_UNITS as OSCILLATOR_UNITS
from damper.hysteresis.oscillator import HystereticOscillator
from damper.models.force_terms import WithForceTerms
from damper.models.registry import MODELS, get_model_class
from damper.models.series_dashpot import scaled_law
from damper.models.response import simulate
from damper.models.voltage_laws import (Constant, Exponential, Polynomial, Saturating, SeedKappaW, Tabulated,
                                 VoltageLaw)

__all__ = ["FORMAT", "FORMAT_VERSION", "ModelFile", "InputSpec", "read_model_file", "write_model_file",
           "parameter_unit", "file_provenance", "OSCILLATOR_MODEL", "LAW_FIELDS", "looks_like_model_file",
           "capacity_force", "dropped_share", "command_ends", "CONSTANT_EFFECTS", "CAPACITY_TEST", "SWITCHINGS_PER_CYCLE", "as_range", "load_json"]

FORMAT = "sbib-damper-model"
FORMAT_VERSION = 1
#: The force-driven hysteretic oscillator of ``sbib hysteresis`` (not a device of the building).
OSCILLATOR_MODEL = "hysteretic_oscillator"
#: Input quantities and their units.
INPUT_UNITS = {"voltage": "V", "current": "A"}
#: Fields of each law kind in the file.
LAW_FIELDS = {"constant": ("value",), "polynomial": ("coefficients",), "exponential": ("a", "b", "c"),
              "seed_kappa_w": ("k",), "tabulated": ("inputs", "values"), "saturating": ("a", "b", "c", "e")}
#: The motion at which a model's capacity is its peak force (``--damper-scale 1000kN``): a sine of
#: 0.1 m amplitude at 0.5 Hz (peak velocity 0.31 m/s, a typical base motion of the building),
#: at the largest input, three cycles, peak over the last.
CAPACITY_TEST = {"amplitude_m": 0.1, "frequency_hz": 0.5, "cycles": 3}

_KEYS = {"format", "format_version", "model", "input", "parameters", "effects", "quality", "provenance",
         "notes"}
_REQUIRED = ("format", "model", "input", "parameters")
_COMMON_UNITS = {"kappa_x": "N/m", "kappa_xdot": "N*s/m", "kappa_w": "N", "rho": "1/m", "sigma": "1",
                 "n": "1", "roll_off_velocity": "m/s", "field_lag": "s", "substep_tolerance": "1",
                 # the Spencer-type base of the residual loop (spencer_bouc_wen): its spring in series
                 # with the Bouc-Wen element and its series dashpot
                 "k0": "N/m", "c1": "N*s/m"}
#: The unit written for a parameter without one in these tables (a user's registered model, or
#: a parameter earlier versions had no unit for); read back as SI.
_UNKNOWN_UNIT = "SI"
# units by model; "{u}" is the input unit (coefficients per volt or per ampere)
_MODEL_UNITS = {
    "spencer": {"alpha_a": "N/m", "alpha_b": "N/(m*{u})", "c0a": "N*s/m", "c0b": "N*s/(m*{u})", "k0": "N/m",
                "c1a": "N*s/m", "c1b": "N*s/(m*{u})", "k1": "N/m", "x0": "m", "gamma": "1/m^n",
                "beta": "1/m^n", "A": "1", "n": "1", "eta": "1/s", "substep_tolerance": "1"},
    "virtual": {"yield_force": "N", "c0": "N*s/m", "c1": "N*s/m", "k0": "N/m", "k1": "N/m", "x0": "m",
                "rho": "1/m", "sigma": "1", "n": "1", "eta": "1/s", "substep_tolerance": "1"},
    "bingham": {"f_c": "N", "c0": "N*s/m", "f0": "N"},
    "hyperbolic_tangent": {"c": "N*s/m", "k": "N/m", "alpha": "N", "beta": "s/m", "delta": "1", "f0": "N"},
    # written as its inner model plus effects (write_model_file); the inner model has its own table
    "with_force_terms": {"inner": "model", "asymmetry": "1", "stiffness": "N/m",
                         "shear_thinning": "N*(s/m)^0.5", "quadratic_damping": "N*s^2/m^2"},
    OSCILLATOR_MODEL: dict(OSCILLATOR_UNITS),
}


def _norm_unit(unit: str) -> str:
    """Spelling-insensitive unit: ``N·s/m``, ``N s/m`` and ``N*s/m`` compare equal; ``-`` is ``1``."""
    u = str(unit).strip().replace("·", "*").replace(" ", "*").replace("²", "^2").replace("³", "^3")
    return "1" if u in ("", "-") else u


def as_range(values) -> tuple[float, float]:
    """``(min, max)`` as floats.

    Parameters
    ----------
    values : sequence of float
        At least two numbers, ``(min, max)``, e.g. an input range (V or A); further items are ignored.

    Returns
    -------
    tuple of float
        ``(float(values[0]), float(values[1]))``.
    """
    return float(values[0]), float(values[1])


def parameter_unit(model: str, name: str, input_unit: str = "V") -> str | None:
    """The SI unit of parameter ``name`` of registered model ``model`` (``None`` when unknown).

    Parameters
    ----------
    model : str
        Registered model name (:mod:`damper.models.registry`) or ``"hysteretic_oscillator"``;
        a model without a unit table of its own uses the Bouc-Wen units.
    name : str
        Parameter (dataclass field) name, e.g. ``"kappa_w"``.
    input_unit : str, optional
        Unit of the model's input (``"V"`` or ``"A"``), substituted in the units of the
        coefficients per unit input (``N/(m*V)``).

    Returns
    -------
    str or None
        The unit as written in the file (``"N*s/m"``), or ``None`` when the parameter is unknown.
    """
    table = _MODEL_UNITS.get(model, _COMMON_UNITS)
    unit = table.get(name, _COMMON_UNITS.get(name) if model not in _MODEL_UNITS else None)
    return None if unit is None else unit.replace("{u}", input_unit)


@dataclass(frozen=True)
class InputSpec:
    """The model's input: ``quantity`` (``voltage`` or ``current``), ``unit`` (V or A), admissible
    ``range`` and the ``levels`` of the tests it was fitted on.

    Parameters
    ----------
    quantity : str
        ``"voltage"`` or ``"current"`` (``"force"`` for the hysteretic oscillator).
    unit : str
        Unit of the input: ``"V"`` for a voltage, ``"A"`` for a current (``"N"`` for a force).
    range : tuple of float
        Admissible input ``(min, max)`` in ``unit``; the laws are checked over it.
    levels : tuple of float
        Input levels (in ``unit``) of the tests the model was fitted on; empty when unknown.
    """

    quantity: str = "voltage"
    unit: str = "V"
    range: tuple[float, float] = (0.0, 1.0)
    levels: tuple[float, ...] = ()

    @property
    def single_level(self) -> bool:
        """Fitted at one input level: its force does not depend on a command."""
        return len(self.levels) == 1

    def to_json(self) -> dict:
        """The ``input`` object of the model file: quantity, unit, range and levels (floats)."""
        return {"quantity": self.quantity, "unit": self.unit, "range": [float(v) for v in self.range],
                "levels": [float(v) for v in self.levels]}


@dataclass(frozen=True)
class ModelFile:
    """A damper model as the file carries it.

    Attributes
    ----------
    model : DamperModel or HystereticOscillator
        The registered base model (voltage laws included).
    input : InputSpec
    effects : tuple of Effect
        Terms of an augmented model on top of ``model`` (empty for a plain model).
    quality, provenance : dict
    notes : tuple of str
    path : str
        Where it was read from (empty when built in memory).
    scale : float
        Force similitude applied by :meth:`scaled` (1: the device as fitted).
    """

    model: Any
    input: InputSpec = InputSpec()
    effects: tuple = ()
    quality: dict = field(default_factory=dict)
    provenance: dict = field(default_factory=dict)
    notes: tuple = ()
    path: str = ""
    scale: float = 1.0

    @property
    def model_name(self) -> str:
        return OSCILLATOR_MODEL if isinstance(self.model, HystereticOscillator) else str(self.model.name)

    @property
    def label(self) -> str:
        """The file's name (or the model's name when built in memory)."""
        return Path(self.path).name if self.path else self.model_name

    def augmented(self, constant: bool = True) -> AugmentedModel:
        """The model with its effects as an :class:`~damper.diagnosis.augmented.AugmentedModel`.

        The bases are those of :data:`damper.diagnosis.augmented.BASE_MODELS` (normalized, extended
        and Spencer-type Bouc-Wen), the bases ``sbib diagnose --model`` fits.

        Parameters
        ----------
        constant : bool, optional
            Keep the effects of :data:`CONSTANT_EFFECTS` (a constant force); False: the device's
            force as a building carries it (its damper installed at rest).
        """
        if type(self.model) not in BASE_MODELS.values():
            raise InputError(f"{self.label}: effects compose with a {_base_names()} base, "
                             f"not {self.model_name}")
        return AugmentedModel(self.model, tuple(e for e in self.effects
                                                if constant or e.name not in CONSTANT_EFFECTS))

    def building_model(self) -> tuple[DamperModel, list[str]]:
        """The registered model the building runs, and the effects it cannot run (one line each).

        :meth:`damper.diagnosis.augmented.AugmentedModel.building_model` of the model with its effects
        (κ_x, the series dashpot, force terms; what cannot run is listed with the reason).

        Raises
        ------
        InputError
            For the hysteretic oscillator (a force-driven system, not a device model).
        """
        where = self.path or self.model_name
        if isinstance(self.model, HystereticOscillator):
            raise InputError(f"{where}: model {OSCILLATOR_MODEL} is a force-driven oscillator (sbib hysteresis), "
                             "not a device model the building can run; give a model of damper.models.registry")
        if not self.effects:
            return self.model, []
        try:
            return AugmentedModel(self.model, self.effects).building_model()
        except (InputError, ParameterError) as exc:  # name the file: the building's model is built from it
            raise InputError(f"{where}: its model in the building: {exc}") from None

    def scaled(self, factor: float) -> "ModelFile":
        """The model under force similitude ``factor`` (module docstring); ``scale`` multiplies.

        Parameters
        ----------
        factor : float
            Force similitude factor (finite, > 0): every force parameter (unit N...) and every
            effect in N or kg is multiplied by it; displacements, velocities and times unchanged.

        Returns
        -------
        ModelFile
            A new model file (``self`` when ``factor`` is 1).

        Raises
        ------
        InputError
            ``factor`` is not finite or not positive.
        """
        factor = float(factor)
        if not (math.isfinite(factor) and factor > 0):
            raise InputError(f"damper scale: expected a finite factor > 0, got {factor!r}")
        if factor == 1.0:
            return self
        name = self.model_name
        changes = {}
        for f in dataclasses.fields(self.model):
            if f.name == "voltage_range":
                continue
            unit = parameter_unit(name, f.name, self.input.unit)
            if unit is None:  # scaling it or not would be a guess: a force parameter left unscaled breaks the model
                raise InputError(f"damper scale: parameter {f.name} of {name} has no known unit, so the force "
                                 "similitude cannot tell whether to scale it (damper.io.model_file units)")
            if unit.startswith("N"):
                value = getattr(self.model, f.name)
                changes[f.name] = scaled_law(value, factor) if isinstance(value, VoltageLaw) else value * factor
        model = dataclasses.replace(self.model, **changes)
        effects = tuple(type(e)(e.value * factor) if (e.unit.startswith("N") or e.unit == "kg") else e
                        for e in self.effects)
        return dataclasses.replace(self, model=model, effects=effects, scale=self.scale * factor)

    def describe(self) -> dict:
        """What results record about the model: file, name, input, scale, effects."""
        return {"file": self.label, "path": self.path, "model": self.model_name, "input": self.input.to_json(),
                "scale": self.scale, "effects": [_effect_json(e) for e in self.effects]}


# ------------------------------------------------------------------------------------ writing

def _law_json(law: VoltageLaw) -> dict:
    if isinstance(law, Constant):
        return {"law": "constant", "value": law.value}
    if isinstance(law, Polynomial):
        return {"law": "polynomial", "coefficients": list(law.coefficients)}
    if isinstance(law, Exponential):
        return {"law": "exponential", "a": law.a, "b": law.b, "c": law.c}
    if isinstance(law, SeedKappaW):
        return {"law": "seed_kappa_w", "k": list(law.k)}
    if isinstance(law, Tabulated):
        return {"law": "tabulated", "inputs": list(law.voltages), "values": list(law.values)}
    if isinstance(law, Saturating):
        return {"law": "saturating", "a": law.a, "b": law.b, "c": law.c, "e": law.e}
    raise InputError(f"model file: cannot write a {type(law).__name__} law")


def _effect_json(e: Effect) -> dict:
    return {"name": e.name, "parameter": e.parameter_name, "value": e.value, "unit": e.unit}


def _jsonable(x):
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, (np.floating, np.integer, np.bool_)):
        return x.item()
    if isinstance(x, (tuple, set)):
        return list(x)
    if isinstance(x, Path):
        return str(x)
    raise TypeError(f"not JSON serializable: {type(x).__name__}")


def _no_nan(x):
    """``x`` with every non-finite number in it as ``None`` (JSON's null): a statistic that could
    not be estimated (a standard error from one bootstrap refit, a held-out error with no other
    test at the level) is unknown, not a number."""
    if isinstance(x, dict):
        return {k: _no_nan(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_no_nan(v) for v in x]
    if isinstance(x, np.ndarray):
        return _no_nan(x.tolist())
    if isinstance(x, (float, np.floating)) and not math.isfinite(float(x)):
        return None
    return x


def file_provenance(inputs: Sequence = (), command: str | None = None, **extra) -> dict:
    """Provenance of a model file: input files with their SHA-256, the command line (default:
    the CLI's arguments), package version, commit, time, library versions, ``extra``.

    Parameters
    ----------
    inputs : sequence of path-like, optional
        Data files the model was fitted on; each is recorded with its SHA-256 (``None`` when the
        file does not exist).
    command : str, optional
        Command line to record; default the one :func:`benchmark.foundation.provenance.provenance`
        records (``sbib`` and its arguments).
    **extra
        Further entries passed to :func:`benchmark.foundation.provenance.provenance` (e.g.
        ``kind="sbib diagnose"``).

    Returns
    -------
    dict
        JSON-ready provenance.
    """
    files = []
    for p in inputs:
        p = Path(p)
        files.append({"path": str(p), "sha256": sha256_of(p) if p.is_file() else None})
    out: dict[str, Any] = dict(base_provenance(**extra))
    out["inputs"] = files
    if command is not None:  # else provenance()'s: the CLI's arguments, or this process's
        out["command"] = command
    return out


def write_model_file(path, model, *, input: InputSpec | None = None, effects: Sequence[Effect] = (),
                     quality: dict | None = None, provenance: dict | None = None,
                     notes: Sequence[str] = (), extra: dict | None = None) -> Path:
    """Write ``model`` (a registered damper model, an :class:`~damper.diagnosis.augmented.AugmentedModel` or
    the hysteretic oscillator) as a model file, atomically; return the path.

    Parameters
    ----------
    path : path-like
    model : DamperModel, AugmentedModel or HystereticOscillator
        An augmented model is written as its base model plus ``effects``.
    input : InputSpec, optional
        Default: voltage over the model's ``voltage_range`` (a current for ``unit="A"``).
    effects : sequence of Effect
        Terms on top of ``model`` (added to an augmented model's own).
    quality, provenance : dict, optional
        Errors and standard errors; :func:`file_provenance` by default.
    notes : sequence of str
    extra : dict, optional
        More entries of ``quality`` (the hysteretic oscillator's integration settings).
    """
    effects = tuple(effects)
    if isinstance(model, AugmentedModel):
        effects = tuple(model.effects) + effects
        model = model.base
    if isinstance(model, WithForceTerms):  # its terms are effects of the file (what building_model reads)
        effects = tuple(EFFECTS[name](value) for name, value in model.terms.items()) + effects
        model = model.inner
    if isinstance(model, HystereticOscillator):
        name = OSCILLATOR_MODEL
        params = {k: {"value": float(v), "unit": OSCILLATOR_UNITS[k]} for k, v in model.parameters().items()}
        spec = input or InputSpec("force", "N", (-math.inf, math.inf), ())
    else:
        if not isinstance(model, DamperModel) or MODELS.get(getattr(model, "name", "")) is not type(model):
            raise InputError(f"model file: {type(model).__name__} is not a registered damper model")
        name = model.name
        spec = input or InputSpec("voltage", "V", as_range(model.voltage_range), ())
        params = {}
        for f in dataclasses.fields(model):  # type: ignore[arg-type]  # every registered model is a dataclass
            if f.name == "voltage_range":
                continue
            value = getattr(model, f.name)
            unit = parameter_unit(name, f.name, spec.unit) or _UNKNOWN_UNIT
            entry = _law_json(value) if isinstance(value, VoltageLaw) else {"value": float(value)}
            params[f.name] = {**entry, "unit": unit}
    doc: dict[str, Any] = {"format": FORMAT, "format_version": FORMAT_VERSION, "model": name,
           "input": {**spec.to_json(), "range": [None if not math.isfinite(v) else float(v) for v in spec.range]},
           "parameters": params, "effects": [_effect_json(e) for e in effects],
           "quality": dict(quality or {}), "provenance": dict(provenance or file_provenance()),
           "notes": list(notes)}
    if extra:
        doc["quality"].update(extra)
    doc["quality"] = _no_nan(doc["quality"])
    path = Path(path)
    return atomic_write_text(path, json.dumps(doc, indent=2, default=_jsonable, allow_nan=False) + "\n")


# ------------------------------------------------------------------------------------ reading

def looks_like_model_file(text: str) -> bool:
    """``text`` names a JSON file (rather than a registered model name).

    Parameters
    ----------
    text : str
        A ``--damper`` value: a path (ends in ``.json`` or contains a path separator) or a
        registered model's name.
    """
    return str(text).lower().endswith(".json") or "/" in str(text) or "\\" in str(text)


def _number(value, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"{where}: expected a number, got {value!r}")
    if not math.isfinite(float(value)):
        raise InputError(f"{where}: expected a finite number, got {value!r}")
    return float(value)


def _numbers(value, where: str, length: int | None = None) -> list[float]:
    if not isinstance(value, list) or not value:
        raise InputError(f"{where}: expected a list of numbers, got {value!r}")
    if length is not None and len(value) != length:
        raise InputError(f"{where}: expected {length} numbers, got {len(value)}")
    return [_number(v, f"{where}[{i}]") for i, v in enumerate(value)]


def _read_input(doc: dict, where: str) -> InputSpec:
    raw = doc.get("input")
    if not isinstance(raw, dict):
        raise InputError(f"{where}: input: expected an object with quantity, unit, range, levels")
    unknown = set(raw) - {"quantity", "unit", "range", "levels"}
    if unknown:
        raise InputError(f"{where}: input: unknown field(s) {', '.join(sorted(unknown))}; expected quantity, "
                         "unit, range, levels")
    quantity = raw.get("quantity", "voltage")
    if not isinstance(quantity, str) or quantity not in INPUT_UNITS:
        raise InputError(f"{where}: input.quantity: expected voltage or current, got {quantity!r}")
    unit = raw.get("unit", INPUT_UNITS[quantity])
    if unit != INPUT_UNITS[quantity]:
        raise InputError(f"{where}: input.unit: expected {INPUT_UNITS[quantity]} for a {quantity}, got {unit!r}")
    lo, hi = _numbers(raw.get("range", [0.0, 1.0]), f"{where}: input.range", 2)
    if not lo < hi:
        raise InputError(f"{where}: input.range: expected min < max, got [{lo:g}, {hi:g}] {unit}")
    levels = tuple(_numbers(raw["levels"], f"{where}: input.levels")) if raw.get("levels") else ()
    for v in levels:
        if not lo - 1e-9 <= v <= hi + 1e-9:
            raise InputError(f"{where}: input.levels: {v:g} {unit} is outside the input range "
                             f"[{lo:g}, {hi:g}] {unit}")
    return InputSpec(quantity, unit, (lo, hi), levels)


def _read_law(entry: dict, where: str, spec: InputSpec) -> VoltageLaw:
    kind = entry.get("law")
    if not isinstance(kind, str) or kind not in LAW_FIELDS:
        raise InputError(f"{where}: law: expected one of {', '.join(LAW_FIELDS)}, got {kind!r}")
    expected = set(LAW_FIELDS[kind]) | {"law", "unit"}
    unknown = set(entry) - expected
    missing = [k for k in LAW_FIELDS[kind] if k not in entry]
    if unknown or missing:
        raise InputError(f"{where}: a {kind} law has fields {', '.join(LAW_FIELDS[kind])}"
                         + (f"; missing {', '.join(missing)}" if missing else "")
                         + (f"; extra {', '.join(sorted(unknown))}" if unknown else ""))
    try:
        return _build_law(kind, entry, where, spec)
    except InputError as exc:
        if str(exc).startswith(where):
            raise
        # the law's own check (e.g. nodes not increasing) knows neither the file nor the field
        raise InputError(f"{where}: {exc}") from None


def _build_law(kind: str, entry: dict, where: str, spec: InputSpec) -> VoltageLaw:
    if kind == "constant":
        return Constant(_number(entry["value"], f"{where}.value"))
    if kind == "polynomial":
        return Polynomial(tuple(_numbers(entry["coefficients"], f"{where}.coefficients")))
    if kind == "seed_kappa_w":
        return SeedKappaW(tuple(_numbers(entry["k"], f"{where}.k", 9)))
    if kind == "tabulated":
        inputs = _numbers(entry["inputs"], f"{where}.inputs")
        values = _numbers(entry["values"], f"{where}.values", len(inputs))
        lo, hi = spec.range
        for v in inputs:
            if not lo - 1e-9 <= v <= hi + 1e-9:
                raise InputError(f"{where}: law node at {v:g} {spec.unit} is outside the input range "
                                 f"[{lo:g}, {hi:g}] {spec.unit}")
        return Tabulated(tuple(inputs), tuple(values))
    args = [_number(entry[k], f"{where}.{k}") for k in LAW_FIELDS[kind]]
    return Exponential(*args) if kind == "exponential" else Saturating(*args)


def _read_parameters(doc: dict, where: str, name: str, cls, spec: InputSpec) -> dict:
    raw = doc.get("parameters")
    if not isinstance(raw, dict):
        raise InputError(f"{where}: parameters: expected an object of name: {{value, unit}}")
    if cls is HystereticOscillator:
        expected = list(OSCILLATOR_UNITS)
        required = [k for k in expected if k != "branch"]
    else:
        fields = [f for f in dataclasses.fields(cls) if f.name != "voltage_range"]
        expected = [f.name for f in fields]
        required = [f.name for f in fields if f.default is dataclasses.MISSING
                    and f.default_factory is dataclasses.MISSING]
    missing = [k for k in required if k not in raw]
    extra = [k for k in raw if k not in expected]
    if missing:
        raise InputError(f"{where}: parameters: missing {', '.join(missing)} for model {name} "
                         f"(expected {', '.join(expected)})")
    if extra:
        raise InputError(f"{where}: parameters: {', '.join(extra)} not a parameter of model {name} "
                         f"(expected {', '.join(expected)})")
    out: dict[str, Any] = {}
    for key, entry in raw.items():
        at = f"{where}: parameters.{key}"
        if isinstance(entry, (int, float)) and not isinstance(entry, bool):
            raise InputError(f"{at}: expected {{\"value\": ..., \"unit\": ...}} (units are required), got {entry!r}")
        if not isinstance(entry, dict):
            raise InputError(f"{at}: expected {{\"value\": ..., \"unit\": ...}} or a law, got {entry!r}")
        unit = parameter_unit(name, key, spec.unit)
        if "unit" not in entry:
            raise InputError(f"{at}: unit missing" + (f"; expected {unit}" if unit else ""))
        if unit is not None and _norm_unit(entry["unit"]) not in (_norm_unit(unit), _UNKNOWN_UNIT):
            raise InputError(f"{at}: unit {entry['unit']!r}; expected {unit} (SI)")
        if "law" in entry:
            if cls is HystereticOscillator:
                raise InputError(f"{at}: the hysteretic oscillator has no input laws; give a value")
            out[key] = _read_law(entry, at, spec)
        else:
            if set(entry) - {"value", "unit"} or "value" not in entry:
                raise InputError(f"{at}: expected the fields value and unit (or law, unit and the law's fields)")
            out[key] = _number(entry["value"], at)
    return out


def _read_effects(doc: dict, where: str) -> tuple:
    raw = doc.get("effects", [])
    if not isinstance(raw, list):
        raise InputError(f"{where}: effects: expected a list of {{name, parameter, value, unit}}")
    effects = []
    for i, entry in enumerate(raw):
        at = f"{where}: effects[{i}]"
        if not isinstance(entry, dict) or "name" not in entry or "value" not in entry:
            raise InputError(f"{at}: expected {{name, parameter, value, unit}}, got {entry!r}")
        cls = EFFECTS.get(entry["name"]) if isinstance(entry["name"], str) else None
        if cls is None:
            raise InputError(f"{at}: unknown effect {entry['name']!r}; expected one of {', '.join(EFFECTS)}")
        extra = set(entry) - {"name", "parameter", "value", "unit"}
        if extra:
            raise InputError(f"{at}: unknown field(s) {', '.join(sorted(extra))}")
        if entry.get("parameter", cls.parameter_name) != cls.parameter_name:
            raise InputError(f"{at}: {cls.name} has parameter {cls.parameter_name}, got {entry['parameter']!r}")
        if "unit" not in entry:
            raise InputError(f"{at}: unit missing; expected {cls.unit}")
        if _norm_unit(entry["unit"]) != _norm_unit(cls.unit):
            raise InputError(f"{at}: unit {entry['unit']!r}; expected {cls.unit} (SI)")
        value = _number(entry["value"], f"{at}.value")
        try:
            effects.append(cls(value))  # type: ignore[call-arg]
        except InputError as exc:
            raise InputError(f"{at}: {exc}") from None
    return tuple(effects)


def load_json(path, what: str = "JSON file") -> Any:
    """The JSON document in ``path``, or one :class:`InputError` line naming the file.

    Parameters
    ----------
    path : path-like
        The file: UTF-8 text (a byte-order mark is dropped; :mod:`benchmark.foundation.textfile`).
    what : str
        What the file is, for the messages (``"damper model file"``).

    Raises
    ------
    DataNotFoundError
        The file does not exist.
    InputError
        Not a regular file, not UTF-8 text, not JSON (with the line and column), or nested too
        deeply for the parser.
    """
    text = read_text(path, what)
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"{path}:{exc.lineno}: not a JSON file ({exc.__class__.__name__}: {exc})") from None
    except RecursionError:  # thousands of nested brackets: no file this project writes
        raise InputError(f"{path}: not a {what}: JSON nested too deeply to read") from None


def read_model_file(path) -> ModelFile:
    """Read a model file (module docstring); every problem is one :class:`InputError` line.

    Parameters
    ----------
    path : path-like
        The model file (``model.json``); the hysteretic oscillator's earlier
        ``{"kind": "hysteretic_oscillator", ...}`` layout is read too.

    Returns
    -------
    ModelFile
        The model with its input, effects, quality, provenance and notes (SI).

    Raises
    ------
    DataNotFoundError
        The file does not exist.
    InputError
        Anything else wrong with it (the message names the file and the field).
    """
    path = Path(path)
    where = str(path)
    if not path.exists():
        raise DataNotFoundError(f"{where}: damper model file not found")
    doc = load_json(path, "damper model file")
    if not isinstance(doc, dict):
        raise InputError(f"{where}: expected a JSON object with format {FORMAT!r}")
    if doc.get("format") != FORMAT:
        if doc.get("kind") == OSCILLATOR_MODEL:
            return _read_legacy_oscillator(doc, where)
        raise InputError(f"{where}: format: expected {FORMAT!r}, got {doc.get('format')!r}")
    version = doc.get("format_version", FORMAT_VERSION)
    if version != FORMAT_VERSION:
        raise InputError(f"{where}: format_version: expected {FORMAT_VERSION}, got {version!r}")
    missing = [k for k in _REQUIRED if k not in doc]
    if missing:
        raise InputError(f"{where}: missing field(s) {', '.join(missing)}")
    extra = set(doc) - _KEYS
    if extra:
        raise InputError(f"{where}: unknown field(s) {', '.join(sorted(extra))}; expected "
                         + ", ".join(sorted(_KEYS)))
    name = doc["model"]
    if not isinstance(name, str):  # a list or an object is not a name (and not hashable)
        raise InputError(f"{where}: model: expected a model name (one of {', '.join(sorted(MODELS))} or "
                         f"{OSCILLATOR_MODEL}), got {name!r}")
    for key, kind in (("quality", dict), ("provenance", dict), ("notes", list)):
        if doc.get(key) is not None and not isinstance(doc[key], kind):
            raise InputError(f"{where}: {key}: expected {'an object' if kind is dict else 'a list of notes'}, "
                             f"got {doc[key]!r}")
    if name == OSCILLATOR_MODEL:
        cls: Any = HystereticOscillator
        spec = InputSpec("force", "N", (-math.inf, math.inf), ())
    else:
        if name not in MODELS:
            raise InputError(f"{where}: model: unknown model {name!r}; expected one of {', '.join(sorted(MODELS))}"
                             f" or {OSCILLATOR_MODEL}")
        cls = get_model_class(name)
        spec = _read_input(doc, where)
    params = _read_parameters(doc, where, name, cls, spec)
    effects = _read_effects(doc, where)
    try:
        if cls is HystereticOscillator:
            model = HystereticOscillator(**params)
        else:
            model = cls(**params, voltage_range=spec.range)
    except InputError as exc:  # ParameterError: a value or a law outside its class over the range
        raise InputError(f"{where}: {exc} (over the input range [{spec.range[0]:g}, {spec.range[1]:g}] "
                         f"{spec.unit})") from None
    except TypeError as exc:
        raise InputError(f"{where}: parameters do not fit model {name}: {exc}") from None
    if effects and type(model) not in BASE_MODELS.values():
        raise InputError(f"{where}: effects need a {_base_names()} model, not {name}")
    out = ModelFile(model=model, input=spec, effects=effects,
                    quality=doc.get("quality") or {}, provenance=doc.get("provenance") or {},
                    notes=tuple(str(n) for n in doc.get("notes") or ()), path=str(path))
    if effects:
        try:
            out.augmented()
        except InputError as exc:
            raise InputError(f"{where}: effects: {exc}") from None
    return out


def _base_names() -> str:
    """The model names effects compose with, for messages ("a or b or c")."""
    return " or ".join(str(cls.name) for cls in BASE_MODELS.values())


def _read_legacy_oscillator(doc: dict, where: str) -> ModelFile:
    """The hysteretic oscillator's file of before the common format (``{"kind", "parameters", ...}``)."""
    params = doc.get("parameters")
    if not isinstance(params, dict) or sorted(params) != sorted(OSCILLATOR_UNITS):
        raise InputError(f"{where}: parameters: expected {', '.join(OSCILLATOR_UNITS)}")
    try:
        model = HystereticOscillator(**params)
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None
    quality = {k: v for k, v in doc.items() if k not in ("kind", "parameters")}
    return ModelFile(model=model, input=InputSpec("force", "N", (-math.inf, math.inf), ()), quality=quality,
                     path=where)


#: Effects that are a constant force: the building never runs them and they are no part of the
#: device's force there (a damper is installed at rest), so neither its capacity nor the share of
#: its force the building leaves out counts them (:mod:`benchmark.applications.damper_choice`).
CONSTANT_EFFECTS = ("offset",)


#: Switchings of the command per cycle of the capacity test in :func:`dropped_share`'s second
#: measure (a bang-bang controller's few hertz against the test's 0.5 Hz).
SWITCHINGS_PER_CYCLE = 8


def command_ends(voltage_range: Sequence[float]) -> tuple[float, float]:
    """The lowest and highest input a building's controller commands for a model of this input
    range: ``[max(lo, 0), hi]`` (controllers command ``u`` in ``[0, hi]``,
    :mod:`benchmark.applications.damper_choice`). A range fitted to a rig's command that went
    negative (the Dyke recording's -0.44 V) is not driven there in the building.

    Parameters
    ----------
    voltage_range : sequence of two floats
        The model's input range ``(lo, hi)`` [V] or [A].
    """
    lo, hi = (float(v) for v in voltage_range)
    return max(lo, 0.0), hi


def _capacity_cycle(model, test: dict | None = None, switching: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Force [N] of ``model`` (registered or augmented) over the last cycle of the capacity test,
    at the top input, or with ``switching`` under a command that switches between the ends of
    the commands a controller gives (:func:`command_ends`) :data:`SWITCHINGS_PER_CYCLE` times a cycle."""
    test = dict(CAPACITY_TEST if test is None else test)
    f, a, cycles = test["frequency_hz"], test["amplitude_m"], test["cycles"]
    t = np.linspace(0.0, cycles / f, int(cycles * 400) + 1)
    w = 2 * np.pi * f
    x, xd, xdd = a * np.sin(w * t), w * a * np.cos(w * t), -w * w * a * np.sin(w * t)
    lo, top = command_ends(model.base.voltage_range if isinstance(model, AugmentedModel) else model.voltage_range)
    v = np.where(np.sin(0.5 * SWITCHINGS_PER_CYCLE * w * t) >= 0.0, top, lo) if switching else top
    force = (model.simulate(t, x, xd, xdd, v).force if isinstance(model, AugmentedModel)
             else simulate(model, t, x, xd, v).force)
    last = t >= (cycles - 1) / f
    return t[last], force[last]


def dropped_share(full, building) -> float:
    """RMS of the force the building model lacks, over the full model's RMS force, on the last
    cycle of :data:`CAPACITY_TEST`: how much of the fitted device the effects without a building
    kernel carry (:meth:`ModelFile.building_model`). The larger of two measures: at the top input,
    and under a command switching between the input range's ends (an effect of the command's
    dynamics, a field lag, carries nothing at a constant input; a probe's dropped 30-ms lag had
    read '0 %' while it moved J6 by a fifth under clipped-optimal control).

    Parameters
    ----------
    full : AugmentedModel or DamperModel
        The model as fitted (:meth:`ModelFile.augmented`).
    building : DamperModel
        The model the building runs.
    """
    shares = []
    for switching in (False, True):
        try:
            _, f_full = _capacity_cycle(full, switching=switching)
            _, f_run = _capacity_cycle(building, switching=switching)
        except NumericalError:
            # a measure, not the run: a model failing on this cycle must not stop the building
            # (the run itself reports a failure at its own motion); the other measure stands
            continue
        den = float(np.sqrt(np.mean(f_full ** 2)))
        shares.append(float(np.sqrt(np.mean((f_full - f_run) ** 2)) / den) if den > 0 else 0.0)
    return max(shares) if shares else math.nan


def capacity_force(model: DamperModel, test: dict | None = None) -> float:
    """Peak force [N] of ``model`` at its largest input under :data:`CAPACITY_TEST` (the force a
    target capacity is compared with).

    Parameters
    ----------
    model : DamperModel or AugmentedModel
        A registered damper model, or one with effects; driven at the top of its
        ``voltage_range``.
    test : dict, optional
        The sine motion: ``amplitude_m`` [m], ``frequency_hz`` [Hz] and ``cycles``; default
        :data:`CAPACITY_TEST`. The peak is taken over the last cycle.

    Returns
    -------
    float
        Peak absolute force [N] over the last cycle.
    """
    return float(np.max(np.abs(_capacity_cycle(model, test)[1])))
