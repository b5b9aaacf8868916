// expect: 8 endless loop
model M
  parameter Real p = 1;
  Real x;
algorithm
  x := 0;
  while p > 0 loop
    x := x + 1;
  end while;
end M;
