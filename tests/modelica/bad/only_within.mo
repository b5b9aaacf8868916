// expect: 1 no class
within;
