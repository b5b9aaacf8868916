"""The MSL external functions re-implemented natively (bgmodelica.modelica.externals)."""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest
from scipy.interpolate import Akima1DInterpolator, PchipInterpolator
from scipy.io import loadmat, savemat

from bgmodelica.core.expr import Expr, Leaf, differentiate, to_sx
from bgmodelica.errors import ModelError
from bgmodelica.modelica.externals import (
    IMPLEMENTATIONS as X,
)
from bgmodelica.modelica.externals import (
    ExtrapolationError,
    TableError,
    in_range,
    time_breakpoints,
    valid_range,
)
from bgmodelica.modelica.externals.tables import NO_EVENT

LIN, AKIMA, CONST, FB, STEFFEN, MAKIMA = range(1, 7)
HOLD, LAST2, PERIODIC, NOEXT = range(1, 5)
ALWAYS, AT_DISC, NO_EVENTS = 1, 2, 3
T1D = "ModelicaStandardTables_CombiTable1D_"
TT = "ModelicaStandardTables_CombiTimeTable_"

REQUIRED = [
    T1D + "init3", T1D + "getValue", T1D + "close", T1D + "getDerValue",
    TT + "init3", TT + "getValue", TT + "nextTimeEvent", TT + "minimumTime",
    TT + "maximumTime", TT + "close", TT + "getDerValue",
    "ModelicaStrings_compare", "ModelicaStrings_length", "ModelicaStrings_substring",
    "ModelicaStrings_skipWhiteSpace", "ModelicaInternal_fullPathName",
    "ModelicaInternal_removeFile", "ModelicaInternal_stat", "ModelicaInternal_print",
    "ModelicaStreams_closeFile", "ModelicaIO_writeRealMatrix", "ModelicaFFT_kiss_fftr",
]


def table1d(m, smooth=LIN, extrap=LAST2, columns=None):
    m = np.asarray(m, dtype=float)
    cols = columns or list(range(2, m.shape[1] + 1))
    return X[T1D + "init3"]("NoName", "NoName", m, m.shape[0], m.shape[1], cols, len(cols),
                            smooth, extrap, False, ",", 0)


def time_table(m, smooth=LIN, extrap=LAST2, start=0.0, shift=0.0, events=ALWAYS):
    m = np.asarray(m, dtype=float)
    cols = list(range(2, m.shape[1] + 1))
    return X[TT + "init3"]("NoName", "NoName", m, m.shape[0], m.shape[1], start, cols,
                           len(cols), smooth, extrap, shift, events, False, ",", 0)


def get(t, u, icol=1):
    return X[T1D + "getValue"](t, icol, u)


class _Sym:
    def __init__(self, name: str) -> None:
        self.name = name
        self.sx = ca.SX.sym(name)


def lowered(expr_of):
    """A numeric function of one variable from a symbolic result (through to_sx)."""
    sym = _Sym("u")
    e = expr_of(Leaf(sym))
    assert isinstance(e, Expr)
    f = ca.Function("f", [sym.sx], [to_sx(e)])
    return lambda v: float(f(v))


def test_registry_has_the_census_entry_points():
    assert not [k for k in REQUIRED if k not in X]


# -- 1-D tables -------------------------------------------------------------------------------

DOC = [[0, 0], [1, 1], [2, 4], [4, 16]]


def test_linear_interpolation_and_extrapolation_modes():
    t = table1d(DOC)
    assert [get(t, u) for u in (1.0, 1.5, 2.0, -1.0, 3.0, 5.0)] == [1, 2.5, 4, -1, 10, 22]
    hold = table1d(DOC, extrap=HOLD)
    assert [get(hold, u) for u in (-1.0, 5.0, 3.0)] == [0, 16, 10]
    per = table1d(DOC, extrap=PERIODIC)
    assert [get(per, u) for u in (5.0, -1.0, 6.5, 4.0, 0.0)] == [1, 10, 7, 0, 0]
    strict = table1d(DOC, extrap=NOEXT)
    assert get(strict, 4.0) == 16 and get(strict, 0.0) == 0
    with pytest.raises(ExtrapolationError, match="outside the table range"):
        get(strict, 4.5)
    assert valid_range(strict) == (0.0, 4.0)
    assert in_range(strict, 4.0) and not in_range(strict, -0.1)
    ok = lowered(lambda u: in_range(strict, u))
    assert [ok(u) for u in (-0.1, 0.0, 2.0, 4.0, 4.1)] == [0, 1, 1, 1, 0]
    assert X[T1D + "getValue"](strict, 1, ca.SX(2.0)) == 4.0
    assert X[T1D + "minimumAbscissa"](t) == 0 and X[T1D + "maximumAbscissa"](t) == 4
    assert X[T1D + "close"](t) is None


