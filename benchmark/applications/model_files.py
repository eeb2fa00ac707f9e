"""Model files written by the fitting commands (``sbib diagnose``, ``sbib identify --data``).

Both go through the one writer, :func:`damper.io.model_file.write_model_file`; this module only
turns each command's result into a model, its input (voltage or current, range, levels), its
quality and its provenance.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from benchmark.foundation.errors import InputError
from damper.diagnosis.augmented import make_base
from damper.io.model_file import InputSpec, as_range, file_provenance, write_model_file
from damper.models.voltage_laws import Tabulated

__all__ = ["write_diagnosis_models", "write_identified_models"]


def _levels(values) -> tuple[float, ...]:
    return tuple(float(v) for v in np.unique(np.round(np.asarray(values, dtype=float), 9)))


def write_diagnosis_models(result: Any, out: str | Path, inputs: Sequence[str]) -> dict[str, Path]:
    """Write ``base_model.json`` and ``final_model.json`` of a :class:`damper.diagnosis.loop.Diagnosis`
    into ``out``; return their paths by name (``base_model``, ``final_model``).

    Parameters
    ----------
    result : Diagnosis
        The result of ``sbib diagnose``: base and final models, held-out errors, the data's
        input (voltage or current, range, levels).
    out : str or Path
        Output folder (created if needed).
    inputs : sequence of str
        Data files diagnosed (recorded with their SHA-256 in the provenance).
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    data = result.data
    nodes = data.nodes()
    levels = _levels(data.levels()) if nodes is None else _levels(nodes)
    spec = InputSpec(data.input_name, data.input_unit, as_range(data.voltage_range()), levels)
    prov = file_provenance(inputs, kind="sbib diagnose")
    by_input = {k: {"before": b, "after": a} for k, (b, a) in result.errors_by_input.items()}
    fitted = [(m.x[k], m.xdot[k]) for m, k in zip(data.motions, data.train) if k.any()]
    common = {"error_measure": "held-out relative RMS force error ||F - F_model|| / ||F||",
              "holdout": result.settings.get("holdout"),
              "standard_errors": None,
              # the motion the model has seen: a run far beyond it is an extrapolation (said by sbib run)
              "fitted_motion": {"stroke_m": max(float(np.max(np.abs(x))) for x, _ in fitted),
                                "velocity_m_s": max(float(np.max(np.abs(v))) for _, v in fitted)}}
    notes = ["standard errors: the residual loop does not compute them (sbib identify --data does)"]
    if spec.single_level:
        notes.append(f"fitted at one {spec.quantity} level ({levels[0]:g} {spec.unit}): the model's force does "
                     "not depend on a command")
    paths = {}
    for name, model, error, which in (("base_model", result.base_model, result.error_before, "before"),
                                      ("final_model", result.final_model, result.error_after, "after")):
        quality = {**common, "held_out_rel_rms_error": float(error),
                   "held_out_rel_rms_error_by_input": {f"{k:g} {spec.unit}": v[which] for k, v in by_input.items()},
                   "held_out_rel_rms_error_by_test": {k: v[0 if which == "before" else 1]
                                                      for k, v in result.errors_by_test.items()}}
        if name == "final_model":
            quality["unexplained_in"] = [{"variable": v, "share": s, "level": lv}
                                         for v, s, lv in result.unexplained_in]
        paths[name] = write_model_file(out / f"{name}.json", model, input=spec, quality=quality,
                                       provenance=prov, notes=notes)
    return paths


