"""Which observed outputs can turn non-finite for finite inputs (the result check evaluates
only those): a division by, or a root, logarithm or power of, something that varies."""

from __future__ import annotations

import casadi as ca

from bgmodelica.diagnose import unsafe_outputs


def test_unsafe_outputs_by_operation_and_by_what_varies():
    x, p = ca.SX.sym("x", 4), ca.SX.sym("p")
    outs = [x[0] / x[1],            # 0: division by a varying input
            1 / p,                  # 1: by a constant input only
            ca.sqrt(x[2] * p),      # 2: root of something varying
            ca.log(p),              # 3: of a constant input
            x[0] ** x[1],           # 4: power
            ca.sin(x[3]) / 2,       # 5: division by a number
            x[0] * p + 3,           # 6: polynomial
            ca.exp(1 / x[2]) - x[3],  # 7: a division deep inside
            ca.DM(2.0)]             # 8: a constant
    f = ca.Function("f", [x, p], [ca.vertcat(*outs)])
    assert unsafe_outputs(f, (0,)) == [0, 2, 4, 7]
    assert unsafe_outputs(f, (0, 1)) == [0, 1, 2, 3, 4, 7]     # p varies too
    assert unsafe_outputs(f, ()) == []


def test_all_finite_is_exact_when_the_sum_overflows_or_cancels():
    import numpy as np

    from bgmodelica.simulate import _all_finite

    assert _all_finite(np.ones((3, 4)))
    assert _all_finite(np.full((2, 3), 1e308))               # the sum overflows: all finite
    assert _all_finite(np.zeros((0, 5)))
    for bad in (np.nan, np.inf, -np.inf):
        a = np.ones((3, 4))
        a[1, 2] = bad
        assert not _all_finite(a)
    a = np.ones(6)
    a[0], a[1] = np.inf, -np.inf                              # the sum is nan, not inf
    assert not _all_finite(a)


def test_the_result_check_analyses_only_what_is_nonlinear_in_what_varies():
    from types import SimpleNamespace

    from bgmodelica.simulate import _unsafe

    t, x, z, p = ca.SX.sym("t"), ca.SX.sym("x", 4), ca.SX.sym("z", 0), ca.SX.sym("p")
    observed = ca.vertcat(x[0] / x[1], x[0] / p, ca.sqrt(x[2] * p), ca.log(p) * x[3],
                          x[0] ** x[1], ca.sin(t) / 2, x[0] * p + 3, ca.exp(1 / x[2]) - x[3],
                          x[1] / (t - 1), x[0] + x[1])
    dae = SimpleNamespace(t=t, x=x, z=z, p=p, observed=observed)
    assert _unsafe(dae, range(10)) == [0, 2, 4, 7, 8]
    assert _unsafe(dae, [1, 3, 5, 6, 9]) == []
