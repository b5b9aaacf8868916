"""The Modelica Standard Library subset: what ``Modelica.*`` names mean without the MSL sources.

This is the fallback only: with a ``Modelica`` package on the library path (MODELICAPATH,
``--modelica-path``; :mod:`.library_path`), ``Modelica.*`` names mean that source and this
mapping is not used (one meaning per name).

Two parts:

- :data:`MAPPING`: MSL component classes (Electrical.Analog.Basic/Sources/Sensors/Ideal,
  Mechanics.Rotational and Translational components, sources and sensors, Blocks.Continuous/
  Math/Sources/Nonlinear) mapped onto the classes of the project's ``library/`` package, with
  the MSL parameter names translated. ``library`` is imported only when a model uses one of
  them (``bgmodelica`` itself does not depend on it).
- :data:`STUB`: Modelica text for the rest a textbook model uses: ``Modelica.Units.SI`` (and
  ``Modelica.SIunits``) types, ``Modelica.Constants``, ``Modelica.Icons``, the connectors and
  partial models of ``*.Interfaces`` (``Pin``, ``OnePort``, ``Flange_a``,
  ``PartialCompliant``, ``RealInput``, ``SISO``...) and ``Modelica.Blocks.Types``. Models that
  ``extends Modelica.Electrical.Analog.Interfaces.OnePort`` get these equations.

A modifier of an MSL parameter that the mapped class does not have is accepted only at the
MSL default value (e.g. ``useHeatPort = false``); otherwise the error names it.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

from .errors import ModelicaError


@dataclass(frozen=True)
class Entry:
    """One MSL class mapped onto ``module.cls``.

    rename: MSL member name -> library name (parameters, variables, connectors).
    ctor: MSL parameter -> library constructor argument (values fixed at construction).
    ignore: MSL parameters without a library counterpart, accepted at these values only.
    enum_ctor: MSL parameter whose enumeration value becomes a constructor string
    (``controllerType = SimpleController.PI`` -> ``controller_type="PI"``).
    """

    module: str
    cls: str
    rename: dict[str, str] = field(default_factory=dict)
    ctor: dict[str, str] = field(default_factory=dict)
    ignore: dict[str, Any] = field(default_factory=dict)
    enum_ctor: dict[str, str] = field(default_factory=dict)
    #: MSL parameters whose default is minus another one (``yMin = -yMax``)
    negated: dict[str, str] = field(default_factory=dict)

    def load(self) -> type:
        try:
            module = importlib.import_module(self.module)
        except ImportError as err:
            raise ModelicaError(f"the Modelica Standard Library mapping needs the project's "
                                f"'library' package ({self.module}): {err}") from None
        return getattr(module, self.cls)


_E = "library.electrical"
_R = "library.rotational"
_T = "library.translational"
_B = "library.blocks"
_HEAT = {"useHeatPort": False, "T_ref": 300.15, "alpha": 0.0, "T": 300.15}
_SUPPORT = {"useSupport": False}
_START = {"startTime": 0.0}

#: MSL class -> library class
MAPPING: dict[str, Entry] = {
    # Electrical.Analog.Basic
    "Modelica.Electrical.Analog.Basic.Ground": Entry(_E, "Ground"),
    "Modelica.Electrical.Analog.Basic.Resistor": Entry(_E, "Resistor", ignore=_HEAT),
    "Modelica.Electrical.Analog.Basic.Capacitor": Entry(_E, "Capacitor"),
    "Modelica.Electrical.Analog.Basic.Inductor": Entry(_E, "Inductor"),
    "Modelica.Electrical.Analog.Basic.EMF": Entry(_E, "EMF", ignore=_SUPPORT),
    # Electrical.Analog.Sources
    "Modelica.Electrical.Analog.Sources.ConstantVoltage": Entry(_E, "ConstantVoltage"),
    "Modelica.Electrical.Analog.Sources.StepVoltage":
        Entry(_E, "StepVoltage", rename={"startTime": "start_time"}),
    "Modelica.Electrical.Analog.Sources.SineVoltage":
        Entry(_E, "SineVoltage", rename={"freqHz": "f"}, ignore=_START),
    "Modelica.Electrical.Analog.Sources.SignalVoltage": Entry(_E, "SignalVoltage",
                                                              rename={"v": "u"}),
    "Modelica.Electrical.Analog.Sources.ConstantCurrent": Entry(_E, "ConstantCurrent"),
    "Modelica.Electrical.Analog.Sources.StepCurrent":
        Entry(_E, "StepCurrent", rename={"startTime": "start_time"}),
    "Modelica.Electrical.Analog.Sources.SineCurrent":
        Entry(_E, "SineCurrent", rename={"freqHz": "f"}, ignore=_START),
    "Modelica.Electrical.Analog.Sources.SignalCurrent": Entry(_E, "SignalCurrent",
                                                              rename={"i": "u"}),
    # Electrical.Analog.Sensors
    "Modelica.Electrical.Analog.Sensors.VoltageSensor": Entry(_E, "VoltageSensor"),
    "Modelica.Electrical.Analog.Sensors.CurrentSensor": Entry(_E, "CurrentSensor"),
    # Electrical.Analog.Ideal
    "Modelica.Electrical.Analog.Ideal.IdealDiode": Entry(_E, "IdealDiode", ignore=_HEAT),
    "Modelica.Electrical.Analog.Ideal.IdealOpeningSwitch":
        Entry(_E, "IdealOpeningSwitch", ignore=_HEAT),
    "Modelica.Electrical.Analog.Ideal.IdealClosingSwitch":
        Entry(_E, "IdealClosingSwitch", ignore=_HEAT),
    "Modelica.Electrical.Analog.Ideal.IdealCommutingSwitch":
        Entry(_E, "IdealCommutingSwitch", ignore=_HEAT),
    "Modelica.Electrical.Analog.Ideal.ControlledIdealOpeningSwitch":
        Entry(_E, "ControlledIdealOpeningSwitch", ignore=_HEAT),
    "Modelica.Electrical.Analog.Ideal.ControlledIdealClosingSwitch":
        Entry(_E, "ControlledIdealClosingSwitch", ignore=_HEAT),
    "Modelica.Electrical.Analog.Ideal.ControlledIdealCommutingSwitch":
        Entry(_E, "ControlledIdealCommutingSwitch", ignore=_HEAT),
    # Mechanics.Rotational
    "Modelica.Mechanics.Rotational.Components.Fixed": Entry(_R, "Fixed"),
    "Modelica.Mechanics.Rotational.Components.Inertia":
        Entry(_R, "Inertia", ignore={"stateSelect": None}),
    "Modelica.Mechanics.Rotational.Components.Damper": Entry(_R, "Damper", ignore=_HEAT),
    "Modelica.Mechanics.Rotational.Components.Spring": Entry(_R, "Spring"),
    "Modelica.Mechanics.Rotational.Components.SpringDamper": Entry(_R, "SpringDamper",
                                                                   ignore=_HEAT),
    "Modelica.Mechanics.Rotational.Components.IdealGear": Entry(_R, "IdealGear",
                                                                ignore=_SUPPORT),
    "Modelica.Mechanics.Rotational.Sources.Torque": Entry(_R, "Torque", ignore=_SUPPORT),
    "Modelica.Mechanics.Rotational.Sources.ConstantTorque": Entry(_R, "ConstantTorque",
                                                                  ignore=_SUPPORT),
    "Modelica.Mechanics.Rotational.Sensors.AngleSensor": Entry(_R, "AngleSensor"),
    "Modelica.Mechanics.Rotational.Sensors.SpeedSensor": Entry(_R, "SpeedSensor"),
    "Modelica.Mechanics.Rotational.Sensors.TorqueSensor": Entry(_R, "TorqueSensor"),
    # Mechanics.Translational
    "Modelica.Mechanics.Translational.Components.Fixed": Entry(_T, "Fixed"),
    "Modelica.Mechanics.Translational.Components.Mass":
        Entry(_T, "Mass", ignore={"stateSelect": None}),
    "Modelica.Mechanics.Translational.Components.Rod": Entry(_T, "Rod"),
    "Modelica.Mechanics.Translational.Components.Spring": Entry(_T, "Spring"),
    "Modelica.Mechanics.Translational.Components.Damper": Entry(_T, "Damper", ignore=_HEAT),
    "Modelica.Mechanics.Translational.Components.SpringDamper":
        Entry(_T, "SpringDamper", ignore=_HEAT),
    "Modelica.Mechanics.Translational.Sources.Force": Entry(_T, "Force", ignore=_SUPPORT),
    "Modelica.Mechanics.Translational.Sources.ConstantForce": Entry(_T, "ConstantForce",
                                                                    ignore=_SUPPORT),
    "Modelica.Mechanics.Translational.Sensors.PositionSensor": Entry(_T, "PositionSensor"),
    "Modelica.Mechanics.Translational.Sensors.SpeedSensor": Entry(_T, "SpeedSensor"),
    "Modelica.Mechanics.Translational.Sensors.AccSensor": Entry(_T, "AccSensor"),
    "Modelica.Mechanics.Translational.Sensors.ForceSensor": Entry(_T, "ForceSensor"),
    # Blocks
    "Modelica.Blocks.Continuous.Integrator":
        Entry(_B, "Integrator", ctor={"y_start": "y_start"},
              ignore={"initType": None, "use_reset": False, "use_set": False}),
    "Modelica.Blocks.Continuous.FirstOrder":
        Entry(_B, "FirstOrder", ctor={"y_start": "y_start"}, ignore={"initType": None}),
    "Modelica.Blocks.Continuous.Derivative":
        Entry(_B, "Derivative", ctor={"x_start": "x_start"},
              ignore={"initType": None, "y_start": 0.0}),
    "Modelica.Blocks.Continuous.LimPID":
        Entry(_B, "LimPID", rename={"yMax": "y_max", "yMin": "y_min"},
              ctor={"xi_start": "xi_start"}, enum_ctor={"controllerType": "controller_type"},
              negated={"yMin": "yMax"},
              ignore={"initType": None, "xd_start": 0.0, "y_start": 0.0,
                      "withFeedForward": False, "kFF": 1.0, "limitsAtInit": True,
                      "homotopyType": None, "strict": False}),
    "Modelica.Blocks.Math.Gain": Entry(_B, "Gain"),
    "Modelica.Blocks.Math.Add": Entry(_B, "Add"),
    "Modelica.Blocks.Math.Feedback": Entry(_B, "Feedback"),
    "Modelica.Blocks.Math.Product": Entry(_B, "Product"),
    "Modelica.Blocks.Sources.Constant": Entry(_B, "Constant"),
    "Modelica.Blocks.Sources.Step":
        Entry(_B, "Step", rename={"startTime": "start_time"}),
    "Modelica.Blocks.Sources.Sine":
        Entry(_B, "Sine", rename={"freqHz": "f"}, ignore=_START),
    "Modelica.Blocks.Sources.Ramp":
        Entry(_B, "Ramp", rename={"startTime": "start_time"}),
    "Modelica.Blocks.Nonlinear.Limiter":
        Entry(_B, "Limiter", rename={"uMax": "u_max", "uMin": "u_min"}, negated={"uMin": "uMax"},
              ignore={"strict": False, "homotopyType": None}),
}

#: SI type -> unit (Modelica.Units.SI and Modelica.SIunits)
SI_TYPES: dict[str, str] = {
    "Time": "s", "Frequency": "Hz", "AngularFrequency": "rad/s", "Length": "m",
    "Position": "m", "Distance": "m", "Height": "m", "Diameter": "m", "Radius": "m",
    "Area": "m2", "Volume": "m3", "Velocity": "m/s", "Acceleration": "m/s2",
    "Angle": "rad", "AngularVelocity": "rad/s", "AngularAcceleration": "rad/s2",
    "Mass": "kg", "Density": "kg/m3", "Force": "N", "Torque": "N.m", "Power": "W",
    "Energy": "J", "Work": "J", "Pressure": "Pa", "Inertia": "kg.m2",
    "MomentOfInertia": "kg.m2", "Momentum": "kg.m/s", "AngularMomentum": "kg.m2/s",
    "TranslationalSpringConstant": "N/m", "TranslationalDampingConstant": "N.s/m",
    "RotationalSpringConstant": "N.m/rad", "RotationalDampingConstant": "N.m.s/rad",
    "Voltage": "V", "ElectricPotential": "V", "Current": "A", "ElectricCurrent": "A",
    "Resistance": "Ohm", "Conductance": "S", "Capacitance": "F", "Inductance": "H",
    "ElectricCharge": "C", "MagneticFlux": "Wb", "ElectricalTorqueConstant": "N.m/A",
    "Temperature": "K", "ThermodynamicTemperature": "K", "TemperatureDifference": "K",
    "HeatFlowRate": "W", "ThermalConductance": "W/K", "HeatCapacity": "J/K",
    "MassFlowRate": "kg/s", "VolumeFlowRate": "m3/s", "Efficiency": "1",
    "DampingCoefficient": "1/s",
    "PerUnit": "1", "Voltage_rms": "V", "Current_rms": "A",
}

_BUILTIN_FUNCTIONS = ("sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh",
                      "tanh", "exp", "log", "log10", "sqrt")


def _si_package(name: str) -> str:
    lines = [f"  package {name}"]
    for t, u in SI_TYPES.items():
        lines.append(f'    type {t} = Real(final unit="{u}");')
    lines.append(f"  end {name};")
    return "\n".join(lines)


def _stub_text() -> str:
    si = _si_package("SIunits")
    return f'''
package Modelica "Modelica Standard Library: the subset bgmodelica reads without its sources"
  package Constants
    constant Real pi = 3.141592653589793;
    constant Real e = 2.718281828459045;
    constant Real g_n(unit="m/s2") = 9.80665;
    constant Real eps = 2.220446049250313e-16;
    constant Real small = 1e-60;
    constant Real inf = 1e60;
    constant Real D2R(unit="rad/deg") = 0.017453292519943295;
    constant Real R2D(unit="deg/rad") = 57.29577951308232;
  end Constants;
  package Icons
    partial class Example end Example;
    partial class Package end Package;
    partial class Library end Library;
    partial class Function end Function;
    partial class Record end Record;
    partial class Block end Block;
    partial class ObsoleteModel end ObsoleteModel;
  end Icons;
  package Units
{_si_package("SI").replace(chr(10), chr(10) + "  ")}
  end Units;
{si}
  package Blocks
    package Interfaces
      connector RealInput = input Real;
      connector RealOutput = output Real;
      connector BooleanInput = input Boolean;
      connector BooleanOutput = output Boolean;
      connector IntegerInput = input Integer;
      connector IntegerOutput = output Integer;
      partial block SO
        RealOutput y;
      end SO;
      partial block SI
        RealInput u;
      end SI;
      partial block SISO
        RealInput u;
        RealOutput y;
      end SISO;
      partial block SI2SO
        RealInput u1;
        RealInput u2;
        RealOutput y;
      end SI2SO;
      partial block SignalSource
        extends SO;
        parameter Real offset = 0;
        parameter Real startTime(unit="s") = 0;
      end SignalSource;
    end Interfaces;
    package Types
      type Init = enumeration(NoInit, SteadyState, InitialState, InitialOutput);
      type SimpleController = enumeration(P, PI, PD, PID);
    end Types;
  end Blocks;
  package Electrical
    package Analog
      package Interfaces
        connector Pin
          Real v(unit="V");
          flow Real i(unit="A");
        end Pin;
        connector PositivePin
          Real v(unit="V");
          flow Real i(unit="A");
        end PositivePin;
        connector NegativePin
          Real v(unit="V");
          flow Real i(unit="A");
        end NegativePin;
        partial model TwoPin
          Real v(unit="V");
          PositivePin p;
          NegativePin n;
        equation
          v = p.v - n.v;
        end TwoPin;
        partial model OnePort
          PositivePin p;
          NegativePin n;
          Real v(unit="V");
          Real i(unit="A");
        equation
          v = p.v - n.v;
          0 = p.i + n.i;
          i = p.i;
        end OnePort;
      end Interfaces;
    end Analog;
  end Electrical;
  package Mechanics
    package Rotational
      package Interfaces
        connector Flange
          Real phi(unit="rad");
          flow Real tau(unit="N.m");
        end Flange;
        connector Flange_a
          Real phi(unit="rad");
          flow Real tau(unit="N.m");
        end Flange_a;
        connector Flange_b
          Real phi(unit="rad");
          flow Real tau(unit="N.m");
        end Flange_b;
        partial model PartialTwoFlanges
          Flange_a flange_a;
          Flange_b flange_b;
        end PartialTwoFlanges;
        partial model PartialCompliant
          extends PartialTwoFlanges;
          Real phi_rel(unit="rad");
          Real tau(unit="N.m");
        equation
          phi_rel = flange_b.phi - flange_a.phi;
          flange_b.tau = tau;
          flange_a.tau = -tau;
        end PartialCompliant;
      end Interfaces;
    end Rotational;
    package Translational
      package Interfaces
        connector Flange
          Real s(unit="m");
          flow Real f(unit="N");
        end Flange;
        connector Flange_a
          Real s(unit="m");
          flow Real f(unit="N");
        end Flange_a;
        connector Flange_b
          Real s(unit="m");
          flow Real f(unit="N");
        end Flange_b;
        partial model PartialTwoFlanges
          Flange_a flange_a;
          Flange_b flange_b;
        end PartialTwoFlanges;
        partial model PartialCompliant
          extends PartialTwoFlanges;
          Real s_rel(unit="m");
          Real f(unit="N");
        equation
          s_rel = flange_b.s - flange_a.s;
          flange_b.f = f;
          flange_a.f = -f;
        end PartialCompliant;
      end Interfaces;
    end Translational;
  end Mechanics;
  package Math
  end Math;
end Modelica;
'''


@lru_cache(maxsize=1)
def stub_scope():
    """The parsed stub (a :class:`~.scope.FileScope`), built once per process."""
    from .parser import parse_text
    from .scope import FileScope

    return FileScope(parse_text(_stub_text(), "<Modelica Standard Library subset>"), msl=True)


@lru_cache(maxsize=1)
def _namespaces() -> frozenset[str]:
    out = set()
    for name in MAPPING:
        parts = name.split(".")
        for k in range(1, len(parts)):
            out.add(".".join(parts[:k]))
    out.update({"Modelica.Math"})

    def packages(scope, prefix: str) -> None:
        for el in scope.cdef.elements:
            from .ast import ClassDef
            if isinstance(el, ClassDef) and el.kind == "package":
                out.add(f"{prefix}.{el.name}")
                packages(scope.nested(el.name), f"{prefix}.{el.name}")

    root = stub_scope().classes["Modelica"]
    out.add("Modelica")
    packages(root, "Modelica")
    return frozenset(out)


def resolve(path: str) -> Any:
    """What ``path`` (``Modelica.X.Y``) names: a mapped class, a stub class or constant, a
    package (namespace), a math function, or None."""
    from .scope import MslClass, MslNamespace

    entry = MAPPING.get(path)
    if entry is not None:
        return MslClass(path, entry)
    if path in _namespaces():
        return MslNamespace(path)
    if path.startswith("Modelica.Math.") and path.count(".") == 2:
        fname = path.rpartition(".")[2]
        if fname in _BUILTIN_FUNCTIONS:
            return ("function", fname)
    return stub_scope().find_full(path)


def stub_class(path: str) -> Any:
    """The stub's class scope for a package path (for lookups inside it)."""
    return stub_scope().find_full(path)


def supported() -> list[str]:
    """The MSL component classes that load without the MSL sources."""
    return sorted(MAPPING)
