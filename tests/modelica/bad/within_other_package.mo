// expect: 2 within
within NoSuchLibrary.Sub;
model M
  Real x;
equation
  x = 1;
end M;
