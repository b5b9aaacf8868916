// expect: 6 String
model A
  parameter Real k = 1;
end A;
model M
  A a(k = "two");
end M;
