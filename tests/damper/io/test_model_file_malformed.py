"""Damper model files of the wrong shape: one line naming the file and the field, never a traceback."""

from __future__ import annotations

import json

import pytest

from benchmark.foundation.errors import InputError
from damper.io.model_file import InputSpec, read_model_file, write_model_file
from damper.models.bouc_wen import NormalizedBoucWen
from damper.models.voltage_laws import Tabulated


def _doc(tmp_path):
    model = NormalizedBoucWen(kappa_xdot=Tabulated((0.0, 0.5, 1.0), (1500.0, 4300.0, 7700.0)),
                              kappa_w=Tabulated((0.0, 0.5, 1.0), (130.0, 700.0, 1130.0)),
                              rho=3000.0, sigma=1.1, n=2.5)
    path = write_model_file(tmp_path / "good.json", model, input=InputSpec("current", "A", (0.0, 1.0), ()))
    return json.loads(path.read_text())


@pytest.mark.parametrize("mutate, words", [
    (lambda d: d.update(model=["normalized_bouc_wen"]), "model: expected a model name"),
    (lambda d: d["input"].update(quantity=["current"]), "input.quantity"),
    (lambda d: d["parameters"]["kappa_w"].update(law=["tabulated"]), "parameters.kappa_w: law"),
    (lambda d: d.update(effects=[{"name": ["roll_off"], "value": 0.01, "unit": "m/s"}]), "unknown effect"),
    (lambda d: d["parameters"]["kappa_w"].update(inputs=[0.5, 0.0, 1.0]), "parameters.kappa_w: Tabulated"),
    (lambda d: d.update(quality="good"), "quality: expected an object"),
    (lambda d: d.update(notes="one note"), "notes: expected a list"),
])
def test_wrong_types_are_one_line_naming_file_and_field(tmp_path, mutate, words):
    doc = _doc(tmp_path)
    mutate(doc)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(InputError) as info:
        read_model_file(path)
    message = str(info.value)
    assert str(path) in message and "\n" not in message and words in message, message


def test_deeply_nested_json_is_an_input_error(tmp_path):
    path = tmp_path / "deep.json"
    path.write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(InputError, match="nested too deeply"):
        read_model_file(path)


def test_truncated_file_names_the_line(tmp_path):
    text = json.dumps(_doc(tmp_path), indent=1)
    path = tmp_path / "cut.json"
    path.write_text(text[: len(text) // 2])
    with pytest.raises(InputError, match=r"cut\.json:\d+: not a JSON file"):
        read_model_file(path)


def test_a_byte_order_mark_is_accepted(tmp_path):
    path = tmp_path / "bom.json"
    path.write_bytes(b"\xef\xbb\xbf" + json.dumps(_doc(tmp_path)).encode())
    assert read_model_file(path).input.quantity == "current"


def test_a_directory_is_not_reported_missing(tmp_path):
    (tmp_path / "model.json").mkdir()
    with pytest.raises(InputError, match="not a regular file"):
        read_model_file(tmp_path / "model.json")
