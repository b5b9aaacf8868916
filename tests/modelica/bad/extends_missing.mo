// expect: 3 NoSuchBase
model M
  extends NoSuchBase;
  Real x;
equation
  x = 1;
end M;
