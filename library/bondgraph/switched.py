"""Hybrid bond graphs: circuits and a DC motor with switches (``Sw``, Mosterman & Biswas 1998).

Every switch is written in the resistive form of the Modelica ideal switch
(``e = s*(Ron if on else 1)``, ``f = s*(1 if on else Goff)``), so the causality of the graph is
the same in every mode and a switching is an event that changes coefficients only.

* :class:`SwitchedRL`: ``Se:V -> 1 {R:R, I:L, Sw:sw}``; the switch closes at ``t_s`` (a time
  event, mode given as the string ``"time >= t_s"``). Current before the closing (the open
  switch leaks ``Goff``): ``i = V/(R + 1/Goff) (1 - exp(-t (R + 1/Goff)/L))``; after it
  ``i = i_inf + (i(t_s) - i_inf) exp(-(t - t_s)(R + Ron)/L)``, ``i_inf = V/(R + Ron)``.
* :class:`SwitchedRC`: ``Se:V -> 1 {R:R, Sw:sw, C:C}``: the same with a capacitor, charged
  after ``t_s`` with the time constant ``(R + Ron) C``.
* :class:`SwitchedDCMotor`: a DC motor fed by a half bridge: ``Se:Vs -> 1:a {Sw:hi} -> 0:m
  {Sw:lo} -> 1:i {R:R, I:L} -> GY:k -> 1:w {I:J, R:b}``. A Boolean ``drive`` set by a
  when-clause (true at ``t_on``, false at ``t_off``) closes the high-side switch ``hi``
  (motor voltage ``Vs``) while the low-side switch ``lo`` is open, and the reverse when
  ``drive`` is false (the motor terminals shorted: the armature current freewheels through
  ``lo`` and the motor brakes).

Parameters (SI; defaults in the classes) and the switch parameters ``Ron`` [Ohm], ``Goff``
[S] (default 1e-5, the Modelica defaults) are parameters of each model, passed to its
switches.
"""

from __future__ import annotations

from bgmodelica import Boolean, Parameter, time, when
from bgmodelica.bondgraph import GY, J0, J1, BondGraph, C, I, R, Se, Sw

__all__ = ["SwitchedRL", "SwitchedRC", "SwitchedDCMotor"]


class SwitchedRL(BondGraph):
    """Series RL circuit on a voltage source, closed by a switch at ``t_s``.

    Parameters: V [V], R [Ohm], L [H], t_s [s], Ron [Ohm], Goff [S]. State: ``ind.p`` (L i);
    the current is the flow of the 1-junction ``j`` (``j.f``). The switch mode is the
    string ``"time >= t_s"`` (a time event).
    """

    V = Parameter(10.0, unit="V", description="Source voltage")
    R = Parameter(2.0, unit="Ohm", description="Resistance")
    L = Parameter(0.5, unit="H", description="Inductance")
    t_s = Parameter(0.1, unit="s", description="Closing time of the switch")
    Ron = Parameter(1e-5, unit="Ohm", description="Switch on resistance")
    Goff = Parameter(1e-5, unit="S", description="Switch off conductance")

    def __init__(self, name: str | None = None, **kw) -> None:
        super().__init__(name, **kw)
        self.add("src", Se(E=self.V), at=(0, 0))
        self.add("j", J1(), at=(1.5, 0))
        self.add("res", R(R=self.R), at=(1.5, 1.3))
        self.add("ind", I(I=self.L), at=(1.5, -1.3))
        self.add("sw", Sw(on="time >= t_s", Ron=self.Ron, Goff=self.Goff), at=(3, 0))
        self.bond(self.src, self.j)
        self.bond(self.j, self.res)
        self.bond(self.j, self.ind)
        self.bond(self.j, self.sw)


