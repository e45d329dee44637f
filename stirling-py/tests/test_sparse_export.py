"""Above 500 states the export writes A, B, C, D only as triplets (`a` .. `d` are null):
`StateSpace` reads them back, equal to the dense fields where both are written (200 to 500
states), and the closed loop is `A - B C`."""

import numpy as np

from stirling.results import StateSpace


def systems(e, drop_dense=False):
    def raw(s):
        return {k: (None if drop_dense and k in "abcd" else v) for k, v in s.items()}

    return StateSpace(raw(e["broken_loop"]), e["states"]), StateSpace(raw(e["closed_loop"]), e["states"])


def test_triplets_alone_give_the_dense_matrices(cli):
    e = cli("linearize", "nsection", "--n", "200", "--json")["state_space"]
    dense, sparse = systems(e), systems(e, drop_dense=True)
    for d, s in zip(dense, sparse):
        for m, n in zip(d.matrices(), s.matrices()):
            assert m.shape == n.shape
            np.testing.assert_array_equal(m, n)


def test_above_500_states_the_matrices_come_from_triplets(cli):
    e = cli("linearize", "nsection", "--n", "250", "--json")["state_space"]
    assert all(e["broken_loop"][k] is None for k in "abcd")
    bl, cl = systems(e)
    A, B, C, D = bl.matrices()
    assert (A.shape, B.shape, C.shape, D.shape) == ((507, 507), (507, 1), (1, 507), (1, 1))
    np.testing.assert_allclose(cl.A, A - B @ C, rtol=0, atol=1e-12 * abs(cl.A).max())
