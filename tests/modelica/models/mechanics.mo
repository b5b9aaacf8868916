package Mechanics "A high-index model and a hybrid one"
  import SI = Modelica.Units.SI;

  model Pendulum "Point mass on a massless rod, Cartesian coordinates (index 3)"
    parameter SI.Length L = 1 "Rod length";
    parameter SI.Mass m = 1 "Mass";
    parameter SI.Acceleration g = 9.81 "Gravity along -y";
    SI.Position x(start = 1) "Horizontal position";
    SI.Position y(start = 0, fixed = true) "Vertical position";
    SI.Velocity vx(start = 0) "Horizontal velocity";
    SI.Velocity vy(start = 0, fixed = true) "Vertical velocity";
    Real T(unit = "N/m") "Rod force per unit length";
  equation
    der(x) = vx;
    der(y) = vy;
    m*der(vx) = -T*x;
    m*der(vy) = -T*y - m*g;
    x^2 + y^2 = L^2;
    annotation(experiment(StopTime = 3, Interval = 0.01));
  end Pendulum;

  model BouncingBall "A ball dropped on a rigid floor; rests once a bounce is below v_min"
    parameter SI.Height h0 = 1 "Start height";
    parameter SI.Velocity v0 = 0 "Start speed (up positive)";
    parameter Real e(unit = "1") = 0.7 "Coefficient of restitution";
    parameter SI.Acceleration g = 9.81 "Gravity";
    parameter SI.Velocity v_min = 0.1 "Bounce speed below which the ball rests";
    SI.Height h(start = 1, fixed = true) "Height above the floor";
    SI.Velocity v(start = 0, fixed = true) "Vertical speed";
    Boolean flying(start = true) "False once the ball rests";
  equation
    der(h) = v;
    der(v) = if flying then -g else 0;
    when initial() then
      reinit(h, h0);
      reinit(v, v0);
    end when;
    when h < 0 then
      flying = -e*pre(v) >= v_min;
      reinit(v, if -e*pre(v) >= v_min then -e*pre(v) else 0);
      reinit(h, 0);
    end when;
    annotation(experiment(StopTime = 3, Interval = 0.01));
  end BouncingBall;
end Mechanics;
