#!/usr/bin/env python3
"""SciPy's counterpart of `frictionid compare fixtures/fmm-compare.toml`: the five classical
laws fitted in the velocity domain to the three bundled FMM records.

Usage: python3 benches/scipy_fmm_compare.py [--repeat N] [--laws coulomb,lugre,...]

What a SciPy user would write for the same fits. The rig of the config (m 10.391 kg,
c 0.275 N s/m, k 1982 N/m, N 14.5 N), each record (fixtures/x10mm.csv, x14mm.csv, x22mm.csv)
released from rest at its x0, simulated at its sample times and compared with its measured
velocity; the three records' residuals stacked; `least_squares` (`trf`, bounds,
`x_scale='jac'`, its own difference quotients for the Jacobian) from frictionid's default
start of each law:

- coulomb (mu), viscous_coulomb (mu, viscous), stribeck (mu_c, mu_s, v_s, viscous; delta 2):
  `solve_ivp` (RK45, rtol 1e-8, atol 1e-11) one half-cycle at a time, a terminal event at
  zero velocity, and at each stop the stick test (the spring force against the static level):
  the slide rests for good when it holds, else the next half-cycle starts the other way;
- dahl (sigma0, mu_c, alpha) and lugre (sigma0, sigma1, sigma2, mu_c, mu_s, v_s) with their
  internal state: LSODA (rtol 1e-8, atol 1e-11) with the analytic Jacobian of the right-hand
  side; sigma0 fitted as ln(sigma0).

Prints each law's fitted values, RMS residual, function evaluations and time, and the median
wall time of `--repeat` compares (the five fits in turn). Needs numpy and scipy.
"""

import argparse
import csv
import statistics
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import least_squares

M, C, K, N = 10.391, 0.275, 1982.0, 14.5
FIXTURES = Path(__file__).resolve().parent.parent / "fixtures"
RECORDS = [("x10mm.csv", 0.010), ("x14mm.csv", 0.014), ("x22mm.csv", 0.022)]
TOL = {"rtol": 1e-8, "atol": 1e-11}


def read_record(name):
    rows = [r for r in csv.reader(l for l in open(FIXTURES / name) if not l.startswith("#"))]
    data = np.array([[float(a), float(b)] for a, b in rows[1:]])
    return data[:, 0], data[:, 1]


def static_decay(t, x0, level, static_level, viscous):
    """Velocity at the times t of a free decay under F = level sgn(v) + viscous v that
    sticks when the spring force at a stop is within static_level(level)."""
    out = np.zeros_like(t)
    t0, x, direction = t[0], x0, -np.sign(x0)
    if abs(K * x) <= static_level:
        return out
    while t0 < t[-1]:
        def rhs(_t, y, s=direction):
            return [y[1], -(C * y[1] + K * y[0] + level(y[1], s) + viscous * y[1]) / M]

        def stop(_t, y):
            return y[1]

        stop.terminal, stop.direction = True, direction * -1.0
        inside = t[(t > t0) & (t <= t[-1])]
        sol = solve_ivp(rhs, (t0, t[-1]), [x, 0.0], t_eval=inside, events=stop,
                        method="RK45", **TOL)
        mask = (t > t0) & (t <= t[-1])
        idx = np.nonzero(mask)[0][: sol.y.shape[1]]
        out[idx] = sol.y[1]
        if sol.status != 1:
            break
        t0, x = sol.t_events[0][0], sol.y_events[0][0][0]
        direction = -direction
        if abs(K * x) <= static_level:
            break
    return out


def coulomb_like(kind):
    def velocity(p, t, x0):
        if kind == "coulomb":
            mu, viscous = p[0], 0.0
            level, static = (lambda v, s: mu * N * s), mu * N
        elif kind == "viscous_coulomb":
            mu, viscous = p
            level, static = (lambda v, s: mu * N * s), mu * N
        else:
            mu_c, mu_s, v_s, viscous = p
            level = lambda v, s: N * (mu_c + (mu_s - mu_c) * np.exp(-((v / v_s) ** 2))) * s
            static = mu_s * N
        return static_decay(t, x0, level, static, viscous)

    return velocity


