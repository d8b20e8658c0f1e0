#!/usr/bin/python3
"""The reference of actuator_coupling_test, computed apart from Caliper's code: a free ball
hanging on a tendon from a fixed point straight above it; a DC motor reels the tendon in through a
linear series-elastic element and lifts the ball. One stiff ODE, solved by SciPy's Radau at tight
tolerances. The equations are TENDONS.md's, written out here; nothing is taken from the
project's C++.

Usage: actuator_coupling_reference.py OUT.csv
Writes `time [s], height [m], tension [N]` every 5 ms over 0.5 s.
"""

import sys

import numpy as np
from scipy.integrate import solve_ivp
from scipy.special import expit

# the rig: keep in step with actuator_coupling_test.cc
G = 9.81  # [m/s^2]
MASS = 1.0  # [kg]
ANCHOR_Z = 0.4  # the tendon's fixed end, straight above the ball [m]
Z0 = 0.0  # the ball's centre at the start (near the origin: Bullet's floats round least there) [m]
STIFFNESS = 5000.0  # [N/m]
DAMPING = 10.0  # [N s/m]
REST = 0.1  # elastic element's rest length [m]
PRETENSION = 9.81  # [N]: the ball's weight, so that it starts at rest in equilibrium
VOLTAGE = 12.0  # from t = 0 [V]
# the reference motor of TENDONS.md (the kind's defaults)
R, L_ARM, KT, KE = 0.516, 5.73e-5, 11.5e-3, 11.5e-3
J = 14.5e-7 + 0.4e-7
N, ETA, RS = 128.0, 0.59, 0.0045
DURATION, SAMPLE = 0.5, 0.005  # [s]


def path(z, vz):
    """Tendon length [m] and its rate [m/s]: the ball hangs straight below the anchor."""
    return ANCHOR_Z - z, -vz


def tension(z, vz, w, phi, line0):
    length, rate = path(z, vz)
    line = line0 - RS * phi  # kite line left between spool and elastic element
    stretch = length - line - REST
    if stretch <= 0:
        return 0.0
    return max(STIFFNESS * stretch + DAMPING * (rate + RS * w), 0.0)


def rhs(_t, y, line0):
    z, vz, i, w, phi = y
    f = tension(z, vz, w, phi, line0)
    # gear efficiency: eta driving, 1/eta back-driven, the logistic of TENDONS.md
    rho = ETA + (1 / ETA - ETA) * float(expit(-(1000 * i * w + 10)))
    return [
        vz,
        -G + f / MASS,
        (VOLTAGE - R * i - KE * N * w) / L_ARM,
        (KT * i - RS * f / (rho * N)) / (N * J),
        w,
    ]


def main():
    out = sys.argv[1]
    length0, _ = path(Z0, 0.0)
    line0 = length0 - (REST + PRETENSION / STIFFNESS)  # just taut at the pretension at rest
    times = np.arange(0.0, DURATION + SAMPLE / 2, SAMPLE)
    sol = solve_ivp(rhs, (0.0, DURATION), [Z0, 0.0, 0.0, 0.0, 0.0],
                    method="Radau", t_eval=times, rtol=1e-10, atol=1e-12, args=(line0,))
    if not sol.success:
        sys.exit("reference: the solver failed: " + sol.message)
    with open(out, "w", encoding="utf-8") as f:
        f.write("time [s],height [m],tension [N]\n")
        for k, t in enumerate(sol.t):
            z, vz, _i, w, phi = sol.y[:, k]
            f.write(f"{t:.6f},{z:.15e},{tension(z, vz, w, phi, line0):.15e}\n")


if __name__ == "__main__":
    main()
