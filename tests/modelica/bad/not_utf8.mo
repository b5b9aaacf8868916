// expect: 3 UTF-8
model M
  Real x "café";
equation
  x = 1;
end M;
