// expect: 6 end_mismatch
model end_mismatch
  Real x;
equation
  x = 1;
end M;
