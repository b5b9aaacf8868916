package Motors "DC motor drives: MSL-style components written out, and with Modelica.* classes"
  import SI = Modelica.Units.SI;

  package Rotational "MSL-style 1-D rotational mechanics"
    connector Flange "Rotational flange"
      SI.Angle phi "Absolute rotation angle";
      flow SI.Torque tau "Cut torque into the component";
    end Flange;

    partial model PartialTwoFlanges
      Flange flange_a;
      Flange flange_b;
    end PartialTwoFlanges;

    model Inertia "Rigid rotating body"
      extends PartialTwoFlanges;
      parameter SI.Inertia J(min = 0) = 1 "Moment of inertia";
      SI.Angle phi(stateSelect = StateSelect.prefer) "Absolute rotation angle";
      SI.AngularVelocity w(stateSelect = StateSelect.prefer) "Absolute angular speed";
      SI.AngularAcceleration a "Absolute angular acceleration";
    equation
      phi = flange_a.phi;
      phi = flange_b.phi;
      w = der(phi);
      a = der(w);
      J*a = flange_a.tau + flange_b.tau;
    end Inertia;

    model Damper "Linear damper, written on the flange angles directly"
      extends PartialTwoFlanges;
      parameter SI.RotationalDampingConstant d = 0;
      SI.Torque tau "Torque from flange_a to flange_b";
    equation
      tau = d*der(flange_b.phi - flange_a.phi);
      flange_b.tau = tau;
      flange_a.tau = -tau;
    end Damper;

    model Fixed "Flange fixed to the housing"
      parameter SI.Angle phi0 = 0;
      Flange flange;
    equation
      flange.phi = phi0;
    end Fixed;
  end Rotational;

  package Electrical
    connector Pin
      SI.Voltage v;
      flow SI.Current i;
    end Pin;

    partial model OnePort
      Pin p, n;
      SI.Voltage v;
      SI.Current i;
    equation
      v = p.v - n.v;
      0 = p.i + n.i;
      i = p.i;
    end OnePort;

    model Resistor
      extends OnePort;
      parameter SI.Resistance R = 1;
    equation
      v = R*i;
    end Resistor;

    model Inductor
      extends OnePort;
      parameter SI.Inductance L = 1;
    equation
      v = L*der(i);
    end Inductor;

    model ConstantVoltage
      extends OnePort;
      parameter SI.Voltage V = 1;
    equation
      v = V;
    end ConstantVoltage;

    model Ground
      Pin p;
    equation
      p.v = 0;
    end Ground;

    model EMF "Electromechanical converter"
      parameter SI.ElectricalTorqueConstant k = 1;
      Pin p, n;
      Rotational.Flange flange;
      SI.Voltage v;
      SI.Current i;
      SI.AngularVelocity w;
    equation
      v = p.v - n.v;
      0 = p.i + n.i;
      i = p.i;
      w = der(flange.phi);
      v = k*w;
      flange.tau = -k*i;
    end EMF;
  end Electrical;

  model DCMotor "DC motor started on 12 V, driving an inertia and a damper"
    Electrical.ConstantVoltage source(V = 12.0);
    Electrical.Resistor resistor(R = 1.0);
    Electrical.Inductor inductor(L = 0.01, i(start = 0.0, fixed = true));
    Electrical.EMF emf(k = 0.1);
    Electrical.Ground ground;
    Rotational.Inertia rotor(J = 0.002, phi(start = 0.0, fixed = true), w(start = 0.0, fixed = true));
    Rotational.Inertia load(J = 0.008);
    Rotational.Damper damper(d = 0.001);
    Rotational.Fixed fixed;
  equation
    connect(source.p, resistor.p);
    connect(resistor.n, inductor.p);
    connect(inductor.n, emf.p);
    connect(emf.n, source.n);
    connect(source.n, ground.p);
    connect(emf.flange, rotor.flange_a);
    connect(rotor.flange_b, load.flange_a);
    connect(load.flange_b, damper.flange_a);
    connect(damper.flange_b, fixed.flange);
    annotation(experiment(StopTime = 2, Interval = 0.01));
  end DCMotor;

  model DCMotorMSL "The same drive built from Modelica Standard Library classes"
    import Modelica.Electrical.Analog.Basic;
    Modelica.Electrical.Analog.Sources.ConstantVoltage source(V = 12);
    Basic.Resistor resistor(R = 1, useHeatPort = false);
    Basic.Inductor inductor(L = 0.01, i(start = 0, fixed = true));
    Basic.EMF emf(k = 0.1);
    Basic.Ground ground;
    Modelica.Mechanics.Rotational.Components.Inertia rotor(J = 0.002, phi(start = 0, fixed = true), w(start = 0, fixed = true));
    Modelica.Mechanics.Rotational.Components.Inertia load(J = 0.008);
    Modelica.Mechanics.Rotational.Components.Damper damper(d = 0.001);
    Modelica.Mechanics.Rotational.Components.Fixed fixed;
  equation
    connect(source.p, resistor.p);
    connect(resistor.n, inductor.p);
    connect(inductor.n, emf.p);
    connect(emf.n, source.n);
    connect(source.n, ground.p);
    connect(emf.flange, rotor.flange_a);
    connect(rotor.flange_b, load.flange_a);
    connect(load.flange_b, damper.flange_a);
    connect(damper.flange_b, fixed.flange);
    annotation(experiment(StopTime = 2, Interval = 0.01));
  end DCMotorMSL;

  model PIDSpeedControlMSL "Speed loop of DCMotorMSL: Modelica.Blocks.Continuous.LimPID"
    extends DCMotorMSL(redeclare Modelica.Electrical.Analog.Sources.SignalVoltage source);
    Modelica.Blocks.Sources.Step setpoint(height = 100, startTime = 0.1);
    Modelica.Blocks.Sources.Step load_torque(height = -0.5, startTime = 1);
    Modelica.Blocks.Continuous.LimPID controller(
      controllerType = Modelica.Blocks.Types.SimpleController.PI,
      k = 4, Ti = 0.2, Ni = 0.9, yMax = 24, yMin = -24);
    Modelica.Mechanics.Rotational.Sources.Torque torque;
    Modelica.Mechanics.Rotational.Sensors.SpeedSensor speed_sensor;
  equation
    connect(setpoint.y, controller.u_s);
    connect(speed_sensor.w, controller.u_m);
    connect(controller.y, source.v);
    connect(load_torque.y, torque.tau);
    connect(torque.flange, load.flange_b);
    connect(speed_sensor.flange, rotor.flange_b);
    annotation(experiment(StopTime = 2, Interval = 0.005));
  end PIDSpeedControlMSL;
end Motors;
