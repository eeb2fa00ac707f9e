"""Every model name in the report's identification tables is explained on the page, and the
J formulas are page text (issue 22 item 6)."""

from __future__ import annotations

import json
import re

from benchmark.applications.report import build_report_html, explain_model_name
from benchmark.simulator.criteria import CRITERIA

NAMES = ["original", "proposed", "normalized", "extended", "normalized+lag", "extended+lag",
         "extended-free-kx", "extended-free-kx+lag", "extended-free-kx-pchip", "extended-free-kx-pchip+lag",
         "loop-from-normalized", "closed-loop-normalized", "closed-loop-extended"]


def test_every_study_model_name_has_words():
    missing = [n for n in NAMES if not explain_model_name(n)]
    assert not missing
    assert "commanded voltage" in explain_model_name("extended+lag")
    assert explain_model_name("no-such-model") is None


def test_validation_table_names_are_explained_on_the_page(tmp_path):
    folder = tmp_path / "identification"
    folder.mkdir()
    summary = {n: {"mean_rel_rms_error": 0.1, "max_rel_rms_error": 0.2, "mean_peak_error": 0.1,
                   "mean_energy_error": 0.1} for n in NAMES}
    (folder / "validation.json").write_text(json.dumps({"controller": "clipped-optimal", "models": NAMES,
                                                        "summary": summary, "errors": {}}))
    page = build_report_html(tmp_path)
    explained = set(re.findall(r'<dl class="glossary">.*?</dl>', page, flags=re.S)[0].split("<dt>"))
    for name in NAMES:
        assert any(part.startswith(f"{name}</dt><dd>") for part in explained), name


def test_j_formulas_are_page_text():
    import html

    from benchmark.applications.report import _j_key

    key = html.unescape(_j_key())
    for criterion in CRITERIA.values():
        assert criterion.formula in key, criterion.key
