"""One HTML page for a results directory of ``sbib study`` (``make run``): ``report.html``.

The main job writes dozens of files; the report gathers what a reader looks at first: the
evaluation criteria J1–J9 per controller (with their key), the identification errors, the
diagnosis of the damper models before and after the residual loop, and the key figures with
captions. Every table and figure links to the data file it comes from. The page is
self-contained and works offline: inline CSS, no script, no web font or CDN, figures referenced
by paths relative to the page (so the results folder can be moved or zipped as a whole).

Steps that are absent from the directory (e.g. a partial run) are listed as "not in this
results directory" rather than failing, so the builder works on any subset of the study's
outputs. Run it again on a finished directory with ``python -m benchmark.applications.report RESULTS_DIR``.
"""

from __future__ import annotations

import csv
import re
import html
import json
import math
import sys
from pathlib import Path
from typing import Any, Iterable, Sequence

from benchmark.foundation.atomic import atomic_write_text
from benchmark.foundation.errors import InputError
from benchmark.simulator.evaluation import J_DESCRIPTIONS, J_NAMES
from benchmark.simulator.criteria import CRITERIA
from benchmark.foundation.provenance import provenance
from damper.diagnosis.interference import interference_lines
from damper.diagnosis.levels import level_lines

__all__ = ["write_report", "build_report_html", "REPORT_NAME"]

REPORT_NAME = "report.html"

_CSS = """
body { font-family: system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; margin: 2rem auto;
       max-width: 72rem; padding: 0 1rem; color: #1b1b1b; line-height: 1.45; }
h1 { font-size: 1.7rem; margin-bottom: .2rem; } h2 { margin-top: 2.2rem; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; margin: .6rem 0 1rem; font-size: .92rem; }
th, td { border: 1px solid #c8c8c8; padding: .25rem .55rem; text-align: right; }
th { background: #f0f0f0; } td.name, th.name { text-align: left; }
figure { margin: 1rem 0 1.6rem; } figure img { max-width: min(100%, 56rem); border: 1px solid #ddd; }
figcaption { font-size: .9rem; color: #333; max-width: 60rem; }
.meta, .note { color: #555; font-size: .9rem; } .missing { color: #8a4b00; }
dl.key { display: grid; grid-template-columns: max-content auto; gap: .1rem 1rem; font-size: .88rem; }
dl.key dt { font-weight: 600; } dl.key dd { margin: 0; }
.formula { font-family: ui-monospace, monospace; color: #333; }
dl.glossary { font-size: .88rem; max-width: 60rem; } dl.glossary dt { font-weight: 600; }
dl.glossary dd { margin: 0 0 .3rem 1.5rem; }
"""


def _e(value: Any) -> str:
    return html.escape(str(value), quote=True)


def _num(value: Any, digits: int = 3) -> str:
    if value is None:
        return "–"
    try:
        v = float(value)
    except (TypeError, ValueError):
        return _e(value)
    if not math.isfinite(v):
        return "–"
    return f"{v:.{digits}f}"


def _pct(value: Any) -> str:
    try:
        v = float(value)
    except (TypeError, ValueError):
        return "–"
    return f"{100.0 * v:.1f} %" if math.isfinite(v) else "–"


def _kilo(value: Any) -> str:
    """An SI value shown in kilo-units (N/m -> kN/m, N -> kN), one decimal."""
    try:
        return _num(float(value) / 1e3, 1)
    except (TypeError, ValueError):
        return "–"


def _read_json(path: Path) -> Any:
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        return None


def _link(root: Path, path: Path, text: str | None = None) -> str:
    rel = path.relative_to(root).as_posix()
    return f'<a href="{_e(rel)}">{_e(text or rel)}</a>'


def _data_links(root: Path, paths: Iterable[Path]) -> str:
    links = [_link(root, p) for p in paths if p.is_file()]
    return ("data: " + ", ".join(links)) if links else ""


def _table(header: Sequence[str], rows: Iterable[Sequence[str]], left: Sequence[int] = (0,)) -> str:
    """An HTML table; ``rows`` hold HTML already escaped; columns ``left`` are text (left-aligned)."""
    head = "".join(f'<th class="name">{_e(h)}</th>' if i in left else f"<th>{_e(h)}</th>"
                   for i, h in enumerate(header))
    body = []
    for row in rows:
        cells = "".join(f'<td class="name">{c}</td>' if i in left else f"<td>{c}</td>"
                        for i, c in enumerate(row))
        body.append(f"<tr>{cells}</tr>")
    return f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(body)}</tbody></table>"