def test_columns_and_single_row():
    t = table1d([[0, 1, 10], [2, 3, 30]], columns=[3, 2])
    assert get(t, 1.0, 1) == 20 and get(t, 1.0, 2) == 2
    one = table1d([[5, 7]])
    assert get(one, -100.0) == 7 and get(one, 100.0) == 7


def test_constant_segments_are_right_continuous():
    m = [[0, 1], [1, 3], [2, 2]]
    t = table1d(m, CONST)
    assert [get(t, u) for u in (0.5, 1.0, 1.999, 2.0)] == [1, 3, 3, 2]
    assert get(t, 3.0) == 1.0 and get(t, -1.0) == -1.0     # through the last two points
    assert get(table1d(m, CONST, HOLD), 3.0) == 2.0
    assert X[T1D + "getDerValue"](t, 1, 0.5, 1.0) == 0.0


def test_akima_matches_the_akima_1970_spline():
    x = np.array([0.0, 1.0, 2.5, 3.0, 4.5, 6.0, 7.0])
    y = np.array([1.0, 2.0, 0.5, 0.8, 3.0, 2.5, 4.0])
    t = table1d(np.column_stack([x, y]), AKIMA)
    ref = Akima1DInterpolator(x, y)
    for u in np.linspace(0, 7, 57):
        assert get(t, u) == pytest.approx(float(ref(u)), abs=1e-12)
    # LastTwoPoints continues the end derivatives
    d0, d1 = float(ref(0.0, 1)), float(ref(7.0, 1))
    assert get(t, -2.0) == pytest.approx(1.0 - 2 * d0)
    assert get(t, 8.0) == pytest.approx(4.0 + d1)
    mk = table1d(np.column_stack([x, y]), MAKIMA)
    ref_mk = Akima1DInterpolator(x, y, method="makima")
    for u in np.linspace(0, 7, 57):
        assert get(mk, u) == pytest.approx(float(ref_mk(u)), abs=1e-12)


def test_akima_with_three_points_is_the_parabola():
    t = table1d([[0, 0], [1, 1], [3, 9]], AKIMA)
    for u in (0.3, 1.7, 2.9, -1.0):
        assert get(t, u) == pytest.approx(u * u if u >= 0 else 2 * 0 * u)
    assert X[T1D + "getDerValue"](t, 1, 2.0, 1.0) == pytest.approx(4.0)


def test_fritsch_butland_and_steffen_hand_values():
    m = [[0, 0], [1, 1], [2, 3]]
    fb, st = table1d(m, FB), table1d(m, STEFFEN)
    # slopes: FB 1, 4/3, 2; Steffen 1, 3/2, 2 (ends: end secants); Hermite at the midpoint
    assert get(fb, 0.5) == pytest.approx(0.125 + 0.5 - 0.125 * 4 / 3)
    assert get(st, 0.5) == pytest.approx(0.125 + 0.5 - 0.125 * 1.5)
    assert X[T1D + "getDerValue"](fb, 1, 1.0, 1.0) == pytest.approx(4 / 3)
    assert X[T1D + "getDerValue"](st, 1, 1.0, 1.0) == pytest.approx(1.5)
    assert get(fb, 3.0) == pytest.approx(5.0)          # end slope 2 continued


def test_fritsch_butland_interior_slopes_are_pchip():
    x = np.array([0.0, 0.7, 1.5, 3.0, 3.2, 5.0])
    y = np.array([0.0, 0.5, 0.5, 2.0, 4.0, 4.5])
    t = table1d(np.column_stack([x, y]), FB)
    ref = PchipInterpolator(x, y)
    for xi in x[1:-1]:
        assert X[T1D + "getDerValue"](t, 1, xi, 1.0) == pytest.approx(float(ref(xi, 1)))


