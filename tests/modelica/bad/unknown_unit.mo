// expect: 3 unit
model M
  parameter Real p(unit = "furlongz/fortnite") = 1;
  Real x;
equation
  x = p;
end M;
