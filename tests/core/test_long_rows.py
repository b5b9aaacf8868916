"""Long sums (a ground node joined to every section) are kept out of the whole-model
sparsity pass: same incidence, same compiled model, and the flag survives the passes. Dense
columns of large patterns get a pass of their own, with the same incidence. Also the
coloring that batches the explicit scalar solutions."""

from __future__ import annotations

import random

import casadi as ca
from hypothesis import given, settings
from hypothesis import strategies as st

import bgmodelica as bg
from bgmodelica.passes.symbolic import LONG_ROW, _coloring, incidence
from library.examples import RCLadder


def test_incidence_with_long_rows_equals_the_plain_pass():
    random.seed(3)
    x = ca.SX.sym("x", 500)
    xs = ca.vertsplit(x)
    rows = [xs[i] * ca.sin(xs[(i * 7) % 500]) - xs[(i * 13) % 500] for i in range(400)]
    rows.insert(17, ca.sum1(x[::2]) + ca.floor(xs[3]))       # one long sum
    plain = incidence(rows, xs)
    assert incidence(rows, xs, {17}) == plain
    assert plain[17][:3] == [0, 2, 3] and len(plain[17]) == 251


def test_dense_columns_get_their_own_pass_with_the_same_incidence(monkeypatch):
    import bgmodelica.passes.symbolic as symbolic

    n = 3000
    x = ca.SX.sym("x", n + 2)
    g, h, xx = x[n], x[n + 1], x[:n]
    every_third = ca.DM([1.0 if k % 3 == 0 else 0.0 for k in range(n - 2)])
    r = ca.vertcat(xx[0] * h, xx[:-2] - 2 * xx[1:-1] + ca.sin(xx[2:]) + g * every_third,
                   xx[-1] * g)
    plain = symbolic._sparsity_rows(r, x)                  # below the size: one pass
    assert plain[1] == [0, 1, 2, n] and plain[2] == [1, 2, 3] and plain[0] == [0, n + 1]
    monkeypatch.setattr(symbolic, "DENSE_CHECK_SIZE", 100)
    assert list(symbolic._dense_columns(r, x)) == [n]      # g: a third of the rows
    split = symbolic._sparsity_rows(r, x)
    assert split == plain and all(type(c) is int for row in split for c in row)
    monkeypatch.setattr(symbolic, "DENSE_SAMPLE", 50)      # few samples: more "dense"
    assert symbolic._sparsity_rows(r, x) == plain
    compiled = bg.compile(RCLadder(40))                      # the compiler on the split
    monkeypatch.setattr(symbolic, "DENSE_CHECK_SIZE", 2**17)
    ref = bg.compile(RCLadder(40))
    assert str(compiled.dae.ode) == str(ref.dae.ode)


def test_ground_balance_is_marked_long_and_compiles_as_without_the_split(monkeypatch):
    n = LONG_ROW + 10
    compiled = bg.compile(RCLadder(n))
    long = [e for e in compiled.flat.equations if e.terms > LONG_ROW]   # after aliases
    assert len(long) == 1 and long[0].terms == n + 2        # C1..Cn, source and ground
    res = bg.simulate(compiled, stop_time=0.2, interval=0.1)
    import bgmodelica.passes.sorting as sorting
    import bgmodelica.passes.symbolic as symbolic

    monkeypatch.setattr(symbolic, "LONG_ROW", 10**9)         # no split anywhere
    monkeypatch.setattr(sorting, "LONG_ROW", 10**9)
    plain = bg.compile(RCLadder(n))
    assert plain.summary()["states"] == compiled.summary()["states"]
    ref = bg.simulate(plain, stop_time=0.2, interval=0.1)
    assert all((res[k] == ref[k]).all() for k in ref.names)


@settings(max_examples=300, deadline=None)
@given(st.integers(1, 40).flatmap(lambda n: st.lists(
    st.lists(st.integers(0, n - 1), max_size=5), min_size=n, max_size=n)))
def test_scalar_block_coloring_separates_every_residual_from_its_other_variables(rows):
    n = len(rows)
    color = _coloring(n, rows).tolist()
    assert min(color) == 0
    for i, row in enumerate(rows):          # no residual sees another variable of its color
        assert all(color[j] != color[i] for j in row if j != i)
    alone = [i for i in range(n) if set(rows[i]) <= {i}
             and all(i not in rows[k] for k in range(n) if k != i)]
    assert all(color[i] == 0 for i in alone)      # no neighbours: the first color


def test_a_long_chain_needs_few_colors_not_one_round_per_link():
    n = 100_000
    rows = [[k - 1, k] if k else [0] for k in range(n)]        # each needs the one before
    color = _coloring(n, rows)
    assert all(color[k] != color[k - 1] for k in range(1, n))
    assert color.max() < 20
