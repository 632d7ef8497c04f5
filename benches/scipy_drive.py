#!/usr/bin/env python3
"""SciPy's counterpart of `frictionid compare benches/drive/drive-compare.toml`: five friction
laws fitted to the drive benchmark's record (benches/drive/drive.csv, 19 000 samples) by
inverse dynamics, for the table in benches/README.md: what a user would otherwise write.

Usage: python3 benches/scipy_drive.py [--repeat N] [--record benches/drive/drive.csv]

As frictionid does, the acceleration is the Savitzky-Golay derivative of the measured
velocity (quartic, 21 samples) and the input force u is compared with M a + F(v, z), the mass
M fitted with the law (the axis's damping is not separated from the laws' viscous terms).
The laws: coulomb (Fc), viscous_coulomb (Fc, Fv), stribeck (Fc, Fs, vs, Fv; exponent 2), Dahl
at alpha = 1 in closed form along the displacement (the trapezoid of the velocity: F relaxes
exponentially towards Fc sgn(dx) in the travel), and LuGre stepped exactly over each sample
interval at the interval's mean velocity (the bristle relaxes exponentially in the travel).
Each law by `least_squares` (trf, x_scale='jac'), the static laws with their analytic
Jacobian, Dahl and LuGre with difference quotients, from a start a user would take: the
linear least-squares estimate of M, Fc and Fv, the bristle stiffness at a presliding
displacement of 20 um. Prints per law the estimates, the RMS residual and nfev, and the
median wall time of reading and fitting all five.
Needs numpy and scipy (`pip install numpy scipy`).
"""

import argparse
import statistics
import time

import numpy as np
from scipy.optimize import least_squares
from scipy.signal import savgol_filter


def read(path):
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    return data[:, 0], data[:, 1], data[:, 2]


def dahl_force(dx, sigma0, fc):
    """Dahl (alpha = 1) along the displacement increments dx from F = 0."""
    force = np.empty(len(dx) + 1)
    f = 0.0
    force[0] = 0.0
    decay = np.exp(-sigma0 * np.abs(dx) / fc)
    target = fc * np.sign(dx)
    for i in range(len(dx)):
        f = target[i] + (f - target[i]) * decay[i]
        force[i + 1] = f
    return force


def lugre_force(v, dt, p):
    """LuGre stepped exactly interval by interval at the mean velocity, from z = 0."""
    sigma0, sigma1, sigma2, fc, fs, vs = p
    vbar = 0.5 * (v[1:] + v[:-1])
    g = fc + (fs - fc) * np.exp(-(vbar / vs) ** 2)
    zss = g * np.sign(vbar) / sigma0
    decay = np.exp(-sigma0 * np.abs(vbar) * dt / g)
    gs = fc + (fs - fc) * np.exp(-(v / vs) ** 2)
    z = np.empty(len(v))
    zi = 0.0
    z[0] = 0.0
    for i in range(len(vbar)):
        zi = zss[i] + (zi - zss[i]) * decay[i]
        z[i + 1] = zi
    zdot = v - sigma0 * np.abs(v) * z / gs
    return sigma0 * z + sigma1 * zdot + sigma2 * v


def fit_all(t, v, u):
    dt = t[1] - t[0]
    a = savgol_filter(v, 21, 4, deriv=1, delta=dt)
    sign = np.sign(v)
    dx = 0.5 * (v[1:] + v[:-1]) * np.diff(t)
    linear = np.linalg.lstsq(np.column_stack([a, sign, v]), u, rcond=None)[0]
    m0, fc0, fv0 = linear
    results = {}

    def static(name, force, jac, start, bounds):
        def res(p):
            return p[0] * a + force(p[1:]) - u

        def jacobian(p):
            return np.column_stack([a] + jac(p[1:]))

        results[name] = least_squares(res, start, jac=jacobian, bounds=bounds, x_scale="jac")

    static("coulomb", lambda p: p[0] * sign, lambda p: [sign], [m0, fc0],
           ([0, 0], [np.inf, np.inf]))
    static("viscous_coulomb", lambda p: p[0] * sign + p[1] * v, lambda p: [sign, v],
           [m0, fc0, fv0], ([0, 0, 0], [np.inf] * 3))

    def stribeck(p):
        fc, fs, vs, fv = p
        return (fc + (fs - fc) * np.exp(-(v / vs) ** 2)) * sign + fv * v

    def stribeck_jac(p):
        fc, fs, vs, fv = p
        e = np.exp(-(v / vs) ** 2)
        return [(1 - e) * sign, e * sign, (fs - fc) * e * 2 * v ** 2 / vs ** 3 * sign, v]

    static("stribeck", stribeck, stribeck_jac, [m0, fc0, 1.2 * fc0, 0.01, fv0],
           ([0, 0, 0, 1e-6, 0], [np.inf] * 5))
    sigma0 = fc0 / 20e-6
    results["dahl"] = least_squares(
        lambda p: p[0] * a + dahl_force(dx, np.exp(p[1]), p[2]) - u,
        [m0, np.log(sigma0), fc0], bounds=([0, 0, 1e-6], [np.inf, 40, np.inf]), x_scale="jac")
    results["lugre"] = least_squares(
        lambda p: p[0] * a + lugre_force(v, dt, [np.exp(p[1]), p[2], p[3], p[4], p[5], p[6]]) - u,
        [m0, np.log(sigma0), 0.0, fv0, fc0, 1.2 * fc0, 0.01],
        bounds=([0, 0, 0, 0, 1e-6, 1e-6, 1e-6], [np.inf, 40, np.inf, np.inf, np.inf, np.inf, 10]),
        x_scale="jac")
    return results


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--record", default="benches/drive/drive.csv")
    args = parser.parse_args()
    times = []
    for _ in range(args.repeat):
        start = time.perf_counter()
        results = fit_all(*read(args.record))
        times.append(time.perf_counter() - start)
    for name, r in results.items():
        rms = np.sqrt(np.mean(r.fun ** 2))
        print(f"{name}: rms {rms:.4f} N, nfev {r.nfev}, x {np.array2string(r.x, precision=5)}")
    print(f"median {statistics.median(times):.2f} s over {args.repeat} runs")


if __name__ == "__main__":
    main()
