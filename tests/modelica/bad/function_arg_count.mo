// expect: 9 input(s)
function f
  input Real a;
  output Real y;
algorithm
  y := 2 * a;
end f;
model M
  Real x = f(1, 2);
end M;
