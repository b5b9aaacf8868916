// expect: 6 der
model M
  parameter Real p = 1;
  Real x;
equation
  x = der(p);
end M;
