"""The result objects of frictionid's functions, against the known truth of simulated records
and the CLI: the dict access of before, the parameter table, the text report, the plots and
the notebook view, and `run`, which writes nothing unless asked."""

import html
import json
import os
import pickle
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import frictionid

pd = pytest.importorskip("pandas")
matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
FIXTURES = ROOT / "fixtures"
FMM = {"mass": 10.391, "damping": 0.275, "stiffness": 1982.0, "normal_force": 14.5}
MU = 0.24
COLUMNS = ["value", "std_error", "ci_low", "ci_high", "unit", "status"]


def simulated_records(x0s=(0.010, 0.022), mu=MU, noise=2e-4, seed=7):
    """Coulomb releases of the FMM stage (truth mu) with white velocity noise."""
    t = np.arange(0, 1201) * 1e-3
    rng = np.random.default_rng(seed)
    records = []
    for x0 in x0s:
        v = frictionid.simulate(FMM, {"type": "coulomb", "mu": mu}, x0, t)["v"]
        records.append({"name": f"x{x0 * 1e3:.0f}mm", "t": t, "v": v + rng.normal(0, noise, t.size), "x0": x0})
    return records


@pytest.fixture(scope="module")
def records():
    return simulated_records()


@pytest.fixture(scope="module")
def fitted(records):
    return frictionid.fit(FMM, {"type": "coulomb", "mu": 0.2}, records, {"free": ["mu"]})


@pytest.fixture(scope="module")
def compared(records):
    return frictionid.compare(FMM, ["viscous_coulomb", "coulomb"], records)


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def test_a_fit_is_still_its_dict(fitted):
    assert isinstance(fitted, dict) and isinstance(fitted, frictionid.FitResult)
    (mu,) = fitted["parameters"]
    assert mu["name"] == "mu" and fitted["model"] == "coulomb"
    assert set(fitted["records"][0]) >= {"time", "measured", "fitted"}
    # A plain dict of it serializes as report.json does once the arrays are left out.
    plain = {k: v for k, v in fitted.items() if k != "records"}
    assert json.loads(json.dumps(plain)) == plain
    # It travels to worker processes whole (pickle), text included.
    copy = pickle.loads(pickle.dumps(fitted))
    assert copy.report() == fitted.report() and copy["parameters"] == fitted["parameters"]


def test_params_is_a_table_of_the_fitted_truth(fitted):
    params = fitted.params
    assert isinstance(params, pd.DataFrame)
    assert list(params.columns) == COLUMNS and list(params.index) == ["mu"]
    assert params.index.name == "parameter"
    row = params.loc["mu"]
    assert abs(row["value"] / MU - 1.0) < 2e-3
    assert row["ci_low"] < MU < row["ci_high"] or abs(row["value"] - MU) < 4 * row["std_error"]
    assert row["std_error"] > 0 and row["unit"] == "1" and row["status"] == "fitted"
    # The table holds the dict's numbers, not copies rounded for print.
    (mu,) = fitted["parameters"]
    assert row["value"] == mu["value"] and [row["ci_low"], row["ci_high"]] == mu["ci95"]


def test_a_parameter_held_fixed_says_so(records):
    out = frictionid.fit(FMM, {"type": "viscous_coulomb", "mu": 0.2, "viscous": 0.0}, records, {"free": ["mu"]})
    params = out.params
    assert params.loc["viscous", "status"] == "fixed" and params.loc["viscous", "value"] == 0.0
    assert params.loc["mu", "status"] == "fitted" and abs(params.loc["mu", "value"] / MU - 1) < 2e-3
    assert params.loc["viscous", "unit"] == "N s/m"


def test_report_is_the_cli_summary_with_the_parameters(fitted):
    text = fitted.report()
    (line,) = [l for l in text.splitlines() if l.startswith("mu ")]
    value = fitted["parameters"][0]["value"]
    assert f"{value:.5f}"[:6] in line and "fitted" in line
    assert "coulomb" in text and "AIC" in text
    markdown = fitted.report("markdown")
    assert markdown.startswith("# frictionid fit") and "| mu |" in markdown
    with pytest.raises(ValueError, match="one of `text`, `markdown`"):
        fitted.report("pdf")


