"""A misspelt model name lists what the module or file really offers and the close matches."""

from __future__ import annotations

import pytest

from bgmodelica.errors import ModelLoadError
from bgmodelica.loader import load_model, module_models


def test_package_lists_re_exported_models_and_suggests():
    with pytest.raises(ModelLoadError) as err:
        load_model("library.examples:RCLader")
    text = str(err.value)
    assert "\n" not in text
    assert "did you mean RCLadder" in text
    assert "no models" not in text
    assert "DCMotor" in text and "SeriesRLC" in text          # re-exported from submodules


def test_case_only_difference_is_suggested():
    with pytest.raises(ModelLoadError, match="did you mean RC[,?]"):
        load_model("library.examples.circuits:rc")


def test_file_lists_its_own_models_not_imported_parts(tmp_path):
    path = tmp_path / "my_circuit.py"
    path.write_text(
        "from bgmodelica import Component, Connector, connect, sin\n"
        "from library.electrical import Capacitor, Ground, Resistor\n\n"
        "class Divider(Component):\n"
        "    R = Resistor(R=1.0)\n\n"
        "def divider_of(n: int = 2):\n"
        "    return Divider()\n\n"
        "class Pin2(Connector):\n"
        "    pass\n\n"
        "GAIN = 2.0\n")
    with pytest.raises(ModelLoadError) as err:
        load_model(f"{path}:Dividr")
    text = str(err.value)
    assert "did you mean Divider" in text
    assert "it offers: Divider, divider_of)" in text


def test_empty_module_says_no_models(tmp_path):
    path = tmp_path / "empty_models.py"
    path.write_text("X = 1\n")
    with pytest.raises(ModelLoadError, match="offers no models"):
        load_model(f"{path}:M")


def test_module_models_of_the_examples():
    import library.examples as examples
    assert set(examples.__all__) <= set(module_models(examples))
