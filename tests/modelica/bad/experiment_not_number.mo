// expect: 7 experiment
model M
  Real x(start = 1, fixed = true);
equation
  der(x) = -x;
  annotation(
    experiment(StopTime = "ten"));
end M;