def test_report_matches_what_the_cli_prints(tmp_path):
    binary = os.environ.get("FRICTIONID_BIN")
    if not binary:
        pytest.skip("FRICTIONID_BIN names no CLI binary")
    config = FIXTURES / "fmm-fit.toml"
    printed = subprocess.run(
        [binary, "fit", config, "--out", tmp_path / "cli"], capture_output=True, text=True, check=True
    ).stdout
    result = frictionid.run(config)
    assert printed == result.report() + f"wrote {tmp_path / 'cli'}\n"


def test_plot_of_a_fit_draws_measured_and_fitted_per_record(fitted):
    fig = fitted.plot()
    assert isinstance(fig, matplotlib.figure.Figure)
    assert len(fig.axes) == len(fitted["records"]) == 2
    for ax, record in zip(fig.axes, fitted["records"]):
        measured, fit_line = ax.get_lines()[:2]
        assert np.array_equal(measured.get_ydata(), record["measured"])
        assert np.array_equal(fit_line.get_ydata(), record["fitted"])
    # The time axis is cut to the motion: the 10 mm release rests after three half-cycles of
    # pi/wd = 0.227 s each (the 22 mm one still moves at the record's end).
    first = fig.axes[0].get_xlim()[1]
    assert 3 * 0.227 < first < 0.9


def test_notebook_view_shows_the_verdict_and_the_table(fitted):
    page = fitted._repr_html_()
    assert "<table" in page and "<td>mu</td>" in page
    assert fitted.verdict and html.escape(fitted.verdict) in page
    assert fitted.status in ("pass", "warn", "fail")


def test_compare_recommends_the_simpler_true_law(compared):
    assert isinstance(compared, frictionid.CompareResult) and compared["command"] == "compare"
    assert set(compared.results) == {"coulomb", "viscous_coulomb"}
    assert compared["recommended"] == "coulomb"
    best = compared.recommended
    assert isinstance(best, frictionid.FitResult) and best["model"] == "coulomb"
    assert abs(best.params.loc["mu", "value"] / MU - 1) < 2e-3
    # The comparison's own table is the recommended law's.
    assert compared.params.equals(best.params)
    table = compared.ranking_table
    assert list(table.index) == [f["model"] for f in compared["ranking"]]
    assert table["recommended"].tolist() == [m == "coulomb" for m in table.index]
    assert compared.verdict.startswith("recommended: `coulomb`")
    assert "coulomb" in compared.report() and "viscous_coulomb" in compared.report()
    # Each law's own report is a fit report of that law.
    assert "| viscous |" in compared.results["viscous_coulomb"].report("markdown")
    assert "use coulomb" in compared._repr_html_()
    # Still the dict it was, export included.
    assert "#define FID_MU " in compared.export("c")


def test_compare_plots_one_panel_per_law_recommended_first(compared):
    fig = compared.plot()
    assert len(fig.axes) == 2
    assert fig.axes[0].get_title() == "coulomb (recommended)"
    assert fig.axes[1].get_title() == "viscous_coulomb"
    per_record = compared.plot("recommended")
    assert len(per_record.axes) == 2
    residuals = compared.plot(residuals=True)
    law = compared.results["viscous_coulomb"]
    for line, record in zip(residuals.axes[1].get_lines(), law["records"]):
        assert np.array_equal(line.get_ydata(), record["measured"] - record["fitted"])
    # One scale for every law: their residuals compare at a glance.
    assert residuals.axes[0].get_ylim() == residuals.axes[1].get_ylim()
    with pytest.raises(ValueError, match="no fitted law `lugre`"):
        compared.plot("lugre")


def test_simulate_result_tables_its_model_and_plots_the_trajectory():
    t = np.linspace(0.0, 1.0, 1001)
    sim = frictionid.simulate(FMM, {"type": "coulomb", "mu": MU}, 0.014, t)
    assert isinstance(sim, frictionid.SimulateResult) and sim["half_cycles"] > 0
    params = sim.params
    assert list(params.columns) == COLUMNS
    assert params.loc["mu", "value"] == MU and params.loc["mu", "status"] == "given"
    assert params.loc["mu", "unit"] == "1" and np.isnan(params.loc["mu", "std_error"])
    assert "final displacement" in sim.report()
    fig = sim.plot()
    assert len(fig.axes) == 3
    assert np.array_equal(fig.axes[0].get_lines()[0].get_ydata(), sim["x"])
    assert np.array_equal(fig.axes[2].get_lines()[0].get_ydata(), sim["force"])
    assert "<td>mu</td>" in sim._repr_html_()


