"""Which damper the building runs, how many, where, and at what scale (``--damper``, ``--devices``,
``--damper-scale``; ensembles' ``damper``, ``devices``, ``damper_scale``).

* ``--damper FILE.json|NAME``: a damper model file (:mod:`damper.io.model_file`) or a registered
  model's name (``virtual``, the default, ...). A file's effects that a building kernel carries
  are folded in (:meth:`damper.io.model_file.ModelFile.building_model`); the others are listed as
  not run.
* ``--damper-scale F``: force similitude: every force parameter of the model times ``F``
  (displacements, velocities, times and the input unchanged). ``--damper-scale 1000kN`` (or
  ``1e6N``, ``1MN``) asks for a target capacity instead: ``F`` makes the model's peak force at its
  largest input under :data:`damper.io.model_file.CAPACITY_TEST` (±0.1 m at 0.5 Hz) equal to it.
* ``--devices N``: ``N`` devices (even), ``N/2`` per direction at the default layout's
  positions (:class:`benchmark.simulator.devices.DeviceLayout`): for ``N/2 < 8`` positions evenly
  spread over each direction's list, beyond 8 the list repeats (devices side by side).
  ``--devices LAYOUT.json``: ``{"name": ..., "devices": [{"x": m, "y": m, "direction": "x"|"y",
  "model": FILE.json|NAME (optional, default --damper), "label": ...}, ...]}`` (model files
  relative to the layout's folder; ``--damper-scale`` applies to every slot).

The model's input (volts or amperes, its range) is the controllers' command: a controller
commands ``[0, v_max]`` with ``v_max`` the top of the model's input range, and the command is
the model's input in its unit (:attr:`DamperChoice.input_mapping` says it in one line). A model
fitted at one input level has nothing to command: :attr:`DamperChoice.notes` says so. The
uncontrolled reference is the building without devices whatever the damper.
"""

from __future__ import annotations

import functools
import json
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from benchmark.foundation.errors import InputError, SbibError
from benchmark.simulator.devices import (DEFAULT_X_POSITIONS, DEFAULT_Y_POSITIONS, DeviceLayout, DeviceSlot,
                                         default_damper_model)
from damper.models.base import DamperModel
from damper.io.model_file import (CAPACITY_TEST, CONSTANT_EFFECTS, SWITCHINGS_PER_CYCLE, InputSpec, command_ends, as_range, ModelFile, capacity_force, dropped_share,
                                  looks_like_model_file,
                               read_model_file)
from damper.models.registry import MODELS, get_model_class

__all__ = ["DamperChoice", "resolve_damper", "resolve_layout", "parse_scale", "add_damper_options",
           "command_unit", "MIXED_COMMAND_UNITS", "motion_notes", "device_motion", "MOTION_EXTRAPOLATION", "DEFAULT_DAMPER"]

DEFAULT_DAMPER = "virtual"


def command_unit(damper: Any, label: str | None = None) -> str:
    """The unit of the devices' command history: the damper models' input unit (``"V"``, or
    ``"A"`` for a model identified on the coil current).

    Parameters
    ----------
    damper : dict or None
        A run's damper summary (``{"dampers": [{"damper": label, "input": {"unit": ...}}, ...]}``).
    label : str, optional
        The one damper model to take (a ``compare --dampers`` run); None: all of them, ``"V"``
        when none is named, their one unit when they share it, and ``MIXED_COMMAND_UNITS`` when a
        layout mixes models read in volts and in amperes (each device's command is in its own
        model's unit: the damper summary says which).
    """
    units = {d.get("input", {}).get("unit", "V") for d in (damper or {}).get("dampers", [])
             if isinstance(d, dict) and (label is None or d.get("damper") == label)}
    if len(units) > 1:
        return MIXED_COMMAND_UNITS
    return units.pop() if units else "V"


#: A run whose devices move beyond this multiple of the stroke or velocity a model file was fitted
#: on is said to extrapolate its hysteresis (:func:`motion_notes`).
MOTION_EXTRAPOLATION = 1.5


def device_motion(result: Any) -> tuple[float, float]:
    """A run's largest device stroke [m] and velocity [m/s] (``(0, 0)`` without devices): what
    :func:`motion_notes` compares with a model's fitted motion.

    Parameters
    ----------
    result : SimulationResult
        A building run (``device_displacement``, ``device_velocity``).
    """
    x = getattr(result, "device_displacement", None)
    v = getattr(result, "device_velocity", None)
    if x is None or v is None or not np.size(x):
        return 0.0, 0.0
    return float(np.max(np.abs(x))), float(np.max(np.abs(v)))


