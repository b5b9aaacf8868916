"""Co-simulation of FMUs: SSP set-ups, a fixed-step master (Jacobi / Gauss-Seidel, optional
input extrapolation, Co-Simulation and Model Exchange FMUs), checks of the set-up, a
cross-check against ``fmucontainer`` and the robot verification (monolithic vs split)."""
