"""Speed of the paper's robot (two geared DC motors + two-link arm + two PIDs, 10 s).

Measures, in one run:

1. bgmodelica: build time (``compile(RobotPID())``: flatten, alias elimination, index
   reduction of the index-3 multibody arm, BLT/tearing, CasADi DAE) and the time of
   ``simulate`` over 10 s (IDAS and CVODES; static state selection, and once with the
   default dynamic state selection);
2. a hand-written CasADi ODE of the same robot (motors + Lagrange arm + the same PID law)
   integrated with CVODES, integrator construction included;
3. scipy ``solve_ivp(method="BDF")`` with a numpy right-hand side (finite-difference Jacobian).

All at rtol 1e-6, atol 1e-8, output every 10 ms. Prints times and ratios; targets: build
< 0.3 s, the default simulation within 1.1x of the hand-written CasADi baseline and faster
than scipy.

    PYTHONPATH=. .venv/bin/python benchmarks/robot_speed.py [--repeat N]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import casadi as ca
import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bgmodelica import compile, simulate  # noqa: E402
from bgmodelica.backends.casadi_init import initialize  # noqa: E402
from library.robots.baseline import N_STATES, robot_rhs  # noqa: E402
from library.robots.robot import RobotPID  # noqa: E402

STOP, DT, RTOL, ATOL = 10.0, 0.01, 1e-6, 1e-8
def best_of(fn, repeat):
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def main(repeat: int = 5) -> dict:
    grid = np.linspace(0.0, STOP, int(round(STOP / DT)) + 1)

    # 1. bgmodelica ------------------------------------------------------------------------
    t0 = time.perf_counter()
    compiled = compile(RobotPID())
    build_first = time.perf_counter() - t0
    build, compiled = best_of(lambda: compile(RobotPID()), repeat)
    sims = {}
    for label, opts in (("idas", {"solver": "idas"}), ("cvodes", {"solver": "cvodes"})):
        sims[label] = best_of(lambda o=opts: simulate(compiled, stop_time=STOP, interval=DT,
                                                      rtol=RTOL, atol=ATOL, dynamic=False,
                                                      **o), repeat)
    sims["cvodes, 2 outputs"] = best_of(lambda: simulate(
        compiled, stop_time=STOP, interval=DT, rtol=RTOL, atol=ATOL, dynamic=False,
        solver="cvodes", outputs=["arm.joint1.q", "arm.joint2.q"]), repeat)
    # the integration alone: the compiled DAE handed to CasADi's integrators directly
    dae = compiled.dae
    init = initialize(dae, dae.p_vector(), 0.0)
    core = {}
    for solver in ("cvodes", "idas"):
        core[solver] = best_of(lambda s=solver: ca.integrator(
            "core", s, {"x": dae.x, "p": dae.p, "t": dae.t, "ode": dae.ode}, 0.0,
            list(grid[1:]), {"abstol": ATOL, "reltol": RTOL})(x0=init.x0, p=dae.p_vector()),
            repeat)[0]
    res = sims["idas"][1]

    # 2. hand-written CasADi ODE + CVODES -------------------------------------------------------
    x = ca.SX.sym("x", N_STATES)
    t = ca.SX.sym("t")
    ode = robot_rhs(ca)(t, x)

    def casadi_run():
        F = ca.integrator("robot", "cvodes", {"x": x, "t": t, "ode": ode}, 0.0,
                          list(grid[1:]), {"abstol": ATOL, "reltol": RTOL})
        return F, np.asarray(F(x0=np.zeros(N_STATES))["xf"])

    def auto_run():
        return simulate(compiled, stop_time=STOP, interval=DT, rtol=RTOL, atol=ATOL,
                        solver="auto")

    # the headline ratio: the two alternate, so that a noisy spell hits both
    sim_dynamic = t_casadi = float("inf")
    for _ in range(repeat):
        t_auto, res_dyn = best_of(auto_run, 1)
        t_hand, (F, xs) = best_of(casadi_run, 1)
        sim_dynamic, t_casadi = min(sim_dynamic, t_auto), min(t_casadi, t_hand)
    casadi_steps = int(F.stats()["nsteps"])

    # 3. scipy BDF, numpy right-hand side -----------------------------------------------------
    rhs = robot_rhs(np)
    t_scipy, sol = best_of(lambda: solve_ivp(rhs, (0, STOP), np.zeros(N_STATES), method="BDF",
                                             t_eval=grid, rtol=RTOL, atol=ATOL),
                           max(1, repeat // 2))

    # agreement of the three (same model, independently written)
    q_bg = np.column_stack([res["arm.q1"], res["arm.q2"]])
    dev_casadi = float(np.max(np.abs(q_bg[1:] - xs[:2].T)))
    dev_scipy = float(np.max(np.abs(q_bg - sol.y[:2].T)))
    dev_dynamic = float(np.max(np.abs(q_bg - np.column_stack([res_dyn["arm.q1"],
                                                               res_dyn["arm.q2"]]))))

    t_idas, t_cvodes = sims["idas"][0], sims["cvodes"][0]
    stats = res.meta["stats"]
    print("Robot (2 DC motors + 2-link multibody arm + 2 PIDs), 10 s, rtol 1e-6, atol 1e-8")
    print(f"  build (compile)           first {build_first:.3f} s, best {build:.3f} s"
          f"  [target < 0.3 s]  stages: "
          + ", ".join(f"{k} {v * 1e3:.1f} ms" for k, v in compiled.timings.items()))
    print(f"  simulate, IDAS            {t_idas:.4f} s  ({int(stats['nsteps'])} steps, "
          f"{int(stats['netfails'])} error-test failures)")
    print(f"  simulate, CVODES          {t_cvodes:.4f} s  "
          f"({int(sims['cvodes'][1].meta['stats']['nsteps'])} steps)")
    print(f"  simulate, CVODES, 2 outputs {sims['cvodes, 2 outputs'][0]:.4f} s  (observing 2 "
          f"variables instead of all {len(dae.names)})")
    print(f"  integration only (compiled DAE -> ca.integrator): CVODES {core['cvodes']:.4f} s, "
          f"IDAS {core['idas']:.4f} s")
    print(f"  simulate, solver='auto'   {sim_dynamic:.4f} s  (solver {res_dyn.meta['solver']} "
          f"({res_dyn.meta['solver_choice']}), dynamic state selection; switches: "
          f"{res_dyn.meta.get('state_switches', [])[:1]})")
    print(f"  hand-written CasADi+CVODES {t_casadi:.4f} s  ({casadi_steps} steps)")
    print(f"  scipy BDF (numpy rhs)     {t_scipy:.3f} s  ({sol.nfev} rhs evaluations)")
    print(f"  ratio bgmodelica auto / CasADi {sim_dynamic / t_casadi:.2f}  [target <= 1.1]")
    print(f"  ratio bgmodelica IDAS / CasADi   {t_idas / t_casadi:.2f}")
    print(f"  ratio bgmodelica CVODES / CasADi {t_cvodes / t_casadi:.2f}")
    print(f"  ratio integration only CVODES / CasADi {core['cvodes'] / t_casadi:.2f}")
    print(f"  ratio scipy / bgmodelica IDAS    {t_scipy / t_idas:.1f}  [target > 1]")
    print(f"  max |q - q_casadi| {dev_casadi:.2e} rad, |q - q_scipy| {dev_scipy:.2e} rad, "
          f"|q - q_dynamic| {dev_dynamic:.2e} rad")
    return {"build": build, "build_first": build_first, "idas": t_idas, "cvodes": t_cvodes,
            "dynamic": sim_dynamic, "core_cvodes": core["cvodes"], "core_idas": core["idas"],
            "casadi": t_casadi, "scipy": t_scipy,
            "dev_casadi": dev_casadi, "dev_scipy": dev_scipy}


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    main(ap.parse_args().repeat)
