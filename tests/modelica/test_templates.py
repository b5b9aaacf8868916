"""Equations of many instances of one Modelica class evaluated once
(``bgmodelica.modelica.builder.templates``): copies equal to evaluations, classes whose
equations a parameter can change left to evaluation, groups written once as array
equations giving the scalar pipeline's and the Python library's results."""

from __future__ import annotations

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica.array_path import ArrayCompiledModel
from bgmodelica.core.flatten_vectorized import array_equations
from bgmodelica.modelica import load_modelica_text
from bgmodelica.modelica.builder.equations import equations_of

CHAIN = """
model Chain
  model Cell
    parameter Real k = 1;
    parameter Boolean damped = false;
    Real x(start = 1, fixed = true);
    Real y;
  equation
    der(x) = -k*x + 1;
    y = 2*x - sin(k);
  end Cell;
  model Switched
    parameter Boolean damped = false;
    Real x(start = 1, fixed = true);
  equation
    if damped then
      der(x) = -x;
    else
      der(x) = 0;
    end if;
  end Switched;
  parameter Integer n = 70;
  Cell c[n](k = {0.5 + i/n for i in 1:n});
  Switched s[n](damped = {mod(i, 2) == 0 for i in 1:n});
end Chain;
"""


def _text(eqs) -> list[str]:
    return [repr(eq) for eq in eqs]


def test_copies_equal_the_evaluation_of_each_instance(monkeypatch):
    import importlib

    instantiate = importlib.import_module("bgmodelica.modelica.builder.instantiate")
    model = load_modelica_text(CHAIN, "Chain")
    cells = [model._children[f"c[{i}]"] for i in range(1, 71)]
    evaluated = []
    monkeypatch.setattr(instantiate, "equations_of",
                        lambda *a, **k: evaluated.append(1) or equations_of(*a, **k))
    got = [cell.equations() for cell in cells]
    assert len(evaluated) == 1       # the first was evaluated at load, the second here
    for cell, eqs in zip(cells, got, strict=True):
        env = cell.__dict__["_mo_env"]
        again = equations_of(env, env.view.equations)
        assert _text(eqs) == _text(again)
        leaves = {id(leaf.sym) for eq in eqs for leaf in _leaves(eq)}
        assert leaves == {id(leaf.sym) for eq in again for leaf in _leaves(eq)}
        assert id(cell._symbols["x"]) in leaves                 # its own symbols


def _leaves(eq):
    from bgmodelica.core.expr import Leaf

    out = []

    def walk(e):
        if isinstance(e, Leaf):
            out.append(e)
        for a in getattr(e, "args", ()):
            walk(a)

    walk(eq.lhs)
    walk(eq.rhs)
    return out


def test_equations_a_parameter_changes_are_evaluated_for_each_instance():
    model = load_modelica_text(CHAIN, "Chain")
    switched = [model._children[f"s[{i}]"] for i in range(1, 71)]
    texts = [_text(s.equations()) for s in switched]
    assert texts[0] == ["der(x) == 0"] and texts[1] == ["der(x) == -x"]
    assert array_equations(switched) is None       # not one set of equations for all


def test_a_group_written_once_gives_the_scalar_pipelines_results():
    model = load_modelica_text(CHAIN, "Chain")
    cells = [model._children[f"c[{i}]"] for i in range(1, 71)]
    eqs = array_equations(cells)
    assert eqs is not None and all(eq.shape == (70,) for eq in eqs)
    fast = bg.compile(load_modelica_text(CHAIN, "Chain"))
    slow = bg.compile(load_modelica_text(CHAIN, "Chain"), array_path=False)
    assert fast.dae.names == slow.dae.names
    res = [bg.simulate(m, stop_time=1.0, interval=0.5, outputs=["c[7].y", "s[2].x"],
                       rtol=1e-10, atol=1e-10) for m in (fast, slow)]
    assert np.max(np.abs(res[0]["c[7].y"] - res[1]["c[7].y"])) < 1e-12
    k7 = 0.5 + 7 / 70
    t = res[0].time
    exact = 1 / k7 + (1 - 1 / k7) * np.exp(-k7 * t)       # x' = -k x + 1, x(0) = 1
    assert np.max(np.abs(res[0]["c[7].y"] - (2 * exact - np.sin(k7)))) < 1e-8
    assert res[0]["s[2].x"][-1] == pytest.approx(np.exp(-1.0), rel=1e-8)


def test_the_modelica_ladder_compiles_as_the_python_one():
    from pathlib import Path

    from library.examples.circuits import RCLadder

    mo = Path(__file__).resolve().parent / "models" / "circuits.mo"
    compiled = bg.compile(bg.load_modelica(mo, "Circuits.RCLadder", n=1000))
    assert isinstance(compiled, ArrayCompiledModel)
    python = bg.compile(RCLadder(1000))
    assert len(compiled.dae.names) == len(python.dae.names)
    assert compiled.n_flat_equations == python.n_flat_equations
