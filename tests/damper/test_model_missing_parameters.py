"""A damper model built without its parameters fails with one line that names them all
(a ParameterError the CLI prints as one line), not with a TypeError traceback."""

from __future__ import annotations

import dataclasses

import pytest

import damper
from benchmark.foundation.errors import ParameterError
from damper.models.registry import MODELS


def _required(cls) -> list[str]:
    return [f.name for f in dataclasses.fields(cls) if f.init and f.default is dataclasses.MISSING
            and f.default_factory is dataclasses.MISSING]


def test_spencer_without_parameters_names_them():
    with pytest.raises(ParameterError) as info:
        damper.get_model_class("spencer")()
    message = str(info.value)
    assert "\n" not in message and "spencer" in message
    for name in _required(damper.get_model_class("spencer")):
        assert name in message


@pytest.mark.parametrize("name", sorted(MODELS))
def test_every_registered_model_names_missing_and_unknown_parameters(name):
    cls = MODELS[name]
    required = _required(cls)
    if required:
        with pytest.raises(ParameterError, match="missing required parameter"):
            cls()
    with pytest.raises(ParameterError, match="unknown parameter no_such_thing"):
        cls(no_such_thing=1.0)
