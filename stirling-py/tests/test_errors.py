"""Bad input raises a clear exception (a `stirling.errors` class, also a ValueError) with the
library's message: what is wrong and where; nothing crashes the interpreter."""

import math

import numpy as np
import pytest
from pathlib import Path

import stirling
from stirling.errors import ModelError, OptionError, ParameterError, RecordError, StirlingError


@pytest.fixture(scope="module")
def cv1():
    return stirling.load("cv1")


def test_unknown_model_and_bad_sections():
    with pytest.raises(ModelError, match="unknown model `cv9`: expected one of schmidt, cv1, cv2, nsection"):
        stirling.load("cv9")
    with pytest.raises(ModelError, match="no regenerator sections"):
        stirling.load("schmidt", n=3)
    with pytest.raises(ModelError, match="n must be a whole number of sections >= 1"):
        stirling.load("nsection", n=0)
    with pytest.raises(ModelError, match="alias `order8` fixes n = 2"):
        stirling.load("order8", n=3)
    with pytest.raises(ModelError, match="closure"):
        stirling.load("cv1", closure="frozenish")
    with pytest.raises(ModelError, match=r"engine\.stirling"):
        stirling.load("engine.stirling")


def test_an_engine_file_loads_and_its_mistakes_are_placed(tmp_path):
    root = Path(__file__).resolve().parents[2]
    cv1 = stirling.load(str(root / "examples" / "engines" / "cv1.stirling"))
    fam = stirling.load("cv1")
    assert cv1.n_states == fam.n_states
    assert abs(cv1.linearize().margins.gain_db - fam.linearize().margins.gain_db) < 1e-9
    bad = tmp_path / "typo.stirling"
    bad.write_text("model Typo extends default_engine {\n    name \"typo\";\n    sensor q: nope \"Pa\";\n}\n")
    with pytest.raises(ModelError, match=r"typo\.stirling:3:"):
        stirling.load(str(bad))


def test_unknown_parameter_lists_the_valid_ones(cv1):
    with pytest.raises(ParameterError, match="unknown parameter `Thot` for model `cv1`; valid parameters: R, gamma"):
        cv1.with_params(Thot=650.0)
    with pytest.raises(ParameterError, match="unknown parameter `kz`"):
        stirling.load("cv1", params={"kz": 1.0})
    with pytest.raises(ParameterError, match="unknown parameter `kz`"):
        cv1.fit(cv1.rig(settle=3.0, t_end=1.0), bounds={"kz": (1.0, 2.0)})
    with pytest.raises(ParameterError, match="unknown parameter `kz`"):
        cv1.rig(params={"kz": 1.0})


def test_nan_and_unphysical_parameters(cv1):
    with pytest.raises(ParameterError, match="parameter `Th` = NaN is not physical: must be finite"):
        cv1.with_params(Th=math.nan)
    with pytest.raises(ParameterError, match="`Th` = 200 is not physical: the hot wall must be hotter than the cold wall"):
        cv1.with_params(Th=200.0)
    with pytest.raises(ParameterError, match="must be a number"):
        cv1.with_params(Th="hot")
    assert isinstance(ParameterError("x"), ValueError)


def test_wrong_shapes_and_non_finite_states(cv1):
    n = cv1.n_states
    with pytest.raises(OptionError, match=rf"x has 3 entries; it must have {n} \(the states of `cv1`: x, v, y, w, P_gas\)"):
        cv1.rhs(np.zeros(3))
    with pytest.raises(OptionError, match=r"must be one-dimensional, got an array of shape \(5, 2\)"):
        cv1.jacobian(np.zeros((5, 2)))
    x = cv1.rest_state()
    x[4] = math.nan
    with pytest.raises(OptionError, match=r"x0\[4\] = NaN is not a finite number"):
        cv1.simulate(0.1, x0=x)
    with pytest.raises(OptionError, match="sequence of numbers"):
        cv1.rhs(["a", "b"])
    with pytest.raises(OptionError, match="t_end = -1 must be a positive number of seconds"):
        cv1.simulate(-1.0)
    with pytest.raises(OptionError, match=r"rtol = 0.5 must be in \(0, 0.1\]"):
        cv1.simulate(0.1, rtol=0.5)
    with pytest.raises(OptionError, match="give x0 or perturb, not both"):
        cv1.simulate(0.1, x0=cv1.rest_state(), perturb=1e-3)