def _figure(root: Path, image: Path, caption: str, data: Sequence[Path]) -> str:
    if not image.is_file():
        return ""
    rel = image.relative_to(root).as_posix()
    links = _data_links(root, data)
    return (f'<figure><a href="{_e(rel)}"><img src="{_e(rel)}" alt="{_e(caption)}"></a>'
            f"<figcaption>{_e(caption)}{' — ' + links if links else ''}</figcaption></figure>")


def _missing(what: str) -> str:
    return (f'<p class="missing">{_e(what)}: not in this results directory '
            "(step not run, or its file is unreadable).</p>")


# --------------------------------------------------------------------------- sections

def _j_key() -> str:
    # the formulas as page text (the figures carry only the names)
    items = "".join(f"<dt>{_e(j)}</dt><dd>{_e(d)}"
                    + (f' <span class="formula">= {_e(CRITERIA[j].formula)}</span>' if j in CRITERIA else "")
                    + "</dd>" for j, d in J_DESCRIPTIONS.items())
    return (f'<dl class="key">{items}</dl><p class="note">J1–J5, J7, J8: ratios to the uncontrolled run '
            "(below 1 = reduced). J6 and J9 are fractions of the controlled run itself, not ratios "
            "to the uncontrolled run (definitions and sources: <code>docs/criteria.md</code>, <code>benchmark/simulator/criteria.py</code>).</p>")


def _suite_section(root: Path) -> str:
    folder = root / "suite"
    data = _read_json(folder / "comparison.json")
    out = ['<h2 id="suite">Controllers: evaluation criteria J1–J9</h2>']
    if not isinstance(data, dict) or not isinstance(data.get("summary"), dict):
        return out[0] + _missing("the benchmark suite (suite/comparison.json)")
    runs = data.get("runs") or []
    cases = sorted({(r.get("record"), r.get("orientation")) for r in runs if isinstance(r, dict)})
    synthetic = (_read_json(root / "summary.json") or {}).get("steps", {}).get("suite", {}).get(
        "synthetic_records", False)
    out.append(f'<p>Mean / max over {len(cases)} record–orientation case(s)'
               f'{" (SYNTHETIC records)" if synthetic else ""}: '
               + _e(", ".join(f"{r} {o}" for r, o in cases)) + ".</p>")
    rows = []
    for controller, entry in data["summary"].items():
        cells = [_e(controller)]
        for j in J_NAMES:
            stat = entry.get(j) or {}
            cells.append(f"{_num(stat.get('mean'), 2)} / {_num(stat.get('max'), 2)}")
        rows.append(cells)
    out.append(_table(["controller", *J_NAMES], rows))
    out.append(f'<p class="note">{_data_links(root, [folder / "comparison.json", folder / "table.txt", folder / "comparison.h5"])}</p>')
    out.append(_j_key())
    plots = folder / "plots"
    out.append(_figure(root, plots / "J_summary.png",
                       "J1–J9 per controller, mean and max over the runs.", [folder / "comparison.json"]))
    out.append(_figure(root, plots / "J_by_record.png",
                       "Each J per record and orientation.", [folder / "comparison.json"]))
    for image in sorted(plots.glob("histories_*.png"))[:1]:
        case = image.stem.removeprefix("histories_").replace("_", " ")
        out.append(_figure(root, image, f"Time histories, {case}: uncontrolled and every controller.",
                           [folder / "comparison.h5"]))
    return "".join(out)