class SwitchedRC(BondGraph):
    """Series RC circuit on a voltage source, closed by a switch at ``t_s``.

    Parameters: V [V], R [Ohm], Cap [F], t_s [s], Ron [Ohm], Goff [S]. State: ``cap.q``
    (C v); the capacitor voltage is ``cap.port.e``. The mode is given as a callable
    (``lambda m: time >= m.t_s``).
    """

    V = Parameter(5.0, unit="V", description="Source voltage")
    R = Parameter(100.0, unit="Ohm", description="Resistance")
    Cap = Parameter(1e-3, unit="F", description="Capacitance")
    t_s = Parameter(0.05, unit="s", description="Closing time of the switch")
    Ron = Parameter(1e-5, unit="Ohm", description="Switch on resistance")
    Goff = Parameter(1e-5, unit="S", description="Switch off conductance")

    def __init__(self, name: str | None = None, **kw) -> None:
        super().__init__(name, **kw)
        self.add("src", Se(E=self.V), at=(0, 0))
        self.add("j", J1(), at=(1.5, 0))
        self.add("res", R(R=self.R), at=(1.5, 1.3))
        self.add("cap", C(C=self.Cap, q=0.0), at=(1.5, -1.3))
        self.add("sw", Sw(on=lambda m: time >= m.t_s, Ron=self.Ron, Goff=self.Goff),
                 at=(3, 0))
        self.bond(self.src, self.j)
        self.bond(self.j, self.res)
        self.bond(self.j, self.cap)
        self.bond(self.j, self.sw)


class SwitchedDCMotor(BondGraph):
    """DC motor on a half bridge of two switches driven by the Boolean ``drive``.

    ``drive`` becomes true at ``t_on`` and false at ``t_off`` (a when/elsewhen clause on
    time relations): while true the high-side switch ``hi`` is on and the low-side ``lo``
    off (motor voltage ``Vs``); while false ``hi`` is off and ``lo`` on (terminals shorted,
    the current freewheels and the motor brakes).

    Parameters: Vs [V], R [Ohm], L [H], k [N.m/A], J [kg.m2], b [N.m.s/rad], t_on, t_off [s],
    Ron [Ohm], Goff [S]. States: ``ind.p`` (L i), ``rotor.p`` (J w); the armature current is
    ``i.f``, the speed ``w.f``, the motor voltage ``m.e``.
    """

    Vs = Parameter(12.0, unit="V", description="Supply voltage")
    R = Parameter(1.0, unit="Ohm", description="Armature resistance")
    L = Parameter(0.05, unit="H", description="Armature inductance")
    k = Parameter(0.1, unit="N.m/A", description="Torque and back-EMF constant")
    J = Parameter(1e-3, unit="kg.m2", description="Rotor inertia")
    b = Parameter(1e-3, unit="N.m.s/rad", description="Viscous friction")
    t_on = Parameter(0.05, unit="s", description="Drive on")
    t_off = Parameter(0.5, unit="s", description="Drive off (freewheel and brake)")
    Ron = Parameter(1e-5, unit="Ohm", description="Switch on resistance")
    Goff = Parameter(1e-5, unit="S", description="Switch off conductance")
    drive = Boolean(start=False, description="High side on, low side off")

    def __init__(self, name: str | None = None, **kw) -> None:
        super().__init__(name, **kw)
        self.add("src", Se(E=self.Vs, label="Vs"), at=(0, 0))
        self.add("a", J1(), at=(1.5, 0))
        self.add("hi", Sw(on="drive", Ron=self.Ron, Goff=self.Goff), at=(1.5, 1.3))
        self.add("m", J0(), at=(3, 0))
        self.add("lo", Sw(on=lambda m: ~m.drive, Ron=self.Ron, Goff=self.Goff),
                 at=(3, -1.3))
        self.add("i", J1(), at=(4.5, 0))
        self.add("res", R(R=self.R), at=(4.5, 1.3))
        self.add("ind", I(I=self.L), at=(4.5, -1.3))
        self.add("gy", GY(r=self.k), at=(6, 0))
        self.add("w", J1(), at=(7.5, 0))
        self.add("rotor", I(I=self.J), at=(7.5, 1.3))
        self.add("fric", R(R=self.b), at=(7.5, -1.3))
        self.bond(self.src, self.a)
        self.bond(self.a, self.hi)
        self.bond(self.a, self.m)
        self.bond(self.m, self.lo)
        self.bond(self.m, self.i)
        self.bond(self.i, self.res)
        self.bond(self.i, self.ind)
        self.bond(self.i, self.gy)
        self.bond(self.gy, self.w)
        self.bond(self.w, self.rotor)
        self.bond(self.w, self.fric)

    def equations(self):
        yield (when(time >= self.t_on, self.drive == True)  # noqa: E712 -- an assignment
               .elsewhen(time >= self.t_off, self.drive == False))  # noqa: E712
