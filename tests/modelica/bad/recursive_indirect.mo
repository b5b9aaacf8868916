// expect: 6 recursive
model A
  B b;
end A;
model B
  A a;
end B;
model M
  A a;
end M;