@pytest.mark.parametrize("smooth", [FB, STEFFEN])
def test_monotone_splines_preserve_monotonicity(smooth):
    rng = np.random.default_rng(1)
    x = np.cumsum(rng.uniform(0.1, 2.0, 12))
    y = np.cumsum(rng.choice([0.0, 0.01, 1.0, 5.0], 12))
    t = table1d(np.column_stack([x, y]), smooth)
    vals = np.array([get(t, u) for u in np.linspace(x[0], x[-1], 2000)])
    assert np.all(np.diff(vals) >= -1e-12)
    assert vals.min() >= y[0] - 1e-12 and vals.max() <= y[-1] + 1e-12


SMOOTH_TABLE = np.array([[0.0, 1.0, -1.0], [0.5, 2.0, 0.0], [1.5, 1.0, 2.0], [2.0, 3.0, 2.5],
                         [3.5, 2.0, 5.0], [4.0, 4.0, 5.5]])


@pytest.mark.parametrize("smooth", range(1, 7))
@pytest.mark.parametrize("extrap", [HOLD, LAST2, PERIODIC, NOEXT])
def test_symbolic_equals_numeric(smooth, extrap):
    t = table1d(SMOOTH_TABLE, smooth, extrap)
    rng = np.random.default_rng(smooth * 10 + extrap)
    lo, hi = (0.0, 4.0) if extrap == NOEXT else (-3.0, 7.0)
    us = rng.uniform(lo, hi, 200)
    for icol in (1, 2):
        f = lowered(lambda u, icol=icol: get(t, u, icol))
        for u in us:
            assert f(u) == pytest.approx(get(t, u, icol), rel=1e-12, abs=1e-12)
    if smooth != CONST:
        g = lowered(lambda u: X[T1D + "getDerValue"](t, 1, u, 2.0))
        for u in us[:50]:
            assert g(u) == pytest.approx(X[T1D + "getDerValue"](t, 1, u, 2.0), abs=1e-12)


@pytest.mark.parametrize("smooth", [LIN, AKIMA, STEFFEN])
def test_differentiating_the_closed_form_gives_get_der_value(smooth):
    t = table1d(SMOOTH_TABLE, smooth, PERIODIC)
    f = lowered(lambda u: differentiate(get(t, u), lambda sym: 1.0))
    for u in np.linspace(-3.0, 7.0, 37):
        assert f(u) == pytest.approx(X[T1D + "getDerValue"](t, 1, u, 1.0), abs=1e-12)


def test_symbolic_casadi_input():
    t = table1d(SMOOTH_TABLE, AKIMA)
    u = ca.SX.sym("u")
    f = ca.Function("f", [u], [get(t, u)])
    assert float(f(1.234)) == pytest.approx(get(t, 1.234))


def test_symbolic_jump_is_right_continuous():
    t = table1d([[0, 0], [1, 0], [1, 1], [2, 1]])
    f = lowered(lambda u: get(t, u))
    assert f(1.0) == 1.0 and f(0.999) == 0.0 and get(t, 1.0) == 1.0


@pytest.mark.parametrize("smooth", [LIN, AKIMA, FB, STEFFEN, MAKIMA])
def test_derivative_matches_finite_differences(smooth):
    t = table1d(SMOOTH_TABLE, smooth, LAST2)
    rng = np.random.default_rng(smooth)
    der = X[T1D + "getDerValue"]
    der2 = X[T1D + "getDer2Value"]
    h = 1e-6
    for u in rng.uniform(-1.0, 5.0, 40):
        if np.min(np.abs(SMOOTH_TABLE[:, 0] - u)) < 1e-3:
            continue
        fd = (get(t, u + h) - get(t, u - h)) / (2 * h)
        assert der(t, 1, u, 3.0) == pytest.approx(3.0 * fd, rel=1e-6, abs=1e-6)
        fd2 = (der(t, 1, u + h, 1.0) - der(t, 1, u - h, 1.0)) / (2 * h)
        assert der2(t, 1, u, 3.0, 0.5) == pytest.approx(
            9.0 * fd2 + 0.5 * der(t, 1, u, 1.0), rel=1e-5, abs=1e-5)


