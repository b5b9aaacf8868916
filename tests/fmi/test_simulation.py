"""Simulation of the exported FMUs with fmpy against analytic / scipy references."""

from __future__ import annotations

import numpy as np
import pytest
from fmi_models import (
    LOOP_P,
    MOTOR_U,
    VERSIONS,
    dc_motor_exact,
    loop_scipy,
    oscillator_exact,
    oscillator_zoh,
)
from fmpy import simulate_fmu

ME_RTOL = 1e-6   # CVode with a tight tolerance
CS_RTOL = 1e-4   # embedded BDF at its default tolerance 1e-6


def rel_err(value: np.ndarray, ref: np.ndarray) -> float:
    return float(np.max(np.abs(value - ref)) / np.max(np.abs(ref)))


def sim(fmu, kind: str, **kw):
    if kind == "me":
        kw.setdefault("relative_tolerance", 1e-11)
        return simulate_fmu(str(fmu), fmi_type="ModelExchange", solver="CVode", **kw)
    if kind == "euler":
        return simulate_fmu(str(fmu), fmi_type="ModelExchange", solver="Euler", **kw)
    return simulate_fmu(str(fmu), fmi_type="CoSimulation", **kw)


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("kind", ["me", "cs"])
def test_oscillator_free_motion(build_fmu, version, kind):
    r = sim(build_fmu("osc", version, kind), kind, output=["pos", "spring.f", "mass.Ekin"],
            output_interval=0.01)
    exact = oscillator_exact(r["time"])
    assert rel_err(r["pos"], exact) < (ME_RTOL if kind == "me" else CS_RTOL)
    assert rel_err(r["spring.f"], 4.0 * exact) < (ME_RTOL if kind == "me" else CS_RTOL)
    assert np.all(r["mass.Ekin"] >= 0.0)


@pytest.mark.parametrize("version", VERSIONS)
def test_oscillator_euler(build_fmu, version):
    # fmpy's Euler takes one step per output interval
    r = sim(build_fmu("osc", version, "me"), "euler", step_size=2e-4, output_interval=2e-4,
            output=["pos"], stop_time=1.0)
    err = rel_err(r["pos"], oscillator_exact(r["time"]))
    # explicit Euler is first order: the error is O(h) (here about 2e-4)
    assert 1e-6 < err < 1e-3


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("kind", ["me", "cs"])
def test_oscillator_parameters_and_constant_input(build_fmu, version, kind):
    start = {"mass.m": 2.0, "damper.d": 1.0, "spring.c": 8.0, "mass.s": 0.5, "mass.v": 1.0}
    signal = np.array([(0.0, 3.0), (10.0, 3.0)], dtype=[("time", np.float64),
                                                         ("force", np.float64)])
    r = sim(build_fmu("osc", version, kind), kind, start_values=start, input=signal,
            output=["pos"], output_interval=0.01)
    exact = oscillator_exact(r["time"], m=2.0, d=1.0, c=8.0, force=3.0, s0=0.5, v0=1.0)
    assert rel_err(r["pos"], exact) < (ME_RTOL if kind == "me" else CS_RTOL)


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("kind", ["me", "cs"])
def test_oscillator_ramp_input(build_fmu, version, kind):
    """A time-varying input; fmpy samples it at every output point and holds it in between."""
    signal = np.array([(0.0, 0.0), (10.0, 5.0)], dtype=[("time", np.float64),
                                                         ("force", np.float64)])
    r = sim(build_fmu("osc", version, kind), kind, input=signal, output=["pos", "force"],
            output_interval=0.05, relative_tolerance=1e-8 if kind == "me" else None)
    assert r["force"][-1] > 4.9
    ref = oscillator_zoh(r["time"], lambda t: 0.5 * t)
    # CS holds the input over each communication step exactly like the reference.  fmpy's ME
    # loop lets CVode step past the output point with the old input before switching, which
    # blurs the switching instants (an importer effect, about 1e-3 here).
    assert rel_err(r["pos"], ref) < (2e-3 if kind == "me" else CS_RTOL)


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("kind", ["me", "cs"])
def test_stiff_dc_motor(build_fmu, version, kind):
    r = sim(build_fmu("motor", version, kind), kind, output=["current", "speed", "power"])
    exact = dc_motor_exact(r["time"])
    tol = ME_RTOL if kind == "me" else CS_RTOL
    assert rel_err(r["current"], exact[:, 0]) < tol
    assert rel_err(r["speed"], exact[:, 1]) < tol
    assert rel_err(r["power"], MOTOR_U * exact[:, 0]) < tol


