package T
  function poly "a*x^2 + b with a loop and a while"
    input Real x;
    input Real a = 2;
    output Real y;
    output Real z;
  protected
    Integer k;
    Real acc;
  algorithm
    acc := 0;
    for i in 1:3 loop
      acc := acc + i;
    end for;
    k := 0;
    while k < 2 loop
      k := k + 1;
    end while;
    if x > 0 then
      y := a*x^2 + acc - 6 + k - 2;
    else
      y := -a*x^2;
    end if;
    z := 2*y;
  end poly;

  model M
    Real x(start = 1, fixed = true);
    Real y;
    Real y2;
    Integer n(start = 0, fixed = true);
    Real w;
  equation
    der(x) = -x;
    (y, y2) = poly(time - 0.5);
  algorithm
    w := 3*x;
    when time >= 0.25 then
      n := pre(n) + 1;
    elsewhen time >= 0.75 then
      n := pre(n) + 10;
    end when;
    annotation(experiment(StopTime = 1));
  end M;
end T;
