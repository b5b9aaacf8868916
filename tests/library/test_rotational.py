"""Rotational components: gear ratio and energy, spring-inertia oscillator."""

from __future__ import annotations

import numpy as np
from library_testing import TIGHT, rel_error

import bgmodelica as bg
from bgmodelica import Component, Input, connect
from library.examples import GearedInertias, TorsionOscillator
from library.rotational import Damper, Fixed, Inertia, SpeedSensor, Torque


def test_ideal_gear_speeds_and_energy():
    result = bg.simulate(GearedInertias(), stop_time=2.0, interval=1e-3, **TIGHT)
    t = result.time
    tau, j1, j2, ratio = 2.0, 0.1, 0.8, 4.0
    j_eff = j1 + j2 / ratio**2
    w1, w2 = result["input_shaft.w"], result["output_shaft.w"]
    assert rel_error(w1, tau * t / j_eff) < 1e-6
    assert rel_error(w2, tau * t / j_eff / ratio) < 1e-6
    assert rel_error(result["input_shaft.phi"], ratio * result["output_shaft.phi"]) < 1e-9
    # the work of the torque is the kinetic energy of both shafts
    work = tau * result["input_shaft.phi"]
    energy = 0.5 * j1 * w1**2 + 0.5 * j2 * w2**2
    assert rel_error(energy, work) < 1e-6
    # torque balance through the gear: output torque = ratio * input torque
    tau_out = -result["gear.flange_b.tau"]
    assert rel_error(tau_out, j2 * tau / j_eff / ratio * np.ones_like(t)) < 1e-6


def test_spring_inertia_period():
    result = bg.simulate(TorsionOscillator(), stop_time=1.0, interval=1e-4, **TIGHT)
    t, phi = result.time, result["body.phi"]
    w0 = np.sqrt(4.0 / 0.01)
    assert rel_error(phi, 0.5 * np.cos(w0 * t)) < 1e-6
    up = [t[k] - phi[k] * (t[k + 1] - t[k]) / (phi[k + 1] - phi[k])
          for k in range(len(t) - 1) if phi[k] < 0 <= phi[k + 1]]
    assert abs(np.mean(np.diff(up)) - 2 * np.pi / w0) < 1e-6


def test_torque_sign_and_damper():
    """A positive torque signal accelerates; the damper brakes: w -> tau/d, time const J/d."""

    class Brake(Component):
        tau = Input(unit="N.m", description="Driving torque (model input)")
        drive = Torque()
        body = Inertia(J=2.0, phi=0.0, w=0.0)
        damper = Damper(d=0.5)
        fixed = Fixed()
        sensor = SpeedSensor()

        def equations(self):
            yield connect(self.tau, self.drive.tau)
            yield connect(self.drive.flange, self.body.flange_a)
            yield connect(self.body.flange_b, self.damper.flange_a)
            yield connect(self.damper.flange_b, self.fixed.flange)
            yield connect(self.sensor.flange, self.body.flange_a)

    result = bg.simulate(Brake(), stop_time=10.0, interval=1e-2, params={"tau": 1.5},
                         **TIGHT)
    expected = 1.5 / 0.5 * (1 - np.exp(-0.5 * result.time / 2.0))
    assert rel_error(result["sensor.w"], expected) < 1e-6
    # MSL sign: phi_rel = flange_b.phi - flange_a.phi = 0 - body.phi, tau = d*der(phi_rel)
    assert rel_error(result["damper.tau"], -0.5 * expected) < 1e-6
