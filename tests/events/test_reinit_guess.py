"""Consistent algebraic variables after an event: solved from their values just before it."""

from __future__ import annotations

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica import Component, Variable, der, if_else, time


class TwoBranches(Component):
    """x = t, and an algebraic z with two roots, z = x and z = x - 1: z starts on the first and
    stays on it. Two time events (t = 1, t = 3) leave both alone; between them x moves by 2,
    so Newton's method from the solution of the previous event would land on the other root
    (its basin boundary is z = x - 1/2)."""

    x = Variable(start=0.0, fixed=True)
    z = Variable(start=0.0)
    mode = Variable()

    def equations(self):
        yield der(self.x) == 1.0
        yield self.z * self.z - (2 * self.x - 1) * self.z + self.x * (self.x - 1) == 0
        yield self.mode == if_else(time < 1, 0.0, if_else(time < 3, 1.0, 2.0))


def test_algebraic_variables_after_an_event_start_from_the_left_limit():
    res = bg.simulate(TwoBranches(), stop_time=4.0, interval=0.5, rtol=1e-8, atol=1e-10)
    assert res.meta["event_times"] == [1.0, 3.0]
    assert res.meta["states"] == ["x"] and res.meta["solver"] == "idas"
    np.testing.assert_allclose(res["x"], res.time, atol=1e-9)
    np.testing.assert_allclose(res["z"], res.time, atol=1e-7)      # the branch z = x
    assert res["mode"][-1] == pytest.approx(2.0)
