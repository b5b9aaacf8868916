"""Functions with algorithm sections and algorithm sections of models, against the values the
statements compute by hand."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica.modelica import ModelicaError, load_modelica_text

DATA = Path(__file__).parent / "data"


def test_function_and_model_algorithms():
    model = bg.load_modelica(DATA / "algorithms.mo", "T.M")
    r = bg.simulate(model, stop_time=1.0, rtol=1e-10, atol=1e-12)
    t = r.time
    u = t - 0.5
    # poly(): for-loop sum 6, while-loop count 2, branches on the sign of x, second output
    np.testing.assert_allclose(r["y"], np.where(u > 0, 2 * u**2, -2 * u**2), atol=1e-12)
    np.testing.assert_allclose(r["y2"], 2 * r["y"], atol=1e-12)
    np.testing.assert_allclose(r["w"], 3 * np.exp(-t), rtol=1e-6)
    # when / elsewhen in an algorithm: +1 at t = 0.25, +10 at t = 0.75
    n = r["n"]
    assert n[t < 0.25].max() == 0
    assert set(n[(t > 0.26) & (t < 0.74)]) == {1}
    assert set(n[t > 0.76]) == {11}


def _model(body: str, fn: str = "") -> str:
    return f"package P\n{fn}\nmodel M\n{body}\nend M;\nend P;\n"


def test_function_defaults_named_arguments_and_return():
    fn = ("function f\n  input Real a;\n  input Real b = 2*a;\n  output Real y;\nalgorithm\n"
          "  y := a + b;\n  if a > 0 then\n    return;\n  end if;\n  y := 0;\nend f;\n")
    model = load_modelica_text(_model("  Real x = f(1.5);\n  Real z = f(a = 1, b = 5);\n"
                                      "  Real w = f(-1);", fn), "P.M")
    r = bg.simulate(model, stop_time=0.1)
    assert r["x"][0] == pytest.approx(4.5)
    assert r["z"][0] == pytest.approx(6.0)
    assert r["w"][0] == pytest.approx(0.0)


def test_endless_loop_is_refused():
    fn = ("function f\n  input Real a;\n  output Real y;\nalgorithm\n  y := 0;\n"
          "  while a > 0 loop\n    y := y + 1;\n  end while;\nend f;\n")
    with pytest.raises(ModelicaError, match=r"<string>:\d+:\d+: .*did not finish after"):
        bg.simulate(load_modelica_text(_model("  Real x = f(1);", fn), "P.M"), stop_time=0.1)


def test_while_on_a_time_varying_condition_is_refused():
    fn = ("function f\n  input Real a;\n  output Real y;\nalgorithm\n  y := a;\n"
          "  while y > 0 loop\n    y := y - 1;\n  end while;\nend f;\n")
    with pytest.raises(ModelicaError, match="while-loop condition depends on time-varying"):
        bg.simulate(load_modelica_text(_model("  Real x = f(time);", fn), "P.M"),
                    stop_time=0.1)


def test_return_under_a_time_varying_condition():
    fn = ("function firstTrue\n  input Boolean b[:];\n  output Integer index;\nalgorithm\n"
          "  index := 0;\n  for i in 1:size(b, 1) loop\n    if b[i] then\n      index := i;\n"
          "      return;\n    end if;\n  end for;\nend firstTrue;\n")
    model = load_modelica_text(
        _model("  Integer k;\nequation\n  k = firstTrue({time > 0.7, time > 0.3, time > 0.5});",
               fn), "P.M")
    r = bg.simulate(model, stop_time=1.0)
    t, k = r.time, r["k"]
    inner = np.r_[True, np.diff(t) > 0] & np.r_[np.diff(t) > 0, True]   # not at events
    expected = np.where(t > 0.7, 1, np.where(t > 0.3, 2, 0))
    np.testing.assert_array_equal(k[inner], expected[inner])
