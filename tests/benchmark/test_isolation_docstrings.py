"""Every public function of the isolation and output modules documents itself and its arguments."""

from __future__ import annotations

import importlib
import inspect

import pytest

MODULES = ["benchmark.simulator.isolation.registry", "benchmark.simulator.isolation.configurations",
           "benchmark.simulator.isolation.linear", "benchmark.simulator.isolation.lead_rubber",
           "benchmark.simulator.isolation.friction_pendulum", "benchmark.simulator.isolation.park_wen",
           "benchmark.simulator.isolation.base", "benchmark.simulator.evaluation", "benchmark.simulator.results",
           "benchmark.simulator.plots", "benchmark.applications.cli_run"]

# arguments that are self-explanatory positional kernel arguments, documented once in the
# module docstring of benchmark.simulator.isolation.registry (the dispatch contract)
KERNEL_ARGS = {"params", "state", "ux0", "uy0", "ux1", "uy1", "vx0", "vy0", "vx1", "vy1", "dt",
               "force_out", "ux", "uy", "vx", "vy", "hysteretic_force", "offset"}


@pytest.mark.parametrize("module_name", MODULES)
def test_public_names_are_documented(module_name):
    module = importlib.import_module(module_name)
    assert module.__doc__ and module.__all__
    missing = []
    for name in module.__all__:
        obj = getattr(module, name)
        if not (inspect.isfunction(obj) or inspect.isclass(obj) or hasattr(obj, "py_func")):
            continue
        doc = inspect.getdoc(obj) or ""
        if not doc:
            missing.append(f"{name}: no docstring")
            continue
        func = getattr(obj, "py_func", obj)
        if inspect.isclass(func):
            continue
        for arg in inspect.signature(func).parameters:
            if arg in KERNEL_ARGS or arg.startswith("_") or arg in ("args", "kwargs", "extra"):
                continue
            if arg not in doc:
                missing.append(f"{name}: argument {arg!r} not documented")
    assert not missing, "\n".join(missing)
