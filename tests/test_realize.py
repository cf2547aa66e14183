"""A least-squares result exported as a robot (dynid.identification.realize.consistent_robot,
``dynid export`` of a result without --physical): when a physically consistent robot has the
estimate's base parameters it is found and written; otherwise the export is refused naming the
base parameter that no rigid body can have.

Independent checks: the robot found is checked link by link for consistency (its own
pseudo-inertia test) and its torques by its rnea against the least-squares prediction Y theta
(computed from the result's base regressor), on states the fit never saw.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import dynid
import dynid.cli
from dynid.export.result_files import save_result
from dynid.identification.log_identification import identify_log
from dynid.identification.realize import consistent_robot
from test_log_identification import fourier_log


@pytest.fixture(scope="module")
def exact():
    robot = dynid.models.kuka_lwr4()
    return robot, identify_log(
        fourier_log(robot, 7, seconds=10.0), robot, rotor=True, friction=True
    )


def _states(n: int, seed: int = 11):
    return np.random.default_rng(seed).uniform(-1.5, 1.5, (3, 40, n))


def test_an_exact_estimate_becomes_a_consistent_robot(exact):
    robot, result = exact
    found = consistent_robot(result)
    assert found.is_physically_consistent()
    q, qd, qdd = _states(robot.n)
    expected = result.regressor(q, qd, qdd) @ result.theta  # the least-squares model
    got = found.rnea(q, qd, qdd)
    assert np.max(np.abs(got - expected)) <= 1e-6 * np.max(np.abs(expected))
    # Ia1, Ia2 are grouped with link inertias (only their sums are base parameters): the
    # robot found has its own split, with every drive term >= 0.
    assert np.all(found.Ia >= 0) and np.all(found.Fv >= 0) and np.all(found.Fs >= 0)
    np.testing.assert_allclose(found.Ia[2:], robot.Ia[2:], rtol=1e-6)


def test_export_writes_it(exact, tmp_path):
    robot, result = exact
    save_result(result, tmp_path / "ls")
    urdf = tmp_path / "ls.urdf"
    assert dynid.cli.main(["export", str(tmp_path / "ls"), "--urdf", str(urdf)]) == 0
    again = dynid.Robot.from_urdf(urdf)
    q, qd, qdd = _states(robot.n, 3)
    expected = result.regressor(q, qd, qdd) @ result.theta
    assert np.max(np.abs(again.rnea(q, qd, qdd) - expected)) <= 1e-6 * np.max(np.abs(expected))


def test_an_estimate_no_rigid_body_has_is_refused(exact, tmp_path, capsys):
    _, result = exact
    # Ia_7 enters the base parameters alone (the last joint's rotor): a negative value is a
    # rotor no motor has, whatever the links.
    k = result.names.index("Ia7")
    theta = result.theta.copy()
    theta[k] = -0.5
    bad = dataclasses.replace(result, theta=theta)
    with pytest.raises(ValueError, match=r"not physically consistent.*Ia7.*--physical"):
        consistent_robot(bad)
    save_result(bad, tmp_path / "bad")
    assert dynid.cli.main(["export", str(tmp_path / "bad"), "--urdf", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert "not physically consistent" in err and err.count("\n") == 1
    assert not (tmp_path / "x").exists()


def test_undetermined_parameters_are_refused(exact):
    _, result = exact
    std = result.std.copy()
    std[0] = np.inf
    with pytest.raises(ValueError, match="not determined by the data"):
        consistent_robot(dataclasses.replace(result, std=std))


def test_export_writes_a_model_file_for_cpp(exact, tmp_path):
    """--model-file: the consistent robot as a model file (what dynid::load_model reads in C++),
    written atomically; it predicts the least-squares model's torques."""
    robot, result = exact
    save_result(result, tmp_path / "ls")
    model = tmp_path / "identified.json"
    argv = ["export", str(tmp_path / "ls"), "--model-file", str(model), "--name", "ident"]
    assert dynid.cli.main(argv) == 0
    again = dynid.load_model(model)
    assert again.name == "ident"
    q, qd, qdd = _states(robot.n, 5)
    expected = result.regressor(q, qd, qdd) @ result.theta
    assert np.max(np.abs(again.rnea(q, qd, qdd) - expected)) <= 1e-6 * np.max(np.abs(expected))
    assert dynid.cli.main(argv) == 2  # exists: not replaced without --overwrite
    bad = ["export", str(tmp_path / "ls"), "--model-file", str(tmp_path / "m.txt")]
    assert dynid.cli.main(bad) == 2
