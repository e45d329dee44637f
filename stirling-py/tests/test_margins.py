"""python-control finds the seed's margins from the module's state space directly: the
4th-order model (schmidt), its loop broken at the pressure force, `control.margin` on
`control.ss(A, B, C, D)` (Gm -6.63 dB at 81.6 rad/s, Pm -79.5 deg at 91.3 rad/s), and the
module's own margins agree with it."""

import math

import control
import numpy as np

import stirling


def test_python_control_reads_the_seed_margins_from_the_state_space():
    lin = stirling.load("schmidt").linearize()
    A, B, C, D = lin.broken_loop.matrices()
    assert A.shape == (4, 4) and B.shape == (4, 1) and C.shape == (1, 4) and D.shape == (1, 1)
    gm, pm, w_pc, w_gc = control.margin(control.ss(A, B, C, D))
    gm_db = 20.0 * math.log10(gm)
    assert abs(gm_db + 6.63) <= 0.05, gm_db
    assert abs(w_pc - 81.6) <= 0.05, w_pc
    assert abs(pm + 79.5) <= 0.5, pm
    assert abs(w_gc - 91.3) <= 0.05, w_gc
    m = lin.margins
    assert abs(m.gain_db - gm_db) < 1e-3 and abs(m.phase_crossover_rad_s - w_pc) < 1e-3
    assert abs(m.phase_deg - pm) < 1e-2 and abs(m.gain_crossover_rad_s - w_gc) < 1e-3


def test_to_control_keeps_names_and_closes_the_loop_as_documented():
    lin = stirling.load("schmidt").linearize()
    sys = lin.broken_loop.to_control()
    assert isinstance(sys, control.StateSpace)
    assert list(sys.state_labels) == lin.broken_loop.states
    closed = lin.closed_loop
    A, B, C, _ = lin.broken_loop.matrices()
    np.testing.assert_allclose(closed.A, A - B @ C, rtol=1e-12, atol=1e-12 * np.abs(A).max())
    # the closed loop's poles are the linearization's poles (the engine's RHP pair)
    got = np.sort_complex(np.linalg.eigvals(closed.A))
    np.testing.assert_allclose(got, np.sort_complex(lin.poles), rtol=1e-8)
    assert lin.rhp_count == 2


def test_bode_data_cross_minus_180_where_the_margin_is():
    lin = stirling.load("schmidt").linearize()
    b = lin.bode
    k = np.argmin(np.abs(b.w - lin.margins.phase_crossover_rad_s))
    assert abs(((b.phase_deg[k] + 180.0) + 180.0) % 360.0 - 180.0) < 2.0
    assert abs(b.magnitude_db[k] + lin.margins.gain_db) < 0.2
