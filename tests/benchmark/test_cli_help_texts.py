"""Every ``sbib`` sub-command's ``--help`` reads as plain text: no raw reST markup from the
docstrings it is built from, and every option says what it is."""

from __future__ import annotations

import argparse
import re

import pytest

from benchmark.applications.cli import build_parser

#: reST that must not reach a terminal: inline literals, roles, literal-block markers
RAW_REST = re.compile(r"``|:(?:mod|func|class|meth|attr|data|ref|doc):|::\s*$", re.MULTILINE)


def _subparsers(parser: argparse.ArgumentParser, prefix: str = "sbib"):
    yield prefix, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _subparsers(sub, f"{prefix} {name}")


ALL = list(_subparsers(build_parser()))


def test_every_command_is_walked():
    names = {name for name, _ in ALL}
    assert {"sbib run", "sbib compare", "sbib damper test", "sbib diagnose", "sbib identify"} <= names


@pytest.mark.parametrize("name, parser", ALL, ids=[n for n, _ in ALL])
def test_help_has_no_raw_rest(name, parser):
    text = parser.format_help()
    bad = [m.group(0) for m in RAW_REST.finditer(text)]
    assert not bad, f"{name} --help shows raw reST {bad}:\n{text}"


@pytest.mark.parametrize("name, parser", ALL, ids=[n for n, _ in ALL])
def test_every_option_has_help(name, parser):
    missing = [a.option_strings[0] for a in parser._actions
               if a.option_strings and a.help in (None, "") and not isinstance(a, argparse._HelpAction)]
    assert not missing, f"{name}: options without help text: {missing}"


def test_run_help_lists_the_controllers():
    from controllers.registry import controller_names

    parser = dict(ALL)["sbib run"]
    text = " ".join(parser.format_help().split())
    for name in controller_names():
        assert name in text, f"sbib run --help does not list the controller {name!r}"


def test_diagnose_help_explains_its_terms():
    text = " ".join(dict(ALL)["sbib diagnose"].format_help().split())
    # what held-out BIC means, what the effects are, what --coarse-samples counts, what it writes
    assert "Bayesian information criterion" in text
    assert "held-out" in text and "not used in the fit" in text
    assert "samples per test" in text or "samples in all" in text
    assert "example" in text.lower()
    assert "report.md" in text and "diagnosis.json" in text
