"""frictionid from Python, against independent oracles (closed forms, fixture truth, the CLI)."""

import json
import math
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import frictionid

ROOT = Path(__file__).resolve().parents[2]
FIXTURES = ROOT / "fixtures"
FMM = {"mass": 10.391, "damping": 0.275, "stiffness": 1982.0, "normal_force": 14.5}
PAPER = dict(FMM, normal_force=10.391 * 9.81)


def coulomb_rest(osc, mu, x0):
    """Rest position and half-cycles of a viscously damped oscillator with Coulomb friction,
    released from rest: each half-cycle is a damped oscillation about +-F/k lasting pi/wd."""
    m, c, k = osc["mass"], osc["damping"], osc["stiffness"]
    force = mu * osc["normal_force"]
    w = math.sqrt(k / m)
    zeta = c / (2.0 * math.sqrt(k * m))
    wd = w * math.sqrt(1.0 - zeta**2)
    ratio = math.exp(-zeta * w * math.pi / wd)
    x, half_cycles, t = x0, 0, 0.0
    while abs(k * x) > force:
        centre = math.copysign(force / k, x)
        x = centre - (x - centre) * ratio
        half_cycles += 1
        t += math.pi / wd
    return x, half_cycles, t


def fixture_records(as_type=np.asarray):
    records = []
    for name, x0 in [("x10mm.csv", 0.010), ("x14mm.csv", 0.014), ("x22mm.csv", 0.022)]:
        data = np.loadtxt(FIXTURES / name, delimiter=",", skiprows=2)
        records.append({"name": name, "t": as_type(data[:, 0]), "v": as_type(data[:, 1]), "x0": x0})
    return records


def test_models_match_the_cli_listing():
    models = frictionid.models()
    names = [m["name"] for m in models]
    assert "coulomb" in names and "lugre" in names
    coulomb = models[names.index("coulomb")]
    assert [p["name"] for p in coulomb["parameters"]] == ["mu"]
    # On a rotary axis, as `frictionid models --axis rotary` lists them: N m s/rad, no N s/m.
    units = lambda listing: {p["unit"] for m in listing for p in m["parameters"]}
    rotary = frictionid.models(axis="rotary")
    assert "N m s/rad" in units(rotary) and "N s/m" not in units(rotary)
    assert "N s/m" in units(models) and not any("rad" in u for u in units(models))
    binary = os.environ.get("FRICTIONID_BIN")
    if binary:
        cli = subprocess.run([binary, "models", "--json", "--axis", "rotary"], capture_output=True, check=True)
        assert json.loads(cli.stdout) == rotary
    with pytest.raises(ValueError, match=r"models: unknown axis `angular`: `linear` or `rotary`"):
        frictionid.models(axis="angular")


def test_simulate_reproduces_the_exact_coulomb_rest_position():
    rest, half_cycles, rest_time = coulomb_rest(PAPER, 0.24, 0.140)
    assert half_cycles == 6
    t = np.arange(0, 2001) * 1e-3
    out = frictionid.simulate(PAPER, {"type": "coulomb", "mu": 0.24}, 0.140, t)
    assert abs(out["final_displacement"] - rest) < 1e-9
    assert abs(out["final_displacement"] - (-9.29682614e-3)) < 1e-9
    assert out["half_cycles"] == half_cycles
    assert abs(out["rest_time"] - rest_time) < 1e-6
    for key in ["t", "x", "v", "a", "force", "energy"]:
        assert isinstance(out[key], np.ndarray) and out[key].dtype == np.float64
        assert out[key].shape == t.shape
    assert np.array_equal(out["t"], t)
    assert abs(out["x"][-1] - rest) < 1e-9
    assert set(["events", "stats", "samples"]) <= set(out)


def test_simulate_accepts_lists_and_float32_times():
    model = {"type": "coulomb", "mu": 0.24}
    t64 = np.linspace(0.0, 1.0, 101)
    reference = frictionid.simulate(FMM, model, 0.014, t64)
    from_list = frictionid.simulate(FMM, model, 0.014, t64.tolist())
    assert np.array_equal(from_list["v"], reference["v"])
    t32 = np.linspace(0.0, 1.0, 101, dtype=np.float32)
    from_f32 = frictionid.simulate(FMM, model, 0.014, t32)
    assert np.array_equal(from_f32["t"], t32.astype(np.float64))
    assert from_f32["v"].dtype == np.float64


