"""Modelica ``assert`` in models: checked while simulating (the run stops at the first output
time where the condition is false, with the message and the rows before), a warning level
that only warns, a condition false when the model is built refused then."""

from __future__ import annotations

import pytest

import bgmodelica as bg
from bgmodelica.asserts import AssertionWarning
from bgmodelica.cli import main
from bgmodelica.errors import AssertionViolation
from bgmodelica.modelica import ModelicaError, load_modelica_text

TEXT = """model A
  parameter Real limit = 0.5;
  Real x(start = 0, fixed = true);
equation
  der(x) = 1;
  assert(x < limit, "x too large");
  assert(x < 0.2, "x above 0.2", AssertionLevel.warning);
end A;
"""


def test_a_violated_assert_stops_the_run_at_its_time():
    with pytest.warns(AssertionWarning, match=r"t = 0.2\d* s .*x above 0.2"):
        with pytest.raises(AssertionViolation, match=r"assert failed at t = 0.5\d* s "
                                                     r"\[top level \(A\)\]: x too large "
                                                     r"\(<string>:6:3\)") as info:
            bg.simulate(load_modelica_text(TEXT, "A"), stop_time=1.0, interval=0.01)
    err = info.value
    assert 0.5 <= err.time_reached <= 0.52                    # x = t crosses 0.5 at t = 0.5
    assert err.result is not None and err.result.time[-1] < err.time_reached
    assert (err.result["x"] < 0.5 + 1e-9).all()


def test_a_held_assert_lets_the_run_finish():
    with pytest.warns(AssertionWarning):
        r = bg.simulate(load_modelica_text(TEXT, "A", limit=2.0), stop_time=1.0)
    assert r.time[-1] == pytest.approx(1.0)


def test_an_assert_false_when_built_is_refused():
    text = "model B\n  parameter Real k = -1;\n  Real x = k;\nequation\n" \
           "  assert(k > 0, \"k must be positive\");\nend B;\n"
    with pytest.raises(ModelicaError, match=r"<string>:5:3: assert failed: k must be positive"):
        load_modelica_text(text, "B")


def test_the_command_line_says_it_in_one_line(tmp_path, capsys):
    path = tmp_path / "a.mo"
    path.write_text(TEXT)
    assert main(["simulate", f"{path}:A", "--stop-time", "1", "-o",
                 str(tmp_path / "a.csv")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "assert failed at t = 0.5" in err[0] and "a.mo:6:3" in err[0]
