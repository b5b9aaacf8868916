// expect: 6 nonexistent
model A
  parameter Real k = 1;
end A;
model M
  A a(nonexistent = 2);
end M;
