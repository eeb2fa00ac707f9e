"""Identification of measured constant-voltage (or constant-current) tests, e.g. the UTFSM files.

Each file is read once (:func:`damper.io.reader.read_test`: UTFSM names ``<amp>mm<freq>Hz<cur>A.txt``,
Dyke records or damper CSV; every reader screens the data, :mod:`damper.io.screening`, and the
flagged samples count neither in the fits nor in the errors)
and identified with :func:`~damper.identification.identify.identify` (closed form, refinement,
uncertainty). When several files share one voltage/current (different amplitudes or
frequencies):

* each file's model predicts every other file at that level (the *held-out* error: how well
  one test's parameters transfer);
* ONE model is fitted per level over all its tests (:func:`~damper.identification.refine.refine_common`,
  the seed's method per voltage), started from the per-file fit that predicts the level's
  tests best, and each test's error under that one model is reported.

Every parameter a fit left at (or within 1e-3 of) a bound is flagged
(:func:`~damper.identification.refine.parameters_at_bounds`): the data did not identify it.
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from benchmark.foundation.errors import InputError
from benchmark.foundation.display_units import parameter_kind, si_unit
from benchmark.foundation.paths import file_label
from damper.identification.identify import Identification, identify
from damper.identification.metrics import force_errors
from damper.identification.refine import parameters_at_bounds, refine_common
from damper.models.response import simulate
from damper.io.reader import check_coil_inputs, read_test, unique_names
from damper.io.screening import screening_key, unstated_line
from damper.identification import plots

__all__ = ["identify_files", "held_out_errors", "fit_levels"]


def _level_key(ident: Identification) -> str:
    return "unknown" if math.isnan(ident.level) else f"{ident.level:g} {ident.level_unit}"


def held_out_errors(identifications: Sequence[Identification]) -> dict[str, dict[str, dict]]:
    """Errors of each file's model on the other files at the same level.

    Returns ``{trained_on: {predicted_file: force_errors over its steady cycles}}``.

    Parameters
    ----------
    identifications : Sequence[Identification]
        The identifications of the files.
    """
    groups: dict[tuple, list[Identification]] = {}
    for ident in identifications:
        groups.setdefault((_level_key(ident), ident.model_name), []).append(ident)
    out: dict[str, dict[str, dict]] = {}
    for members in groups.values():
        if len(members) < 2:
            continue
        for trained in members:
            for other in members:
                if other is trained:
                    continue
                w = other.window
                pred = simulate(trained.model, other.t, other.x, other.xdot, 0.0).force
                out.setdefault(trained.name, {})[other.name] = force_errors(
                    other.t[w], other.force[w], pred[w], other.x[w], other.xdot[w],
                    mask=None if other.mask is None else other.mask[w])
    return out


def fit_levels(identifications: Sequence[Identification], max_nfev: int = 100) -> dict[str, dict]:
    """ONE model per input level and model form over all its tests.

    The start is the per-test fit whose model predicts the level's tests best (a multi-start
    over the per-test optima); :func:`~damper.identification.refine.refine_common` then
    refines one parameter set over all of them.

    Parameters
    ----------
    identifications : sequence of Identification
        The per-test fits (each knows its test, model form and input level).
    max_nfev : int
        Cap on residual evaluations of each shared refinement.


    Returns
    -------
    dict
        ``{"<level> [<model>]": {"level", "level_unit", "model", "tests", "parameters",
        "standard_error", "errors": {test: relative RMS error}, "mean_error", "per_test_errors":
        {test: error of its own fit}, "started_from", "at_bounds", "success", "nfev"}}``.
    """
    groups: dict[tuple, list[Identification]] = {}
    for ident in identifications:
        groups.setdefault((_level_key(ident), ident.model_name), []).append(ident)
    out: dict[str, dict] = {}
    for (level, model), members in groups.items():
        if len(members) < 2:
            continue
        tests = [(m.t, m.x, m.xdot, m.force, m.cycles, m.mask) for m in members]

        def score(candidate) -> float:
            total = 0.0
            for m in members:
                w = m.window
                pred = simulate(candidate.model, m.t, m.x, m.xdot, 0.0).force
                total += force_errors(m.t[w], m.force[w], pred[w], m.x[w], m.xdot[w],
                                      mask=None if m.mask is None else m.mask[w])["rel_rms_error"] ** 2
            return total

        best = min(members, key=score)
        fit = refine_common(tests, best.parameters, model=model, max_nfev=max_nfev)
        out[f"{level} [{model}]"] = {
            "level": None if math.isnan(members[0].level) else members[0].level,
            "level_unit": members[0].level_unit, "model": model,
            "tests": [m.name for m in members],
            "parameters": fit.parameters, "standard_error": fit.standard_error,
            "units": {k: si_unit(parameter_kind(k)) for k in fit.parameters},
            "errors": dict(zip((m.name for m in members), fit.rel_rms_errors)),
            "mean_error": float(np.mean(fit.rel_rms_errors)),
            "per_test_errors": {m.name: m.errors["rel_rms_error"] for m in members},
            "started_from": best.name, "at_bounds": fit.at_bounds,
            "success": fit.success, "nfev": fit.nfev}
    return out


def _label(test) -> str:
    """A test's label in messages: its file's name when it was read from one (with the test's
    name for one level of a raw logger export, :func:`damper.io.screening.screening_key`), else its
    name."""
    source = getattr(test, "source", "")
    return screening_key(test) if source and Path(source).is_file() else str(test.name)


def identify_files(files: Sequence, models: Sequence[str] = ("normalized", "extended"),
                   n_bootstrap: int = 10, out=None, progress: Callable[[str], None] | None = None,
                   strict: bool = False) -> dict:
    """Identify every file with every model; held-out check; optional figures in ``out``.

    Parameters
    ----------
    files : sequence of path-like or DamperTest
        Test files (all read before the first identification, so that a bad file stops the
        call at once), or tests already read (:func:`damper.io.reader.read_test`).
    models : sequence of {"normalized", "extended"}
    n_bootstrap : int
        Cycle-bootstrap refits per identification.
    out : path-like, optional
        Folder for one error figure per file and model and a parameters-vs-level figure.
    progress : callable, optional
        Called with the file name after each identification.
    strict : bool
        Raise on insufficient excitation (default: keep the fit, record the warning).

    Returns
    -------
    dict
        ``{"tests": [summary per file and model, with "held_out" and "at_bounds"],
        "levels": {one model per level: :func:`fit_levels`}, "screening": {file: findings},
        "failed": {...}, "summary": {...}, "figures": [...]}``; parameters in SI under
        ``kappa_x`` … ``n``, their SI units under each test's ``units``
        (:mod:`benchmark.foundation.display_units`).
    """
    if not files:
        raise InputError("--data: expected at least one file")
    idents: list[Identification] = []
    failed: dict[str, str] = {}
    # each file is read once, here (a DamperTest passes through as it is)
    loaded = unique_names([(_label(item), item) if hasattr(item, "force") else (Path(item).name, read_test(item))
                            for item in files])
    check_coil_inputs(loaded, "--data")
    screenings = {label: {**test.metadata["screening"].to_json(),
                          # the columns read in a rig's units, converted to SI (damper.io.data)
                          **({"file_units": test.metadata["file_units"]} if test.metadata.get("file_units") else {}),
                          # columns read as SI for want of a unit, with the amplitudes read
                          **({"units_unstated": unstated_line(test, test.metadata["units_unstated"])}
                             if test.metadata.get("units_unstated") else {})}
                  for label, test in loaded if "screening" in getattr(test, "metadata", {})}
    for label, test in loaded:
        for m in models:
            try:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    idents.append(identify(test, model=m, n_bootstrap=n_bootstrap, strict=strict))
            except InputError as exc:
                failed[f"{label} [{m}]"] = str(exc)
            if progress is not None:
                progress(f"{label} {m}")
    # Held-out check per model (files at the same level predict each other).
    per_model = {m: held_out_errors([i for i in idents if i.model_name == m]) for m in models}
    tests = []
    for ident in idents:
        s = ident.summary()
        s["file"] = ident.name
        s["units"] = {k: si_unit(parameter_kind(k)) for k in s["parameters"]}
        s["held_out"] = per_model[ident.model_name].get(ident.name, {})
        s["at_bounds"] = parameters_at_bounds(ident.fit.parameters, ident.fit.start, ident.fit.free)
        # the motion the fit has seen: a building run far beyond it extrapolates (said by sbib run)
        w = ident.window
        s["fitted_motion"] = {"stroke_m": float(np.max(np.abs(ident.x[w]))),
                              "velocity_m_s": float(np.max(np.abs(ident.xdot[w])))}
        tests.append(s)
    levels = fit_levels(idents)
    figures: list[str] = []
    if out is not None:
        folder = Path(out)
        folder.mkdir(parents=True, exist_ok=True)
        used: set[str] = set()
        for ident in idents:
            others = [o for o in idents if o.model_name == ident.model_name and o is not ident
                      and _level_key(o) == _level_key(ident)]
            shown = []
            for o in others:
                w = o.window
                pred = simulate(ident.model, o.t, o.x, o.xdot, 0.0).force
                shown.append((o.name, o.t[w], o.force[w], pred[w]))
            # the test's name comes from its file's header: made safe (nothing outside the
            # folder) and unique (two names may read alike once made safe)
            stem = f"fit_{file_label(ident.name)}_{ident.model_name}"
            name, k = stem, 2
            while name in used:
                name, k = f"{stem}_{k}", k + 1
            used.add(name)
            figures.append(str(plots.plot_fit(ident, folder / f"{name}.png", held_out=shown)))
        if tests:
            figures.append(str(plots.plot_parameters_vs_level(
                tests, folder / "parameters_vs_level.png", unit=idents[0].level_unit if idents else "A")))
    summary_by_model: dict[str, dict] = {}
    for m in models:
        rel = [s["errors"]["rel_rms_error"] for s in tests if s["model"] == m]
        ho = [e["rel_rms_error"] for s in tests if s["model"] == m for e in s["held_out"].values()]
        summary_by_model[m] = {"n_tests": len(rel),
                               "mean_fit_rel_rms_error": float(np.mean(rel)) if rel else None,
                               "mean_held_out_rel_rms_error": float(np.mean(ho)) if ho else None}
    for key, entry in levels.items():
        summary_by_model[entry["model"]].setdefault("mean_level_fit_rel_rms_error", {})[key] = entry["mean_error"]
    return {"tests": tests, "failed": failed, "summary": summary_by_model, "levels": levels,
            "screening": screenings, "figures": figures}