def test_lugre_has_internal_states():
    out = frictionid.simulate(FMM, {"type": "lugre"}, 0.014, np.linspace(0, 0.5, 51))
    assert len(out["states"]) == 1 and np.array_equal(out["states"][0], out["z1"])


def test_fit_recovers_the_fixture_truth():
    out = frictionid.fit(FMM, {"type": "coulomb", "mu": 0.2}, fixture_records(), {"free": ["mu"]})
    (mu,) = [p for p in out["parameters"] if p["name"] == "mu"]
    assert abs(mu["value"] - 0.24) / 0.24 < 1e-3
    assert mu["std_error"] > 0 and mu["ci95"][0] < mu["value"] < mu["ci95"][1]
    assert out["converged"] and len(out["records"]) == 3
    record = out["records"][1]
    assert record["fitted"].shape == record["measured"].shape == record["time"].shape
    assert record["file"] == "x14mm.csv"


def test_fit_accepts_float32_and_list_records():
    model = {"type": "coulomb", "mu": 0.2}
    base = frictionid.fit(FMM, model, fixture_records()[:1])
    f32 = frictionid.fit(FMM, model, fixture_records(lambda a: a.astype(np.float32))[:1])
    lists = frictionid.fit(FMM, model, fixture_records(lambda a: a.tolist())[:1])
    assert lists["parameters"] == base["parameters"]
    assert abs(f32["parameters"][0]["value"] - base["parameters"][0]["value"]) < 1e-4


def strip_series(value):
    """A report without arrays (numpy in Python, `series` lists in report.json), timings and
    the source's name (the parts that differ)."""
    if isinstance(value, dict):
        return {
            k: strip_series(v)
            for k, v in value.items()
            if not isinstance(v, np.ndarray) and k not in ("wall_time_s", "config", "files", "series")
        }
    if isinstance(value, list):
        return [strip_series(v) for v in value]
    return value


def test_fit_of_three_records_is_identical_to_the_cli(tmp_path):
    cli = frictionid.run(FIXTURES / "fmm-fit.toml", "fit", tmp_path / "run")
    # The folder `out` names is the CLI's; the result is the same report with report.json's
    # series as arrays, and no files of its own.
    written = json.loads((tmp_path / "run" / "report.json").read_text())
    assert strip_series(written) == strip_series(cli)
    assert "report.html" in written["files"] and cli["files"] == []
    for on_disk, returned in zip(written["records"], cli["records"]):
        assert {"time", "measured", "fitted"} <= set(on_disk["series"])
        for key, values in on_disk["series"].items():
            assert np.array_equal(np.asarray(values, dtype=float), returned[key], equal_nan=True)
    py = frictionid.fit(
        FMM, {"type": "coulomb", "mu": 0.2}, fixture_records(),
        {"free": ["mu"], "bounds": {"mu": [0.0, 1.0]}},
    )
    assert strip_series(py) == strip_series(cli)
    # The CLI binary itself, when named (.ci/run names the one `cargo test` just built).
    binary = os.environ.get("FRICTIONID_BIN")
    if binary:
        subprocess.run(
            [binary, "fit", FIXTURES / "fmm-fit.toml", "--quiet", "--out", tmp_path / "bin"],
            check=True,
        )
        from_binary = json.loads((tmp_path / "bin" / "report.json").read_text())
        assert strip_series(from_binary) == strip_series(py)


def test_compare_and_energy_return_reports():
    records = fixture_records()[1:2]
    out = frictionid.compare(FMM, ["coulomb", {"type": "stribeck"}], records)
    assert out["command"] == "compare" and out["ranking"][0]["model"] in ("coulomb", "stribeck")
    assert "fitted" in out["ranking"][0]["records"][0]
    energy = frictionid.energy(FMM, records, model={"type": "coulomb", "mu": 0.24})
    (record,) = energy["records"]
    assert abs(record["reference"] - 0.24 * 14.5) < 1e-9
    assert record["friction"].shape == record["time"].shape


