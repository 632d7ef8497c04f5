#!/usr/bin/env python3
"""SciPy's solve_ivp on the cases of frictionid's `simulate` benchmarks, for the table in
benches/README.md: what a user would otherwise write in Python.

Usage: python3 benches/scipy_reference.py [--repeat N]

Each case: the FMM rig (m 10.391 kg, c 0.275 N s/m, k 1982 N/m, N 14.5 N), released from rest at
x0 = 22 mm, 2 s sampled at 1 kHz (t_eval), m x'' + c x' + k x + F = 0 with the friction force F
of the model (the sign convention of frictionid and of the paper's Eq. 1). Prints per case and
method the RHS evaluations (nfev), Jacobian evaluations (njev), the median wall time of
`--repeat` runs and the final displacement, so the accuracy can be held against frictionid's.
Needs numpy and scipy (`pip install numpy scipy`).
"""

import argparse
import statistics
import time

import numpy as np
from scipy.integrate import solve_ivp

M, C, K, N = 10.391, 0.275, 1982.0, 14.5
X0, T_END, RATE = 0.022, 2.0, 1000.0


def lugre(sigma0, sigma1=300.0, sigma2=0.5, mu_c=0.2, mu_s=0.3, v_s=0.01):
    """LuGre (Canudas de Wit et al. 1995): y = (x, v, z)."""

    def rhs(_t, y):
        x, v, z = y
        g = N * (mu_c + (mu_s - mu_c) * np.exp(-((v / v_s) ** 2)))
        zdot = v - sigma0 * abs(v) * z / g
        f = sigma0 * z + sigma1 * zdot + sigma2 * v
        return [v, -(C * v + K * x + f) / M, zdot]

    return rhs, [X0, 0.0, 0.0]


def dahl(sigma0, mu_c=0.2, alpha=1.0):
    """Dahl (1968) with the force as its state: y = (x, v, F)."""

    def rhs(_t, y):
        x, v, f = y
        s = 1.0 if v >= 0 else -1.0
        u = 1.0 - f * s / (mu_c * N)
        fdot = sigma0 * v * abs(u) ** alpha * (1.0 if u >= 0 else -1.0)
        return [v, -(C * v + K * x + f) / M, fdot]

    return rhs, [X0, 0.0, 0.0]


CASES = {
    "lugre sigma0=1e5": lugre(1e5),
    "lugre sigma0=1e7": lugre(1e7),
    "lugre sigma0=1e7 sigma1=5000": lugre(1e7, sigma1=5000.0),
    "dahl sigma0=1e5": dahl(1e5),
    "dahl sigma0=1e7": dahl(1e7),
}
METHODS = ["RK45", "LSODA", "BDF", "Radau"]


def run(rhs, y0, method, rtol, atol):
    t_eval = np.linspace(0.0, T_END, int(T_END * RATE) + 1)
    start = time.perf_counter()
    sol = solve_ivp(rhs, (0.0, T_END), y0, method=method, t_eval=t_eval, rtol=rtol, atol=atol)
    return time.perf_counter() - start, sol


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--rtol", type=float, default=1e-8)
    parser.add_argument("--atol", type=float, default=1e-11)
    parser.add_argument("--max-seconds", type=float, default=20.0,
                        help="skip a method on a case once one run takes longer than this")
    args = parser.parse_args()
    print(f"rtol {args.rtol:g}, atol {args.atol:g}, median of {args.repeat} runs")
    print(f"{'case':32} {'method':6} {'nfev':>9} {'njev':>6} {'median':>10} {'x(2 s) [m]':>22}")
    for name, (rhs, y0) in CASES.items():
        for method in METHODS:
            times, sol = [], None
            for _ in range(args.repeat):
                elapsed, sol = run(rhs, y0, method, args.rtol, args.atol)
                times.append(elapsed)
                if elapsed > args.max_seconds:
                    break
            status = "" if sol.success else f"  ({sol.message})"
            print(f"{name:32} {method:6} {sol.nfev:9d} {sol.njev:6d} "
                  f"{statistics.median(times) * 1e3:8.2f} ms {sol.y[0][-1]:22.15e}{status}")


if __name__ == "__main__":
    main()
