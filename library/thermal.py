"""Lumped heat transfer (Modelica.Thermal.HeatTransfer names and sign conventions).

Connector :class:`HeatPort`: potential ``T`` [K], flow ``Q_flow`` [W], positive *into* the
component (``HeatPort_a`` / ``HeatPort_b`` in the MSL are the same connector here).

Components: :class:`HeatCapacitor` (``C*der(T) = port.Q_flow``), :class:`ThermalConductor`
and :class:`ThermalResistor` (conduction ``Q_flow = G*dT``, ``dT = R*Q_flow``, from
``port_a`` to ``port_b``), :class:`Convection` (``Q_flow = Gc*(solid.T - fluid.T)`` with the
signal input ``Gc`` [W/K]), :class:`FixedTemperature` / :class:`PrescribedTemperature`
(boundary temperature), :class:`FixedHeatFlow` / :class:`PrescribedHeatFlow` (heat *into* the
connected component: ``port.Q_flow = -Q_flow*(1 + alpha*(port.T - T_ref))``),
:class:`TemperatureSensor` and :class:`HeatFlowSensor`. Multi-domain:
:class:`HeatingResistor` (Modelica.Electrical.Analog.Basic.HeatingResistor), an electrical
resistor whose resistance follows its heat port's temperature and whose losses leave through
it.

Temperatures are absolute (K); :func:`from_degC` / :func:`to_degC` convert.
"""

from __future__ import annotations

from bgmodelica import (
    Component,
    Connector,
    Flow,
    Input,
    Output,
    Parameter,
    Potential,
    StateSelect,
    Variable,
    der,
)

from .electrical import OnePort

__all__ = ["HeatPort", "Element1D", "HeatCapacitor", "ThermalConductor", "ThermalResistor",
           "Convection", "FixedTemperature", "PrescribedTemperature", "FixedHeatFlow",
           "PrescribedHeatFlow", "TemperatureSensor", "HeatFlowSensor", "HeatingResistor",
           "from_degC", "to_degC"]

#: 0 degC in K
T_ZERO_DEGC = 273.15


def from_degC(t: float) -> float:
    """Celsius -> Kelvin."""
    return t + T_ZERO_DEGC


def to_degC(t: float) -> float:
    """Kelvin -> Celsius."""
    return t - T_ZERO_DEGC


class HeatPort(Connector):
    """Thermal port. Potential ``T`` [K]; flow ``Q_flow`` [W], positive into the component."""

    T = Potential(unit="K", description="Port temperature")
    Q_flow = Flow(unit="W", description="Heat flow rate into the component")


class Element1D(Component):
    """Two heat ports; heat flow ``Q_flow`` [W] from ``port_a`` to ``port_b``,
    ``dT = port_a.T - port_b.T`` [K]; nothing is stored."""

    port_a = HeatPort()
    port_b = HeatPort()
    Q_flow = Variable(unit="W", description="Heat flow rate from port_a to port_b")
    dT = Variable(unit="K", description="port_a.T - port_b.T")

    def equations(self):
        yield self.dT == self.port_a.T - self.port_b.T
        yield self.port_a.Q_flow == self.Q_flow
        yield self.port_b.Q_flow == -self.Q_flow


class HeatCapacitor(Component):
    """Lumped thermal capacity ``C*der(T) = port.Q_flow``. Parameter: C [J/K].

    State: T [K] (``HeatCapacitor(C=..., T=300.0)`` fixes its start). Connector: ``port``.
    """

    C = Parameter(1.0, unit="J/K", description="Heat capacity (cp*m)")
    T = Variable(unit="K", start=293.15, description="Temperature of the element",
                 state_select=StateSelect.PREFER)
    der_T = Variable(unit="K/s", description="Time derivative of the temperature")
    port = HeatPort()

    def equations(self):
        yield self.T == self.port.T
        yield self.der_T == der(self.T)
        yield self.C * self.der_T == self.port.Q_flow


class ThermalConductor(Element1D):
    """Lumped conduction ``Q_flow = G*dT``. Parameter: G [W/K] (e.g. k*A/L)."""

    G = Parameter(1.0, unit="W/K", description="Constant thermal conductance")

    def equations(self):
        yield self.Q_flow == self.G * self.dT


class ThermalResistor(Element1D):
    """Lumped conduction ``dT = R*Q_flow``. Parameter: R [K/W]."""

    R = Parameter(1.0, unit="K/W", description="Constant thermal resistance")

    def equations(self):
        yield self.dT == self.R * self.Q_flow


