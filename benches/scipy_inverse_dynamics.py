#!/usr/bin/env python3
"""SciPy's least_squares on the inverse-dynamics case of frictionid's `identify` benchmark
(`inverse dynamics/*`), for the table in benches/README.md: what a user would otherwise write.

Usage: python3 benches/scipy_inverse_dynamics.py [--repeat N]

The record is the benchmark's own, built the same way: 25 000 samples at 1 kHz of a prescribed
three-tone velocity, the input u = M a + Fv v + Fc sgn(v) + offset (M 8 kg, Fv 200 N s/m,
Fc 20 N, offset 1.5 N) plus two high tones standing for noise. As frictionid does, the
acceleration is the Savitzky-Golay derivative of the velocity (quartic, 21 samples: 20 ms),
the samples with |v| <= 1 mm/s are left out, and M, Fv, Fc and the offset are fitted by
least squares from a start of M 1, Fv 0, Fc 1, offset 0. Timed per run: the differentiation,
the masking and the fit. Prints per method the estimates, nfev and the median wall time.
Needs numpy and scipy (`pip install numpy scipy`).
"""

import argparse
import statistics
import time

import numpy as np
from scipy.optimize import least_squares
from scipy.signal import savgol_filter

TONES = [(0.2, 0.4, 0.0), (0.1, 1.1, 1.0), (0.05, 2.3, 2.0)]
TRUTH = {"mass": 8.0, "viscous": 200.0, "coulomb": 20.0, "offset": 1.5}
DT, SAMPLES, THRESHOLD = 1e-3, 25_000, 1e-3


def record():
    """Time, velocity and input force of the driven axis."""
    t = np.arange(SAMPLES) * DT
    v = sum(a * np.sin(2 * np.pi * f * t + p) for a, f, p in TONES)
    acc = sum(a * 2 * np.pi * f * np.cos(2 * np.pi * f * t + p) for a, f, p in TONES)
    disturbance = 0.1 * np.sin(2 * np.pi * 123.4 * t + 0.7) + 0.07 * np.sin(2 * np.pi * 211.1 * t)
    u = (TRUTH["mass"] * acc + TRUTH["viscous"] * v + TRUTH["coulomb"] * np.sign(v)
         + TRUTH["offset"] + disturbance)
    return t, v, u


def identify(v, u, method):
    """Differentiate, mask, fit: the estimates and the solver's result."""
    a = savgol_filter(v, 21, 4, deriv=1, delta=DT)
    used = np.abs(v) > THRESHOLD
    a, v, u = a[used], v[used], u[used]
    sign = np.sign(v)

    def residuals(p):
        mass, viscous, coulomb, offset = p
        return mass * a + viscous * v + coulomb * sign + offset - u

    return least_squares(residuals, [1.0, 0.0, 1.0, 0.0], method=method)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=20)
    args = parser.parse_args()
    _, v, u = record()
    for method in ["trf", "lm"]:
        times = []
        for _ in range(args.repeat):
            start = time.perf_counter()
            result = identify(v, u, method)
            times.append(time.perf_counter() - start)
        mass, viscous, coulomb, offset = result.x
        print(f"{method}: median {1e3 * statistics.median(times):.2f} ms over {args.repeat} runs, "
              f"nfev {result.nfev}; M {mass:.5f} kg, Fv {viscous:.4f} N s/m, "
              f"Fc {coulomb:.5f} N, offset {offset:.5f} N")


if __name__ == "__main__":
    main()
