"""Thermal examples: a DC motor whose winding heats up (electrical + rotational + thermal),
and heat conduction along a rod discretized with array equations.

:class:`ThermalDCMotor`: the :class:`~library.examples.motors.DCMotor` drive with a
temperature-dependent armature resistance (:class:`~library.thermal.HeatingResistor`) whose
copper losses heat the winding (:class:`~library.thermal.HeatCapacitor`), cooled to the
ambient through a :class:`~library.thermal.ThermalConductor`. :func:`steady_state` gives its
analytic fixed point.

:class:`HeatRod`: the heat equation on a rod with both ends held at a fixed temperature, as
``n`` nodes and array equations (large ``n`` compiles by the array path); its sine mode decays
exactly as :func:`rod_mode` says.
"""

from __future__ import annotations

import math

import numpy as np

from bgmodelica import Component, Parameter, Variable, connect, der
from library.electrical import EMF, ConstantVoltage, Ground, Inductor
from library.rotational import Damper, Fixed, Inertia
from library.thermal import FixedTemperature, HeatCapacitor, HeatingResistor, ThermalConductor

__all__ = ["HeatRod", "ThermalDCMotor", "rod_mode", "steady_state"]


class ThermalDCMotor(Component):
    """DC motor on a constant voltage with a self-heating copper winding.

    Electrical: source (V = 12 V) -> winding (R = R_ref*(1 + alpha*(T - T_ref)), R_ref = 1 Ohm
    at T_ref = 20 degC, alpha = 3.93e-3 1/K) -> inductor (L = 10 mH) -> emf (k = 0.1 N.m/A)
    -> ground. Mechanical: emf.flange -> rotor (J = 0.01 kg.m2) -> damper (d = 0.001 N.m.s/rad)
    -> fixed. Thermal: the winding's losses R*i^2 heat its capacity (C = 5 J/K, T(0) = 20 degC),
    which loses ``G*(T - T_amb)`` (G = 0.05 W/K) to the ambient (T_amb = 20 degC): thermal
    time constant C/G = 100 s, electrical L/R = 10 ms, mechanical about 1 s.
    At steady state ``i = V/(R(T) + k^2/d)`` and ``G*(T - T_amb) = R(T)*i^2``
    (:func:`steady_state`).
    """

    source = ConstantVoltage(V=12.0)
    winding = HeatingResistor(R_ref=1.0, T_ref=293.15, alpha=3.93e-3)
    inductor = Inductor(L=0.01, i=0.0)
    emf = EMF(k=0.1)
    ground = Ground()
    rotor = Inertia(J=0.01, phi=0.0, w=0.0)
    damper = Damper(d=0.001)
    fixed = Fixed()
    capacity = HeatCapacitor(C=5.0, T=293.15)
    cooling = ThermalConductor(G=0.05)
    ambient = FixedTemperature(T=293.15)

    def equations(self):
        yield connect(self.source.p, self.winding.p)
        yield connect(self.winding.n, self.inductor.p)
        yield connect(self.inductor.n, self.emf.p)
        yield connect(self.emf.n, self.source.n)
        yield connect(self.source.n, self.ground.p)
        yield connect(self.emf.flange, self.rotor.flange_a)
        yield connect(self.rotor.flange_b, self.damper.flange_a)
        yield connect(self.damper.flange_b, self.fixed.flange)
        yield connect(self.winding.heatPort, self.capacity.port)
        yield connect(self.capacity.port, self.cooling.port_a)
        yield connect(self.cooling.port_b, self.ambient.port)


