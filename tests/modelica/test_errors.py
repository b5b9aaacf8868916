"""Malformed or unsupported Modelica: one line naming file:line:column and the construct."""

from __future__ import annotations

import re

import pytest

from bgmodelica.cli import main
from bgmodelica.modelica import ModelicaError, ModelicaSyntaxError, load_modelica_text

CASES = [
    # (text, line, column, phrase)
    ("model M\n  Real x(start=1);\nequation\n  der(x) = -x +;\nend M;\n", 4, 16,
     "unexpected ';'"),
    ("model M\n  Real x;\nequation\n  der(x) = -x;\nend N;\n", 5, 5, "closed by 'end N'"),
    ("model M\n  Real x;\nequation\n  x = 1 \"open string;\nend M;\n", 4, 9,
     "unterminated string"),
    ("model M\n  Real x;\nequation\n  der(x) = -x\nend M;\n", 5, 1, "unexpected 'end'"),
    ("model M\n  Real x;\n", 2, 10, "unexpected end of file"),
    ("model M\n  Real x # 2;\nend M;\n", 2, 10, "unexpected character '#'"),
    ("model M\n  inner Real x;\nequation\n  x = 1;\nend M;\n", 2, 14,
     "unsupported Modelica construct: inner"),
    ("model M\n  Real x;\nequation\n  der(x) = -y;\nend M;\n", 4, 13, "unknown name 'y'"),
    ("model M\n  Real x;\nequation\n  x = f(time);\nend M;\n", 4, 7, "unknown function f()"),
    ("model M\n  Modelica.Electrical.Analog.Basic.HeatingResistor r;\nend M;\n", 2, 52,
     "not in bgmodelica's MSL subset"),
    ("model M\n  Real x;\nequation\n  reinit(x, 1);\nend M;\n", 4, 3,
     "reinit() is allowed only inside a when-equation"),
    ("model M\n  Resistor r;\nend M;\n", 2, 12, "unknown class 'Resistor'"),
    ("model M\n  parameter Real p = 1;\n  Real x[p + q];\nend M;\n", 3, 14,
     "unknown name 'q'"),
    ("model M\n  Real v;\n  Real x[v];\nequation\n  v = 1;\nend M;\n", 3, 8,
     "array size of x must be known when the model is built"),
    ("model M\n  Real x(foo = 1);\nequation\n  x = 1;\nend M;\n", 2, 10,
     "'foo' is not an attribute"),
    ("model M\n  Real x;\nequation\n  for i in 1:2 loop\n    x = i;\n  end for;\n"
     "  x = 1 + {1, 2};\nend M;\n", 7, 3, "array equation with a scalar side"),
]


@pytest.mark.parametrize("text, line, col, phrase", CASES,
                         ids=[c[3].split(":")[-1].strip()[:30] for c in CASES])
def test_positioned_errors(text, line, col, phrase):
    with pytest.raises(ModelicaError) as info:
        load_modelica_text(text, "M", file="bad.mo")
    msg = str(info.value)
    assert "\n" not in msg
    assert msg.startswith(f"bad.mo:{line}:{col}: "), msg
    assert phrase in msg, msg


def test_syntax_error_attributes():
    with pytest.raises(ModelicaSyntaxError) as info:
        load_modelica_text("model M\n  Real x\nend M;\n", file="m.mo")
    err = info.value
    assert (err.file, err.line, err.column) == ("m.mo", 3, 1)


def test_cli_malformed_file_one_line(tmp_path, capsys):
    bad = tmp_path / "bad.mo"
    bad.write_text("package P\n  model M\n    Real x(start = 1);\n  equation\n"
                   "    der(x) = -x +;\n  end M;\nend P;\n")
    for cmd in (["simulate", f"{bad}:P.M", "-o", str(tmp_path / "x.csv")],
                ["check", f"{bad}:P.M"], ["export-mo", f"{bad}:P.M", "-o",
                                          str(tmp_path / "y.mo")]):
        assert main(cmd) == 2
        err = capsys.readouterr().err
        lines = err.strip().splitlines()
        assert len(lines) == 1, err
        assert re.match(rf"error: ModelicaSyntaxError: {re.escape(str(bad))}:5:18: ", lines[0]), \
            lines[0]
    assert not (tmp_path / "x.csv").exists() and not (tmp_path / "y.mo").exists()


def test_cli_missing_file_and_class(tmp_path, capsys):
    assert main(["check", str(tmp_path / "nope.mo:P.M")]) == 2
    assert "does not exist" in capsys.readouterr().err
    good = tmp_path / "good.mo"
    good.write_text("package P\n  model M\n    Real x(start = 1, fixed = true);\n"
                    "  equation\n    der(x) = -x;\n  end M;\nend P;\n")
    assert main(["check", f"{good}:P.Q"]) == 2
    err = capsys.readouterr().err
    assert "no class 'P.Q'" in err and "P.M" in err


def test_modifier_of_unknown_element():
    text = ("model R\n  parameter Real R = 1;\nend R;\n"
            "model M\n  R r(Q = 2);\nend M;\n")
    with pytest.raises(ModelicaError, match=r"bad.mo:5:7: .*no element 'Q'"):
        load_modelica_text(text, "M", file="bad.mo")


def test_msl_parameter_outside_mapping():
    text = ("model M\n  Modelica.Electrical.Analog.Basic.Resistor r(useHeatPort = true);\n"
            "end M;\n")
    with pytest.raises(ModelicaError, match="useHeatPort = True is not supported"):
        load_modelica_text(text, "M", file="bad.mo")


def test_unbalanced_model_is_reported_by_the_compiler():
    import bgmodelica as bg
    from bgmodelica.errors import UnbalancedModelError

    model = load_modelica_text("model M\n  Real x, y;\nequation\n  der(x) = -x;\nend M;\n")
    with pytest.raises(UnbalancedModelError):
        bg.compile(model)
