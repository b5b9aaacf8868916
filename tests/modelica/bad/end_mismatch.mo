// model: end_mismatch
// expect: 7 closed by
model end_mismatch
  Real x;
equation
  x = 1;
end M;