@pytest.mark.parametrize("version", VERSIONS)
def test_stiff_dc_motor_parameters_cs(build_fmu, version):
    start = {"motor.R": 2.0, "motor.k": 0.2, "U": 24.0}
    r = sim(build_fmu("motor", version, "cs"), "cs", start_values=start,
            output=["current", "speed"])
    exact = dc_motor_exact(r["time"], U=24.0, R=2.0, k=0.2)
    assert rel_err(r["speed"], exact[:, 1]) < CS_RTOL
    assert rel_err(r["current"], exact[:, 0]) < CS_RTOL


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("kind", ["me", "cs"])
def test_algebraic_loop(build_fmu, version, kind):
    r = sim(build_fmu("loop", version, kind), kind, output=["cap.v", "res.i", "res.v_plus"])
    v, i = loop_scipy(r["time"])
    tol = ME_RTOL if kind == "me" else CS_RTOL
    assert rel_err(r["cap.v"], v) < tol
    assert rel_err(r["res.i"], i) < tol
    assert rel_err(r["res.v_plus"], v + LOOP_P["R"] * i) < tol


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("kind", ["me", "cs"])
def test_algebraic_loop_init_from_parameter(build_fmu, version, kind):
    """The consistent initial state is computed by the init function from cap.v0."""
    r = sim(build_fmu("loop", version, kind), kind, start_values={"cap.v0": -2.0, "res.a": 1.5},
            output=["cap.v", "res.i"])
    assert r["cap.v"][0] == pytest.approx(-2.0, abs=1e-12)
    v, i = loop_scipy(r["time"], v0=-2.0, a=1.5)
    tol = ME_RTOL if kind == "me" else CS_RTOL
    assert rel_err(r["cap.v"], v) < tol
    assert rel_err(r["res.i"], i) < tol


@pytest.mark.parametrize("version", VERSIONS)
def test_cs_solver_parameters(build_fmu, version):
    """A loose solver.tolerance is less accurate but still converges; max_step is honoured."""
    fmu = build_fmu("osc", version, "cs")
    loose = sim(fmu, "cs", start_values={"solver.tolerance": 1e-2, "solver.max_step": 0.5},
                output=["pos"], relative_tolerance=1e-2, output_interval=1.0)
    tight = sim(fmu, "cs", output=["pos"], output_interval=1.0)
    exact = oscillator_exact(loose["time"])
    e_loose, e_tight = rel_err(loose["pos"], exact), rel_err(tight["pos"], exact)
    assert e_tight < 5e-5 and e_tight < e_loose < 0.2


def test_fmi3_cs_with_event_mode(build_fmu):
    r = simulate_fmu(str(build_fmu("motor", 3, "cs")), fmi_type="CoSimulation",
                     use_event_mode=True, output=["speed"])
    assert rel_err(r["speed"], dc_motor_exact(r["time"])[:, 1]) < CS_RTOL


def _solver_steps(fmu, **kw) -> tuple[int, np.ndarray]:
    """Internal steps of the embedded solver (its statistics at fmi2Terminate) and pos."""
    messages: list[str] = []

    def logger(*args):
        text = args[-1]
        messages.append(text.decode() if isinstance(text, bytes) else str(text))

    r = sim(fmu, "cs", output=["pos"], debug_logging=True, logger=logger, **kw)
    stats = next(m for m in messages if "solver statistics" in m)
    return int(stats.split("statistics: ")[1].split()[0]), r["pos"]


def test_cs_solver_steps_do_not_follow_the_communication_grid(build_fmu):
    """The BDF history is kept between communication steps (the state at a communication
    point is interpolated): 1000 communication points cost about as many solver steps as 10,
    and the two runs agree to the tolerance."""
    fmu = build_fmu("osc", 2, "cs")
    coarse, pos_coarse = _solver_steps(fmu, output_interval=1.0)
    fine, pos_fine = _solver_steps(fmu, output_interval=0.01)
    assert fine < 1.5 * coarse, (fine, coarse)
    assert fine < 1000                       # fewer steps than communication points
    t_coarse = np.arange(len(pos_coarse)) * 1.0
    exact = oscillator_exact(t_coarse)
    assert rel_err(pos_coarse, exact) < CS_RTOL
    assert rel_err(pos_fine[::100], exact) < CS_RTOL


def test_cs_new_inputs_take_one_step_method(build_fmu):
    """A piecewise-constant input changing at every communication point: no history straddles
    a jump (those steps are one-step SDIRK4 steps, mostly one per communication step) and the
    result matches the zero-order-hold reference."""
    signal = np.array([(0.0, 0.0), (10.0, 5.0)], dtype=[("time", np.float64),
                                                         ("force", np.float64)])
    fmu = build_fmu("osc", 3, "cs")
    r = sim(fmu, "cs", input=signal, output=["pos"], output_interval=0.5,
            start_values={"solver.tolerance": 1e-9})
    ref = oscillator_zoh(r["time"], lambda t: 0.5 * t)
    assert rel_err(r["pos"], ref) < 1e-6
    steps, _ = _solver_steps(build_fmu("osc", 2, "cs"), input=signal, output_interval=0.01,
                             stop_time=2.0)
    assert steps < 1.2 * 200, steps                # 200 communication steps