def motion_notes(used: Sequence["DamperChoice"], stroke: float, velocity: float) -> list[str]:
    """Warnings for model files whose fitted motion the run's devices exceeded.

    A model identified on laboratory tests (``quality.fitted_motion`` of a file written by
    ``sbib diagnose``) knows its hysteresis only over the strokes and velocities it was fitted
    on; a scaled force does not scale that motion, so a building run far beyond it extrapolates
    the model's transition and velocity laws.

    Parameters
    ----------
    used : sequence of DamperChoice
        The damper choices of the run's layout.
    stroke, velocity : float
        The run's largest device stroke [m] and velocity [m/s].
    """
    notes = []
    for choice in used:
        quality = getattr(choice.source, "quality", None) or {}
        fitted = quality.get("fitted_motion") if isinstance(quality, dict) else None
        if not isinstance(fitted, dict):
            continue
        s0, v0 = fitted.get("stroke_m"), fitted.get("velocity_m_s")
        if not (isinstance(s0, (int, float)) and isinstance(v0, (int, float)) and s0 > 0 and v0 > 0):
            continue
        rs, rv = stroke / s0, velocity / v0
        if max(rs, rv) > MOTION_EXTRAPOLATION:
            notes.append(f"warning: {choice.label}: the devices moved up to {stroke:.3g} m and {velocity:.3g} m/s, "
                         f"{rs:.3g} and {rv:.3g} times the largest stroke and velocity the model was fitted on "
                         f"({1e3 * s0:.3g} mm, {1e3 * v0:.3g} mm/s): its hysteresis there is an extrapolation")
    return list(dict.fromkeys(notes))


#: The command unit of a layout that mixes models read in volts and in amperes (:func:`command_unit`).
MIXED_COMMAND_UNITS = "V or A (each device in its own model's input unit)"
_FORCE_UNITS = {"N": 1.0, "kN": 1e3, "MN": 1e6}


@dataclass(frozen=True)
class DamperChoice:
    """A damper as the building runs it.

    Attributes
    ----------
    label : str
        The file's name or the registered name.
    model : DamperModel
        The registered model every device of this choice runs (scaled, effects folded).
    source : ModelFile
    scale : float
        Force similitude factor (1: as fitted).
    scale_basis : str
        How ``scale`` was set (one line).
    input_mapping : str
        How the controllers' command becomes the model's input (one line).
    notes : tuple of str
        Effects not run, a single input level, ... (one line each).
    """

    label: str
    model: DamperModel
    source: ModelFile
    scale: float = 1.0
    scale_basis: str = "as fitted (no scaling)"
    input_mapping: str = ""
    notes: tuple = ()

    @property
    def single_level(self) -> bool:
        return self.source.input.single_level

    def describe(self) -> dict:
        """JSON-ready description for results and provenance."""
        return {"damper": self.label, "path": self.source.path, "model": _model_label(self.model),
                "file_model": self.source.model_name, "input": self.source.input.to_json(),
                "scale": self.scale, "scale_basis": self.scale_basis, "input_mapping": self.input_mapping,
                "effects": [{"name": e.name, "value": e.value, "unit": e.unit} for e in self.source.effects],
                "notes": list(self.notes)}


def _model_label(model) -> str:
    """The building's model by name; force terms around a model (:mod:`damper.models.force_terms`)
    as ``inner + term + ...`` (``normalized_bouc_wen + shear_thinning``), not the wrapper's name."""
    inner, terms = getattr(model, "inner", None), getattr(model, "terms", None)
    if inner is not None and terms:
        return " + ".join((str(inner.name), *terms))
    return str(model.name)


#: A model file run without --damper-scale whose capacity is below this share of the benchmark
#: damper's is said to be unscaled (a laboratory device).
UNSCALED_WARNING = 0.05
#: A device whose capacity exceeds this multiple of the benchmark damper's is said to be
#: oversized: 16 of them at 10 MN already resist ~80 % of the building's weight (203 MN), and a
#: stiffer device than the step can follow makes the run fail numerically (probed: 1000MN).
OVERSIZE_WARNING = 10.0
#: Share of a model's force (RMS, capacity test) carried by effects the building cannot run above
#: which the run says its results are not the fitted device's.
DROPPED_WARNING = 0.05


@functools.lru_cache(maxsize=1)
def _benchmark_capacity() -> float:
    """Capacity [N] of the benchmark's own damper (:data:`DEFAULT_DAMPER`), computed once."""
    return capacity_force(_source(DEFAULT_DAMPER).model)