def write_identified_models(result: dict, out: str | Path, inputs: Sequence[str]) -> dict[str, Path]:
    """Write one model file per model form (``normalized_model.json``, ``extended_model.json``)
    from :func:`damper.identification.measured.identify_files`'s result; return the paths.

    Files at several input levels give tabulated laws through the levels (at each level the one
    model fitted over all its files, :func:`damper.identification.measured.fit_levels`; a level of
    one file has that file's fit); files at one level give constant parameters (and a note:
    nothing to command). A file without a stated level counts as 0 (V).

    Parameters
    ----------
    result : dict
        The result of :func:`damper.identification.measured.identify_files` (``tests``: one
        entry per file and model form, ``summary``).
    out : str or Path
        Output folder (created if needed).
    inputs : sequence of str
        Data files identified (recorded with their SHA-256 in the provenance).

    Raises
    ------
    InputError
        The files mix input units (volts and amperes).
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    prov = file_provenance(inputs, kind="sbib identify --data")
    paths: dict[str, Path] = {}
    for form in ("normalized", "extended"):
        tests = [s for s in result.get("tests", []) if s["model"] == form]
        if not tests:
            continue
        units = {s["level_unit"] for s in tests}
        if len(units) > 1:
            raise InputError(f"identify --data: the files mix input units {sorted(units)}; give files of one kind")
        unit = units.pop() or "V"
        quantity = "current" if unit == "A" else "voltage"
        by_level: dict[float, list[dict]] = {}
        for s in tests:
            level = 0.0 if s["level"] is None or not math.isfinite(s["level"]) else float(s["level"])
            by_level.setdefault(level, []).append(s)
        levels = tuple(sorted(by_level))
        names = list(tests[0]["parameters"])
        # the one model per level fitted over all its tests (fit_levels), the model the run reports;
        # a level of one test has that test's fit (the file had held the median of each parameter
        # over the per-test fits: a set never fitted nor scored)
        joint = {(0.0 if e["level"] is None else float(e["level"])): e
                 for e in result.get("levels", {}).values() if e["model"] == form}
        values = {k: [joint[lv]["parameters"][k] if lv in joint else by_level[lv][0]["parameters"][k]
                      for lv in levels] for k in names}
        if len(levels) == 1:
            params: dict = {k: v[0] for k, v in values.items()}
        else:
            params = {k: Tabulated(levels, tuple(v)) for k, v in values.items()}
        lo, hi = min(0.0, levels[0]), max(1.0, levels[-1])
        model = make_base(form, params, (lo, hi))
        quality = {"error_measure": "relative RMS force error over the steady cycles (fit), and of each file's "
                                    "model on the other files at its level (held out)",
                   "by_file": {s["file"]: {"level": s["level"], "rel_rms_error": s["errors"]["rel_rms_error"],
                                           "standard_errors": s["standard_error"],
                                           "bootstrap_std": s.get("bootstrap_std"),
                                           "held_out": {k: e["rel_rms_error"] for k, e in s["held_out"].items()}}
                               for s in tests},
                   "summary": result.get("summary", {}).get(form, {}),
                   "by_level": {f"{lv:g} {unit}": ({"tests": joint[lv]["tests"], "rel_rms_error": joint[lv]["errors"],
                                                     "mean_rel_rms_error": joint[lv]["mean_error"],
                                                     "at_bounds": joint[lv]["at_bounds"]}
                                                    if lv in joint else
                                                    {"tests": [by_level[lv][0]["file"]],
                                                     "rel_rms_error": {by_level[lv][0]["file"]:
                                                                       by_level[lv][0]["errors"]["rel_rms_error"]},
                                                     "at_bounds": by_level[lv][0].get("at_bounds")})
                                for lv in levels}}
        seen = [s["fitted_motion"] for s in tests if s.get("fitted_motion")]
        if seen:  # as sbib diagnose's files: a building run far beyond it is said to extrapolate
            quality["fitted_motion"] = {"stroke_m": max(m["stroke_m"] for m in seen),
                                        "velocity_m_s": max(m["velocity_m_s"] for m in seen)}
        notes = [f"parameters at each {quantity} level: one model fitted over all the files at that level "
                 "(errors under it in quality.by_level)"
                 + ("; PCHIP laws between the levels" if len(levels) > 1 else "")]
        if len(levels) == 1:
            notes.append(f"fitted at one {quantity} level ({levels[0]:g} {unit}): the model's force does not "
                         "depend on a command")
        spec = InputSpec(quantity, unit, (lo, hi), levels)
        paths[form] = write_model_file(out / f"{form}_model.json", model, input=spec, quality=quality,
                                       provenance=prov, notes=notes)
    return paths
