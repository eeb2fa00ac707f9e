"""Identification of measured constant-voltage (or constant-current) tests, e.g. the UTFSM files.

Each file is read (:func:`damper.io.data.read_utfsm` for UTFSM names ``<amp>mm<freq>Hz<cur>A.txt``,
:func:`damper.io.data.read_csv` otherwise) and identified with
:func:`~damper.identification.identify.identify` (closed form, refinement, uncertainty). When
several files share one voltage/current (different amplitudes or frequencies), each file's
model predicts every other file at that level: the *held-out* relative RMS error tells how
well the parameters transfer beyond the test they were fitted to.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from benchmark.foundation.errors import InputError
from benchmark.foundation.display_units import parameter_kind, si_unit
from damper.identification.identify import Identification, identify
from damper.identification.metrics import force_errors
from damper.models.response import simulate
from damper.io.data import parse_utfsm_name, read_csv, read_utfsm
from damper.identification import plots

__all__ = ["read_test", "identify_files", "held_out_errors"]


def read_test(path):
    """Read one test file: UTFSM name pattern → :func:`damper.io.data.read_utfsm`, else CSV.

    Parameters
    ----------
    path
        Test file (UTFSM name pattern or CSV).
    """

    path = Path(path)
    try:
        parse_utfsm_name(path)
    except InputError:
        return read_csv(path)
    return read_utfsm(path)


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
                    other.t[w], other.force[w], pred[w], other.x[w], other.xdot[w])
    return out


def identify_files(files: Sequence, models: Sequence[str] = ("normalized", "extended"),
                   n_bootstrap: int = 10, out=None, progress: Callable[[str], None] | None = None,
                   strict: bool = False) -> dict:
    """Identify every file with every model; held-out check; optional figures in ``out``.

    Parameters
    ----------
    files : sequence of path-like or DamperTest
        Test files (all read before the first identification, so that a bad file stops the
        call at once), or tests already read (:func:`read_test`).
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
        ``{"tests": [summary per file and model], "held_out": {...}, "failed": {...},
        "figures": [...]}``; parameters in SI under ``kappa_x`` … ``n``, their SI units under
        each test's ``units`` (:mod:`benchmark.foundation.display_units`).
    """
    if not files:
        raise InputError("--data: expected at least one file")
    idents: list[Identification] = []
    failed: dict[str, str] = {}
    tests = [(str(item.name), item) if hasattr(item, "force") else (Path(item).name, read_test(item))
             for item in files]
    for label, test in tests:
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
        tests.append(s)
    figures: list[str] = []
    if out is not None:
        folder = Path(out)
        folder.mkdir(parents=True, exist_ok=True)
        for ident in idents:
            others = [o for o in idents if o.model_name == ident.model_name and o is not ident
                      and _level_key(o) == _level_key(ident)]
            shown = []
            for o in others:
                w = o.window
                pred = simulate(ident.model, o.t, o.x, o.xdot, 0.0).force
                shown.append((o.name, o.t[w], o.force[w], pred[w]))
            figures.append(str(plots.plot_fit(ident, folder / f"fit_{ident.name}_{ident.model_name}.png",
                                              held_out=shown)))
        if tests:
            figures.append(str(plots.plot_parameters_vs_level(
                tests, folder / "parameters_vs_level.png", unit=idents[0].level_unit if idents else "A")))
    summary_by_model = {}
    for m in models:
        rel = [s["errors"]["rel_rms_error"] for s in tests if s["model"] == m]
        ho = [e["rel_rms_error"] for s in tests if s["model"] == m for e in s["held_out"].values()]
        summary_by_model[m] = {"n_tests": len(rel),
                               "mean_fit_rel_rms_error": float(np.mean(rel)) if rel else None,
                               "mean_held_out_rel_rms_error": float(np.mean(ho)) if ho else None}
    return {"tests": tests, "failed": failed, "summary": summary_by_model, "figures": figures}
