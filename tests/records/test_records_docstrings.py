"""Every public function and class of the records package documents every argument (numpydoc style)."""

from __future__ import annotations

import importlib
import inspect

import pytest

MODULES = ["records.record", "records.readers", "records.catalogue", "records.checks", "records.baseline",
           "records.spectra", "records.synthetic", "records.pulse", "records.measures", "records.plots",
           "records.report"]


def _public(module):
    for name in module.__all__:
        obj = getattr(module, name)
        if inspect.isfunction(obj) or inspect.isclass(obj):
            yield name, obj


@pytest.mark.parametrize("module_name", MODULES)
def test_public_api_is_documented(module_name):
    module = importlib.import_module(module_name)
    assert module.__doc__ and len(module.__doc__) > 80, module_name
    missing = []
    for name, obj in _public(module):
        doc = inspect.getdoc(obj) or ""
        if not doc:
            missing.append(f"{name}: no docstring")
            continue
        target = obj.__init__ if inspect.isclass(obj) and not hasattr(obj, "__dataclass_fields__") else obj
        try:
            params = [p for p in inspect.signature(target).parameters if p not in ("self", "cls")]
        except (TypeError, ValueError):
            continue
        if inspect.isclass(obj) and hasattr(obj, "__dataclass_fields__"):
            params = list(obj.__dataclass_fields__)
        for p in params:
            if p not in doc:
                missing.append(f"{name}: argument {p!r} not documented")
    assert not missing, "\n".join(missing)
