"""Function calls on time-varying values in when-clauses, run on numbers at events, against
values worked out by hand."""

from __future__ import annotations

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica.modelica import ModelicaError, load_modelica_text

HALVINGS = """
function halvings "How often x is halved until it is below 1"
  input Real x;
  output Integer n;
  output Real rest "x/2^n";
algorithm
  n := 0;
  rest := x;
  while rest >= 1 loop
    rest := rest/2;
    n := n + 1;
  end while;
end halvings;
"""


def _package(body: str) -> str:
    return f"package P\n{HALVINGS}\nmodel M\n{body}\nend M;\nend P;\n"


def _at(r, name: str, t: float) -> float:
    return float(r[name][np.argmin(np.abs(r.time - t))])


def test_while_loop_over_a_time_varying_argument_in_a_when_statement():
    # x = 10*t sampled at 0.25, 0.5, 0.75: 2.5 -> 2 halvings (0.625), 5 -> 3 (0.625),
    # 7.5 -> 3 (0.9375); the guarded call runs only where x > 6
    body = ("  Real x = 10*time;\n  discrete Integer k(start = -1, fixed = true);\n"
            "  discrete Real r(start = 0, fixed = true);\n"
            "  discrete Integer g(start = 0, fixed = true);\n"
            "algorithm\n  when sample(0.25, 0.25) then\n    (k, r) := halvings(x);\n"
            "    if x > 6 then\n      g := halvings(x + 10);\n    else\n      g := -1;\n"
            "    end if;\n  end when;\n")
    model = load_modelica_text(_package(body), "P.M")
    r = bg.simulate(model, stop_time=0.9, interval=0.05)
    assert _at(r, "k", 0.1) == -1
    assert (_at(r, "k", 0.3), _at(r, "r", 0.3)) == (2, 0.625)
    assert (_at(r, "k", 0.6), _at(r, "r", 0.6)) == (3, 0.625)
    assert (_at(r, "k", 0.85), _at(r, "r", 0.85)) == (3, 0.9375)
    # x + 10 = 17.5 at t = 0.75: 5 halvings; before, the else-branch
    assert (_at(r, "g", 0.3), _at(r, "g", 0.6), _at(r, "g", 0.85)) == (-1, -1, 5)


def test_while_loop_over_a_time_varying_argument_in_a_when_equation():
    body = ("  Real x = 10*time;\n  discrete Integer k(start = 0, fixed = true);\nequation\n"
            "  when time >= 0.42 then\n    k = halvings(x);\n  end when;\n")
    r = bg.simulate(load_modelica_text(_package(body), "P.M"), stop_time=0.6, interval=0.05)
    assert _at(r, "k", 0.3) == 0
    assert _at(r, "k", 0.55) == 3          # x = 4.2: 2.1, 1.05, 0.525


def test_outside_a_when_clause_the_loop_is_refused_in_one_line():
    body = "  Real x = 10*time;\n  Real k = halvings(x);\n"
    with pytest.raises(ModelicaError, match=r"^\S+:\d+:\d+: while-loop condition depends on "
                       "time-varying values") as err:
        bg.compile(load_modelica_text(_package(body), "P.M"))
    assert "\n" not in str(err.value)


def test_string_of_known_values():
    body = ('  parameter String s = String(2.5) + "|" + String(3) + "|" + String(true) + "|"'
            ' + String(1/3, significantDigits = 3) + "|" + String(7, minimumLength = 3,'
            ' leftJustified = false);\n'
            '  Real y = if s == "2.5|3|true|0.333|  7" then 1 else 0;\n')
    r = bg.simulate(load_modelica_text(_package(body), "P.M"), stop_time=0.1)
    assert r["y"][-1] == 1
