"""Property-based tests (hypothesis): whatever the input, the outcome is a result or a typed
:class:`~bgmodelica.errors.ModelError` -- on the command line exit status 0, or exit status 2
with one line on stderr -- never another exception, a traceback or a hang.

- command-line option values: stop times, intervals, tolerances, ``--set`` and ``--arg``;
- small random component networks (resistors, capacitors, inductors, sources, grounds wired
  at random, balanced or not, grounded or floating, with degenerate values).

The examples are bounded (few, small, short runs) so the module takes a few seconds. The
default profile is derandomized (the same examples on every run, for CI); set
``HYPOTHESIS_PROFILE=explore`` to search with fresh random examples.
"""

from __future__ import annotations

import contextlib
import csv
import io
import math
import os
from pathlib import Path

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import bgmodelica as bg  # noqa: E402
from bgmodelica import Component  # noqa: E402
from bgmodelica.cli import main  # noqa: E402
from bgmodelica.errors import ModelError  # noqa: E402
from bgmodelica.validate import output_grid  # noqa: E402
from library.electrical import (  # noqa: E402
    Capacitor,
    ConstantCurrent,
    ConstantVoltage,
    Ground,
    Inductor,
    Resistor,
)

settings.register_profile("ci", max_examples=25, deadline=None, derandomize=True,
                          database=None, print_blob=True,
                          suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("explore", max_examples=200, deadline=None, database=None,
                          suppress_health_check=[HealthCheck.too_slow])
PROFILE = os.environ.get("HYPOTHESIS_PROFILE", "ci")


def examples(n: int) -> int:
    """``n`` examples in CI, ten times more when exploring."""
    return n if PROFILE == "ci" else 10 * n

MODEL = f"{Path(__file__).resolve().parent / 'bad_models.py'}:RC"
LADDER = f"{Path(__file__).resolve().parent / 'bad_models.py'}:ladder"


def cli(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


def assert_clean(code: int, out: str, err: str) -> None:
    """Exit 0, or exit 2 with exactly one ``error:`` line and nothing on stdout."""
    assert "Traceback" not in err, err
    assert code in (0, 2), (code, err)
    if code == 2:
        lines = err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("error:"), err
        assert out == ""


def number_text(lo: float, hi: float, specials: list[str]) -> st.SearchStrategy[str]:
    """Numbers as command-line text: ordinary values in [lo, hi] and troublesome ones."""
    return st.one_of(st.sampled_from(specials), st.floats(lo, hi).map(repr))


STOPS = number_text(1e-3, 5.0, ["nan", "inf", "-inf", "0", "-0", "-1", "1e-300", "5e-324",
                                "1e308", "abc", "", "0x10", "1_000"])
INTERVALS = number_text(2e-3, 5.0, ["nan", "inf", "-inf", "0", "-0.5", "1e-300", "1e-12",
                                    "tiny", ""])
TOLERANCES = number_text(1e-10, 1e-2, ["0", "-1e-6", "nan", "inf", "1", "2"])


def _expected_grid(stop: float, interval: float | None) -> np.ndarray:
    return output_grid(0.0, stop, interval)


@settings(settings.get_profile(PROFILE), max_examples=examples(30))
@given(stop=STOPS, interval=st.one_of(st.none(), INTERVALS), rtol=st.none() | TOLERANCES)
def test_cli_time_options(tmp_path_factory, stop, interval, rtol):
    out_file = tmp_path_factory.mktemp("fuzz") / "out.csv"
    argv = ["simulate", MODEL, "--stop-time", stop, "-o", str(out_file)]
    if interval is not None:
        argv += ["--interval", interval]
    if rtol is not None:
        argv += ["--rtol", rtol]
    code, out, err = cli(argv)
    assert_clean(code, out, err)
    if code == 0:                     # the grid is exactly the one asked for
        times = [float(r[0]) for r in list(csv.reader(out_file.open()))[1:]]
        want = _expected_grid(float(stop), None if interval is None else float(interval))
        assert np.allclose(times, want, rtol=1e-11, atol=0)
        assert math.isfinite(float(stop)) and float(stop) > 0
    elif out_file.exists():            # only a failed run writes (its good rows), and says so
        assert "written to" in err


SET_NAMES = st.sampled_from(["R.R", "C.C", "C.v", "src.V", "R.i", "gnd.p.v", "R.nope", "",
                             " ", "C"])
SET_VALUES = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.sampled_from(["0", "-0", "1e-320", "1e308", "-1e308", "abc", "", "1 kOhm", "2 V",
                     "3 parsecs", "=", "nan"]),
    st.text(max_size=6))


@settings(settings.get_profile(PROFILE), max_examples=examples(40))
@given(sets=st.lists(st.tuples(SET_NAMES, SET_VALUES), max_size=3))
def test_cli_set_values(tmp_path_factory, sets):
    out_file = tmp_path_factory.mktemp("fuzz") / "out.csv"
    argv = ["simulate", MODEL, "--stop-time", "0.2", "-o", str(out_file)]
    for name, value in sets:
        argv += ["--set", f"{name}={value}"]
    code, out, err = cli(argv)
    assert_clean(code, out, err)


ARG_VALUES = st.one_of(st.integers(-3, 8).map(str), st.floats(allow_nan=True).map(repr),
                       st.sampled_from(["true", "null", "[1]", "{}", "\"3\"", "abc", "",
                                        "NaN", "Infinity", "1e400"]),
                       st.text(max_size=5))


@settings(settings.get_profile(PROFILE), max_examples=examples(30))
@given(args=st.lists(st.tuples(st.sampled_from(["n", "scale", "m", "", "n.x", "1n"]),
                               ARG_VALUES), max_size=3))
def test_cli_arg_values(args):
    argv = ["check", LADDER]
    for name, value in args:
        argv += ["--arg", f"{name}={value}"]
    code, out, err = cli(argv)
    assert_clean(code, out, err)


# -- random networks ------------------------------------------------------------------------

KINDS = ("R", "C", "L", "V", "I")
VALUES = st.sampled_from([1.0, 0.5, 2.0, 100.0, 0.0, -1.0, 1e-9])


@st.composite
def networks(draw):
    """``(n_nodes, [(kind, node_p, node_n, value, fixed_start)], [ground nodes])``."""
    n_nodes = draw(st.integers(1, 4))
    node = st.integers(0, n_nodes - 1)
    parts = draw(st.lists(st.tuples(st.sampled_from(KINDS), node, node, VALUES, st.booleans()),
                          min_size=1, max_size=5))
    grounded = st.lists(node, min_size=1, max_size=2)
    grounds = draw(st.one_of(grounded, grounded, grounded, st.just([])))   # mostly grounded
    return n_nodes, parts, grounds


def build(n_nodes: int, parts, grounds) -> Component:
    m = Component(name="net")
    pins: dict[int, list] = {k: [] for k in range(n_nodes)}
    for k, (kind, a, b, value, fixed) in enumerate(parts):
        if kind == "R":
            c = Resistor(R=value)
        elif kind == "C":
            c = Capacitor(C=value, v=0.0 if fixed else {"start": 0.0, "fixed": False})
        elif kind == "L":
            c = Inductor(L=value, i=0.0 if fixed else {"start": 0.0, "fixed": False})
        elif kind == "V":
            c = ConstantVoltage(V=value)
        else:
            c = ConstantCurrent(I=value)
        m.add(f"{kind}{k}", c)
        pins[a].append(c.p)
        pins[b].append(c.n)
    for k, at in enumerate(grounds):
        g = m.add(f"gnd{k}", Ground())
        pins[at].append(g.p)
    for members in pins.values():
        for x, y in zip(members, members[1:], strict=False):
            m.connect(x, y)
    return m


@settings(settings.get_profile(PROFILE), max_examples=examples(60))
@given(net=networks())
def test_random_networks(net):
    model = build(*net)
    try:
        res = bg.simulate(model, stop_time=0.05, interval=0.01)
    except ModelError as err:
        assert str(err).strip()                 # a typed error with a message
        return
    assert np.all(np.isfinite(res.values))      # a result holds no NaN / Inf
    assert res.time[-1] == pytest.approx(0.05)


@settings(settings.get_profile(PROFILE), max_examples=examples(25))
@given(net=networks())
def test_random_networks_check(net):
    """``compile`` (what ``bgmodelica check`` runs) on the same networks."""
    model = build(*net)
    try:
        bg.compile(model)
    except ModelError as err:
        assert str(err).strip()
