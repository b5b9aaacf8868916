// expect: 6 index
model M
  Real x[3];
equation
  x[1:3] = {1, 2, 3} .* time;
  x[4] = 0;
end M;
