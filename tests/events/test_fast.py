"""Bound-buffer evaluation of CasADi functions (:class:`bgmodelica.events.fast.Fast`)."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

from bgmodelica.events.fast import Fast


def _f() -> ca.Function:
    x = ca.SX.sym("x", 3)
    return ca.Function("f", [x], [2 * x, ca.sum1(x)])


def test_outputs_are_written_into_caller_buffers():
    out = np.full(3, np.nan)
    fast = Fast(_f(), {0: out})
    res = fast([1.0, 2.0, 3.0])
    assert res[0] is out
    np.testing.assert_array_equal(out, [2.0, 4.0, 6.0])
    assert float(res[1][0]) == 6.0
    fast([0.5, 0.5, 0.5])                      # the next call overwrites in place
    np.testing.assert_array_equal(out, [1.0, 1.0, 1.0])


@pytest.mark.parametrize("bad", [np.zeros(2), np.zeros(3, dtype=np.float32),
                                 np.zeros((3, 2))[:, 0]])
def test_a_buffer_of_the_wrong_size_type_or_layout_is_refused(bad):
    with pytest.raises(ValueError, match="contiguous float64 vector of 3"):
        Fast(_f(), {0: bad})
