"""frictionid quickstart: the paper's Fig. 2 and a fit of mu to the FMM fixture records.

    pip install ./python            # from the repository root
    python examples/python/quickstart.py

Plots with matplotlib when it is installed (quickstart.png); prints the numbers either way.
"""

from pathlib import Path

import numpy as np

import frictionid

FIXTURES = Path(__file__).resolve().parents[2] / "fixtures"

# The flexure stage of the paper: m x'' + c x' + k x + F = 0 (SI units).
stage = {"mass": 10.391, "damping": 0.275, "stiffness": 1982.0, "normal_force": 14.5}


def fig2():
    """Fig. 2: Coulomb friction mu = 0.24 under N = m g, released from rest at 140 mm."""
    paper = dict(stage, normal_force=10.391 * 9.81)
    t = np.linspace(0.0, 2.0, 2001)
    sim = frictionid.simulate(paper, {"type": "coulomb", "mu": 0.24}, 0.140, t)
    print(
        f"Fig. 2: at rest at {sim['final_displacement'] * 1e3:.6f} mm "
        f"after {sim['half_cycles']} half-cycles, t = {sim['rest_time']:.4f} s"
    )
    return sim


def fit_mu():
    """Fit mu to the three synthetic FMM records (truth 0.24), as fixtures/fmm-fit.toml does."""
    records = []
    for name, x0 in [("x10mm.csv", 0.010), ("x14mm.csv", 0.014), ("x22mm.csv", 0.022)]:
        data = np.loadtxt(FIXTURES / name, delimiter=",", skiprows=2)
        records.append({"name": name, "t": data[:, 0], "v": data[:, 1], "x0": x0})
    result = frictionid.fit(stage, {"type": "coulomb", "mu": 0.2}, records, {"free": ["mu"]})
    mu = result["parameters"][0]
    print(
        f"fit: mu = {mu['value']:.5f} +- {mu['std_error']:.1e} "
        f"(95 % CI {mu['ci95'][0]:.5f} .. {mu['ci95'][1]:.5f}), "
        f"rms residual {result['rms_residual']:.2e} m/s, converged: {result['converged']}"
    )
    return result


def plot(sim, result):
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("(matplotlib is not installed: no plot)")
        return
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7, 6))
    top.plot(sim["t"], sim["x"] * 1e3)
    top.set(xlabel="time [s]", ylabel="x [mm]", title="Fig. 2: Coulomb friction, x0 = 140 mm")
    for record in result["records"]:
        bottom.plot(record["time"], record["measured"], ".", ms=1, label=f"{record['file']} measured")
        bottom.plot(record["time"], record["fitted"], label=f"{record['file']} fitted")
    bottom.set(xlabel="time [s]", ylabel="v [m/s]", title="Coulomb fit to the FMM records")
    bottom.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig("quickstart.png", dpi=120)
    print("wrote quickstart.png")


if __name__ == "__main__":
    plot(fig2(), fit_mu())
