"""``optimize`` against analytic optimal controls: the double integrator (minimum time,
minimum energy), an LQ problem (Riccati equation) and the DC motor (controllability Gramian,
Pontryagin with a saturated control); refusals on one line with exit code 2."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.integrate import quad_vec, solve_ivp
from scipy.linalg import expm, solve_continuous_are

import bgmodelica as bg
from bgmodelica.cli import main
from bgmodelica.optimal import OptimizationError
from library.examples.control import DCMotorIO, DoubleIntegrator

DI = "library.examples.control:DoubleIntegrator"
MOTOR = "library.examples.control:DCMotorIO"
REST = {"inductor.i": 0.0, "rotor.phi": 0.0, "rotor.w": 0.0}


def test_double_integrator_minimum_time_is_bang_bang(capsys):
    code = main(["optimize", DI, "--control", "u=-1:1", "--initial", "x=0,v=0", "--final",
                 "x=1,v=0", "--minimize", "time", "--intervals", "20", "--json"])
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    assert out["stop_time"] == pytest.approx(2.0, abs=1e-6)
    assert out["objective"] == pytest.approx(2.0, abs=1e-6)
    assert out["resimulation_error"] <= 1e-4
    t, u = (np.array(out["controls"]["u"][k]) for k in ("time", "value"))
    assert np.allclose(u[t < 1 - 1e-6], 1.0, atol=1e-6)       # full push, switch at 1 s,
    assert np.allclose(u[t > 1 + 1e-6], -1.0, atol=1e-6)      # full brake
    assert set(out["states"]) == {"x", "v"} and out["solver"]["status"] == "Solve_Succeeded"


def test_double_integrator_minimum_energy_is_linear():
    """x: 0 -> 1 at rest in T: u = 6/T^2 - 12 t/T^3, cost 12/T^3."""
    T = 2.0
    res = bg.optimize(DoubleIntegrator(), ["u"], initial={"x": 0, "v": 0},
                      final={"x": 1, "v": 0}, stop_time=T, lagrange="u^2", intervals=10)
    assert res.objective == pytest.approx(12 / T**3, rel=1e-8)
    t, u = res.controls["u"]
    assert np.allclose(u, 6 / T**2 - 12 * t / T**3, atol=1e-6)
    assert res.resimulation_error < 1e-8


def test_lq_problem_matches_riccati():
    """min x(T)' S x(T) + int x'Qx + r u^2, x' = Ax + Bu from x0, T fixed: the cost is
    x0' P(0) x0 with P the solution of the Riccati ODE; on a long horizon with S the
    stationary solution, P(0) = S (python-control's lqr gives the same S)."""
    import control

    A = np.array([[0.0, 1.0], [0.0, 0.0]])
    B = np.array([[0.0], [1.0]])
    Q, r = np.diag([1.0, 0.0]), 1.0
    K, S, _ = control.lqr(A, B, Q, np.array([[r]]))
    assert np.allclose(S, solve_continuous_are(A, B, Q, np.array([[r]])))
    x0 = np.array([1.0, 0.0])
    res = bg.optimize(DoubleIntegrator(), ["u"], initial={"x": x0[0], "v": x0[1]},
                      stop_time=3.0, lagrange="x^2 + u^2",
                      mayer=f"{S[0, 0]}*x^2 + {2 * S[0, 1]}*x*v + {S[1, 1]}*v^2",
                      intervals=30)
    assert res.objective == pytest.approx(x0 @ S @ x0, rel=1e-6)
    t, u = res.controls["u"]
    x = np.interp(t, *res.states["x"])
    v = np.interp(t, *res.states["v"])
    assert np.allclose(u, -(K @ np.vstack([x, v])).ravel(), atol=2e-3)   # the LQR feedback

    # a short horizon and no terminal cost: integrate the Riccati ODE backwards
    T = 1.0

    def riccati(_t, p):
        P = p.reshape(2, 2)
        return -(A.T @ P + P @ A - P @ B @ B.T @ P / r + Q).ravel()

    P0 = solve_ivp(riccati, (T, 0.0), np.zeros(4), rtol=1e-11, atol=1e-12).y[:, -1]
    res = bg.optimize(DoubleIntegrator(), ["u"], initial={"x": 1.0, "v": 0.0}, stop_time=T,
                      lagrange="x^2 + u^2", intervals=20)
    assert res.objective == pytest.approx(x0 @ P0.reshape(2, 2) @ x0, rel=1e-6)


def _motor_linear():
    from bgmodelica.analysis.linearize import linearization

    lin = linearization(DCMotorIO())
    assert lin.states == ["inductor.i", "rotor.phi", "rotor.w"]
    return lin.A, lin.B[:, 0]


def test_dc_motor_minimum_energy_matches_gramian():
    """Unbounded: J* = xf' W^-1 xf over the reachable components (phi, w) of the final
    state, W the controllability Gramian of the linear motor over [0, T]."""
    A, B = _motor_linear()
    T, xf = 0.5, np.array([10.0, 0.0])
    W = quad_vec(lambda t: expm(A * (T - t)) @ np.outer(B, B) @ expm(A.T * (T - t)), 0, T,
                 epsabs=1e-12, epsrel=1e-12)[0][1:, 1:]
    exact = xf @ np.linalg.solve(W, xf)
    res = bg.optimize(DCMotorIO(), ["V"], initial=REST, final={"rotor.phi": 10, "rotor.w": 0},
                      stop_time=T, lagrange="V^2", intervals=20)
    assert res.objective == pytest.approx(exact, rel=1e-5)
    assert res.resimulation_error <= 1e-4


def test_dc_motor_saturated_control_matches_pontryagin():
    """|V| <= 20: V = sat(-B' lam / 2), lam' = -A' lam, lam(T) = (0, nu): nu by shooting."""
    from scipy.optimize import fsolve

    A, B = _motor_linear()
    T, lim = 0.5, 20.0

    mu, V = np.linalg.eig(A.T)                   # lam(t) = exp(A'(T - t)) (0, nu)
    Vinv = np.linalg.inv(V)

    def run(nu):
        coef = Vinv @ np.r_[0.0, nu]

        def rhs(t, y):
            lam = (V @ (np.exp(mu * (T - t)) * coef)).real
            v = np.clip(-0.5 * B @ lam, -lim, lim)
            return np.r_[A @ y[:3] + B * v, v * v]

        return solve_ivp(rhs, (0, T), np.zeros(4), rtol=1e-12, atol=1e-12,
                         method="DOP853").y[:, -1]

    nu = fsolve(lambda nu: run(nu)[1:3] - [10.0, 0.0], [-21.2, 5.2], xtol=1e-12)
    exact = run(nu)[-1]
    res = bg.optimize(DCMotorIO(), {"V": (-lim, lim)}, initial=REST,
                      final={"rotor.phi": 10, "rotor.w": 0}, stop_time=T, lagrange="V^2")
    assert res.objective == pytest.approx(exact, abs=2e-3)
    t, v = res.controls["V"]
    assert np.max(np.abs(v)) == pytest.approx(lim) and np.allclose(v[:4], lim)


def test_unreachable_target_is_refused_on_one_line(capsys):
    code = main(["optimize", MOTOR, "--control", "V=-12:12", "--initial",
                 "inductor.i=0,rotor.phi=0,rotor.w=0", "--final", "rotor.phi=10,rotor.w=0",
                 "--stop-time", "0.5", "--lagrange", "V^2", "--intervals", "20"])
    assert code == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "no solution" in err and "rotor.phi" in err


def test_refusals():
    with pytest.raises(OptimizationError, match="bounded controls: u"):
        bg.optimize(DoubleIntegrator(), ["u"], final={"x": 1}, minimize_time=True)
    with pytest.raises(bg.errors.ParameterError, match="not a top-level input"):
        bg.optimize(DoubleIntegrator(), ["x"], final={"x": 1}, stop_time=1, lagrange="u^2")
    with pytest.raises(bg.errors.ParameterError, match="unknown function"):
        bg.optimize(DoubleIntegrator(), ["u"], stop_time=1, lagrange="foo(u)")
    from library.examples.hybrid import BouncingBall

    with pytest.raises(OptimizationError, match="events"):
        bg.optimize(BouncingBall(), ["u"], stop_time=1, lagrange="1")


def test_path_constraint_and_outputs(tmp_path, capsys):
    """A speed limit |v| <= 0.4 on the minimum-time move: accelerate, cruise, brake; the
    time is 1/0.4 + 0.4 = 2.9 s. -o writes the re-simulated trajectories, --plot a figure."""
    csv, png = tmp_path / "di.csv", tmp_path / "di.png"
    code = main(["optimize", DI, "--control", "u=-1:1", "--final", "x=1,v=0", "--minimize",
                 "time", "--stop-time", "3", "--path", "v=-0.4:0.4", "--intervals", "29",
                 "-o", str(csv), "--plot", str(png)])
    assert code == 0
    text = capsys.readouterr().out
    stop = float(text.split("stop time:")[1].split()[0])
    assert stop == pytest.approx(2.9, abs=1e-6) and csv.is_file() and png.is_file()
    result = bg.Result.read_csv(csv)
    assert result.final("x") == pytest.approx(1.0, abs=1e-5)
    assert np.max(result["v"]) <= 0.4 + 1e-6
