"""Models with something wrong in them, one per class of bad input, for
:mod:`tests.core.test_bad_inputs` (loaded as ``path/bad_models.py:Name`` by the command line).

Line numbers matter: the tests look for ``bad_models.py:<line>`` of the statements marked
``# LINE:<tag>``.
"""

from __future__ import annotations

from bgmodelica import (
    Component,
    Input,
    Output,
    Parameter,
    StateSelect,
    Variable,
    connect,
    der,
    if_else,
    log,
    sqrt,
    time,
)
from library.blocks import Constant, Gain
from library.electrical import Capacitor, ConstantVoltage, Ground, Inductor, Resistor


class RC(Component):
    """A correct model: the reference the bad ones are variations of."""

    src = ConstantVoltage(V=1.0)
    R = Resistor(R=2.0)
    C = Capacitor(C=0.5, v=0.0)
    gnd = Ground()

    def equations(self):
        yield connect(self.src.p, self.R.p)
        yield connect(self.R.n, self.C.p)
        yield connect(self.C.n, self.src.n)
        yield connect(self.src.n, self.gnd.p)


# -- model language ---------------------------------------------------------------------------

class SelfConnectPin(RC):
    def equations(self):
        yield connect(self.R.n, self.R.n)


class SelfConnectSignal(Component):
    y = Output()
    u = Input()

    def equations(self):
        yield self.y == 1.0
        yield connect(self.u, self.u)


class OutputToOutput(Component):
    a = Constant(k=1.0)
    b = Constant(k=2.0)

    def equations(self):
        yield connect(self.a.y, self.b.y)


class MissingEquation(Component):
    x = Variable(start=0.0, fixed=True)
    orphan = Variable()

    def equations(self):
        yield der(self.x) == 1.0


class SurplusEquation(Component):
    x = Variable(start=0.0, fixed=True)

    def equations(self):
        yield der(self.x) == 1.0
        yield self.x == 2.0 * time


class Singular(Component):
    a = Variable()
    b = Variable()

    def equations(self):
        yield self.a == 1.0
        yield 2 * self.a == 3.0 + 0 * self.b


class NoGround(Component):
    src = ConstantVoltage(V=1.0)
    R = Resistor(R=2.0)
    C = Capacitor(C=0.5, v=0.0)

    def equations(self):
        yield connect(self.src.p, self.R.p)
        yield connect(self.R.n, self.C.p)
        yield connect(self.C.n, self.src.n)


class NoGroundStar(Component):
    """Three components meeting in one node, none of the nodes grounded."""

    src = ConstantVoltage(V=1.0)
    R = Resistor(R=2.0)
    C = Capacitor(C=0.5, v=0.0)
    L = Inductor(L=0.1, i=0.0)

    def equations(self):
        yield connect(self.src.p, self.R.p)
        yield connect(self.R.n, self.C.p)
        yield connect(self.C.p, self.L.p)
        yield connect(self.R.n, self.C.n)
        yield connect(self.C.n, self.src.n)
        yield connect(self.L.n, self.src.n)


class UnconnectedInput(Component):
    g = Gain(k=2.0)
    x = Variable(start=0.0, fixed=True)

    def equations(self):
        yield der(self.x) == self.g.y


class AlwaysVsNever(Component):
    x = Variable(start=1.0, fixed=True, state_select=StateSelect.ALWAYS)
    y = Variable(state_select=StateSelect.NEVER)

    def equations(self):
        yield der(self.x) == -self.x
        yield self.x == self.y


class NeverButState(Component):
    x = Variable(start=1.0, fixed=True, state_select=StateSelect.NEVER)

    def equations(self):
        yield der(self.x) == -self.x


class AlwaysNotDifferentiated(Component):
    w = Variable(state_select=StateSelect.ALWAYS)

    def equations(self):
        yield self.w == 2 * time


class AlwaysTooMany(Component):
    x1 = Variable(start=0.0, fixed=True, state_select=StateSelect.ALWAYS)
    x2 = Variable(state_select=StateSelect.ALWAYS)
    v1 = Variable(start=0.0, fixed=True)
    v2 = Variable()
    f = Variable()

    def equations(self):
        yield der(self.x1) == self.v1
        yield der(self.x2) == self.v2
        yield der(self.v1) == self.f
        yield der(self.v2) == -self.f + 1
        yield self.x1 == 2 * self.x2


class ParameterOfTime(Component):
    k = Parameter(1.0)
    x = Variable(start=1.0, fixed=True)

    def __init__(self, **kw):
        super().__init__(**kw)
        self.modify(k=1 + time)

    def equations(self):
        yield der(self.x) == -self.k * self.x


class ParameterOfVariable(Component):
    x = Variable(start=1.0, fixed=True)

    def __init__(self, **kw):
        super().__init__(**kw)
        self.load = Resistor(R=self.x)
        self.gnd = Ground()
        self.connect(self.load.p, self.gnd.p)
        self.connect(self.load.n, self.gnd.p)

    def equations(self):
        yield der(self.x) == -self.x


class ParameterOfInput(Component):
    u = Input(start=1.0)
    x = Variable(start=1.0, fixed=True)

    def __init__(self, **kw):
        super().__init__(**kw)
        self.load = Resistor(R=2 * self.u)
        self.gnd = Ground()
        self.connect(self.load.p, self.gnd.p)
        self.connect(self.load.n, self.gnd.p)

    def equations(self):
        yield der(self.x) == -self.x


