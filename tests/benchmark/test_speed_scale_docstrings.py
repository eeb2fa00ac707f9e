"""Every public name of the speed-and-scale modules documents itself and its arguments."""

from __future__ import annotations

import importlib
import inspect

import pytest

MODULES = ["benchmark.applications.ensemble", "benchmark.applications.ensemble_journal", "benchmark.applications.ensemble_simulation",
           "benchmark.applications.fragility", "benchmark.applications.speed", "benchmark.simulator.oracle", "benchmark.applications.cli_ensemble",
           "benchmark.applications.cli_bench"]


@pytest.mark.parametrize("module_name", MODULES)
def test_public_names_are_documented(module_name):
    module = importlib.import_module(module_name)
    assert module.__doc__ and module.__all__
    missing = []
    for name in module.__all__:
        obj = getattr(module, name)
        if not (inspect.isfunction(obj) or inspect.isclass(obj)):
            continue
        doc = inspect.getdoc(obj) or ""
        if not doc:
            missing.append(f"{name}: no docstring")
            continue
        if inspect.isclass(obj):
            continue
        for arg in inspect.signature(obj).parameters:
            if arg.startswith("_") or arg in ("args", "kwargs", "config_options"):
                continue
            if arg not in doc:
                missing.append(f"{name}: argument {arg!r} not documented")
    assert not missing, "\n".join(missing)