def parse_scale(text: Any) -> tuple[str, float] | None:
    """``None``; ``("factor", F)`` for a number; ``("capacity", N)`` for a force with a unit (N, kN, MN).

    Parameters
    ----------
    text : Any
        A ``--damper-scale`` value: ``None``, a number, or text such as ``"400"`` or ``"1000kN"``;
        a capacity is converted to newtons.

    Raises
    ------
    InputError
        Not a number, a unit other than N, kN or MN, or a value that is not finite and positive.
    """
    if text is None:
        return None
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        value, unit = float(text), ""
    else:
        m = re.fullmatch(r"\s*([0-9.eE+-]+)\s*(N|kN|MN)?\s*", str(text))
        if not m:
            raise InputError(f"--damper-scale {text!r}: expected a factor (e.g. 400) or a target capacity with its "
                             "unit (e.g. 1000kN)")
        try:
            value = float(m.group(1))
        except ValueError:
            raise InputError(f"--damper-scale {text!r}: expected a number") from None
        unit = m.group(2) or ""
    if not (math.isfinite(value) and value > 0):
        raise InputError(f"--damper-scale {text!r}: expected a positive finite value")
    return ("capacity", value * _FORCE_UNITS[unit]) if unit else ("factor", value)


def _has_defaults(name: str) -> bool:
    """Whether the registered damper model ``name`` can be built without parameters."""
    try:
        get_model_class(name)()
    except (TypeError, SbibError):
        return False
    return True


def _source(spec: str | None, base_dir: Path | None = None) -> ModelFile:
    if spec is None or spec == "":
        model = default_damper_model()
        return ModelFile(model=model, input=InputSpec("voltage", "V", as_range(model.voltage_range), ()))
    spec = str(spec)
    if looks_like_model_file(spec):
        path = Path(spec)
        if base_dir is not None and not path.is_absolute():
            path = base_dir / path
        return read_model_file(path)
    if spec not in MODELS:
        raise InputError(f"--damper {spec!r}: not a model file (*.json) nor a registered model; expected a file or "
                         f"one of {', '.join(sorted(MODELS))}")
    try:
        model = get_model_class(spec)()
    except (TypeError, SbibError):
        runnable = [name for name in sorted(MODELS) if _has_defaults(name)]
        raise InputError(f"--damper {spec!r}: the registered model {spec} has no default parameters; give a model "
                         "file (*.json: sbib identify and sbib diagnose write one) or one of the models that run by "
                         f"name: {', '.join(runnable)}") from None
    return ModelFile(model=model, input=InputSpec("voltage", "V", as_range(model.voltage_range), ()))


