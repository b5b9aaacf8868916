// expect: 12 protected
model A
  Real y;
protected
  Real z;
equation
  z = 1;
  y = z;
end A;
model M
  A a;
  Real v = a.z;
end M;
