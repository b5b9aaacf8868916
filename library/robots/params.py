"""Default parameters of the paper's robot (a small two-link lab arm driven by two geared DC
motors) and where they come from.

The paper (Baghli & El Bakkali, IJMME-IJENS 14(4), 2014) gives the structure and the symbols
(Table IV: m1, m2, l1, l2, lc1, lc2, I1, I2, g; Sec. 3: R, L, k1, Jm, b, k2) but no numbers, so
the values below are chosen for a small laboratory arm; each entry says why.

=============  ==========  =========  ====================================================
name           default     unit       source / reasoning
=============  ==========  =========  ====================================================
m1             3.0         kg         aluminium link 1 + joint-2 motor housing, lab-arm size
m2             2.0         kg         aluminium link 2 + small payload
l1             0.5         m          link 1 length (spec: "links 0.5 m / 0.4 m")
l2             0.4         m          link 2 length (enters only the tip position)
lc1            0.25        m          l1/2, uniform link (paper Eq. 1 puts the COM at l/2)
lc2            0.2         m          l2/2, uniform link
I1             0.0625      kg.m2      m1*l1^2/12, slender uniform rod about its COM
I2             0.026667    kg.m2      m2*l2^2/12
g              9.81        m/s2       standard gravity
R              1.0         Ohm        armature resistance of a ~100 W 24 V brushed DC motor
L              2.0e-3      H          armature inductance (L/R = 2 ms electrical time const.)
k1             0.2         N.m/A      torque / back-EMF constant (no-load 120 rad/s at 24 V)
Jm             5.0e-5      kg.m2      rotor inertia of that motor class
b              1.0e-4      N.m.s/rad  viscous friction of rotor bearings and brushes
k2             50          1          gear ratio: motor speed = k2 x joint speed
Kp1, Kp2       400, 400    V/rad      PID per joint, tuned here (loop crossover ~ 40 rad/s)
Ki1, Ki2       2000, 2000  V/(rad.s)  integral gains: remove the gravity offset
Kd1, Kd2       10, 2       V.s/rad    derivative gains (filter time constant Kd/(Kp Nd));
                                      joint 2 (lighter) gets less: a well-damped fast mode
Nd             10          1          derivative filter of the LimPID
A1, f1         1.0, 0.25   rad, Hz    reference q1* = A1 sin(2 pi f1 t) (paper Fig. 14)
A2, f2         0.8, 0.4    rad, Hz    reference q2* = A2 sin(2 pi f2 t) (paper Fig. 15)
Vmax           24          V          supply voltage: the PID output saturates at +-Vmax
=============  ==========  =========  ====================================================

Motor values are representative of datasheet ranges of 50-150 W brushed DC servo motors
(R 0.3-2 Ohm, L 0.1-5 mH, k 0.03-0.3 N.m/A, rotor inertia 1e-5-1e-4 kg.m2), not of one
specific motor. With these numbers the worst static gravity torque on joint 1 is
(m1 lc1 + m2 l1 + m2 lc2) g = 21.1 N.m, i.e. 0.42 N.m / 2.1 A at the motor; tracking the
default references takes at most ~22 V, inside the 24 V supply. Measured tracking (10 s,
after the first second): max |q1* - q1| = 0.025 rad, max |q2* - q2| = 0.028 rad.

Tuning: per joint, voltage -> joint angle is ~ k1 k2/R / (s (J_eff R/(k1 k2)^2 s + 1)), i.e.
0.1 rad/(V.s) with a mechanical pole at ~90 rad/s (joint 1, J_eff ~ 1.1 kg.m2 incl. the
reflected rotor k2^2 Jm = 0.125 kg.m2) or ~430 rad/s (joint 2). Kp = 400 V/rad puts the
crossover near 40 rad/s; Ki = 2000 V/(rad.s) (Ti = 0.2 s) gives type-2 behaviour at the
0.25-0.4 Hz references; higher gains track better (Kp 1000, Ki 10000: ~0.007 rad) but make
the loop stiffer and the currents at start-up larger (14 A).
"""

from __future__ import annotations

from .lagrange import ARM_DEFAULTS

__all__ = ["ARM", "MOTOR", "PID", "REFERENCE", "VMAX"]

ARM: dict[str, float] = dict(ARM_DEFAULTS)

MOTOR: dict[str, float] = {"R": 1.0, "L": 2.0e-3, "k1": 0.2, "Jm": 5.0e-5, "b": 1.0e-4,
                           "k2": 50.0}

PID: dict[str, float] = {"Kp1": 400.0, "Ki1": 2000.0, "Kd1": 10.0,
                         "Kp2": 400.0, "Ki2": 2000.0, "Kd2": 2.0, "Nd": 10.0}

REFERENCE: dict[str, float] = {"A1": 1.0, "f1": 0.25, "A2": 0.8, "f2": 0.4}

VMAX = 24.0
