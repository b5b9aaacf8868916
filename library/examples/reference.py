"""Small test models that cover the ground of the FMI standard's reference FMUs, written in
bgmodelica so that they export as FMUs (FMI 2.0/3.0, ME/CS) and check FMU importers:

* :class:`Dahlquist` - the test equation der(x) = -k x, x(t) = exp(-k t);
* :class:`VanDerPol` - the Van der Pol oscillator, a stiff-ish limit cycle;
* :class:`Stair` - an Integer counter stepped by time events every second.

(:class:`~library.examples.hybrid.BouncingBall` covers state events.)
"""

from __future__ import annotations

from bgmodelica import Component, Integer, Output, Parameter, der, pre, sample, when

__all__ = ["Dahlquist", "VanDerPol", "Stair"]


class Dahlquist(Component):
    """Dahlquist's test equation der(x) = -k x, x(0) = 1: x(t) = exp(-k t).

    Parameters: k [1/s] (default 1). Output: x [1], a state.
    """

    k = Parameter(1.0, unit="1/s", description="Decay rate")
    x = Output(start=1.0, fixed=True, description="The decaying state")

    def equations(self):
        yield der(self.x) == -self.k * self.x


class VanDerPol(Component):
    """The Van der Pol oscillator der(x0) = x1, der(x1) = mu (1 - x0^2) x1 - x0.

    Parameters: mu [1] (default 1). Outputs: x0 (start 2), x1 (start 0), both states.
    """

    mu = Parameter(1.0, unit="1", description="Damping parameter")
    x0 = Output(start=2.0, fixed=True, description="Position-like state")
    x1 = Output(start=0.0, fixed=True, description="Velocity-like state")

    def equations(self):
        yield der(self.x0) == self.x1
        yield der(self.x1) == self.mu * (1 - self.x0 ** 2) * self.x1 - self.x0


class Stair(Component):
    """An Integer counter that starts at 1 and goes up by 1 at every time event
    t = 1, 2, 3, ... s: ``counter(t) = 1 + floor(t)``.

    Parameters: period [s] (default 1). Output: counter (Integer).
    """

    period = Parameter(1.0, unit="s", description="Time between steps")
    counter = Integer(start=1, description="1 + the number of steps so far")
    y = Output(description="The counter as a Real output")

    def equations(self):
        yield when(sample(self.period, self.period), self.counter == pre(self.counter) + 1)
        yield self.y == self.counter