def dahl_velocity(p, t, x0):
    sigma0, mu_c, alpha = np.exp(p[0]), p[1], p[2]
    fc = mu_c * N

    def rate(v, f):
        r = 1.0 - f * np.sign(v) / fc
        return sigma0 * v * abs(r) ** alpha * np.sign(r), r

    def rhs(_t, y):
        x, v, f = y
        return [v, -(C * v + K * x + f) / M, rate(v, f)[0]]

    def jac(_t, y):
        x, v, f = y
        _, r = rate(v, f)
        d_f = -sigma0 * abs(v) * alpha * abs(r) ** (alpha - 1.0) / fc
        d_v = sigma0 * abs(r) ** alpha * np.sign(r)
        return [[0.0, 1.0, 0.0], [-K / M, -C / M, -1.0 / M], [0.0, d_v, d_f]]

    return integrate(rhs, jac, t, x0)


def lugre_velocity(p, t, x0):
    sigma0, sigma1, sigma2, mu_c, mu_s, v_s = np.exp(p[0]), *p[1:]

    def parts(v, z):
        e = np.exp(-((v / v_s) ** 2))
        g = N * (mu_c + (mu_s - mu_c) * e)
        dg = N * (mu_s - mu_c) * e * (-2.0 * v / v_s**2)
        zdot = v - sigma0 * abs(v) * z / g
        return zdot, -sigma0 * abs(v) / g, 1.0 - sigma0 * z * (np.sign(v) * g - abs(v) * dg) / g**2

    def rhs(_t, y):
        x, v, z = y
        zdot = parts(v, z)[0]
        return [v, -(C * v + K * x + sigma0 * z + sigma1 * zdot + sigma2 * v) / M, zdot]

    def jac(_t, y):
        x, v, z = y
        _, dz, dv = parts(v, z)
        return [[0.0, 1.0, 0.0], [-K / M, -(C + sigma1 * dv + sigma2) / M,
                                  -(sigma0 + sigma1 * dz) / M], [0.0, dv, dz]]

    return integrate(rhs, jac, t, x0)


def integrate(rhs, jac, t, x0):
    sol = solve_ivp(rhs, (t[0], t[-1]), [x0, 0.0, 0.0], method="LSODA", t_eval=t, jac=jac,
                    **TOL)
    if not sol.success or sol.y.shape[1] != len(t):
        return np.full(len(t), 1.0)
    return sol.y[1]


# law: (velocity of a record, start, lower bounds, upper bounds, names); frictionid's defaults
# and bounds, sigma0 as its logarithm.
LAWS = {
    "coulomb": (coulomb_like("coulomb"), [0.2], [0.0], [10.0], ["mu"]),
    "viscous_coulomb": (coulomb_like("viscous_coulomb"), [0.2, 0.5], [0.0, 0.0],
                        [10.0, np.inf], ["mu", "viscous"]),
    "stribeck": (coulomb_like("stribeck"), [0.2, 0.3, 0.01, 0.5], [0.0, 0.0, 1e-6, 0.0],
                 [10.0, 10.0, 100.0, np.inf], ["mu_c", "mu_s", "v_s", "viscous"]),
    "dahl": (dahl_velocity, [np.log(1e5), 0.2, 1.0], [np.log(1e2), 1e-4, 1e-3],
             [np.log(1e12), 10.0, 10.0], ["ln sigma0", "mu_c", "alpha"]),
    "lugre": (lugre_velocity, [np.log(1e5), 300.0, 0.5, 0.2, 0.3, 0.01],
              [np.log(1e2), 0.0, 0.0, 1e-4, 1e-4, 1e-6],
              [np.log(1e12), 1e6, 1e4, 10.0, 10.0, 100.0],
              ["ln sigma0", "sigma1", "sigma2", "mu_c", "mu_s", "v_s"]),
}


def fit(law, records):
    velocity, start, lower, upper, _ = LAWS[law]

    def residuals(p):
        return np.concatenate([velocity(p, t, x0) - v for t, v, x0 in records])

    return least_squares(residuals, start, bounds=(lower, upper), method="trf", x_scale="jac")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--laws", default=",".join(LAWS))
    args = parser.parse_args()
    laws = args.laws.split(",")
    records = [(*read_record(name), x0) for name, x0 in RECORDS]
    totals = []
    for _ in range(args.repeat):
        total = 0.0
        for law in laws:
            start = time.perf_counter()
            result = fit(law, records)
            seconds = time.perf_counter() - start
            total += seconds
            rms = np.sqrt(np.mean(result.fun**2))
            values = ", ".join(f"{n} {v:.6g}" for n, v in zip(LAWS[law][4], result.x))
            print(f"{law}: {values}; rms {rms:.4e} m/s, nfev {result.nfev}, {seconds:.2f} s")
        totals.append(total)
    print(f"median wall time of {args.repeat} compare(s) of {len(laws)} laws: "
          f"{statistics.median(totals):.2f} s")


if __name__ == "__main__":
    main()
