"""Batch calls split over threads give exactly the single-thread results."""

from __future__ import annotations

import numpy as np
import pytest

import dynid


@pytest.fixture
def two_threads():
    dynid.set_threads(2)
    yield
    dynid.set_threads(1)


def test_threaded_batches_equal_single_thread(two_threads):
    robot = dynid.models.kuka_lwr4()
    rng = np.random.default_rng(7)
    q, qd, qdd = rng.uniform(-1.0, 1.0, (3, 3000, robot.n))  # enough for two workers
    dynid.set_threads(2)
    robot.rnea(q, qd, qdd)
    assert dynid._core._last_batch_threads() == 2  # the batch really was split
    threaded = {
        "rnea": robot.rnea(q, qd, qdd),
        "mass_matrix": robot.mass_matrix(q),
        "regressor": robot.regressor(q, qd, qdd, rotor=True, friction=True),
        "forward_dynamics": robot.forward_dynamics(q, qd, qdd),
    }
    dynid.set_threads(1)
    single = {
        "rnea": robot.rnea(q, qd, qdd),
        "mass_matrix": robot.mass_matrix(q),
        "regressor": robot.regressor(q, qd, qdd, rotor=True, friction=True),
        "forward_dynamics": robot.forward_dynamics(q, qd, qdd),
    }
    for name, value in single.items():
        # Each sample is computed by the same code whichever thread runs it: bit-identical.
        np.testing.assert_array_equal(threaded[name], value, err_msg=name)
    # and per sample as well, for a few samples spread over both halves: single calls run the
    # scalar kernel, batches the SIMD lane kernel (tests/test_batch_lanes.py): 1e-12 relative.
    for t in (0, 1499, 1500, 2999):
        single_call = robot.rnea(q[t], qd[t], qdd[t])
        np.testing.assert_allclose(
            threaded["rnea"][t], single_call, rtol=0, atol=1e-12 * np.abs(single_call).max()
        )


def test_errors_in_worker_threads_reach_python(two_threads):
    robot = dynid.models.kuka_lwr4()
    params = robot.params.copy()
    params[:, 0] = -1.0  # negative masses: M(q) is not positive definite
    robot.params = params
    robot.Ia = np.zeros(robot.n)
    q = np.zeros((2000, robot.n))
    with pytest.raises(ValueError, match="params"):
        robot.forward_dynamics(q, q, q)


@pytest.mark.parametrize("bad", [0, -3])
def test_set_threads_rejects_non_positive_counts(bad):
    with pytest.raises(ValueError, match="threads"):
        dynid.set_threads(bad)
    assert dynid.get_threads() >= 1
