import numpy as np
import pytest

from tunnelkit.tracking.javelin import JavelinState
from tunnelkit.tracking.javelin.state import track_slice


def _state(rng, n_vue=3):
    st = JavelinState.initial([-20.0, 1.0, 1.0], 2.0)
    for k in range(n_vue):
        st.append([5.0 + k, 1.0 - k], np.eye(2) * (k + 1.0))
    A = rng.standard_normal((st.dim, st.dim))
    st.P = A @ A.T + np.eye(st.dim)
    return st


def test_dimension_and_slices():
    st = _state(np.random.default_rng(0))
    assert st.dim == 2 * st.n_tracks + 1 == 9  # D = 2 L_hat + 1 (eq. 43)
    assert st.ids == [1, 2, 3] and track_slice(2) == slice(5, 7)
    np.testing.assert_allclose(st.position(2), [-20.0, 6.0, 0.0])
    np.testing.assert_allclose(st.positions()[:, 0], -20.0)


def test_remove_marginalises_and_append_is_block_diagonal():
    rng = np.random.default_rng(1)
    st = _state(rng)
    P_old = st.P.copy()
    keep = [0, 1, 2, 5, 6]  # UE + VUE 2
    gone = st.remove([1, 3])
    assert gone == [1, 3] and st.ids == [2]
    np.testing.assert_array_equal(st.P, P_old[np.ix_(keep, keep)])
    tid = st.append([0.5, 0.5], 4 * np.eye(2), transient=True)
    assert tid == 4 and st.transient == [False, True]
    np.testing.assert_array_equal(st.P[:5, 5:], 0.0)
    with pytest.raises(ValueError, match=r"^tracks"):
        st.remove([0])


def test_validation():
    with pytest.raises(ValueError, match=r"^x"):
        JavelinState(np.zeros(4), np.eye(4))
    with pytest.raises(ValueError, match=r"^ids"):
        JavelinState(np.zeros(5), np.eye(5))
    with pytest.raises(ValueError, match=r"^sigma"):
        JavelinState.initial([0, 0, 0], -1.0)