def test_bad_input_raises_value_error_with_the_cli_message(tmp_path):
    with pytest.raises(ValueError, match=r"did you mean `coulomb`"):
        frictionid.simulate(FMM, {"type": "colomb"}, 0.01, [0.0, 0.1])
    with pytest.raises(ValueError, match=r"\[oscillator\]: simulate needs .*`mass`, `stiffness`, `normal_force` not given"):
        frictionid.simulate({"damping": 0.2}, "coulomb", 0.01, [0.0, 0.1])
    with pytest.raises(ValueError, match=r"3 time stamps but 2 velocities"):
        frictionid.fit(FMM, "coulomb", [{"t": [0.0, 0.1, 0.2], "v": [0.0, 0.1], "x0": 0.01}])
    with pytest.raises(ValueError, match=r"record `record 1`: missing `x0`.*velocity-domain fit"):
        frictionid.fit(FMM, "coulomb", [{"t": [0.0, 0.1], "v": [0.0, 0.1]}])
    with pytest.raises(ValueError, match=r"unknown key `velocty`"):
        frictionid.fit(FMM, "coulomb", [{"t": [0.0, 0.1], "velocty": [0.0, 0.1], "x0": 0.01}])
    # The same mistake in a config file and in a dict: the CLI's message, after the file name.
    config = (FIXTURES / "fmm-fit.toml").read_text().replace('free = ["mu"]', 'free = ["mu_"]')
    path = tmp_path / "bad.toml"
    path.write_text(config.replace('file = "', f'file = "{FIXTURES}/'))
    with pytest.raises(ValueError) as from_run:
        frictionid.run(path, "fit", tmp_path / "out")
    with pytest.raises(ValueError) as from_dict:
        frictionid.fit(FMM, "coulomb", fixture_records(), {"free": ["mu_"]})
    assert "(did you mean `mu`?)" in str(from_dict.value)
    assert str(from_run.value).endswith(str(from_dict.value))


def test_x0_comes_from_the_dict_or_the_first_displacement_sample():
    # The configuration's rule: a record with a displacement channel and no `x0` is released
    # from its first sample; a velocity-only record needs `x0` only where it is simulated.
    t = np.linspace(0.0, 1.5, 1501)
    sim = frictionid.simulate(FMM, {"type": "coulomb", "mu": 0.24}, 0.014, t)
    rng = np.random.default_rng(3)
    x = sim["x"] + rng.normal(0.0, 5e-7, t.size)
    v = sim["v"] + rng.normal(0.0, 2e-4, t.size)
    pair = {"t": t, "x": x, "v": v}
    fit = frictionid.fit(FMM, "coulomb", [pair], {"free": ["mu"]})
    assert fit["records"][0]["x0"] == x[0]
    assert abs(fit["parameters"][0]["value"] / 0.24 - 1.0) < 1e-3
    given = frictionid.fit(FMM, "coulomb", [dict(pair, x0=0.014)], {"free": ["mu"]})
    assert given["records"][0]["x0"] == 0.014
    with pytest.raises(ValueError, match=r"missing `x0` .*: a velocity-domain fit"):
        frictionid.fit(FMM, "coulomb", [{"t": t, "v": sim["v"]}])


def test_a_fit_without_a_normal_force_gives_the_level_in_newtons():
    # No normal force in the dict nor in the records: the Coulomb level is the friction
    # force itself, the fixture's mu N = 0.24 * 14.5 N.
    stage = {k: v for k, v in FMM.items() if k != "normal_force"}
    fit = frictionid.fit(stage, "coulomb", fixture_records(), {"free": ["mu"]})
    (mu,) = fit["parameters"]
    assert mu["unit"] == "N"
    assert abs(mu["value"] / (0.24 * 14.5) - 1.0) < 5e-3


