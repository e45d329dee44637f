"""The module computes what the command line computes: a simulation's arrays and a limit
cycle equal `stirling simulate --json` to 1e-12, and a fit and a diagnosis of one record give
the command line's numbers (timings aside)."""

import csv

import numpy as np

import stirling
from conftest import close

SECONDS = {"seconds"}  # wall-clock fields differ between runs


def drop_timings(v):
    if isinstance(v, dict):
        return {k: drop_timings(x) for k, x in v.items() if k not in SECONDS}
    if isinstance(v, list):
        return [drop_timings(x) for x in v]
    return v


def test_simulation_arrays_equal_the_command_lines(cli, tmp_path):
    out = tmp_path / "run.csv"
    js = cli("simulate", "nsection", "--n", "2", "--t-end", "0.3", "--samples", "301", "--json", "--out", str(out))
    sim = stirling.load("nsection", n=2).simulate(0.3, samples=301)
    close(sim.final_state.tolist(), js["final_state"], 1e-12, "final_state")
    assert sim.stats.raw["steps"] == js["steps"] and sim.stats.raw["rhs_calls"] == js["rhs_calls"]
    with open(out) as f:
        rows = [r for r in csv.reader(f)]
    assert rows[0] == ["t"] + sim.state_names
    table = np.array(rows[1:], dtype=float)
    assert table.shape == (301, 1 + sim.x.shape[1])
    # the CSV holds 11 significant digits
    np.testing.assert_allclose(table[:, 0], sim.t, rtol=1e-10, atol=0)
    np.testing.assert_allclose(table[:, 1:], sim.x, rtol=1e-10, atol=1e-300)
    # the last sample is interpolated at t_end; the final state is the solver's own
    np.testing.assert_allclose(sim.x[-1], sim.final_state, rtol=1e-6)


def test_limit_cycle_equals_the_command_lines(cli):
    js = cli("simulate", "cv1", "--t-end", "20", "--limit-cycle", "--json")
    lc = stirling.load("cv1").limit_cycle(20.0)
    close(drop_timings(lc.summary.raw), drop_timings(js), 1e-12, "limit cycle")
    assert abs(lc.power - js["power_w"]) <= 1e-12 * abs(js["power_w"])
    np.testing.assert_allclose(lc.floquet.real, [f[0] for f in js["floquet"]], rtol=1e-12, atol=1e-15)


def record(tmp_path, **kw):
    """A short rig record of cv1, written and read back as the command line reads it."""
    rec = stirling.rig("cv1", settle=3.0, t_end=1.0, seed=3, **kw)
    path = tmp_path / "rec.csv"
    rec.write_csv(path)
    return path, stirling.read_csv(path)


def test_fit_gives_the_command_lines_numbers(cli, tmp_path):
    path, rec = record(tmp_path)
    js = cli("fit", "cv1", "--data", str(path), "--json")
    fit = stirling.load("cv1").fit(rec)
    close(drop_timings(fit.raw), drop_timings(js), 1e-12, "fit")
    kd = fit.estimates["kd"]
    assert kd.covers(650.74) and kd.std_error > 0
    cov = fit.stage1.covariance
    assert np.allclose(cov, cov.T) and np.all(np.diag(cov) > 0)


def test_diagnosis_gives_the_command_lines_numbers(cli, tmp_path):
    path, rec = record(tmp_path, effects={"sensor_lag": 0.002})
    js = cli("diagnose", "cv1", "--data", str(path), "--json")
    d = stirling.load("cv1").diagnose(rec)
    close(drop_timings(d.raw), drop_timings(js), 1e-12, "diagnosis")
    assert d.verdict.verdict == js["verdict"]["verdict"] == "effect"
    assert d.effect == "sensor_lag"
