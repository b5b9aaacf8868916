// expect: 4 non-negative
model M
  parameter Integer n = -2;
  Real x[n];
  Real y;
equation
  y = 1;
end M;
