// expect: 4 recursive
model M
  Real x;
  M inner_m;
equation
  x = 1;
end M;