def test_a_failed_computation_raises_fit_error():
    assert issubclass(frictionid.FitError, Exception)
    assert not issubclass(frictionid.FitError, ValueError)
    t = np.linspace(0.0, 1.0, 1001)
    with pytest.raises(frictionid.FitError, match=r"^integration failed at t = .* more than max_steps = 3 steps$"):
        # Named: the default integrator (auto) solves Coulomb friction in closed form, with no
        # steps to run out of.
        frictionid.simulate(FMM, "coulomb", 0.01, t, options={"method": "dopri5", "max_steps": 3})
    with pytest.raises(ValueError, match=r"record `record 1`: x0 and v0 must be finite"):
        frictionid.fit(FMM, "coulomb", [{"t": t, "v": np.zeros_like(t), "x0": float("nan")}])


def test_ctrl_c_interrupts_a_long_fit():
    import signal
    import sys
    import time

    script = (
        "import numpy as np, frictionid\n"
        f"osc = {FMM!r}\n"
        "t = np.linspace(0, 2, 2001)\n"
        "recs = [{'t': t, 'v': frictionid.simulate(osc, 'coulomb', x0, t)['v'], 'x0': x0}"
        " for x0 in (0.01, 0.014, 0.022)]\n"
        "print('ready', flush=True)\n"
        "try:\n"
        "    frictionid.fit(osc, {'type': 'lugre'}, recs, {'options': {'multistart': 8}})\n"
        "    print('finished')\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted')\n"
    )
    proc = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    assert proc.stdout.readline().strip() == "ready"
    time.sleep(0.5)
    proc.send_signal(signal.SIGINT)
    out, _ = proc.communicate(timeout=60)
    assert out.strip() in ("interrupted", "finished")
    assert proc.returncode == 0


def test_force_domain_fit_from_arrays_recovers_a_coulomb_law():
    """A tribometer-like record from Python arrays: the imposed motion x = A sin(w t), a
    measured friction force mu N sgn(v) plus a load-cell offset and a sampled normal force.
    The force-domain fit needs only N (no m, c, k) and returns mu and the offset exactly."""
    t = np.arange(0.0, 2.0, 1e-3)
    x = 1e-3 * np.sin(2.0 * np.pi * 1.5 * t)
    v = 1e-3 * 2.0 * np.pi * 1.5 * np.cos(2.0 * np.pi * 1.5 * t)
    normal = 5.0 + 0.5 * np.sin(2.0 * np.pi * 0.25 * t)
    mu, offset = 0.31, 0.02
    force = mu * normal * np.sign(v) + offset
    record = {"name": "tribo", "t": t, "x": x, "v": v, "force": force, "normal_force": normal, "x0": 0.0}
    out = frictionid.fit(
        {}, {"type": "coulomb", "mu": 0.2}, [record],
        {"options": {"domain": "force", "force_offset": True}},
    )
    (param,) = [p for p in out["parameters"] if p["name"] == "mu"]
    assert abs(param["value"] / mu - 1.0) < 1e-6


def test_a_named_channel_of_a_record_dict_feeds_a_law_beyond_speed():
    """A gearbox's load torque given as a named channel: coulomb_load recovers its level and
    load coefficient exactly from F = (2 + 0.03 |load|) sgn(v) + 5 v, its results' parameter
    table carries mu_load, and a record without the channel is refused naming both."""
    t = np.arange(0.0, 10.0, 5e-3)
    v = 0.5 * np.sin(2.0 * np.pi * t / 3.0 + 0.1)
    load = 30.0 * np.sin(2.0 * np.pi * 0.13 * t) + 10.0 * np.sin(2.0 * np.pi * 0.41 * t + 1.0)
    force = (2.0 + 0.03 * np.abs(load)) * np.sign(v) + 5.0 * v
    record = {"name": "joint", "t": t, "v": v, "force": force, "channels": {"load": load}}
    model = {"type": "coulomb_load", "mu": 1.5, "mu_load": 0.01, "viscous": 3.0}
    options = {"options": {"domain": "force"}}
    out = frictionid.fit({}, model, [record], options)
    values = {p["name"]: p["value"] for p in out["parameters"]}
    assert abs(values["mu_load"] / 0.03 - 1.0) < 1e-6
    assert abs(values["mu"] / 2.0 - 1.0) < 1e-6
    del record["channels"]
    with pytest.raises(ValueError, match=r"record `joint`: the law reads channel `load`"):
        frictionid.fit({}, model, [record], options)


