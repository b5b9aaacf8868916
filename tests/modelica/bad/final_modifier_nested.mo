// expect: 9 final
model A
  parameter Real k = 1;
end A;
model B
  A a(final k = 2);
end B;
model M
  B b(a(k = 3));
end M;
