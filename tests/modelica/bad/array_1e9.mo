// expect: 4 array
model M
  parameter Integer n = 1000000000;
  Real x[n];
equation
  x = fill(1, n);
end M;