def resolve_damper(spec: str | None = None, scale: Any = None, base_dir: Path | None = None) -> DamperChoice:
    """The damper of ``--damper`` at ``--damper-scale`` (module docstring).

    Parameters
    ----------
    spec : str, optional
        A model file (``*.json``) or a registered model's name; ``None`` or ``""``: the default
        device model.
    scale : Any, optional
        ``--damper-scale``: a factor or a target capacity with its unit (:func:`parse_scale`);
        ``None``: as fitted.
    base_dir : Path, optional
        Folder a relative model file is taken from (a layout file's folder); default: the
        working directory.

    Returns
    -------
    DamperChoice
        The model the building runs, its label, scale and input mapping.

    Raises
    ------
    InputError
        A bad file or name (one line from :func:`damper.io.model_file.read_model_file`), a bad scale.
    """
    source = _source(spec, base_dir)
    label = source.label if source.path else (spec or DEFAULT_DAMPER)
    model, dropped = source.building_model()
    # the effects whose force the building leaves out: a constant force (an offset) is no part of
    # a damper installed at rest, so it neither sizes the device nor counts as force left out
    missing = [line for line in dropped if line.split(" (", 1)[0] not in CONSTANT_EFFECTS]
    how = parse_scale(scale)
    factor, basis = 1.0, "as fitted (no scaling)"
    if how is not None:
        kind, value = how
        if kind == "factor":
            factor = value
            basis = f"force similitude x{factor:g} (given)"
        else:
            # the fitted device's capacity, effects the building cannot run included: the scale
            # maps that device onto the target, whatever the building then leaves out
            cap = capacity_force(source.augmented(constant=False) if missing else model)
            factor = value / cap
            basis = (f"force similitude x{factor:.6g}: capacity {cap / 1e3:.4g} kN -> {value / 1e3:.4g} kN (peak force at "
                     f"{source.input.range[1]:g} {source.input.unit}, ±{CAPACITY_TEST['amplitude_m']:g} m at "
                     f"{CAPACITY_TEST['frequency_hz']:g} Hz)")
        basis += "; forces scaled, displacements, velocities and times not"
        source = source.scaled(factor)
        model, dropped = source.building_model()
    spec_in = source.input
    lo, hi = (float(v) for v in model.voltage_range)
    mapping = (f"controller command u in [0, {hi:g}] is the model's {spec_in.quantity} in {spec_in.unit} "
               f"(input range [{lo:g}, {hi:g}] {spec_in.unit}")
    if spec_in.levels:
        mapping += "; fitted at " + ", ".join(f"{v:g}" for v in spec_in.levels) + f" {spec_in.unit}"
    mapping += ")"
    if lo > 0:
        mapping += f"; commands below {lo:g} {spec_in.unit} are outside the model's range"
    notes = list(dropped)
    if spec_in.levels and not spec_in.single_level:
        top, bottom = max(spec_in.levels), min(spec_in.levels)
        span = top - bottom
        if hi > top + 1e-6 * span or lo < bottom - 1e-6 * span:
            notes.append(f"warning: {label}: input range [{lo:g}, {hi:g}] {spec_in.unit} goes beyond the levels it "
                         f"was fitted at ({bottom:g}-{top:g} {spec_in.unit}); its laws hold their end values "
                         "there (an extrapolation nobody measured)")
    if missing:
        share = dropped_share(source.augmented(constant=False), model)
        names = ", ".join(line.split(" (", 1)[0] for line in missing)  # "name (parameter ...): ..."
        low, high = command_ends(model.voltage_range)
        amount = ("a share of its force that could not be measured (the model fails numerically on the "
                  "test cycle)" if math.isnan(share) else f"{100 * share:.0f} % of its force")
        line = (f"{label}: the building runs it without {names}, {amount} (RMS "
                f"over a ±{CAPACITY_TEST['amplitude_m']:g} m, {CAPACITY_TEST['frequency_hz']:g} Hz cycle at "
                f"{high:g} {spec_in.unit}, or with the command switching between "
                f"{low:g} and {high:g} {spec_in.unit} {SWITCHINGS_PER_CYCLE} times "
                "a cycle: the larger)")
        notes.append(f"warning: {line}: its results are not the fitted device's"
                     if math.isnan(share) or share >= DROPPED_WARNING else line)
    # the device's size against the benchmark damper's: a file run as fitted, or after a scale
    cap = None
    if how is not None:
        cap = how[1] if how[0] == "capacity" else capacity_force(model)
    elif source.path:
        cap = capacity_force(model)
    ref = _benchmark_capacity()
    after = " after --damper-scale" if how is not None else ", run as fitted"
    if cap is not None and cap < UNSCALED_WARNING * ref:
        # a laboratory device (kN) among 16 building dampers of ~1 MN: almost surely a missing
        # scale; after a scale, a factor that leaves the devices doing nothing
        notes.append(f"warning: {label}: capacity {cap / 1e3:.4g} kN{after}, {100 * cap / ref:.2g} % of the "
                     f"benchmark damper's {ref / 1e3:.4g} kN: "
                     + ("give --damper-scale (e.g. 1000kN) to size the device for the building" if how is None
                        else "the devices will barely act (a scale meant as a capacity, or kN for MN?)"))
    if cap is not None and cap > OVERSIZE_WARNING * ref:
        notes.append(f"warning: {label}: capacity {cap / 1e6:.4g} MN{after}, "
                     f"{cap / ref:.3g} times the benchmark damper's "
                     f"{ref / 1e3:.4g} kN: a device that size is not in the building's range "
                     "(a unit slip, kN for MN?), and a run may fail numerically")
    if spec_in.single_level:
        notes.append(f"{label}: fitted at one {spec_in.quantity} level ({spec_in.levels[0]:g} {spec_in.unit}); its "
                     "force does not depend on the command: a controller has nothing to command")
    return DamperChoice(label=label, model=model, source=source, scale=factor, scale_basis=basis,
                        input_mapping=mapping, notes=tuple(notes))


def _spread(positions, k: int) -> list:
    if k <= len(positions):
        idx = np.unique(np.round(np.linspace(0, len(positions) - 1, k)).astype(int))
        return [positions[i] for i in idx]
    return [positions[i % len(positions)] for i in range(k)]


