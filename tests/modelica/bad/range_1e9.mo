// expect: 6 range
model M
  parameter Integer n = 1000000000;
  Real s;
equation
  s = sum(i for i in 1:n);
end M;