def steady_state(V: float = 12.0, R_ref: float = 1.0, T_ref: float = 293.15,
                 alpha: float = 3.93e-3, k: float = 0.1, d: float = 0.001, G: float = 0.05,
                 T_amb: float = 293.15) -> dict[str, float]:
    """The analytic fixed point of :class:`ThermalDCMotor` (defaults: its parameters).

    With ``K = k^2/d`` the steady current is ``i = V/(R + K)`` and the winding temperature
    solves ``G*(T - T_amb)*(R(T) + K)^2 = R(T)*V^2``, ``R(T) = R_ref*(1 + alpha*(T - T_ref))``:
    a cubic in ``T``, whose root above ``T_amb`` is found by Newton's method from ``T_amb``
    (the left side grows faster than the right one there) to machine precision.
    Returns ``T`` [K], ``R`` [Ohm], ``i`` [A], ``w`` [rad/s] and ``P`` [W] (copper losses).
    """
    K = k * k / d

    def res(T: float) -> tuple[float, float]:
        R = R_ref * (1 + alpha * (T - T_ref))
        dR = R_ref * alpha
        f = G * (T - T_amb) * (R + K) ** 2 - R * V * V
        df = G * (R + K) ** 2 + 2 * G * (T - T_amb) * (R + K) * dR - dR * V * V
        return f, df

    T = T_amb
    for _ in range(100):
        f, df = res(T)
        step = f / df
        T -= step
        if abs(step) <= 1e-15 * abs(T):
            break
    R = R_ref * (1 + alpha * (T - T_ref))
    i = V / (R + K)
    if not math.isfinite(T):
        raise ArithmeticError("no steady state (thermal runaway)")
    return {"T": T, "R": R, "i": i, "w": k * i / d, "P": R * i * i}


class HeatRod(Component):
    """Heat conduction along a rod of length ``L`` whose ends are held at ``T_end``: the
    heat equation ``dT/dt = alpha d2T/dx2`` on ``n`` interior nodes ``x_k = k h``,
    ``h = L/(n + 1)`` (second-order central differences, written as array equations)::

        der(T[1])     = c (T_end - 2 T[1] + T[2])
        der(T[2:n-1]) = c (T[1:n-2] - 2 T[2:n-1] + T[3:n])
        der(T[n])     = c (T[n-1] - 2 T[n] + T_end)          c = alpha / h^2

    Parameters: ``alpha`` thermal diffusivity [m2/s] (1e-4), ``L`` [m] (0.1), ``T_end`` [K]
    (300). States: ``T[1..n]`` [K], starting at ``T_end + A sin(pi x_k / L)`` (``A`` = 10 K,
    the constructor's ``amplitude``), the rod's slowest mode, which then decays exactly as
    :func:`rod_mode`.
    """

    T = Variable(shape="n", unit="K", description="node temperature")
    alpha = Parameter(1e-4, unit="m2/s", description="thermal diffusivity")
    L = Parameter(0.1, unit="m", description="rod length")
    T_end = Parameter(300.0, unit="K", description="temperature held at both ends")

    def __init__(self, n: int = 10, amplitude: float = 10.0, **modifiers):
        if n < 3:
            raise ValueError("HeatRod needs n >= 3 nodes")
        self.n = n
        x = np.arange(1, n + 1) / (n + 1)
        super().__init__(**{"T": 300.0 + amplitude * np.sin(np.pi * x), **modifiers})

    def equations(self):
        T = self.T
        c = self.alpha * (self.n + 1) ** 2 / self.L**2
        yield der(T[0]) == c * (self.T_end - 2.0 * T[0] + T[1])
        yield der(T[1:-1]) == c * (T[:-2] - 2.0 * T[1:-1] + T[2:])
        yield der(T[-1]) == c * (T[-2] - 2.0 * T[-1] + self.T_end)


def rod_mode(n: int, t: float, alpha: float = 1e-4, L: float = 0.1, T_end: float = 300.0,
             amplitude: float = 10.0) -> np.ndarray:
    """The node temperatures of :class:`HeatRod` at time ``t`` [s]: its start profile is an
    eigenvector of the discrete Laplacian, so ``T_k(t) = T_end + A e^(lambda t)
    sin(pi x_k / L)`` with ``lambda = -(4 alpha / h^2) sin^2(pi h / (2 L))`` exactly."""
    h = L / (n + 1)
    lam = -4.0 * alpha / h**2 * math.sin(math.pi * h / (2.0 * L)) ** 2
    x = np.arange(1, n + 1) / (n + 1)
    return T_end + amplitude * math.exp(lam * t) * np.sin(np.pi * x)
