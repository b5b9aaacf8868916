"""Co-simulation splits of example models, for ``bgmodelica verify MODEL SSP``.

The PWM motor (:class:`library.examples.hybrid.PWMMotor`) split into two FMUs:

* ``driver`` (:class:`PWMDriver`): the PWM voltage source (time events from
  ``sample(0, 1/f_pwm)`` and the switch-off instant) and the armature winding
  ``L der(i) = U - R i - k w``; input ``w`` (rotor speed [rad/s]), outputs ``i`` [A] and ``U``
  [V]. A hybrid FMU: the events are located inside ``doStep``.
* ``motor`` (:class:`MotorMechanics`): the rotor ``J der(w) = k i - b w``; input ``i``,
  output ``w``.

Connections ``driver.i -> motor.i`` and ``motor.w -> driver.w``: a two-way coupling (current
one way, back-EMF speed the other), so the co-simulation has a true coupling error. The
outputs ``driver.i``, ``driver.U`` and ``motor.w`` match the monolithic ``PWMMotor``'s ``i``,
``U`` and ``w`` by name (element prefix dropped). Parameter defaults equal ``PWMMotor``'s.

``export_pwm_setup(out_dir)`` builds the two FMUs and writes ``pwm_motor.ssp``; then::

    bgmodelica verify library.examples.hybrid:PWMMotor out_dir/pwm_motor.ssp \\
        --stop-time 0.005 --step 10e-6,5e-6,2.5e-6 --tolerance 1e-2

Macro steps that divide the on time (``duty/f_pwm`` = 30 us) and the period (50 us) keep
the switching instants on communication points.

Known limit (a bug of the hybrid Co-Simulation runtime, not of the split): when the master's
``currentCommunicationPoint`` (``k*H``) differs by a rounding error from the FMU's own time
(the sum of the steps), the driver FMU skips some ``sample`` ticks that fall on a
communication point (H = 5 us: periods 42, 45, 48, ... from t = 2.1 ms; H = 2.5 us: from
1.05 ms); fmpy's loop, which passes the accumulated time, sees every tick. Hence the 2 ms
horizon with steps of 5 us and more in the tests and the README.
"""

from __future__ import annotations

from pathlib import Path

from bgmodelica import (
    Component,
    Discrete,
    Input,
    Output,
    Parameter,
    Variable,
    der,
    if_else,
    sample,
    time,
    when,
)


class PWMDriver(Component):
    """PWM voltage source and armature winding of :class:`PWMMotor` (the electrical part).

    Parameters: R [Ohm], L [H], k [N.m/A], Vs [V], f_pwm [Hz], duty [1]. Input: w [rad/s].
    Outputs: i [A] (state), U [V]. Discrete ``period_start`` [s].
    """

    R = Parameter(1.0, unit="Ohm", description="Armature resistance")
    L = Parameter(1e-3, unit="H", description="Armature inductance")
    k = Parameter(0.05, unit="N.m/A", description="Torque and back-EMF constant")
    Vs = Parameter(24.0, unit="V", description="Supply voltage")
    f_pwm = Parameter(20e3, unit="Hz", description="PWM frequency")
    duty = Parameter(0.6, unit="1", description="Duty cycle")
    w = Input(unit="rad/s", description="Rotor speed (back EMF)")
    i = Output(unit="A", description="Armature current")
    U = Output(unit="V", description="Armature voltage")
    i_s = Variable(unit="A", start=0.0, fixed=True, description="Armature current (state)")
    period_start = Discrete(unit="s", start=0.0, description="Start of the current PWM period")

    def equations(self):
        yield when(sample(0.0, 1.0 / self.f_pwm), self.period_start == time)
        yield self.U == if_else(time < self.period_start + self.duty / self.f_pwm,
                                self.Vs, 0.0)
        yield self.L * der(self.i_s) == self.U - self.R * self.i_s - self.k * self.w
        yield self.i == self.i_s


class MotorMechanics(Component):
    """The rotor of :class:`PWMMotor`: ``J der(w) = k i - b w``.

    Parameters: k [N.m/A], J [kg.m2], b [N.m.s/rad]. Input: i [A]. Output: w [rad/s].
    """

    k = Parameter(0.05, unit="N.m/A", description="Torque constant")
    J = Parameter(2e-5, unit="kg.m2", description="Rotor inertia")
    b = Parameter(1e-5, unit="N.m.s/rad", description="Viscous friction")
    i = Input(unit="A", description="Armature current")
    w = Output(unit="rad/s", description="Rotor speed")
    w_s = Variable(unit="rad/s", start=0.0, fixed=True, description="Rotor speed (state)")

    def equations(self):
        yield self.J * der(self.w_s) == self.k * self.i - self.b * self.w_s
        yield self.w == self.w_s


#: element -> factory of the PWM motor split (Gauss-Seidel order: driver first).
PWM_ELEMENTS = {"driver": PWMDriver, "motor": MotorMechanics}
#: (from element, output, to element, input)
PWM_CONNECTIONS = [("driver", "i", "motor", "i"), ("motor", "w", "driver", "w")]


def build_pwm_fmus(out_dir: str | Path, fmi_version: int = 2, fmu_type: str = "both",
                   stop_time: float = 0.01, tolerance: float = 1e-8) -> dict[str, Path]:
    """Export the two FMUs of the split (``PWMDriver``, ``MotorMechanics``) into
    ``out_dir``; returns element name -> FMU path. Needs a C compiler."""
    from bgmodelica.fmi.from_model import export_model

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    return {el: export_model(factory(), out, fmi_version=fmi_version, fmu_type=fmu_type,
                             stop_time=stop_time, tolerance=tolerance)
            for el, factory in PWM_ELEMENTS.items()}


def pwm_system(fmus: dict[str, str | Path], step_size: float = 5e-6,
               stop_time: float = 0.01, name: str = "pwm_motor"):
    """The split as a :class:`bgmodelica.cosim.ssp.SystemStructure` on ``fmus`` (element
    name -> FMU path, as returned by :func:`build_pwm_fmus`)."""
    from bgmodelica.cosim.ssp import system_from_fmus

    return system_from_fmus(
        name, {el: fmus[el] for el in PWM_ELEMENTS}, PWM_CONNECTIONS, stop_time=stop_time,
        master={"step_size": step_size, "order": "gauss-seidel", "extrapolation": False},
        description="PWM-driven DC motor (library.examples.hybrid.PWMMotor) split into the "
                    "PWM driver with the armature winding (hybrid FMU, time events) and the "
                    "rotor mechanics")


def export_pwm_setup(out_dir: str | Path, fmi_version: int = 2,
                     stop_time: float = 0.01) -> dict[str, Path]:
    """Build the FMUs into ``out_dir/cosim`` and write ``out_dir/pwm_motor.ssp``; returns
    the paths (``ssp``, ``driver``, ``motor``)."""
    from bgmodelica.cosim.ssp import write_ssp

    out = Path(out_dir)
    fmus = build_pwm_fmus(out / "cosim", fmi_version=fmi_version, stop_time=stop_time)
    ssp = write_ssp(pwm_system(fmus, stop_time=stop_time), out / "pwm_motor.ssp")
    return {"ssp": ssp, **fmus}
