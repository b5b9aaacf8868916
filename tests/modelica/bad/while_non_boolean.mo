// expect: 7 condition
model M
  parameter Integer n = 2;
  Real x;
algorithm
  x := 0;
  while n loop
    x := x + 1;
  end while;
end M;
