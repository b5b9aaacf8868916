// expect: 6 der()
model M
  parameter Integer n = 3;
  Real x;
equation
  x = der(n);
end M;