class RaisesInInit(Component):
    def __init__(self, **kw):
        super().__init__(**kw)
        self.R = Resistor(R=1.0)
        raise ValueError("the user's bug")  # LINE:init


class Leaky(Component):
    x = Variable(start=1.0, fixed=True)

    def equations(self):
        yield der(self.x) == -self.x
        raise RuntimeError("broken equations")  # LINE:equations


class RaisesInEquations(Component):
    inner = Leaky()


class TypoInEquations(Component):
    x = Variable(start=1.0, fixed=True)

    def equations(self):
        yield der(self.x) == -self.x + "1"  # LINE:typo


class Flaky(Resistor):
    """Builds once (the class-body template), fails on the copy each model instance makes."""

    built = 0

    def __init__(self, **kw):
        type(self).built += 1
        if type(self).built > 1:
            raise KeyError("no second copy")  # LINE:clone
        super().__init__(**kw)


class RaisesInSubcomponent(Component):
    part = Flaky()


class NotAnEquation(Component):
    x = Variable()

    def equations(self):
        yield self.x + 1


def ladder(n=3, scale=1.0):
    """A function model: n resistors in series on a source."""
    if n < 1:
        raise ValueError(f"ladder needs n >= 1, got {n}")  # LINE:ladder
    m = Component(name="ladder")
    m.add("src", ConstantVoltage(V=scale))
    m.add("gnd", Ground())
    m.connect(m.src.n, m.gnd.p)
    node = m.src.p
    for k in range(n):
        r = m.add(f"R{k}", Resistor(R=1.0 + k))
        m.connect(node, r.p)
        node = r.n
    m.connect(node, m.gnd.p)
    return m


def not_a_model():
    return 42


# -- parameters and start values -----------------------------------------------------------------

class Bounded(Component):
    k = Parameter(1.0, min=0.0, max=10.0)
    x = Variable(start=1.0, fixed=True, min=-5.0, max=5.0)

    def equations(self):
        yield der(self.x) == -self.k * self.x


class DefaultOutOfRange(Component):
    k = Parameter(-2.0, min=0.0)
    x = Variable(start=1.0, fixed=True)

    def equations(self):
        yield der(self.x) == -self.k * self.x


class PositiveResistor(Resistor):
    R = Parameter(1.0, unit="Ohm", min=0.0, description="Resistance")


class BoundOutOfRange(Component):
    """R1.R is bound to Rtot/2: a negative Rtot puts it below its min = 0."""

    Rtot = Parameter(4.0, unit="Ohm")

    def __init__(self, **kw):
        super().__init__(**kw)
        self.src = ConstantVoltage(V=2.0)
        self.R1 = PositiveResistor(R=self.Rtot / 2)
        self.gnd = Ground()
        self.connect(self.src.p, self.R1.p)
        self.connect(self.R1.n, self.src.n)
        self.connect(self.src.n, self.gnd.p)


class NanParameter(Component):
    k = Parameter(float("nan"))
    x = Variable(start=1.0, fixed=True)

    def equations(self):
        yield der(self.x) == -self.k * self.x


class NanStart(RC):
    C = Capacitor(C=0.5, v=float("inf"))


class StartOutOfRange(Component):
    x = Variable(start=-9.0, fixed=True, min=-5.0)

    def equations(self):
        yield der(self.x) == -self.x


class LogOfNegative(Component):
    a = Parameter(-1.0)
    x = Variable(start=1.0, fixed=True)

    def equations(self):
        yield der(self.x) == log(self.a) * self.x


class DivisionByZero(Component):
    a = Parameter(0.0)
    x = Variable(start=1.0, fixed=True)

    def equations(self):
        yield der(self.x) == self.x / self.a


class SqrtOfNegative(Component):
    c = Parameter(-4.0)
    x = Variable(start=1.0, fixed=True)
    y = Variable()

    def equations(self):
        yield self.y == sqrt(self.c + self.x)
        yield der(self.x) == -self.y


# -- results -------------------------------------------------------------------------------------

class NanLater(Component):
    """y = sqrt(1 - t) is NaN after t = 1: an error naming y and the time."""

    x = Variable(start=0.0, fixed=True)
    y = Variable()

    def equations(self):
        yield der(self.x) == 1.0
        yield self.y == sqrt(1.0 - self.x)


class NanLaterHybrid(NanLater):
    """The same through the event loop (a when-clause makes it hybrid)."""

    n = Variable(start=0.0, fixed=True)

    def equations(self):
        yield der(self.n) == if_else(self.x > 0.25, 1.0, 0.0)


class LosesSolution(Component):
    """z = sqrt(1 - t^2) has no real solution after t = 1: the solver fails there."""

    x = Variable(start=0.0, fixed=True)
    z = Variable(start=1.0)

    def equations(self):
        yield der(self.x) == 1.0
        yield self.z**2 + self.x**2 == 1.0


class _Lag(Component):
    T = Parameter(1.0)
    U = Parameter(1.0)
    x = Variable(start=1.0, fixed=True)

    def equations(self):
        yield der(self.x) == -self.x / self.T


class RecursiveBindings(Component):
    """c1.U bound to c2.T, c2.T bound to c1.U."""

    def __init__(self, **kw):
        super().__init__(**kw)
        self.add("c1", _Lag())
        self.add("c2", _Lag(T=self.c1.U))
        self.c1.U = self.c2.T

    def equations(self):
        return ()


class TextStart(Component):
    x = Variable(start="half a volt", fixed=True, unit="V")
    k = Parameter(1.0, unit="1/s")

    def equations(self):
        yield der(self.x) == -self.k * self.x
