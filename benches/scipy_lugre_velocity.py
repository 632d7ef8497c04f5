#!/usr/bin/env python3
"""SciPy's counterpart of frictionid's `lugre/default start, 3 records of 2 s` benchmark
(engine/benches/identify.rs): a LuGre velocity-domain fit from the default start.

Usage: python3 benches/scipy_lugre_velocity.py [--repeat N]

The records are those of the benchmark's set-up, made here with SciPy: the FMM rig (m 10.391
kg, c 0.275 N s/m, k 1982 N/m, N 14.5 N) released from rest at 10, 14 and 22 mm, 2 s at 1 kHz,
LuGre truth sigma0 1e5 N/m, sigma1 500 N s/m, sigma2 1 N s/m, mu_c 0.22, mu_s 0.30,
v_s 0.01 m/s, Gaussian velocity noise of 0.2 mm/s (numpy's generator: the same case as the
benchmark, another draw of the noise). The fit is what a SciPy user would write: each record
simulated by LSODA (rtol 1e-8, atol 1e-11, with the analytic Jacobian of the right-hand side)
at the sample times, the velocities stacked, and `least_squares` (`trf`, bounds,
`x_scale='jac'`, its own difference quotients for the Jacobian) over the six parameters,
sigma0 as ln(sigma0), from frictionid's default start (sigma0 1e5, sigma1 300, sigma2 0.5,
mu_c 0.2, mu_s 0.3, v_s 0.01). Prints the fitted values, the RMS residual, the function
evaluations and the median wall time of `--repeat` fits.
Needs numpy and scipy.
"""

import argparse
import statistics
import time

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import least_squares

M, C, K, N = 10.391, 0.275, 1982.0, 14.5
RELEASES = [0.010, 0.014, 0.022]
T = np.arange(2001) * 1e-3
TRUTH = [1e5, 500.0, 1.0, 0.22, 0.30, 0.01]
START = [1e5, 300.0, 0.5, 0.2, 0.3, 0.01]
NOISE = 2e-4


def system(p):
    sigma0, sigma1, sigma2, mu_c, mu_s, v_s = p

    def parts(v, z):
        e = np.exp(-((v / v_s) ** 2))
        g = N * (mu_c + (mu_s - mu_c) * e)
        dg = N * (mu_s - mu_c) * e * (-2.0 * v / v_s**2)
        zdot = v - sigma0 * abs(v) * z / g
        dzdot_dz = -sigma0 * abs(v) / g
        dzdot_dv = 1.0 - sigma0 * z * (np.sign(v) * g - abs(v) * dg) / g**2
        return zdot, dzdot_dz, dzdot_dv

    def rhs(_t, y):
        x, v, z = y
        zdot, _, _ = parts(v, z)
        f = sigma0 * z + sigma1 * zdot + sigma2 * v
        return [v, -(C * v + K * x + f) / M, zdot]

    def jac(_t, y):
        x, v, z = y
        _, dz, dv = parts(v, z)
        df_dv = sigma1 * dv + sigma2
        df_dz = sigma0 + sigma1 * dz
        return [[0.0, 1.0, 0.0], [-K / M, -(C + df_dv) / M, -df_dz / M], [0.0, dv, dz]]

    return rhs, jac


def simulate(p, x0):
    rhs, jac = system(p)
    sol = solve_ivp(rhs, (0.0, T[-1]), [x0, 0.0, 0.0], method="LSODA", t_eval=T,
                    jac=jac, rtol=1e-8, atol=1e-11)
    if not sol.success or sol.y.shape[1] != len(T):
        return np.full(len(T), 1.0)
    return sol.y[1]


def records():
    rng = np.random.default_rng(41)
    return [simulate(TRUTH, x0) + rng.normal(0.0, NOISE, len(T)) for x0 in RELEASES]


def fit(measured):
    def physical(u):
        return [np.exp(u[0]), *u[1:]]

    def residuals(u):
        p = physical(u)
        return np.concatenate([simulate(p, x0) - m for x0, m in zip(RELEASES, measured)])

    u0 = [np.log(START[0]), *START[1:]]
    lower = [np.log(1e3), 0.0, 0.0, 1e-3, 1e-3, 1e-4]
    upper = [np.log(1e9), 1e5, 100.0, 10.0, 10.0, 1.0]
    result = least_squares(residuals, u0, bounds=(lower, upper), method="trf", x_scale="jac")
    return physical(result.x), result


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--repeat", type=int, default=1)
    args = parser.parse_args()
    measured = records()
    times = []
    for _ in range(args.repeat):
        start = time.perf_counter()
        p, result = fit(measured)
        times.append(time.perf_counter() - start)
    rms = np.sqrt(np.mean(result.fun**2))
    names = ["sigma0", "sigma1", "sigma2", "mu_c", "mu_s", "v_s"]
    print("fitted:", ", ".join(f"{n} {v:.6g}" for n, v in zip(names, p)))
    print(f"rms {rms:.3e} m/s, nfev {result.nfev}, njev {result.njev}, status {result.status}")
    print(f"median wall time of {args.repeat} fit(s): {statistics.median(times):.2f} s")


if __name__ == "__main__":
    main()