def _identification_section(root: Path) -> str:
    folder = root / "identification"
    out = ['<h2 id="identification">Identification of the virtual benchmark damper</h2>']
    params = folder / "parameters.csv"
    validation = _read_json(folder / "validation.json")
    if not params.is_file() and not isinstance(validation, dict):
        return out[0] + _missing("the identification study (identification/parameters.csv)")
    if params.is_file():
        try:
            lines = [ln for ln in params.read_text(encoding="utf-8").splitlines() if not ln.startswith("#")]
            # column names carry their unit ("kappa_x [N/m]"); the table reads them by name
            records = [{re.sub(r"\s*\[[^\]]*\]$", "", k or ""): v for k, v in row.items()}
                       for row in csv.DictReader(lines)]
        except (OSError, UnicodeDecodeError, csv.Error):
            records = []
        shown = _grid_ends_and_middle(records)
        if shown:
            out.append("<p>Identification errors on the identification test (relative RMS force error "
                       "over the steady cycles; κ_x in kN/m, κ_ẋ in kN·s/m, κ_w in kN)"
                       + (f", at {len(shown) // max(1, len({_model_label(r) for r in shown}))} of the "
                          f"{len(records) // max(1, len({_model_label(r) for r in records}))} voltages "
                          "(all of them in parameters.csv)" if len(shown) < len(records) else "") + ".</p>")
            rows = []
            for r in shown:
                rows.append([_e(_model_label(r)), _num(r.get("voltage"), 2),
                             _kilo(r.get("kappa_x")), _kilo(r.get("kappa_xdot")), _kilo(r.get("kappa_w")),
                             _num(r.get("rho"), 1), _num(r.get("sigma"), 2), _num(r.get("n"), 2),
                             _pct(r.get("rel_rms_error"))])
            out.append(_table(["model", "v [V]", "κ_x [kN/m]", "κ_ẋ [kN·s/m]", "κ_w [kN]", "ρ [1/m]",
                               "σ", "n", "fit error"], rows))
            out.append(_glossary(list(dict.fromkeys(_model_label(r) for r in shown))))
    if isinstance(validation, dict) and isinstance(validation.get("summary"), dict):
        errors = validation.get("errors") or {}
        n_runs = sum(len(v) for v in errors.values() if isinstance(v, dict))
        out.append(f"<p>Validation inside {n_runs} earthquake run(s) under "
                   f"{_e(validation.get('controller', '?'))}: force error of each identified model "
                   "against the device (“+lag”: the commanded voltage through the identified field "
                   "filter).</p>")
        models = validation.get("models") or list(validation["summary"])
        rows = [[_e(model), _pct(s.get("mean_rel_rms_error")), _pct(s.get("max_rel_rms_error")),
                 _pct(s.get("mean_peak_error")), _pct(s.get("mean_energy_error"))]
                for model, s in validation["summary"].items()
                if isinstance(s, dict) and model in models and "mean_rel_rms_error" in s]
        out.append(_table(["model", "relative RMS (mean)", "relative RMS (max)", "peak (mean)",
                           "energy (mean)"], rows))
        out.append(_glossary([m for m, s in validation["summary"].items()
                              if isinstance(s, dict) and m in models and "mean_rel_rms_error" in s]))
    out.append(f'<p class="note">{_data_links(root, [params, folder / "validation.json", folder / "voltage_laws.json", folder / "ceiling.json", folder / "identification.h5"])}</p>')
    figures = folder / "figures"
    out.append(_figure(root, figures / "fig08_parameters_vs_voltage.png",
                       "Identified parameters against voltage, with the fitted voltage laws (seed Fig. 8).",
                       [params, folder / "voltage_laws.json"]))
    out.append(_figure(root, figures / "fig01_loops_0V.png",
                       "Force–displacement and force–velocity loops at 0 V: device and identified models (seed Fig. 1).",
                       [params]))
    out.append(_figure(root, figures / "fig11_error_anatomy.png",
                       "Where the validation error comes from: errors by field regime and the structural ceiling.",
                       [folder / "validation.json", folder / "ceiling.json"]))
    return "".join(out)