class Convection(Component):
    """Convection between a solid and a fluid: ``Q_flow = Gc*(solid.T - fluid.T)``.

    Input: Gc [W/K] convective thermal conductance (h*A). Connectors: ``solid``, ``fluid``;
    ``Q_flow`` [W] flows from the solid to the fluid.
    """

    Gc = Input(unit="W/K", description="Convective thermal conductance")
    solid = HeatPort()
    fluid = HeatPort()
    Q_flow = Variable(unit="W", description="Heat flow rate from solid to fluid")
    dT = Variable(unit="K", description="solid.T - fluid.T")

    def equations(self):
        yield self.dT == self.solid.T - self.fluid.T
        yield self.solid.Q_flow == self.Q_flow
        yield self.fluid.Q_flow == -self.Q_flow
        yield self.Q_flow == self.Gc * self.dT


class FixedTemperature(Component):
    """Fixed boundary temperature ``port.T = T``. Parameter: T [K]."""

    T = Parameter(293.15, unit="K", description="Fixed temperature at port")
    port = HeatPort()

    def equations(self):
        yield self.port.T == self.T


class PrescribedTemperature(Component):
    """Boundary temperature from the signal input ``T`` [K]: ``port.T = T``."""

    T = Input(unit="K", description="Temperature at port")
    port = HeatPort()

    def equations(self):
        yield self.port.T == self.T


class FixedHeatFlow(Component):
    """Fixed heat flow into the connected component:
    ``port.Q_flow = -Q_flow*(1 + alpha*(port.T - T_ref))``.

    Parameters: Q_flow [W], T_ref [K], alpha [1/K] (0: independent of the temperature).
    """

    Q_flow = Parameter(0.0, unit="W", description="Fixed heat flow rate at port")
    T_ref = Parameter(293.15, unit="K", description="Reference temperature")
    alpha = Parameter(0.0, unit="1/K", description="Temperature coefficient of heat flow rate")
    port = HeatPort()

    def equations(self):
        yield self.port.Q_flow == -self.Q_flow * (1 + self.alpha * (self.port.T - self.T_ref))


class PrescribedHeatFlow(Component):
    """Heat flow from the signal input ``Q_flow`` [W] into the connected component:
    ``port.Q_flow = -Q_flow*(1 + alpha*(port.T - T_ref))``. Parameters: T_ref [K],
    alpha [1/K]."""

    Q_flow = Input(unit="W", description="Heat flow rate into the connected component")
    T_ref = Parameter(293.15, unit="K", description="Reference temperature")
    alpha = Parameter(0.0, unit="1/K", description="Temperature coefficient of heat flow rate")
    port = HeatPort()

    def equations(self):
        yield self.port.Q_flow == -self.Q_flow * (1 + self.alpha * (self.port.T - self.T_ref))


class TemperatureSensor(Component):
    """Ideal absolute temperature sensor: output ``T`` [K] of ``port`` (no heat flow)."""

    T = Output(unit="K", description="Absolute temperature")
    port = HeatPort()

    def equations(self):
        yield self.port.Q_flow == 0
        yield self.T == self.port.T


class HeatFlowSensor(Element1D):
    """Ideal heat flow sensor between its ports (no temperature drop): output ``Q_flow``
    [W] from ``port_a`` to ``port_b``."""

    Q_flow = Output(unit="W", description="Heat flow from port_a to port_b")

    def equations(self):
        yield self.dT == 0


class HeatingResistor(OnePort):
    """Temperature-dependent electrical resistor that heats its ``heatPort``.

    ``R = R_ref*(1 + alpha*(heatPort.T - T_ref))``, ``v = R*i``, and the electrical power
    leaves through the heat port: ``heatPort.Q_flow = -v*i`` (``LossPower``).
    Parameters: R_ref [Ohm] at T_ref [K], alpha [1/K] temperature coefficient (copper:
    3.93e-3). Connectors: pins ``p``, ``n``; ``heatPort``.
    """

    R_ref = Parameter(1.0, unit="Ohm", description="Resistance at temperature T_ref")
    T_ref = Parameter(300.15, unit="K", description="Reference temperature")
    alpha = Parameter(0.0, unit="1/K", description="Temperature coefficient of resistance")
    R = Variable(unit="Ohm", description="Resistance = R_ref*(1 + alpha*(T_heatPort - T_ref))")
    LossPower = Variable(unit="W", description="Loss power leaving as heat")
    heatPort = HeatPort()

    def equations(self):
        yield self.R == self.R_ref * (1 + self.alpha * (self.heatPort.T - self.T_ref))
        yield self.v == self.R * self.i
        yield self.LossPower == self.v * self.i
        yield self.heatPort.Q_flow == -self.LossPower