@pytest.mark.parametrize(("m", "smooth", "cols", "match"), [
    ([[0, 1], [2, 2], [1, 3]], LIN, [2], "not monotonically increasing"),
    ([[0, 1], [1, 2], [1, 3], [2, 4]], AKIMA, [2], "not strictly increasing"),
    ([[0, 1], [1, 2]], LIN, [3], "column 3 out of range"),
    (np.zeros((0, 2)), LIN, [2], "empty"),
    ([[1, 1], [1, 2]], LIN, [2], "all abscissae are equal"),
])
def test_invalid_tables(m, smooth, cols, match):
    with pytest.raises(TableError, match=match) as err:
        table1d(m, smooth, columns=cols)
    assert isinstance(err.value, ValueError) and isinstance(err.value, ModelError)
    assert "CombiTable1D" in str(err.value)


def test_output_index_out_of_range():
    with pytest.raises(TableError, match="output 2 requested"):
        get(table1d(DOC), 0.5, 2)


def test_tables_from_text_and_mat_files(tmp_path):
    text = tmp_path / "tables.txt"
    text.write_text("#1\ndouble tab1(3,2)   # comment\n  0 0\n  1 1\n  2, 4\n"
                    "double tab2(2,3)\n0 1 2; 3 4 5 # end\n")
    t = X[T1D + "init3"](str(text), "tab1", np.zeros((0, 2)), 0, 2, [2], 1, LIN, LAST2,
                         False, ",", 0)
    assert get(t, 1.5) == 2.5
    t2 = X[T1D + "init3"](str(text), "tab2", np.zeros((0, 2)), 0, 2, [3], 1, LIN, LAST2,
                          False, ",", 0)
    assert get(t2, 1.5) == 3.5
    with pytest.raises(TableError, match="'tab3' is not declared"):
        X[T1D + "init3"](str(text), "tab3", np.zeros((0, 2)), 0, 2, [2], 1, LIN, LAST2,
                         False, ",", 0)
    mat = tmp_path / "t.mat"
    savemat(mat, {"m": np.array([[0.0, 1.0], [2.0, 5.0]])}, format="4")
    tm = X[TT + "init3"](str(mat), "m", np.zeros((0, 2)), 0, 2, 0.0, [2], 1, LIN, LAST2,
                         0.0, ALWAYS, False, ",", 0)
    assert X[TT + "getValue"](tm, 1, 1.0, NO_EVENT, 0.0) == 3.0


# -- time tables ------------------------------------------------------------------------------

def events_from(t, t0, n):
    out, now = [], t0
    for _ in range(n):
        now = X[TT + "nextTimeEvent"](t, now)
        out.append(now)
        if now == NO_EVENT:
            break
    return out


def test_time_table_documentation_example():
    m = [[0, 0], [1, 0], [1, 1], [2, 4], [3, 9], [4, 16]]
    t = time_table(m, events=AT_DISC)
    val = X[TT + "getValue"]
    assert events_from(t, 0.0, 5) == [1.0, NO_EVENT]
    assert val(t, 1, 1.0, 1.0, 1.0) == 0.0                # before the event at t = 1
    assert val(t, 1, 1.0, NO_EVENT, 1.0) == 1.0           # after it
    assert val(t, 1, 1.5, NO_EVENT, 1.0) == 2.5
    assert val(t, 1, 2.0, NO_EVENT, 1.0) == 4.0
    assert val(t, 1, 5.0, NO_EVENT, 1.0) == 23.0
    assert events_from(time_table(m), 0.0, 6) == [1.0, 2.0, 3.0, 4.0, NO_EVENT]
    assert events_from(time_table(m, events=NO_EVENTS), 0.0, 2) == [NO_EVENT]
    assert X[TT + "minimumTime"](t) == 0.0 and X[TT + "maximumTime"](t) == 4.0


