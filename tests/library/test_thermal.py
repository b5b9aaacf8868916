"""Thermal domain (Modelica.Thermal.HeatTransfer conventions) and the self-heating DC motor."""

from __future__ import annotations

import math

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica import Component, connect
from library.blocks import Constant
from library.examples.thermal import ThermalDCMotor, steady_state
from library.thermal import (
    Convection,
    FixedHeatFlow,
    FixedTemperature,
    HeatCapacitor,
    HeatFlowSensor,
    PrescribedHeatFlow,
    TemperatureSensor,
    ThermalConductor,
    ThermalResistor,
    from_degC,
    to_degC,
)

TIGHT = {"rtol": 1e-10, "atol": 1e-12}


class Heated(Component):
    """A capacitor heated by a fixed heat flow: T = T0 + Q t / C (heat flows *into* it)."""

    heater = FixedHeatFlow(Q_flow=10.0)
    body = HeatCapacitor(C=2.0, T=300.0)
    sensor = TemperatureSensor()

    def equations(self):
        yield connect(self.heater.port, self.body.port)
        yield connect(self.body.port, self.sensor.port)


def test_heat_flow_source_heats_the_capacitor():
    res = bg.simulate(Heated(), stop_time=3.0, interval=0.5, **TIGHT)
    assert np.allclose(res["body.T"], 300.0 + 10.0 * res.time / 2.0, rtol=0, atol=1e-9)
    assert np.allclose(res["sensor.T"], res["body.T"])
    # MSL sign: the source's port flow is negative (it leaves the source)
    assert np.allclose(res["heater.port.Q_flow"], -10.0)
    assert np.allclose(res["body.port.Q_flow"], 10.0)


class Cooling(Component):
    """Two capacitors: one cooled by convection to a fixed temperature through a conductor
    and a resistor in series: 1/G_total = 1/G + R + 1/Gc."""

    body = HeatCapacitor(C=4.0, T=400.0)
    wall = ThermalConductor(G=2.0)
    layer = ThermalResistor(R=0.25)
    meter = HeatFlowSensor()
    film = Convection()
    gc = Constant(k=4.0)
    ambient = FixedTemperature(T=300.0)

    def equations(self):
        yield connect(self.body.port, self.wall.port_a)
        yield connect(self.wall.port_b, self.layer.port_a)
        yield connect(self.layer.port_b, self.meter.port_a)
        yield connect(self.meter.port_b, self.film.solid)
        yield connect(self.film.fluid, self.ambient.port)
        yield connect(self.gc.y, self.film.Gc)


def test_series_conduction_and_convection_decay():
    res = bg.simulate(Cooling(), stop_time=10.0, interval=0.5, **TIGHT)
    g = 1.0 / (1 / 2.0 + 0.25 + 1 / 4.0)                   # 1 W/K
    expected = 300.0 + 100.0 * np.exp(-g * res.time / 4.0)
    assert np.max(np.abs(res["body.T"] - expected)) < 1e-6    # 2.5e-9 of T at rtol 1e-10
    # heat flows from port_a to port_b (out of the hot body, into the ambient)
    assert np.allclose(res["wall.Q_flow"], g * (res["body.T"] - 300.0), atol=1e-7)
    assert np.allclose(res["meter.Q_flow"], res["wall.Q_flow"], atol=1e-9)
    assert np.allclose(res["film.Q_flow"], res["wall.Q_flow"], atol=1e-9)
    assert np.all(res["film.dT"] > 0)


class Prescribed(Component):
    q = Constant(k=5.0)
    heater = PrescribedHeatFlow(alpha=0.01, T_ref=300.0)
    body = HeatCapacitor(C=1.0, T=300.0)

    def equations(self):
        yield connect(self.q.y, self.heater.Q_flow)
        yield connect(self.heater.port, self.body.port)


def test_prescribed_heat_flow_with_temperature_coefficient():
    # C dT/dt = Q (1 + alpha (T - T_ref)): T - T_ref = (exp(Q alpha t / C) - 1) / alpha
    res = bg.simulate(Prescribed(), stop_time=2.0, interval=0.5, **TIGHT)
    expected = 300.0 + (np.exp(5.0 * 0.01 * res.time) - 1.0) / 0.01
    assert np.max(np.abs(res["body.T"] - expected)) < 1e-6


def test_celsius_helpers():
    assert from_degC(20.0) == pytest.approx(293.15)
    assert to_degC(373.15) == pytest.approx(100.0)


def test_thermal_dc_motor_reaches_the_analytic_fixed_point():
    ss = steady_state()
    # the fixed point solves G (T - T_amb) (R(T) + k^2/d)^2 = R(T) V^2
    R = 1.0 * (1 + 3.93e-3 * (ss["T"] - 293.15))
    assert 0.05 * (ss["T"] - 293.15) * (R + 10.0) ** 2 == pytest.approx(R * 144.0, rel=1e-14)
    # 40 thermal time constants (C/G = 100 s): the transient has decayed below 1e-15
    res = bg.simulate(ThermalDCMotor(), stop_time=4000.0, interval=10.0, rtol=1e-12,
                      atol=1e-12)
    assert abs(res.final("capacity.T") - ss["T"]) < 1e-8
    assert abs(res.final("winding.R") - ss["R"]) < 1e-10
    assert abs(res.final("inductor.i") - ss["i"]) < 1e-10
    assert abs(res.final("rotor.w") - ss["w"]) < 1e-8
    assert abs(res.final("winding.LossPower") - ss["P"]) < 1e-10
    assert res.unit("capacity.T") == "K" and res.unit("winding.LossPower") == "W"
    # hotter winding, higher resistance, lower current than the cold motor
    assert ss["R"] > 1.0 and ss["i"] < 12.0 / 11.0
    assert math.isclose(ss["T"] - 293.15, ss["P"] / 0.05, rel_tol=1e-12)