def test_records_with_bad_arrays():
    t = np.linspace(0.0, 1.0, 101)
    with pytest.raises(RecordError, match=r"channel `p` has 100 entries; it must have 101"):
        stirling.Record(t, p=np.zeros(100))
    p = np.full(101, 1e5)
    p[17] = math.nan
    with pytest.raises(RecordError, match=r"channel `p`\[17\] = NaN is not a finite number"):
        stirling.Record(t, p=p)
    with pytest.raises(RecordError, match=r"t must increase strictly: t\[2\] = 0.01 is not after t\[1\] = 0.01"):
        stirling.Record(np.r_[0.0, 0.01, 0.01, 0.02], p=np.ones(4))
    with pytest.raises(RecordError, match="at least one channel"):
        stirling.Record(t)
    with pytest.raises(RecordError, match="channel name `a,b`"):
        stirling.Record(t, {"a,b": np.ones(101)})


def test_a_record_without_motion_is_refused_by_the_fit_and_the_diagnosis(cv1):
    rng = np.random.default_rng(1)
    t = np.arange(2001) / 2000.0
    rest = cv1.rest_state()
    still = stirling.Record(
        t,
        p=rest[4] + 50.0 * rng.standard_normal(t.size),
        x=20e-6 * rng.standard_normal(t.size),
        y=20e-6 * rng.standard_normal(t.size),
    )
    with pytest.raises(RecordError, match=r"channel `\w+` does not move enough to fit.*is the engine running in this record\?"):
        cv1.fit(still)
    with pytest.raises(RecordError, match="(fewer than two cycles|motion dies out|does not move)"):
        cv1.diagnose(still)


def test_irregular_sampling_and_blocks(cv1):
    rec = cv1.rig(settle=3.0, t_end=1.0)
    t = rec.t.copy()
    t[500:] += 0.01
    gappy = stirling.Record(t, {c: rec[c] for c in rec.channels})
    with pytest.raises(RecordError, match="irregular sampling: a gap"):
        cv1.fit(gappy)
    with pytest.raises(OptionError, match="train = .*reaches outside the record"):
        cv1.fit(rec, train=(0.0, 5.0))
    with pytest.raises(OptionError, match="holdout = .* must follow the training block"):
        cv1.fit(rec, train=(0.0, 0.7), holdout=(0.5, 1.0))
    with pytest.raises(RecordError, match="expected a stirling.Record"):
        cv1.fit([1, 2, 3])
    with pytest.raises(OptionError, match="restart_cycles = 0: above 0"):
        cv1.fit(rec, restart_cycles=0.0)


def test_csv_errors_name_row_and_column(tmp_path):
    f = tmp_path / "bad.csv"
    f.write_text("t,p,x,y\n0,1e5,0,0\n0.0005,abc,0,0\n")
    with pytest.raises(RecordError, match=r"bad.csv: row 3, column `p`"):
        stirling.read_csv(f)
    with pytest.raises(RecordError, match="cannot read the file"):
        stirling.read_csv(tmp_path / "missing.csv")


def test_rig_and_diagnosis_options(cv1):
    with pytest.raises(OptionError, match="unknown effect or effect parameter `lek`"):
        cv1.rig(effects={"lek": 1e-8})
    rec = cv1.rig(settle=3.0, t_end=1.0)
    with pytest.raises(OptionError, match="unknown effect `lek`"):
        cv1.diagnose(rec, effects=["lek"])
    with pytest.raises(ModelError, match="no augmented member"):
        stirling.load("schmidt").diagnose(rec)


def test_every_error_is_a_stirling_error_with_its_message():
    try:
        stirling.load("cv9")
    except StirlingError as e:
        assert "unknown model `cv9`" in str(e)
        assert isinstance(e, ValueError)
    else:
        raise AssertionError("no error")
