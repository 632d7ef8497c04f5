#!/usr/bin/env python3
"""SciPy counterpart of the friction-damper benchmark: Coulomb and Dahl (alpha = 1) fitted to
each of the 30 damper strokes that `cargo run --release -p frictionid-engine --example
bench_data` writes to target/bench-data/damper/, as a SciPy user would write the fits.

Each record (time, displacement, force) is fitted in the force domain with a load-cell offset:

- Coulomb: F = F_c sgn(v) + offset, v the central difference of the displacement;
- Dahl at alpha = 1, integrated in closed form along the measured displacement: on a run of
  samples moving one way (direction s) from x_a, where the force was F_a,
  F(x) = s F_c + (F_a - s F_c) exp(-sigma0 |x - x_a| / F_c), from F = 0 at the first sample.
  Parameters ln(sigma0), F_c and the offset, with the analytic Jacobian (the same recursion
  over the runs, differentiated).

Both by `scipy.optimize.least_squares` (trf, bounds, x_scale='jac'), ten starts per record and
model (Dahl: sigma0 log-uniform over 1e3..1e8 N/m), the best kept, with standard errors from
the Jacobian at the optimum. Prints per record the fitted values against the truth
(truth.csv), and the wall time of the whole run (reading the files and fitting) as the median
of --repeat runs; with --jobs N the records are fitted by N processes
(concurrent.futures), as `frictionid campaign` fits its groups on every core.

    /tmp/scipy-ref/bin/python benches/scipy_damper.py --repeat 3 [--jobs 2]
"""

import argparse
import concurrent.futures
import csv
import math
import pathlib
import statistics
import time

import numpy as np
from scipy.optimize import least_squares

STARTS = 10
DATA = pathlib.Path(__file__).resolve().parent.parent / "target" / "bench-data" / "damper"


def read_record(path):
    """time, displacement and force columns of one record."""
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    return data[:, 0], data[:, 1], data[:, 2]


class DahlPath:
    """The measured displacement cut into runs that move one way, for the closed form."""

    def __init__(self, x):
        dx = np.diff(x)
        sign = np.sign(dx)
        # A sample that does not move keeps the direction before it (the force stays).
        nonzero = np.flatnonzero(sign)
        if nonzero.size == 0:
            sign[:] = 1.0
        else:
            fill = np.maximum.accumulate(np.where(sign != 0, np.arange(sign.size), 0))
            sign = sign[fill]
            sign[: nonzero[0]] = sign[nonzero[0]]
        starts = np.flatnonzero(np.r_[True, sign[1:] != sign[:-1]])
        run_of_interval = np.cumsum(np.r_[True, sign[1:] != sign[:-1]]) - 1
        self.run_sign = sign[starts]
        # Sample n >= 1 is reached through interval n - 1.
        run = run_of_interval
        self.sample_run = run
        self.sample_sign = self.run_sign[run]
        self.distance = np.abs(x[1:] - x[starts][run])
        ends = np.r_[starts[1:], x.size - 1]
        self.run_length = np.abs(x[ends] - x[starts]).tolist()
        self.signs = self.run_sign.tolist()

    def force(self, sigma0, level, jacobian=False):
        """The force at every sample (F = 0 at the first), and with `jacobian` its derivatives
        by ln(sigma0) and F_c."""
        k = sigma0 / level
        n_runs = len(self.signs)
        start = [0.0] * n_runs
        d_start_u = [0.0] * n_runs
        d_start_c = [0.0] * n_runs
        f, du, dc = 0.0, 0.0, 0.0
        for r in range(n_runs):
            start[r], d_start_u[r], d_start_c[r] = f, du, dc
            s = self.signs[r]
            length = self.run_length[r]
            e = math.exp(-k * length)
            gap = f - s * level
            if jacobian:
                # dk/du = k, dk/dF_c = -k / F_c
                du = du * e - gap * e * length * k
                dc = s * (1.0 - e) + dc * e + gap * e * length * k / level
            f = s * level + gap * e
        start = np.asarray(start)[self.sample_run]
        s = self.sample_sign
        e = np.exp(-k * self.distance)
        gap = start - s * level
        force = np.r_[0.0, s * level + gap * e]
        if not jacobian:
            return force
        su = np.asarray(d_start_u)[self.sample_run]
        sc = np.asarray(d_start_c)[self.sample_run]
        grad_u = np.r_[0.0, su * e - gap * e * self.distance * k]
        grad_c = np.r_[0.0, s * (1.0 - e) + sc * e + gap * e * self.distance * k / level]
        return force, grad_u, grad_c


