"""Hand-made FmuSpecs for the FMU exporter tests, with reference solutions."""

from __future__ import annotations

import casadi as ca
import numpy as np
from scipy.integrate import solve_ivp
from scipy.linalg import expm
from scipy.optimize import brentq

from bgmodelica.fmi import FmuSpec
from bgmodelica.fmi import ScalarVariable as SV

# ----------------------------------------------------------------------------- oscillator
OSC_P = {"mass.m": 1.0, "damper.d": 0.4, "spring.c": 4.0}
OSC_X0 = (1.0, 0.0)


def oscillator() -> FmuSpec:
    """m s'' + d s' + c s = F, outputs position and spring force, local kinetic energy."""
    t = ca.SX.sym("t")
    x = ca.SX.sym("x", 2)
    u = ca.SX.sym("u", 1)
    p = ca.SX.sym("p", 3)
    m, d, c = p[0], p[1], p[2]
    s, v = x[0], x[1]
    xdot = ca.vertcat(v, (u[0] - d * v - c * s) / m)
    y = ca.vertcat(s, c * s, m * v**2 / 2)
    ode = ca.Function("osc", [t, x, u, p], [xdot, y])
    return FmuSpec(
        model_name="Oscillator",
        description="Damped spring-mass oscillator driven by a force",
        states=[SV("mass.s", OSC_X0[0], "m", "Position of the mass"),
                SV("mass.v", OSC_X0[1], "m/s", "Velocity of the mass")],
        inputs=[SV("force", 0.0, "N", "External force on the mass")],
        parameters=[SV("mass.m", OSC_P["mass.m"], "kg", "Mass", min=0.0),
                    SV("damper.d", OSC_P["damper.d"], "N.s/m", "Damping", min=0.0),
                    SV("spring.c", OSC_P["spring.c"], "N/m", "Stiffness", min=0.0)],
        outputs=[SV("pos", 0.0, "m", "Position"), SV("spring.f", 0.0, "N", "Spring force")],
        locals=[SV("mass.Ekin", 0.0, "J", "Kinetic energy")],
        ode=ode, init=None, start_time=0.0, stop_time=10.0, tolerance=1e-6,
    )


def oscillator_exact(t: np.ndarray, m: float = 1.0, d: float = 0.4, c: float = 4.0,
                     force: float = 0.0, s0: float = 1.0, v0: float = 0.0) -> np.ndarray:
    """Position for a constant force (underdamped case)."""
    s_eq = force / c
    a = d / (2 * m)
    wd = np.sqrt(c / m - a**2)
    A = s0 - s_eq
    B = (v0 + a * A) / wd
    return s_eq + np.exp(-a * t) * (A * np.cos(wd * t) + B * np.sin(wd * t))


def oscillator_zoh(t: np.ndarray, force, m=1.0, d=0.4, c=4.0) -> np.ndarray:
    """Reference for an input sampled at the points ``t`` and held in between (what fmpy does
    with ``input=`` signals, for Model Exchange and Co-Simulation alike)."""
    x = np.array(OSC_X0, dtype=float)
    out = [x[0]]
    for t0, t1 in zip(t[:-1], t[1:], strict=True):
        f0 = force(t0)
        def rhs(tt, xx, f0=f0):
            return [xx[1], (f0 - d * xx[1] - c * xx[0]) / m]
        sol = solve_ivp(rhs, (t0, t1), x, rtol=1e-12, atol=1e-13, method="DOP853")
        x = sol.y[:, -1]
        out.append(x[0])
    return np.array(out)


# ---------------------------------------------------------------------- stiff DC motor
MOTOR_P = {"R": 1.0, "L": 1e-4, "k": 0.1, "J": 1e-3, "b": 1e-4}
MOTOR_U = 12.0


def dc_motor() -> FmuSpec:
    """L di/dt = U - R i - k w ; J dw/dt = k i - b w (electrical time constant 1e-4 s)."""
    t = ca.MX.sym("t")
    x = ca.MX.sym("x", 2)
    u = ca.MX.sym("u", 1)
    p = ca.MX.sym("p", 5)
    R, L, k, J, b = (p[i] for i in range(5))
    i, w = x[0], x[1]
    U = u[0]
    xdot = ca.vertcat((U - R * i - k * w) / L, (k * i - b * w) / J)
    y = ca.vertcat(w, i, k * i, U * i)
    ode = ca.Function("motor", [t, x, u, p], [xdot, y])
    return FmuSpec(
        model_name="DCMotor",
        description="Stiff DC motor (armature inductance 0.1 mH)",
        states=[SV("motor.i", 0.0, "A", "Armature current", nominal=10.0),
                SV("motor.w", 0.0, "rad/s", "Angular velocity", nominal=100.0)],
        inputs=[SV("U", MOTOR_U, "V", "Terminal voltage", min=-1000.0, max=1000.0)],
        parameters=[SV("motor.R", MOTOR_P["R"], "Ohm", "Resistance", min=0.0),
                    SV("motor.L", MOTOR_P["L"], "H", "Inductance", min=1e-12),
                    SV("motor.k", MOTOR_P["k"], "N.m/A", "Motor constant"),
                    SV("motor.J", MOTOR_P["J"], "kg.m2", "Inertia", min=1e-12),
                    SV("motor.b", MOTOR_P["b"], "N.m.s/rad", "Viscous friction", min=0.0)],
        outputs=[SV("speed", 0.0, "rad/s"), SV("current", 0.0, "A"),
                 SV("torque", 0.0, "N.m"), SV("power", 0.0, "W")],
        locals=[],
        ode=ode, init=None, start_time=0.0, stop_time=0.5, step_size=1e-3, tolerance=1e-6,
    )


