"""The module's objects: models and parameters with units, the equations and their Jacobians
(checked against finite differences), linear analysis, runs, limit cycles (the work equals the
closed integral of P dV over the p-V loops returned), records and pandas, sweeps, readable
reprs, and the type stub naming every native function."""

import ast
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import stirling
from stirling import _native


def test_models_and_effects_are_listed():
    names = [m.name for m in stirling.models()]
    assert names[:4] == ["schmidt", "cv1", "cv2", "nsection"]
    assert "order8" in stirling.models()[3].aliases
    fx = {e.name: e for e in stirling.effects()}
    assert "leak" in fx and fx["leak"].params[0]["unit"]


def test_parameters_carry_units_and_the_model_is_immutable():
    m = stirling.load("nsection", n=2)
    p = m.parameters
    assert p["Th"].unit == "K" and p["Th"].value == p["Th"].default == 600.0
    assert p["kd"].unit == "N/m"
    hot = m.with_params(Th=650.0)
    assert hot.params["Th"] == 650.0 and m.params["Th"] == 600.0
    assert hot.with_params({"Th": 600.0}) == m
    with pytest.raises(ValueError):
        m.param_vector[0] = 1.0
    assert m.n_states == 12 and m.state_names[:2] == ["x", "v"]
    assert stirling.load("order8", closure="frozen").n_states == 8
    assert "Th" in repr(hot) and "nsection" in repr(hot)


def fd_jacobian(f, x, h=1e-6):
    """Central differences, each step relative to its entry's size (masses are ~1e-5 kg,
    pressures ~1e5 Pa)."""
    f0 = f(x)
    J = np.zeros((f0.size, x.size))
    for j in range(x.size):
        step = h * (abs(x[j]) + 1e-6)
        xp, xm = x.copy(), x.copy()
        xp[j] += step
        xm[j] -= step
        J[:, j] = (f(xp) - f(xm)) / (2 * step)
    return J


@pytest.mark.parametrize("name", ["schmidt", "cv1", "cv2", "nsection"])
def test_jacobians_match_finite_differences(name):
    m = stirling.load(name)
    x = m.simulate(0.05, samples=2).final_state  # a state in motion, away from rest
    f, J = m.rhs_and_jacobian(x)
    np.testing.assert_array_equal(f, m.rhs(x))
    np.testing.assert_allclose(J, m.jacobian(x), rtol=1e-12, atol=0)
    J_fd = fd_jacobian(m.rhs, x)
    scale = np.abs(J).max(axis=1, keepdims=True) + 1e-30
    assert np.max(np.abs(J - J_fd) / scale) < 1e-5
    p0 = m.param_vector.copy()
    Jp = m.param_jacobian(x)
    Jp_fd = fd_jacobian(lambda p: m._m.rhs(p, x, 0.0), p0)
    scale_p = np.abs(Jp).max(axis=1, keepdims=True) + 1e-30
    assert np.max(np.abs(Jp - Jp_fd) / scale_p) < 1e-4


def test_equilibrium_and_poles_agree_with_the_linearization():
    m = stirling.load("order8")
    eq = m.equilibrium()
    assert eq.scaled_residual < 1e-8
    f = m.rhs(eq.x)
    assert np.max(np.abs(f) / (np.abs(m.jacobian(eq.x)) @ np.abs(eq.x) + 1e-30)) < 1e-8
    poles = m.poles()
    lin = m.linearize()
    np.testing.assert_allclose(np.sort_complex(poles.values), np.sort_complex(lin.poles), rtol=1e-10)
    assert poles.rhp_count == lin.rhp_count == 2
    assert lin.channel == "piston" and lin.margins.gain_db is not None
    assert "RHP" in repr(lin) or "rhp" in repr(lin).lower()


def test_simulation_is_named_and_conserves_the_gas():
    m = stirling.load("nsection", n=2)
    s = m.simulate(0.2, samples=201)
    assert s.t.shape == (201,) and s.x.shape == (201, 12)
    np.testing.assert_array_equal(s["x"], s.x[:, 0])
    assert set(s.states) == set(m.state_names)
    masses = [m.energy(x)["gas_mass"] for x in s.x[::50]]
    assert np.ptp(masses) <= 1e-12 * masses[0]
    df = s.to_pandas()
    assert list(df.columns) == m.state_names and df.index.name == "t"


def test_limit_cycle_work_is_the_closed_integral_of_p_dv():
    lc = stirling.load("order8").limit_cycle()
    total = 0.0
    for name, (v, p) in lc.pv.items():
        w = np.sum(0.5 * (p[1:] + p[:-1]) * np.diff(v))
        np.testing.assert_allclose(w, lc.work_per_vessel[name], rtol=1e-3, atol=1e-6)
        total += lc.work_per_vessel[name]
    np.testing.assert_allclose(total, lc.work, rtol=1e-12)
    np.testing.assert_allclose(lc.power, lc.work * lc.frequency_hz, rtol=1e-12)
    assert lc.work > 0 and lc.route == "dense"
    # one multiplier is 1 (the phase along the orbit); the cycle is stable
    assert np.min(np.abs(lc.floquet - 1.0)) < 1e-5
    assert lc.orbit.shape[0] == lc.orbit_t.shape[0] and np.allclose(lc.orbit[0], lc.orbit[-1], rtol=1e-6, atol=1e-9)


def test_records_round_trip_through_pandas_and_csv(tmp_path):
    rec = stirling.rig("cv1", settle=3.0, t_end=0.5, effects={"coulomb": 0.02})
    assert isinstance(rec, stirling.RigRecord) and rec.truth.active_effects == ["coulomb"]
    df = rec.to_pandas()
    assert list(df.columns) == ["p", "x", "y"] and len(df) == len(rec) == 1001
    back = stirling.Record.from_pandas(df)
    np.testing.assert_array_equal(back["p"], rec["p"])
    f = tmp_path / "r.csv"
    rec.write_csv(f)
    with pytest.raises(stirling.OptionError, match="exists: pass force=True"):
        rec.write_csv(f)
    read = stirling.read_csv(f)
    np.testing.assert_allclose(read["x"], rec["x"], rtol=1e-9)
    assert read.slice(0.1, 0.2).t[0] >= 0.1


def test_sweep_columns():
    sw = stirling.load("schmidt").sweep({"Th": (500.0, 700.0, 3), "kd": [600.0, 700.0]}, settle=None)
    assert len(sw.points) == 6 and list(sw.axes) == ["Th", "kd"]
    df = sw.to_pandas()
    assert list(df["Th"]) == [500.0, 500.0, 600.0, 600.0, 700.0, 700.0]
    assert set(df["outcome"]) <= {"unstable", "stable"} and np.all(np.isnan(sw["power_w"]))


def test_the_stub_names_every_native_function_and_class():
    stub = Path(stirling.__file__).with_name("_native.pyi")
    tree = ast.parse(stub.read_text())
    declared = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    public = {n for n in dir(_native) if not n.startswith("_")}
    assert public == declared, (public ^ declared)
    assert (Path(stirling.__file__).with_name("py.typed")).exists()


def test_the_bond_graph_is_drawn_with_junctions_and_strokes():
    m = stirling.load("cv1")
    dot = m.dot()
    assert "digraph" in dot and "arrowhead" in dot
    svg = m.bond_svg()
    assert svg.lstrip().startswith("<svg") or "<svg" in svg[:200]
    assert "I: md" in svg and "TF" in svg
