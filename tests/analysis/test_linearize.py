"""Linearization against analytic references: the DC motor's transfer function and the
Cartesian pendulum (index 3) at its hanging equilibrium."""

from __future__ import annotations

import numpy as np
import pytest

import bgmodelica as bg
from bgmodelica.analysis import linearization
from bgmodelica.errors import ParameterError
from library.examples.constrained import Pendulum
from library.examples.control import DCMotorIO

MOTOR = dict(R=2.0, L=0.05, k=0.3, J=0.02, b=0.004)


def _motor_tf(s: np.ndarray, R: float, L: float, k: float, J: float, b: float) -> np.ndarray:
    return k / ((L * s + R) * (J * s + b) + k**2)


def test_dc_motor_transfer_function():
    sys = bg.linearize(DCMotorIO(), {**MOTOR, "V": 3.0})
    assert sys.input_labels == ["V"] and sys.output_labels == ["w"]
    assert sorted(sys.state_labels) == ["inductor.i", "rotor.phi", "rotor.w"]
    omega = np.concatenate([[0.0], np.logspace(-3, 5, 80)])
    G = sys.linearization.frequency_response(omega)[:, 0, 0]
    ref = _motor_tf(1j * omega, **MOTOR)
    rel = np.max(np.abs(G - ref) / np.abs(ref))
    assert rel < 1e-10, rel
    # python-control sees the same system (its own frequency response)
    resp = sys(1j * omega[1:])
    G2 = np.asarray(resp).reshape(-1)
    assert np.max(np.abs(G2 - ref[1:]) / np.abs(ref[1:])) < 1e-10


def test_dc_motor_poles_and_ranks():
    lin = linearization(DCMotorIO(), MOTOR)
    R, L, k, J, b = (MOTOR[n] for n in "RLkJb")
    ref = np.roots([L * J, L * b + R * J, R * b + k**2])     # (Ls+R)(Js+b)+k^2 = 0
    ev = lin.eigenvalues
    assert np.min(np.abs(ev)) < 1e-12                    # the angle: an integrator
    moving = sorted(ev[np.abs(ev) > 1e-9], key=lambda v: v.real)
    assert np.allclose(sorted(ref, key=lambda v: v.real), moving, rtol=1e-12)
    d = lin.to_dict()
    assert d["controllability_rank"] == 3           # V reaches current, speed and angle
    assert d["observability_rank"] == 2             # the angle is invisible in the speed
    assert d["observability"]["modes"] == [[0.0, 0.0]]


def test_pendulum_hanging_equilibrium():
    """Index 3: the linear model lives on the constraint, in the coordinates the dynamic
    state selection finds valid at the point (x, vx at the bottom)."""
    L, g = 0.7, 9.81
    lin = linearization(Pendulum(), {"L": L, "g": g, "x": 0.1, "y": -0.6},
                        steady_state=True)
    pt = lin.point
    assert abs(pt["x"]) < 1e-14 and abs(pt["y"] + L) < 1e-14
    assert abs(pt["T"] - g / L) < 1e-12                # tension per length = m g / L
    assert lin.states == ["x", "vx"]
    ev = lin.eigenvalues
    w0 = np.sqrt(g / L)
    assert np.max(np.abs(ev.real)) < 1e-8
    assert np.allclose(sorted(ev.imag), [-w0, w0], rtol=0, atol=1e-8)


def test_inputs_outputs_by_name_and_parameters_as_inputs():
    lin = linearization(DCMotorIO(), MOTOR, inputs=["V", "b"],
                        outputs=["rotor.w", "inductor.i", "der(rotor.w)"])
    assert lin.inputs == ["V", "b"] and lin.B.shape == (3, 2)
    assert lin.outputs[0] == "rotor.w" and lin.C.shape == (3, 3)
    # at rest with V = 0 the friction does nothing: d(der(w))/db = -w/J = 0
    assert np.allclose(lin.B[:, 1], 0.0)
    with pytest.raises(ParameterError, match="not an input or free parameter"):
        linearization(DCMotorIO(), inputs=["nope"])
    with pytest.raises(ParameterError, match="not a variable"):
        linearization(DCMotorIO(), outputs=["rotor.ww"])


def test_linearize_at_time_of_a_simulation():
    """The DC motor is linear: the same A, B at any point; the point is the simulated one."""
    lin0 = linearization(DCMotorIO(), {**MOTOR, "V": 2.0})
    lin1 = linearization(DCMotorIO(), {**MOTOR, "V": 2.0}, at_time=0.2)
    assert np.allclose(lin0.A, lin1.A, rtol=1e-12, atol=1e-12)
    assert lin1.point.t == 0.2 and lin1.point["rotor.w"] > 0.1
    assert lin1.point.kind == "simulation at t = 0.2 s"