def fit_dahl(path, measured, rng):
    """Dahl (alpha = 1) and an offset: the best of ten starts."""

    def residuals(p):
        return path.force(math.exp(p[0]), p[1]) + p[2] - measured

    def jacobian(p):
        _, gu, gc = path.force(math.exp(p[0]), p[1], jacobian=True)
        return np.column_stack([gu, gc, np.ones_like(gu)])

    level = np.mean(np.abs(measured - np.median(measured)))
    lower = [math.log(1e2), 1e-3, -np.inf]
    upper = [math.log(1e10), np.inf, np.inf]
    starts = [
        [math.log(10 ** rng.uniform(3.0, 8.0)), level * rng.uniform(0.5, 1.5), np.mean(measured)]
        for _ in range(STARTS)
    ]
    return best_of(residuals, jacobian, starts, (lower, upper))


def fit_coulomb(sign, measured, rng):
    """Coulomb and an offset: the best of ten starts."""

    def residuals(p):
        return p[0] * sign + p[1] - measured

    def jacobian(_p):
        return np.column_stack([sign, np.ones_like(sign)])

    level = np.mean(np.abs(measured - np.median(measured)))
    starts = [[level * rng.uniform(0.5, 1.5), np.mean(measured)] for _ in range(STARTS)]
    return best_of(residuals, jacobian, starts, ([0.0, -np.inf], [np.inf, np.inf]))


def best_of(residuals, jacobian, starts, bounds):
    """The lowest-cost least_squares run over `starts`, with standard errors."""
    best = None
    for x0 in starts:
        run = least_squares(residuals, x0, jac=jacobian, bounds=bounds, x_scale="jac")
        if best is None or run.cost < best.cost:
            best = run
    dof = max(best.fun.size - best.x.size, 1)
    variance = 2.0 * best.cost / dof
    cov = np.linalg.pinv(best.jac.T @ best.jac) * variance
    return best, np.sqrt(np.diag(cov))


def fit_record(file):
    """Both fits of one record: (Coulomb level, Dahl sigma0, Dahl level, Dahl offset)."""
    t, x, measured = read_record(file)
    rng = np.random.default_rng(1)
    sign = np.sign(np.gradient(x, t))
    coulomb, _ = fit_coulomb(sign, measured, rng)
    dahl, errors = fit_dahl(DahlPath(x), measured, rng)
    return {
        "coulomb_level": coulomb.x[0],
        "sigma0": math.exp(dahl.x[0]),
        "sigma0_rel_err": errors[0],
        "level": dahl.x[1],
        "offset": dahl.x[2],
        "rms": math.sqrt(2.0 * dahl.cost / measured.size),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=3, help="timed runs (median reported)")
    parser.add_argument("--data", type=pathlib.Path, default=DATA)
    parser.add_argument("--jobs", type=int, default=1, help="processes fitting records")
    args = parser.parse_args()
    with open(args.data / "runs.csv") as f:
        files = [row["file"] for row in csv.DictReader(f)]
    with open(args.data / "truth.csv") as f:
        truth = {row["file"]: row for row in csv.DictReader(f)}
    times = []
    paths = [args.data / name for name in files]
    for _ in range(args.repeat):
        clock = time.perf_counter()
        if args.jobs > 1:
            with concurrent.futures.ProcessPoolExecutor(args.jobs) as pool:
                fits = dict(zip(files, pool.map(fit_record, paths)))
        else:
            fits = dict(zip(files, map(fit_record, paths)))
        times.append(time.perf_counter() - clock)
    print("file            sigma0 (truth)        F_c dahl (truth)  offset (truth)  F_c coulomb  rms")
    for name, r in fits.items():
        t = truth[name]
        print(
            f"{name}  {r['sigma0']:.4e} ({float(t['sigma0']):.1e})  "
            f"{r['level']:8.3f} ({float(t['level']):8.3f})  "
            f"{r['offset']:6.3f} ({float(t['offset']):6.3f})  "
            f"{r['coulomb_level']:8.3f}  {r['rms']:.3f}"
        )
    print(f"{len(files)} records, Coulomb and Dahl, {STARTS} starts each, {args.jobs} "
          f"process(es): median {statistics.median(times):.2f} s over {len(times)} runs "
          f"({', '.join(f'{x:.2f}' for x in times)})")


if __name__ == "__main__":
    main()