def test_energy_result_tables_each_record_against_the_reference(records):
    out = frictionid.energy(FMM, records, model={"type": "coulomb", "mu": MU})
    assert isinstance(out, frictionid.EnergyResult)
    table = out.record_table
    assert list(table.index) == ["x10mm", "x22mm"]
    assert np.allclose(table["reference"], MU * 14.5, rtol=1e-12)
    # The Eq. 7 force of a Coulomb release is its level, within the noise.
    assert np.allclose(table["half_cycle_mean"], MU * 14.5, rtol=0.02)
    assert out.params.loc["mu", "value"] == MU
    assert "reference" in out.report()
    fig = out.plot()
    assert len(fig.axes) == 2
    eq7, model = fig.axes[0].get_lines()[:2]
    assert np.array_equal(eq7.get_ydata(), out["records"][0]["friction"], equal_nan=True)
    assert model.get_zorder() > eq7.get_zorder()


def test_run_returns_what_fit_returns_and_writes_nothing(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    before = sorted(p.name for p in FIXTURES.iterdir())
    result = frictionid.run(FIXTURES / "fmm-fit.toml")
    assert list(tmp_path.iterdir()) == []
    assert sorted(p.name for p in FIXTURES.iterdir()) == before
    assert isinstance(result, frictionid.FitResult)
    records = []
    for name, x0 in [("x10mm.csv", 0.010), ("x14mm.csv", 0.014), ("x22mm.csv", 0.022)]:
        data = np.loadtxt(FIXTURES / name, delimiter=",", skiprows=2)
        records.append({"name": name, "t": data[:, 0], "v": data[:, 1], "x0": x0})
    direct = frictionid.fit(FMM, {"type": "coulomb", "mu": 0.2}, records,
                            {"free": ["mu"], "bounds": {"mu": [0.0, 1.0]}})
    assert result["parameters"] == direct["parameters"]
    for a, b in zip(result["records"], direct["records"]):
        for key in ("time", "measured", "fitted"):
            assert np.array_equal(a[key], b[key])
    assert result.params.equals(direct.params)


def test_run_writes_the_cli_folder_only_where_asked(tmp_path):
    result = frictionid.run(FIXTURES / "fmm-energy.toml", "energy", tmp_path / "energy")
    assert isinstance(result, frictionid.EnergyResult)
    written = json.loads((tmp_path / "energy" / "report.json").read_text())
    assert [r["mean_abs_force"] for r in written["records"]] == [
        r["mean_abs_force"] for r in result["records"]
    ]
    assert (tmp_path / "energy" / "report.html").exists()
    with pytest.raises(ValueError, match="unknown command `fitt`"):
        frictionid.run(FIXTURES / "fmm-fit.toml", "fitt")


def test_the_core_works_without_pandas_and_matplotlib():
    script = (
        "import sys\n"
        "sys.modules['pandas'] = None\n"
        "sys.modules['matplotlib'] = None\n"
        "import numpy as np, frictionid\n"
        f"osc = {FMM!r}\n"
        "sim = frictionid.simulate(osc, {'type': 'coulomb', 'mu': 0.24}, 0.014, np.linspace(0, 1, 501))\n"
        "assert sim['half_cycles'] > 0 and 'final displacement' in sim.report()\n"
        "assert '<td>mu</td>' in sim._repr_html_()\n"
        "for use in (lambda: sim.params, sim.plot):\n"
        "    try:\n"
        "        use()\n"
        "    except ImportError as e:\n"
        "        assert 'frictionid[notebook]' in str(e)\n"
        "    else:\n"
        "        raise AssertionError('no ImportError')\n"
        "print('ok')\n"
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "ok"


def test_a_rotary_result_speaks_in_angles_and_torques():
    axis = {"axis": "rotary", "inertia": 0.01, "damping": 0.001, "stiffness": 2.0, "normal_force": 10.0}
    sim = frictionid.simulate(axis, {"type": "viscous_coulomb", "mu": 0.01, "viscous": 0.001}, 0.5,
                              np.linspace(0.0, 2.0, 201))
    assert sim.params.loc["viscous", "unit"] == "N m s/rad"
    labels = [ax.get_ylabel() for ax in sim.plot().axes]
    assert labels == ["angle [rad]", "angular velocity [rad/s]", "friction torque [N m]"]