#: What each model name of the identification's tables means (the names are built from these parts).
_MODEL_NAMES = {
    "original": "the seed paper's “original method” (its Fig. 11): Rodríguez et al.'s closed form of "
                "the normalized Bouc-Wen model at each voltage, no elastic term, no refinement, with the "
                "seed's voltage laws",
    "proposed": "the seed paper's proposed method (its Fig. 11): the elastic stiffness κ_x read once "
                "from the ±0.4 m loop at 0 V, then the same closed form on F − κ_x·x, with the seed's "
                "voltage laws",
    "normalized": "normalized Bouc-Wen model (no elastic term), closed form then least-squares "
                  "refinement at each voltage, parameters between voltages by the fitted voltage laws",
    "extended": "extended Bouc-Wen model: the normalized model plus an elastic term κ_x·x, κ_x read "
                "once from the large 0 V loop and held fixed, refined at each voltage, with voltage laws",
    "extended-free-kx": "the extended model with κ_x identified freely at each voltage",
    "closed-loop-normalized": "the normalized model with the effects the residual loop found from the "
                              "extended base, refitted jointly (the claim's pair: it differs from "
                              "closed-loop-extended only by the elastic term)",
    "closed-loop-extended": "the model the residual loop built from the extended base: the base plus "
                            "the effects it found in laboratory tests with changing voltage",
    "loop-from-normalized": "the residual loop's own result from the normalized base (it may add the "
                            "elastic term itself)",
}
_NAME_PARTS = {
    "-pchip": "parameters between the grid's voltages by monotone (PCHIP) interpolation instead of "
              "the voltage laws",
    "+lag": "driven by the commanded voltage through the identified first-order field filter "
            "(the coil's lag)",
    " (κ_x per voltage)": "κ_x identified freely at each voltage",
}


def explain_model_name(name: str) -> str | None:
    """Plain words for a model name of the identification's tables (``None`` if unknown)."""
    extras: list[str] = []
    base = name
    changed = True
    while changed:
        changed = False
        for suffix, words in _NAME_PARTS.items():
            if base.endswith(suffix) and base != suffix:
                base, changed = base[:-len(suffix)], True
                extras.insert(0, words)
    if base not in _MODEL_NAMES:
        return None
    return "; ".join([_MODEL_NAMES[base]] + extras)


def _glossary(names: Sequence[str]) -> str:
    """A definition list explaining each model name shown in the table just above."""
    items = []
    for name in dict.fromkeys(names):
        words = explain_model_name(name)
        items.append(f"<dt>{_e(name)}</dt><dd>{_e(words or 'a model given by the study (see validation.json)')}</dd>")
    return f'<dl class="glossary">{"".join(items)}</dl>' if items else ""


def _model_label(row: dict) -> str:
    mode = row.get("kappa_x_mode") or ""
    model = row.get("model", "")
    return f"{model} (κ_x per voltage)" if mode == "per-voltage" else model


