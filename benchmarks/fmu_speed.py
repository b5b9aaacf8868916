"""Speed of the exported DC-motor FMUs (fmpy) against CasADi's own CVODES/IDAS integration.

Run: ``python benchmarks/fmu_speed.py [--repeat N]``.  All runs simulate 0.5 s of the stiff DC
motor (electrical time constant 1e-4 s) with 501 output points and relative tolerance 1e-6.
Prints wall-clock times (best of N) and the ratio to CasADi CVODES.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import casadi as ca
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from fmpy import simulate_fmu  # noqa: E402

from bgmodelica.fmi import FmuSpec, export_fmu  # noqa: E402
from bgmodelica.fmi import ScalarVariable as SV  # noqa: E402

P = [1.0, 1e-4, 0.1, 1e-3, 1e-4]  # R, L, k, J, b
U = 12.0
STOP = 0.5
N_OUT = 501
RTOL = 1e-6


def motor_functions():
    t = ca.MX.sym("t")
    x = ca.MX.sym("x", 2)
    u = ca.MX.sym("u", 1)
    p = ca.MX.sym("p", 5)
    R, L, k, J, b = (p[i] for i in range(5))
    xdot = ca.vertcat((u[0] - R * x[0] - k * x[1]) / L, (k * x[0] - b * x[1]) / J)
    y = ca.vertcat(x[1], x[0], k * x[0], u[0] * x[0])
    return t, x, u, p, xdot, ca.Function("motor", [t, x, u, p], [xdot, y])


def motor_spec() -> FmuSpec:
    *_, ode = motor_functions()
    names = ["motor.R", "motor.L", "motor.k", "motor.J", "motor.b"]
    return FmuSpec(
        model_name="DCMotorBench", description="stiff DC motor",
        states=[SV("motor.i", 0.0, "A", nominal=10.0), SV("motor.w", 0.0, "rad/s", nominal=100.0)],
        inputs=[SV("U", U, "V")],
        parameters=[SV(n, v) for n, v in zip(names, P, strict=True)],
        outputs=[SV("speed", 0.0, "rad/s"), SV("current", 0.0, "A"), SV("torque", 0.0, "N.m"),
                 SV("power", 0.0, "W")],
        ode=ode, stop_time=STOP, step_size=STOP / (N_OUT - 1), tolerance=RTOL)


def best_of(fn, repeat: int) -> tuple[float, object]:
    best, result = float("inf"), None
    for _ in range(repeat):
        t0 = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - t0)
    return best, result


def casadi_integrator(plugin: str):
    t, x, u, p, xdot, _ = motor_functions()
    grid = np.linspace(0.0, STOP, N_OUT)
    dae = {"x": x, "p": ca.vertcat(u, p), "ode": xdot}
    opts = {"reltol": RTOL, "abstol": RTOL * 10.0}
    if plugin == "idas":
        z = ca.MX.sym("z", 0)
        dae["z"] = z
    integ = ca.integrator("F", plugin, dae, 0.0, grid[1:], opts)
    pv = np.array([U, *P])

    def run():
        return integ(x0=[0.0, 0.0], p=pv)["xf"]
    return run


def one_do_step(fmu_path: Path) -> tuple[float, float]:
    """Integrate the CS FMU in one DoStep; returns (seconds spent in the FMU calls from
    fmi2Instantiate to fmi2FreeInstance, final speed)."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(str(fmu_path))
    unzip = _UNZIPPED.setdefault(str(fmu_path), extract(str(fmu_path)))
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzip,
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="bench")
    t0 = time.perf_counter()
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    fmu.doStep(0.0, STOP)
    vr = next(v.valueReference for v in md.modelVariables if v.name == "speed")
    w = fmu.getReal([vr])[0]
    fmu.terminate()
    fmu.freeInstance()
    elapsed = time.perf_counter() - t0
    fmu.freeLibrary()
    return elapsed, w


_UNZIPPED: dict[str, str] = {}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        me = export_fmu(motor_spec(), Path(tmp) / "me", 2, "me")
        cs = export_fmu(motor_spec(), Path(tmp) / "cs", 2, "cs")
        t_cvodes, xf = best_of(casadi_integrator("cvodes"), args.repeat)
        t_idas, _ = best_of(casadi_integrator("idas"), args.repeat)
        t_me, r_me = best_of(lambda: simulate_fmu(str(me), fmi_type="ModelExchange",
                                                  relative_tolerance=RTOL,
                                                  output=["speed"]), args.repeat)
        t_cs, r_cs = best_of(lambda: simulate_fmu(str(cs), fmi_type="CoSimulation",
                                                  output=["speed"]), args.repeat)
        runs = [one_do_step(cs) for _ in range(args.repeat)]
        t_c, w_end = min(r[0] for r in runs), runs[0][1]
    w_ref = np.array(xf)[1, :]
    print(f"stiff DC motor, {STOP} s, {N_OUT} output points, rtol {RTOL:g}, best of "
          f"{args.repeat}")
    print(f"  casadi CVODES        {t_cvodes * 1e3:9.2f} ms   ratio 1.00")
    print(f"  casadi IDAS          {t_idas * 1e3:9.2f} ms   ratio {t_idas / t_cvodes:5.2f}")
    print(f"  FMU ME (fmpy CVode)  {t_me * 1e3:9.2f} ms   ratio {t_me / t_cvodes:5.2f}   "
          f"max |dw| vs CVODES {np.max(np.abs(r_me['speed'][1:] - w_ref)):.2e}")
    print(f"  FMU CS (BDF)         {t_cs * 1e3:9.2f} ms   ratio {t_cs / t_cvodes:5.2f}   "
          f"max |dw| vs CVODES {np.max(np.abs(r_cs['speed'][1:] - w_ref)):.2e}")
    print(f"  FMU CS, one DoStep   {t_c * 1e3:9.2f} ms   ratio {t_c / t_cvodes:5.2f}   "
          f"|dw(end)| vs CVODES {abs(w_end - w_ref[-1]):.2e}  (C solver without the fmpy loop)")


if __name__ == "__main__":
    main()
