within ;
package Circuits "RC circuit and the SciML RC ladder written as ordinary Modelica"
  import SI = Modelica.Units.SI;

  package Basic "MSL-style electrical components"
    connector Pin "Electrical pin"
      SI.Voltage v "Potential at the pin";
      flow SI.Current i "Current flowing into the pin";
    end Pin;

    partial model OnePort "Two pins, voltage drop and current"
      Pin p "Positive pin";
      Pin n "Negative pin";
      SI.Voltage v "Voltage drop p.v - n.v";
      SI.Current i "Current from p to n";
    equation
      v = p.v - n.v;
      0 = p.i + n.i;
      i = p.i;
    end OnePort;

    model Resistor "Ideal linear resistor"
      extends OnePort;
      parameter SI.Resistance R(start = 1) = 1 "Resistance";
    equation
      v = R*i;
    end Resistor;

    model Capacitor "Ideal linear capacitor"
      extends OnePort(v(start = 0));
      parameter SI.Capacitance C(min = 0) = 1 "Capacitance";
    equation
      i = C*der(v);
    end Capacitor;

    model ConstantVoltage "Constant voltage source"
      extends OnePort;
      parameter SI.Voltage V = 1 "Source voltage";
    equation
      v = V;
    end ConstantVoltage;

    model SineVoltage "Sine voltage source"
      extends OnePort;
      parameter SI.Voltage V = 1 "Amplitude";
      parameter SI.Frequency f = 1 "Frequency";
      parameter SI.Angle phase = 0 "Phase";
      parameter SI.Voltage offset = 0 "Offset";
    equation
      v = offset + V*sin(2*Modelica.Constants.pi*f*time + phase);
    end SineVoltage;

    model Ground "Ground node"
      Pin p;
    equation
      p.v = 0;
    end Ground;
  end Basic;

  model RC "A 10 V source charges a 1 mF capacitor through a 1 kOhm resistor"
    Basic.ConstantVoltage source(V = 10.0);
    Basic.Resistor resistor(R = 1e3);
    Basic.Capacitor capacitor(C = 1e-3, v(start = 0.0, fixed = true));
    Basic.Ground ground;
  equation
    connect(source.p, resistor.p) annotation(Line(points = {{-40, 0}, {-20, 0}}));
    connect(resistor.n, capacitor.p);
    connect(capacitor.n, source.n);
    connect(source.n, ground.p);
    annotation(experiment(StopTime = 5, Interval = 0.01, Tolerance = 1e-6));
  end RC;

  model RCLadder "The SciML RC circuit: n sections R[k] = 1/k, C[k] = 1/k^2, C[k].v(0) = k"
    parameter Integer n = 1000 "Number of sections";
    Basic.SineVoltage source(V = 1.0, f = 10.0);
    Basic.Ground ground;
    Basic.Resistor R[n](R = {1/k for k in 1:n});
    Basic.Capacitor C[n](C = {1/k^2 for k in 1:n}, v(start = {k for k in 1:n}, each fixed = true));
  equation
    connect(source.n, ground.p);
    connect(source.p, R[1].p);
    for k in 1:n loop
      connect(R[k].n, C[k].p);
      connect(C[k].n, ground.p);
    end for;
    for k in 1:n - 1 loop
      connect(R[k].n, R[k + 1].p);
    end for;
    annotation(experiment(StopTime = 10, Interval = 0.01));
  end RCLadder;
end Circuits;