def _grid_ends_and_middle(rows: list[dict]) -> list[dict]:
    """The rows at the lowest, middle and highest voltage of each model (the whole grid is long)."""
    keep = []
    for label in dict.fromkeys(_model_label(r) for r in rows):
        group = [r for r in rows if _model_label(r) == label]
        if len(group) <= 3:
            keep.extend(group)
            continue
        try:
            volts = sorted({float(r.get("voltage")) for r in group})
        except (TypeError, ValueError):
            keep.extend(group)
            continue
        wanted = {volts[0], volts[len(volts) // 2], volts[-1]}
        keep.extend(r for r in group if float(r.get("voltage")) in wanted)  # all parsed above
    return keep


#: What each case of the main job's diagnosis is (``diagnosis/<case>/``); other folders are named as they are.
_DIAGNOSIS_CASES = {
    "virtual": "the virtual benchmark damper (two periodic tests at 0 V, 1 % noise)",
    "utfsm_1A": "the measured UTFSM damper, its six sinusoidal tests at 1 A (last 25 % of each held out)",
    "dyke": "Dyke's measured prototype damper, random motion and switching voltage (last 30 % held out)",
}


def _finding_groups(findings: list[dict], kept: bool) -> list[str]:
    """The findings of one file, one line per kind and channel (a fault yields dozens of spans:
    the page says how many, where and how many samples; report.md lists each)."""
    groups: dict[tuple, list[dict]] = {}
    for f in sorted(findings, key=lambda f: float(f.get("t_start") or 0.0)):
        groups.setdefault((f.get("kind"), f.get("channel")), []).append(f)
    lines = []
    for (kind, channel), group in groups.items():
        t0 = min(float(f.get("t_start") or 0.0) for f in group)
        t1 = max(float(f.get("t_end") or 0.0) for f in group)
        where = f"{_num(t0, 3)} s" if t0 == t1 else f"{_num(t0, 3)}–{_num(t1, 3)} s"
        n = sum(int(f.get("n_samples") or 0) for f in group)
        excluded = any(f.get("excluded") for f in group)
        tail = "excluded" if excluded else "reported only"
        if kept and excluded and kind != "nan":
            tail = "kept (--keep-flagged)"
        spans = f"{len(group)} spans in {where}" if len(group) > 1 else f"at {where}"
        first = "first: " if len(group) > 1 else ""
        lines.append(f"<b>{_e(kind)}</b> ({_e(channel)}) {spans}, {n} samples [{tail}]; "
                     f"{first}{_e(group[0].get('message'))}")
    return lines


def _screening_table(screening: dict) -> str:
    """One row per file: samples, excluded, findings (what, where, how many), estimated lag."""
    rows = []
    for name, doc in screening.items():
        if not isinstance(doc, dict):
            continue
        findings = [f for f in doc.get("findings") or [] if isinstance(f, dict)]
        items = _finding_groups(findings, bool(doc.get("kept_flagged")))
        est = doc.get("estimates") or {}
        lag = est.get("force_velocity_lag_s")
        rows.append([_e(name), _e(doc.get("n_samples", "–")), _e(doc.get("n_excluded", "–")),
                     "<br>".join(items) or "nothing found",
                     "–" if lag is None else f"{_num(1e3 * float(lag), 1)} ms"])
    if not rows:
        return ""
    return (_table(["file", "samples", "excluded from fit and error",
                    "findings (what, where, how many samples; each span in report.md)",
                    "force–velocity lag (estimated)"], rows, left=(0, 3))
            + '<p class="note">The force–velocity lag is the cross-correlation delay of the force on the '
              "velocity: it holds the damper's own hysteresis (a yield-type force lags the velocity by a "
              "fraction of a period) as well as any offset between the channels, so it is reported, not "
              "corrected.</p>")


def _diagnosis_section(root: Path) -> str:
    folder = root / "diagnosis"
    out = ['<h2 id="diagnosis">Diagnosis: what the damper models lack</h2>']
    found = sorted(p.parent for p in folder.glob("*/diagnosis.json")) if folder.is_dir() else []
    if not found:
        return out[0] + _missing("the residual loop (diagnosis/*/diagnosis.json)")
    order = list(_DIAGNOSIS_CASES)
    found.sort(key=lambda p: (order.index(p.name) if p.name in order else len(order), p.name))
    out.append("<p>Held-out relative RMS force error of the base model before and after the "
               "residual loop, the effects it added (in order) and the structure left unexplained. "
               "Measured data are screened first: flagged samples count neither in the fit nor in "
               "the error.</p>")
    rows, cases = [], []
    for case in found:
        d = _read_json(case / "diagnosis.json") or {}
        effects = d.get("effects") or []
        names = ", ".join(str(e.get("name")) for e in effects if isinstance(e, dict)) or "none"
        unexplained = ", ".join(f"{u.get('variable')} ({_num(u.get('share'), 2)})"
                                for u in d.get("unexplained_in") or [] if isinstance(u, dict)) or "none"
        settings = d.get("settings") or {}
        seconds = _num(settings.get("seconds"), 1)
        if settings.get("stopped_by_budget"):
            seconds += f" (cut short by its {_num(settings.get('time_budget'), 0)} s budget)"
        rows.append([_link(root, case / "diagnosis.json", case.name), _e(d.get("model", "?")),
                     _pct(d.get("error_before")), _pct(d.get("error_after")), _e(names), _e(unexplained),
                     seconds])
        cases.append((case, d))
    out.append(_table(["data", "base model", "error before", "error after", "effects added",
                       "unexplained in (share)", "loop time [s]"], rows, left=(0, 1, 4, 5, 6)))
    if not any(case.name == "dyke" for case, _ in cases):
        out.append('<p class="note">The shared Dyke recording (a real damper under random motion and '
                   "switching voltage) joins this section with <code>sbib study --dyke</code> (its "
                   "Spencer base fit takes about half a minute of one core); alone: <code>sbib diagnose "
                   "--data …/ransim_u_converted.csv --model spencer --holdout 0.3</code>.</p>")
    for case, d in cases:
        data = [case / "diagnosis.json", case / "report.md"]
        out.append(f'<h3 id="diagnosis-{_e(case.name)}">{_e(case.name)}: '
                   f"{_e(_DIAGNOSIS_CASES.get(case.name, 'data of ' + case.name))}</h3>")
        settings = d.get("settings") or {}
        if settings.get("stopped_by_budget"):
            out.append(f'<p class="note">The time budget ({_num(settings.get("time_budget"), 0)} s) ended '
                       "the effect selection: the model found so far is shown.</p>")
        if settings.get("decimation", 1) and settings.get("decimation", 1) > 1:
            windows = settings.get("coarse_windows") or 0
            out.append(f'<p class="note">Fitted on one sample in {_e(settings.get("decimation"))}'
                       + (f" over {_e(windows)} windows of the tests" if windows else "")
                       + " (errors, figures and verdict on every sample).</p>")
        screening = d.get("screening")
        if isinstance(screening, dict) and screening:
            out.append("<p>Screening of the measured data:</p>" + _screening_table(screening))
        checks = [text for text, _ in interference_lines(d.get("interference") if isinstance(d.get("interference"), dict)
                                                       else None)]
        levels = d.get("force_levels")
        checks += [text for text, _ in level_lines(levels if isinstance(levels, dict) else None)]
        if settings.get("dropped_at_full_rate"):
            checks.append("left out: " + ", ".join(map(str, settings["dropped_at_full_rate"]))
                          + " (chosen on the coarse pass, no lower held-out error over every sample)")
        out += [f'<p class="note">{_e(text[0].upper() + text[1:])}.</p>' for text in checks]
        out.append(_figure(root, case / "force_window.png",
                           f"{case.name}: measured force, base model and augmented model over a window of "
                           "the held-out part (top) and the residual of each (bottom).", data))
        out.append(_figure(root, case / "residual_trace.png",
                           f"{case.name}: held-out residual against each variable, before and after.", data))
        out.append(_figure(root, case / "loops.png",
                           f"{case.name}: held-out loops, measured, base model and augmented model.", data))
    return "".join(out)


def _records_section(root: Path) -> str:
    folder = root / "records"
    catalogue = _read_json(folder / "catalogue.json")
    out = ['<h2 id="records">Records</h2>']
    if not isinstance(catalogue, dict):
        return out[0] + _missing("the record catalogue (records/catalogue.json)")
    records = [r for r in catalogue.get("records") or [] if isinstance(r, dict)]
    rows = [[_e(r.get("name")), "yes" if r.get("found") else "no",
             " / ".join(_num(v, 3) for v in r.get("pga_g") or []) or "–",
             _num(r.get("duration_s"), 1), _num(r.get("dt_s"), 3),
             _e("; ".join(str(f.get("message", f)) if isinstance(f, dict) else str(f)
                          for f in r.get("flaws") or []) or "none")] for r in records]
    if rows:
        out.append(_table(["record", "found", "PGA [g] (col. 1 / 2)", "duration [s]", "dt [s]", "flaws"], rows,
                          left=(0, 5)))
    out.append(f'<p class="note">{_data_links(root, [folder / "catalogue.json"])}</p>')
    out.append(_figure(root, folder / "spectra.png", "5 %-damped response spectra of the records.",
                       [folder / "catalogue.json"]))
    return "".join(out)


#: The device-family study as measured by ``examples/device_family.py`` (2026-11-24), shown when
#: the results folder holds no run of its own (the study is six identification studies: not part
#: of the main job).
DEVICE_FAMILY_RECORD = Path(__file__).resolve().parents[2] / "docs" / "data" / "device_family.json"


def _device_family_section(root: Path) -> str:
    """The seed's claim across a family of virtual devices: ``RESULTS/device-family/family.json``
    (``examples/device_family.py --out RESULTS/device-family``) when present, else the recorded
    run :data:`DEVICE_FAMILY_RECORD`, labelled as such; nothing when neither exists."""
    path = root / "device-family" / "family.json"
    rows = _read_json(path)
    source = _data_links(root, [path])
    if not isinstance(rows, list) or not rows:
        rows = _read_json(DEVICE_FAMILY_RECORD)
        source = ("recorded run: <code>docs/data/device_family.json</code> (examples/device_family.py, "
                  "2026-11-24; not re-run by the main job)")
    if not isinstance(rows, list) or not rows:
        return ""
    body = []
    for row in rows:
        cells = [f"<code>{_e(row.get('variant'))}</code>: {_e(row.get('description', ''))}"]
        for pair in ("seed", "closed_loop"):
            c = (row.get("claim_test") or {}).get(pair) or {}
            ratios = list((c.get("ratio_by_run") or {}).values())
            cells += [_num(c.get("ratio_mean"), 2),
                      f"{_num(min(ratios), 2)}–{_num(max(ratios), 2)}" if ratios else "–",
                      f"{sum(r < 1 for r in ratios)}/{len(ratios)}" if ratios else "–"]
        body.append(cells)
    return ('<h2 id="device-family">The seed\'s claim across devices</h2>'
            "<p>Extended form's relative RMS force error over the normalized form's in the earthquake runs "
            "(below 1: the extended form is better), per device variant, for the seed's pair (proposed / "
            "original) and the closed loop's pair. " + source + "</p>"
            + _table(["device", "seed: mean", "range", "below 1", "closed loop: mean", "range", "below 1"],
                     body))


def build_report_html(results: str | Path) -> str:
    """Return the HTML text of the report of the results directory ``results``.

    Parameters
    ----------
    results : str | Path
        The results directory (of ``sbib study``).
    """
    root = Path(results)
    summary = _read_json(root / "summary.json")
    steps = summary.get("steps", {}) if isinstance(summary, dict) else {}
    meta = [f"results directory: <code>{_e(root.resolve().name)}</code>"]
    if isinstance(summary, dict) and summary.get("elapsed_s") is not None:
        meta.append(f"main job: {_num(summary['elapsed_s'], 1)} s")
    try:
        p = provenance()
        meta.append(f"sbib {_e(p.get('package_version', '?'))}, commit {_e(str(p.get('git_commit', '?'))[:12])}, "
                    f"written {_e(p.get('created_utc', '?'))}")
    except Exception:  # noqa: BLE001 - provenance is informative only; never fail the report on it
        pass
    timings = [[_e(name), _num(step.get("elapsed_s"), 1)] for name, step in steps.items()
               if isinstance(step, dict)]
    parts = [
        "<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        "<title>sbib results report</title>", f"<style>{_CSS}</style></head><body>",
        "<h1>Smart base-isolated benchmark: results</h1>",
        f'<p class="meta">{" · ".join(meta)}</p>',
        '<p>Sections: <a href="#suite">controllers (J1–J9)</a> · <a href="#identification">identification</a>'
        ' · <a href="#diagnosis">diagnosis</a> · <a href="#records">records</a>. SI units unless stated; '
        "every table and figure links to its data file. "
        + (_link(root, root / "summary.json", "summary.json") + " lists every step's outputs." if (root / "summary.json").is_file() else "")
        + "</p>",
        _suite_section(root), _identification_section(root), _diagnosis_section(root), _records_section(root),
        _device_family_section(root),
    ]
    if timings:
        parts.append('<h2 id="timings">Steps</h2>' + _table(["step", "time [s]"], timings))
    parts.append("</body></html>\n")
    return "\n".join(parts)


def write_report(results: str | Path, out: str | Path | None = None) -> Path:
    """Write ``report.html`` for the results directory ``results`` (atomically) and return its path.

    Parameters
    ----------
    results : path-like
        A directory written by ``sbib study`` (or part of one).
    out : path-like, optional
        The HTML file; default ``results/report.html``. Figures and data are linked by paths
        relative to it, so it must lie inside ``results``.

    Raises
    ------
    InputError
        If ``results`` is not a directory, or ``out`` lies outside it.
    """
    root = Path(results)
    if not root.is_dir():
        raise InputError(f"results directory {root} does not exist; expected the --out folder of sbib study")
    target = Path(out) if out is not None else root / REPORT_NAME
    if target.resolve().parent != root.resolve():
        raise InputError(f"report {target}: expected a file directly inside {root} (links are relative to it)")
    return atomic_write_text(target, build_report_html(root))


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m benchmark.applications.report RESULTS_DIR``: (re)write RESULTS_DIR/report.html."""
    import argparse

    parser = argparse.ArgumentParser(prog="python -m benchmark.applications.report",
                                     description="Write report.html for a results directory of sbib study.")
    parser.add_argument("results", help="results directory (the --out of sbib study)")
    args = parser.parse_args(argv)
    try:
        path = write_report(args.results)
    except InputError as exc:
        print(f"sbib: error: {exc}", file=sys.stderr)
        return 2
    print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