def test_start_time_and_shift_time():
    val = X[TT + "getValue"]
    t = time_table([[0, 1], [1, 2]], start=2.0, shift=2.0)
    assert events_from(t, 0.0, 4) == [2.0, 3.0, NO_EVENT]
    assert val(t, 1, 1.5, 2.0, 0.0) == 0.0
    assert val(t, 1, 2.0, 2.0, 0.0) == 0.0                # output jumps at startTime
    assert val(t, 1, 2.0, 3.0, 2.0) == 1.0
    assert val(t, 1, 2.5, 3.0, 2.0) == 1.5
    assert val(t, 1, 4.0, NO_EVENT, 3.0) == 3.0
    h = time_table([[0, 1], [1, 2]], extrap=HOLD, start=0.0, shift=1.0)
    assert events_from(h, 0.0, 3) == [1.0, 2.0, NO_EVENT]
    assert val(h, 1, 0.5, 1.0, 0.0) == 1.0 and val(h, 1, 5.0, NO_EVENT, 2.0) == 2.0
    assert X[TT + "getDerValue"](h, 1, 1.5, 2.0, 1.0, 2.0) == 2.0
    assert X[TT + "getDerValue"](h, 1, 0.5, 1.0, 0.0, 2.0) == 0.0


def test_periodic_square_wave_with_jumps():
    m = [[0, 0], [1, 0], [1, 1], [2, 1]]
    t = time_table(m, extrap=PERIODIC, start=0.0, shift=0.5)
    val = X[TT + "getValue"]
    assert events_from(t, 0.0, 6) == [0.5, 1.5, 2.5, 3.5, 4.5, 5.5]
    assert val(t, 1, 1.5, 1.5, 0.5) == 0.0 and val(t, 1, 1.5, 2.5, 1.5) == 1.0
    assert val(t, 1, 2.5, 2.5, 1.5) == 1.0 and val(t, 1, 2.5, 3.5, 2.5) == 0.0
    late = 0.5 + 2 * 50 + 1.0                             # a jump far into the run
    assert val(t, 1, late, late, late - 1) == 0.0 and val(t, 1, late, late + 1, late) == 1.0
    assert val(t, 1, 0.2, 0.5, 0.0) == 1.0                # before shiftTime: periodic too
    assert time_breakpoints(t, 0.0, 4.0) == [0.0, 0.5, 1.5, 2.5, 3.5]
    ev = events_from(t, 0.0, 400)
    assert np.allclose(np.diff(ev), 1.0) and ev == sorted(set(ev))


def test_time_table_symbolic_equals_numeric():
    rng = np.random.default_rng(3)
    for smooth, extrap, events in [(LIN, PERIODIC, ALWAYS), (AKIMA, LAST2, NO_EVENTS),
                                   (CONST, HOLD, ALWAYS), (STEFFEN, PERIODIC, NO_EVENTS)]:
        t = time_table(SMOOTH_TABLE, smooth, extrap, start=0.7, shift=0.3, events=events)
        f = lowered(lambda s, t=t: X[TT + "getValue"](t, 2, s, s, s))
        for s in rng.uniform(-1.0, 12.0, 200):
            assert f(s) == pytest.approx(X[TT + "getValue"](t, 2, s, NO_EVENT, 0.0),
                                         rel=1e-12, abs=1e-12)


def test_time_table_one_row_and_errors():
    one = time_table([[0.0, 4.0]], start=1.0)
    assert X[TT + "getValue"](one, 1, 0.5, 1.0, 0.0) == 0.0
    assert X[TT + "getValue"](one, 1, 3.0, NO_EVENT, 1.0) == 4.0
    assert events_from(one, 0.0, 3) == [1.0, NO_EVENT]
    with pytest.raises(TableError, match="CombiTimeTable.*not strictly increasing"):
        time_table([[0, 0], [1, 0], [1, 1], [2, 1]], smooth=AKIMA)
    ok = time_table([[0, 0], [1, 0], [1, 1], [2, 1]], extrap=NOEXT)
    with pytest.raises(ExtrapolationError):
        X[TT + "getValue"](ok, 1, 2.5, NO_EVENT, 2.0)
    late = time_table([[0, 0], [1, 1]], extrap=NOEXT, start=1.0, shift=2.0)
    assert [in_range(late, s) for s in (0.5, 1.5, 2.5, 3.5)] == [True, False, True, False]
    cond = lowered(lambda s: in_range(late, s))
    assert [cond(s) for s in (0.5, 1.5, 2.5, 3.5)] == [1, 0, 1, 0]


# -- strings, files, FFT ----------------------------------------------------------------------

