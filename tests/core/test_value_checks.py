"""Value checks before a run (:mod:`bgmodelica.value_checks`): parameter bounds are checked
against every parameter vector, start values once per DAE, and a DAE copied with other start
values (``dataclasses.replace`` shares the cache) is checked again."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica import Component, Parameter, Variable, der
from bgmodelica.errors import ParameterError
from bgmodelica.value_checks import check_values


class Decay(Component):
    k = Parameter(1.0, min=0.0, max=10.0)
    x = Variable(start=1.0, fixed=True)

    def equations(self):
        yield der(self.x) == -self.k * self.x


def test_parameter_bounds_are_checked_for_every_parameter_vector():
    compiled = bg.compile(Decay())
    dae, flat = compiled.dae, compiled.reduced.model
    check_values(dae, dae.p_default, flat)                  # fine, and now cached
    k = [q.name for q in dae.parameters].index("k")
    for value, side in ((-1.0, "below its min = 0"), (11.0, "above its max = 10"),
                        (np.nan, "must be a finite number")):
        p = np.array(dae.p_default, dtype=float)
        p[k] = value
        with pytest.raises(ParameterError, match=side):
            check_values(dae, p, flat)
    with pytest.raises(ParameterError, match="k = -2 is below its min"):
        bg.simulate(compiled, stop_time=0.1, params={"k": -2.0})


def test_start_values_of_a_copied_dae_are_checked_again():
    compiled = bg.compile(Decay())
    dae, flat = compiled.dae, compiled.reduced.model
    check_values(dae, dae.p_default, flat)
    bad = replace(dae, x_start=np.array([np.inf]))
    assert bad.cache is dae.cache                           # what makes this case matter
    with pytest.raises(ParameterError, match="start value of x is inf"):
        check_values(bad, bad.p_default, flat)
    check_values(dae, dae.p_default, flat)                  # the original still passes