def dc_motor_exact(t: np.ndarray, U: float = MOTOR_U, **over: float) -> np.ndarray:
    """(i, w) for a constant voltage from rest: x(t) = (e^{At} - I) A^{-1} B U."""
    P = {**MOTOR_P, **over}
    A = np.array([[-P["R"] / P["L"], -P["k"] / P["L"]], [P["k"] / P["J"], -P["b"] / P["J"]]])
    Bu = np.array([U / P["L"], 0.0])
    xs = np.linalg.solve(A, Bu)
    return np.array([(expm(A * tt) - np.eye(2)) @ xs for tt in t])


# -------------------------------------------------------- algebraic loop (rootfinder)
LOOP_P = {"R": 2.0, "a": 0.5, "C": 0.1, "v0": 1.0}
LOOP_U = 5.0


def algebraic_loop() -> FmuSpec:
    """RC circuit with a nonlinear resistor: U - vC = R i + a i^3 (solved by fast_newton
    inside the CasADi function); C dvC/dt = i.  Consistent initial state from ``init``."""
    t = ca.MX.sym("t")
    x = ca.MX.sym("x", 1)
    u = ca.MX.sym("u", 1)
    p = ca.MX.sym("p", 4)
    R, a, C, v0 = (p[i] for i in range(4))
    z = ca.MX.sym("z")
    q = ca.MX.sym("q", 3)
    g = ca.Function("g", [z, q], [q[1] * z + q[2] * z**3 - q[0]])
    loop = ca.rootfinder("loop", "fast_newton", g, {"abstol": 1e-14, "abstolStep": 1e-14})
    vr = u[0] - x[0]
    i = loop(vr / R, ca.vertcat(vr, R, a))
    xdot = i / C
    y = ca.vertcat(i, x[0] + R * i)
    ode = ca.Function("loop_ode", [t, x, u, p], [xdot, y])
    init = ca.Function("loop_init", [t, u, p], [v0])
    return FmuSpec(
        model_name="NonlinearRC",
        description="RC circuit with a cubic resistor (algebraic loop solved in C)",
        states=[SV("cap.v", LOOP_P["v0"], "V", "Capacitor voltage")],
        inputs=[SV("source.U", LOOP_U, "V", "Source voltage")],
        parameters=[SV("res.R", LOOP_P["R"], "Ohm", min=1e-9),
                    SV("res.a", LOOP_P["a"], "V/A3", "Cubic coefficient", min=0.0),
                    SV("cap.C", LOOP_P["C"], "F", min=1e-12),
                    SV("cap.v0", LOOP_P["v0"], "V", "Initial capacitor voltage")],
        outputs=[SV("res.i", 0.0, "A", "Current")],
        locals=[SV("res.v_plus", 0.0, "V")],
        ode=ode, init=init, start_time=0.0, stop_time=1.0, tolerance=1e-6,
    )


def loop_current(vr: float, R: float, a: float) -> float:
    if vr == 0.0:
        return 0.0
    hi = abs(vr) / R
    return brentq(lambda z: R * z + a * z**3 - vr, -hi, hi, xtol=1e-15, rtol=1e-15)


def loop_scipy(t: np.ndarray, U: float = LOOP_U, **over: float) -> tuple[np.ndarray, ...]:
    P = {**LOOP_P, **over}

    def rhs(tt, x):
        return [loop_current(U - x[0], P["R"], P["a"]) / P["C"]]
    sol = solve_ivp(rhs, (t[0], t[-1]), [P["v0"]], t_eval=t, rtol=1e-11, atol=1e-12,
                    method="DOP853")
    v = sol.y[0]
    i = np.array([loop_current(U - vv, P["R"], P["a"]) for vv in v])
    return v, i


VERSIONS = (2, 3)
TYPES = ("me", "cs")
SPECS = {"osc": oscillator, "motor": dc_motor, "loop": algebraic_loop}
