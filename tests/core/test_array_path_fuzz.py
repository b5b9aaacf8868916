"""Property-based check of the array path (hypothesis): random models of array equations
(random sizes, slices, math functions, coefficients, which side the unknown is written on)
compile to the DAE of the scalar pipeline: the same names, states, parameters and starts,
and the same ODE and observations at a random point.

The default profile is derandomized (the same examples on every run, for CI); set
``HYPOTHESIS_PROFILE=explore`` to search with fresh random examples.
"""

from __future__ import annotations

import os

import casadi as ca
import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from bgmodelica import Component, Parameter, Variable, der, exp, sin, time  # noqa: E402
from bgmodelica.array_path import compile_arrays, why_not  # noqa: E402
from bgmodelica.compiler import _compile  # noqa: E402

settings.register_profile("array-ci", max_examples=30, deadline=None, derandomize=True,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("array-explore", max_examples=300, deadline=None, database=None)
settings.load_profile("array-explore" if os.environ.get("HYPOTHESIS_PROFILE") == "explore"
                      else "array-ci")

FUNCTIONS = {"x": lambda v: v, "sin": sin, "exp": lambda v: exp(-v), "square": lambda v: v * v}


@st.composite
def array_models(draw):
    """A random explicit model: states ``x[n]``, algebraic ``y[n]`` and ``z[m]``."""
    n = draw(st.integers(3, 24))
    f = FUNCTIONS[draw(st.sampled_from(sorted(FUNCTIONS)))]
    c = draw(st.floats(0.25, 4.0))
    y_left = draw(st.booleans())             # y alone on the left, or scaled on the right
    z_diff = draw(st.booleans())             # z[n-1] of neighbour differences, or z[n]
    x_scaled = draw(st.booleans())           # C*der(x) == ..., or der(x) == ...
    starts = draw(st.lists(st.floats(-2.0, 2.0), min_size=n, max_size=n))
    rates = draw(st.lists(st.floats(0.1, 3.0), min_size=n, max_size=n))
    m = n - 1 if z_diff else n
    alias = draw(st.sampled_from(["none", "u=x", "u=-y", "x=u"]))   # an array alias
    alias_start = draw(st.booleans())                              # u with fixed starts
    scalar_alias = draw(st.booleans())                             # s = -z[1]

    class Random(Component):
        x = Variable(shape="n")
        y = Variable(shape="n")
        z = Variable(shape="m")
        a = Parameter(shape="n", value=1.0)
        b = Parameter(0.5)
        C = Parameter(2.0)
        u = Variable(shape="n")
        s = Variable()

        def __init__(self, **modifiers):
            self.n, self.m = n, m
            mods = {"x": np.array(starts), "a": np.array(rates)}
            if alias_start and alias != "none":
                mods = {"u": -np.array(starts) if alias == "u=-y" else np.array(starts),
                        "a": np.array(rates)}
            super().__init__(**{**mods, **modifiers})

        def equations(self):
            x, y, z = self.x, self.y, self.z
            if y_left:
                yield y == f(x) * c + self.b * time
            else:
                yield c * y - self.b * time == c * c * f(x)
            if z_diff:
                yield z == y[:-1] - c * y[1:]
            else:
                yield 2.0 * z + x == y
            lhs = (lambda e: self.C * e) if x_scaled else (lambda e: e)
            yield lhs(der(x[0])) == -self.a[0] * x[0] + z[0]
            tail = z if z_diff else z[1:]
            yield lhs(der(x[1:])) == -self.a[1:] * x[1:] + tail
            u = self.u
            if alias == "u=x":
                yield u == x
            elif alias == "u=-y":
                yield u == -y
            elif alias == "x=u":
                yield x == u
            else:
                yield u == 3.0 * x
            yield (self.s == -z[0]) if scalar_alias else (self.s == 2.0 * z[0])

    return Random


@given(array_models())
def test_random_array_models_give_the_scalar_pipelines_dae(make):
    reason = why_not(make(), minimum=0)
    assert reason is None or "conflicting" in reason
    if reason is not None:
        return
    fast = compile_arrays(make(), "off", minimum=0).dae
    slow = _compile(make(), None, "off").dae
    assert fast.names == slow.names and fast.state_names == slow.state_names
    assert [q.name for q in fast.parameters] == [q.name for q in slow.parameters]
    assert fast.aliases == slow.aliases
    assert np.array_equal(fast.x_start, slow.x_start) and fast.fixed == slow.fixed
    rng = np.random.default_rng(7)
    x, p = rng.uniform(-1, 1, fast.x.numel()), rng.uniform(0.5, 2, fast.p.numel())
    fa = ca.Function("a", [fast.x, fast.p, fast.t], [fast.ode, fast.observed])
    fb = ca.Function("b", [slow.x, slow.p, slow.t], [slow.ode, slow.observed])
    for u, v in zip(fa(x, p, 0.3), fb(x, p, 0.3), strict=True):
        assert np.allclose(np.asarray(u), np.asarray(v), rtol=1e-12, atol=1e-12)
