// expect: 2 no class
within;
