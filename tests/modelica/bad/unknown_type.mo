// expect: 3 unknown class
model M
  Reel x;
equation
  x = 1;
end M;
