// expect: 6 Boolean
model M
  Boolean b = true;
  Real x;
equation
  x = 2 * b;
end M;
