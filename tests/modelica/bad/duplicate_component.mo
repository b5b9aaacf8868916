// expect: 4 declared twice
model M
  Real x;
  Real x;
equation
  x = 1;
end M;
