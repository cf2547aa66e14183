"""The Cartesian factorization S_p (notes p. 49): mu = S_p xd equals cartesian_dynamics' mu,
and Lamdot - 2 S_p is skew-symmetric, Lamdot taken by central differences of
cartesian_inertia along the motion (an independent computation of the derivative)."""

from __future__ import annotations

import numpy as np
import pytest

import dynid


@pytest.mark.parametrize(
    ("name", "rows", "q"),
    [
        ("puma560", None, [0.2, -0.6, 0.9, 0.3, 0.8, 0.1]),
        ("planar_2r", (0, 1), [0.4, 1.1]),
        ("ur5", None, [0.3, -1.0, 1.2, -0.4, 0.9, 0.2]),
    ],
)
def test_lamdot_minus_2sp_is_skew_and_sp_factors_mu(name, rows, q) -> None:
    robot = getattr(dynid.models, name)()
    q = np.array(q)
    qd = np.linspace(0.3, -0.5, robot.n)
    Sp = robot.cartesian_coriolis_matrix(q, qd, rows=rows)
    _, mu, _ = robot.cartesian_dynamics(q, qd, rows=rows)
    J = robot.jacobian(q)[list(rows) if rows else slice(None)]
    xd = J @ qd
    assert np.max(np.abs(Sp @ xd - mu)) <= 1e-10 * max(1.0, np.abs(mu).max())
    h = 1e-6
    Lam_dot = (
        robot.cartesian_inertia(q + h * qd, rows=rows)
        - robot.cartesian_inertia(q - h * qd, rows=rows)
    ) / (2 * h)
    N = Lam_dot - 2 * Sp
    scale = np.abs(Lam_dot).max() + np.abs(Sp).max()
    assert np.max(np.abs(N + N.T)) <= 1e-7 * scale  # central differences: ~h^2 and rounding
    assert np.max(np.abs(N)) > 1e-3 * scale  # not trivially zero


def test_a_non_square_jacobian_is_refused() -> None:
    robot = dynid.models.kuka_lwr4()  # 7 joints, 6 task rows
    with pytest.raises(ValueError, match="rows: the Cartesian factorization S_p needs a square"):
        robot.cartesian_coriolis_matrix(np.zeros(7) + 0.3, np.ones(7))