def test_strings():
    s = "This is line 111"
    sub = X["ModelicaStrings_substring"]
    assert sub(s, 9, 12) == "line" and sub(s, 9, 0) == "" and sub(s, 0, 4) == "This"
    assert sub(s, 6, -1) == "i" and sub(s, 14, 99) == "111" and sub(s, 30, 40) == ""
    assert X["ModelicaStrings_length"](s) == len(s)
    cmp = X["ModelicaStrings_compare"]
    assert [cmp("a", "b", True), cmp("b", "b", True), cmp("b", "a", True)] == [1, 2, 3]
    assert cmp("ABC", "abc", False) == 2 and cmp("ABC", "abc", True) == 1
    assert X["ModelicaStrings_skipWhiteSpace"]("  \tx", 1) == 4
    assert X["ModelicaStrings_skipWhiteSpace"]("   ", 2) == 4
    assert X["ModelicaStrings_scanReal"]("  -1.5e2 x", 1, False, 0, 0.0) == (9, -150.0)
    assert X["ModelicaStrings_scanReal"]("-3", 1, True) == (1, 0.0)
    assert X["ModelicaStrings_scanInteger"](" 42,", 1, False) == (4, 42)
    assert X["ModelicaStrings_scanInteger"]("1.5", 1, False) == (1, 0)
    assert X["ModelicaStrings_scanIdentifier"](" ab_1+", 1) == (6, "ab_1")
    assert X["ModelicaStrings_scanString"](' "a\\"b" ', 1) == (8, 'a"b')


def test_files_and_streams(tmp_path, capsys):
    f = tmp_path / "out.txt"
    stat = X["ModelicaInternal_stat"]
    assert stat(str(f)) == 1 and stat(str(tmp_path)) == 3
    X["ModelicaInternal_print"]("line 1", str(f))
    X["ModelicaInternal_print"]("line 2", str(f))
    assert f.read_text() == "line 1\nline 2\n" and stat(str(f)) == 2
    X["ModelicaStreams_closeFile"](str(f))
    X["ModelicaInternal_print"]("hello", "")
    assert capsys.readouterr().out == "hello\n"
    assert X["ModelicaInternal_fullPathName"](str(f)) == str(f.resolve())
    X["ModelicaInternal_removeFile"](str(f))
    assert stat(str(f)) == 1
    with pytest.raises(ModelError, match="cannot remove"):
        X["ModelicaInternal_removeFile"](str(f))


def test_write_real_matrix(tmp_path):
    w = X["ModelicaIO_writeRealMatrix"]
    path = str(tmp_path / "m.mat")
    a = np.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]])
    assert w(path, "A", a, 2, 3, False, "4")
    assert w(path, "B", np.eye(2), 2, 2, True, "4")
    data = loadmat(path)
    assert np.array_equal(data["A"], a) and np.array_equal(data["B"], np.eye(2))
    assert w(path, "C", a, 2, 3, False, "7") and set(loadmat(path)) >= {"C"}
    assert "A" not in loadmat(path)
    assert not w(str(tmp_path / "no" / "dir.mat"), "A", a, 2, 3, False, "4")


def test_fft_of_known_signal():
    n = 40
    t = np.arange(n) / n                                  # 1 s, resolution 1 Hz
    u = 3.0 + 2.0 * np.sin(2 * math.pi * 2 * t) + 1.5 * np.cos(2 * math.pi * 3 * t + 0.5)
    nf = n // 2 + 1
    info, amp, phase = X["ModelicaFFT_kiss_fftr"](u, n, np.zeros(3 * n + 2 * nf),
                                                  3 * n + 2 * nf, np.zeros(nf), np.zeros(nf))
    assert info == 0 and amp.shape == (nf,)
    assert amp[0] == pytest.approx(3.0) and amp[2] == pytest.approx(2.0)
    assert amp[3] == pytest.approx(1.5)
    assert phase[2] == pytest.approx(-math.pi / 2) and phase[3] == pytest.approx(0.5)
    others = np.delete(amp, [0, 2, 3])
    assert np.all(others < 1e-12)
    ref = np.fft.rfft(u)
    assert np.allclose(amp[1:], 2 * np.abs(ref[1:]) / n)
    assert X["ModelicaFFT_kiss_fftr"](u[:-1], n - 1, None, None)[0] == 1
    assert X["ModelicaFFT_kiss_fftr"](u, n, None, 7)[0] == 2