def test_channel_noise_keys_weight_a_vibrometer_accelerometer_fit():
    """A vibrometer + accelerometer record with the sensors' noise levels given as
    `velocity_noise` and `acceleration_noise`: the fit compares both channels and reports
    each with the noise it was given (not an estimate), and the truth mu = 0.24 is recovered."""
    t = np.arange(0, 2001) * 1e-3
    sim = frictionid.simulate(FMM, {"type": "coulomb", "mu": 0.24}, 0.014, t)
    rng = np.random.default_rng(5)
    record = {
        "name": "pair", "t": t, "x0": 0.014,
        "v": sim["v"] + rng.normal(0.0, 2e-4, t.size),
        "a": sim["a"] + rng.normal(0.0, 5e-3, t.size),
        "velocity_noise": 2e-4, "acceleration_noise": 5e-3,
    }
    out = frictionid.fit(FMM, {"type": "coulomb", "mu": 0.2}, [record])
    channels = out["records"][0]["channels"]
    assert [(c["channel"], c["noise"]) for c in channels] == [("velocity", 2e-4), ("acceleration", 5e-3)]
    (mu,) = [p["value"] for p in out["parameters"] if p["name"] == "mu"]
    assert abs(mu / 0.24 - 1.0) < 1e-2
    with pytest.raises(ValueError, match="`acceleration_noise` must be a number > 0"):
        frictionid.fit(FMM, {"type": "coulomb"}, [dict(record, acceleration_noise=-1.0)])
    with pytest.raises(ValueError, match="unknown key `speed_noise`"):
        frictionid.fit(FMM, {"type": "coulomb"}, [dict(record, speed_noise=1.0)])


def test_a_fit_exports_its_law_as_source():
    """The exported Python law is the fitted Coulomb law, mu n sgn(v), evaluated at the
    fitted mu (the closed form is the oracle); the C and Rust texts name the same constant."""
    result = frictionid.fit(FMM, {"type": "coulomb", "mu": 0.2}, fixture_records())
    mu = result["model_parameters"]["mu"]
    namespace = {}
    exec(result.export("python"), namespace)
    law = namespace["Law"]()
    for v in (-0.3, -1e-6, 0.0, 2e-3, 0.1):
        expected = mu * 14.5 * ((v > 0) - (v < 0))
        assert law.force(v, 14.5) == pytest.approx(expected, rel=1e-15, abs=0.0)
    forces = namespace["replay"]([0.0, 0.001, 0.002], [0.1, 0.2, -0.1], 14.5)
    assert forces == pytest.approx([mu * 14.5, mu * 14.5, -mu * 14.5], rel=1e-15)
    c = result.export("c", prefix="axis_")
    assert "void axis_update(axis_state *s, double v, double n, double dt)" in c
    assert "#define AXIS_MU " in c
    assert "pub struct Law" in result.export("rust")
    with pytest.raises(ValueError, match="fortran"):
        result.export("fortran")


def test_plan_adds_the_information_of_the_recommended_records():
    """A Coulomb coefficient's information adds over records: the recommended pair's
    standard error is (sum 1/s_i^2)^-1/2 of its two candidates'."""
    plan = {
        "choose": 2,
        "velocity_noise": 2e-4,
        "candidates": [
            {"x0": 0.004, "duration": 1.0},
            {"x0": 0.010, "duration": 1.0},
            {"x0": 0.022, "duration": 1.0, "velocity_noise": 1e-3},
        ],
    }
    report = frictionid.plan(FMM, {"type": "coulomb", "mu": 0.2}, plan)
    stds = [c["predicted_std"]["mu"] for c in report["candidates"]]
    chosen = report["recommended"]
    assert len(chosen) == 2
    combined = sum(stds[i] ** -2 for i in chosen) ** -0.5
    assert math.isclose(report["predicted_std"]["mu"], combined, rel_tol=1e-9)
    with pytest.raises(ValueError, match="choose = 4"):
        frictionid.plan(FMM, {"type": "coulomb", "mu": 0.2}, {**plan, "choose": 4})