def resolve_layout(devices: Any, choice: DamperChoice, scale: Any = None) -> tuple[DeviceLayout, list[DamperChoice]]:
    """The device layout of ``--devices`` (module docstring) and the dampers it uses (``choice`` first).

    ``devices`` ``None`` is the default 16-device layout.

    Parameters
    ----------
    devices : Any
        ``--devices``: ``None``, ``""`` or ``"default"`` (16 devices), an even number of devices,
        or a layout JSON file.
    choice : DamperChoice
        The damper of ``--damper``: every slot without a model of its own runs it.
    scale : Any, optional
        ``--damper-scale``, applied to the models a layout file names.

    Returns
    -------
    tuple of (DeviceLayout, list of DamperChoice)
        The layout and the dampers it uses (``choice`` first when a slot uses it).

    Raises
    ------
    InputError
        An odd or too small number, a missing or malformed layout file, a bad slot or model.
    """
    if devices is None or devices == "" or devices == "default":
        return DeviceLayout.default(model=choice.model), [choice]
    text = str(devices).strip()
    if re.fullmatch(r"\d+", text):
        n = int(text)
        if n < 2 or n % 2:
            raise InputError(f"--devices {text}: expected an even number >= 2 (half per direction), or a LAYOUT.json")
        k = n // 2
        slots = [DeviceSlot(x, y, 0, choice.model, label=f"x{i + 1}") for i, (x, y) in
                 enumerate(_spread(DEFAULT_X_POSITIONS, k))]
        slots += [DeviceSlot(x, y, 1, choice.model, label=f"y{i + 1}") for i, (x, y) in
                  enumerate(_spread(DEFAULT_Y_POSITIONS, k))]
        return DeviceLayout(tuple(slots), name=f"perimeter-{n}"), [choice]
    path = Path(text)
    if not path.is_file():
        raise InputError(f"--devices {text!r}: expected an even number of devices or a layout JSON file (not found)")
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"{path}: not a JSON file ({type(exc).__name__}: {exc})") from None
    if not isinstance(doc, dict) or not isinstance(doc.get("devices"), list) or not doc["devices"]:
        raise InputError(f"{path}: expected {{\"name\": ..., \"devices\": [{{\"x\", \"y\", \"direction\", \"model\"}}, ...]}}")
    extra = set(doc) - {"name", "devices"}
    if extra:
        raise InputError(f"{path}: unknown field(s) {', '.join(sorted(extra))}; expected name, devices")
    choices: dict[str, DamperChoice] = {}
    slots = []
    for i, entry in enumerate(doc["devices"]):
        where = f"{path}: devices[{i}]"
        if not isinstance(entry, dict):
            raise InputError(f"{where}: expected an object with x, y, direction[, model, label]")
        bad = set(entry) - {"x", "y", "direction", "model", "label"}
        missing = [k for k in ("x", "y", "direction") if k not in entry]
        if bad or missing:
            raise InputError(f"{where}: " + (f"missing {', '.join(missing)}" if missing else "")
                             + ("; " if bad and missing else "") + (f"unknown {', '.join(sorted(bad))}" if bad else ""))
        spec = entry.get("model")
        if spec is None:
            slot_choice = choice
        else:
            key = str(spec)
            if key not in choices:
                choices[key] = resolve_damper(key, scale, base_dir=path.parent)
            slot_choice = choices[key]
        try:
            slots.append(DeviceSlot(entry["x"], entry["y"], entry["direction"], slot_choice.model,
                                    label=str(entry.get("label", f"d{i + 1}"))))
        except InputError as exc:
            raise InputError(f"{where}: {exc}") from None
    used = ([choice] if any(e.get("model") is None for e in doc["devices"]) else []) + list(choices.values())
    return DeviceLayout(tuple(slots), name=str(doc.get("name", path.stem))), used


def add_damper_options(parser: Any) -> None:
    """``--damper``, ``--devices``, ``--damper-scale`` (module docstring).

    Parameters
    ----------
    parser : argparse.ArgumentParser
        The (sub)command parser the three options are added to.
    """
    parser.add_argument("--damper", default=None, metavar="FILE.json|NAME",
                        help="damper model of every device: a model file (sbib diagnose/identify write them) or a "
                             f"registered model (default {DEFAULT_DAMPER})")
    parser.add_argument("--devices", default=None, metavar="N|LAYOUT.json",
                        help="number of devices (even; half per direction at the default positions) or a layout "
                             "file with positions, directions and a model per slot (default: 16)")
    parser.add_argument("--damper-scale", default=None, metavar="F|FORCE",
                        help="force similitude of the damper model: a factor (e.g. 400) or a target capacity "
                             "(e.g. 1000kN: peak force at the largest input, ±0.1 m at 0.5 Hz); stated in the results")
