"""`dynid identify --physical --prior` and `dynid export`: the exported URDF is the identified
robot (checked through Robot.from_urdf and Pinocchio's parser, 1e-12), a least-squares result
whose base parameters no rigid bodies have is refused (tests/test_realize.py: the consistent
ones), options are checked."""

from __future__ import annotations

import numpy as np
import pytest

import dynid
import dynid.cli

LOG = "tests/data/measurements_1.npz"
PRIOR = "tests/data/urdf/kuka_lwr4.urdf"


@pytest.fixture(scope="module")
def physical_result(tmp_path_factory):
    out = tmp_path_factory.mktemp("cli") / "physical"
    status = dynid.cli.main(
        [
            "identify",
            LOG,
            "--skip",
            "3000",
            "--rotor",
            "--friction",
            "--offset",
            "--physical",
            "--prior",
            PRIOR,
            "--output",
            str(out),
        ]
    )
    assert status == 0
    return out


def test_export_writes_the_identified_robot(physical_result, tmp_path) -> None:
    import pinocchio

    urdf = tmp_path / "identified.urdf"
    assert dynid.cli.main(["export", str(physical_result), "--urdf", str(urdf)]) == 0
    robot = dynid.load_result(physical_result).robot
    assert robot.is_physically_consistent()
    again = dynid.Robot.from_urdf(urdf)
    q, qd, qdd = np.random.default_rng(5).uniform(-1.5, 1.5, (3, 20, 7))
    expected = robot.rnea(q, qd, qdd)
    assert np.max(np.abs(again.rnea(q, qd, qdd) - expected)) <= 1e-12 * np.max(np.abs(expected))
    # Pinocchio reads the same text: rigid body (+ Ia as armature) equals rnea without friction
    model = pinocchio.buildModelFromXML(urdf.read_text())
    model.armature[:] = robot.Ia
    data = model.createData()
    rigid = robot.copy()
    rigid.Fv = rigid.Fs = np.zeros(7)
    for k in range(5):
        tau = pinocchio.rnea(model, data, q[k], qd[k], qdd[k])
        reference = rigid.rnea(q[k], qd[k], qdd[k])
        assert np.max(np.abs(tau - reference)) <= 1e-12 * np.max(np.abs(reference))


def test_export_refuses_least_squares_results_and_existing_files(
    physical_result, tmp_path, capsys
) -> None:
    plain = tmp_path / "plain"
    assert dynid.cli.main(["identify", LOG, "--skip", "4500", "--output", str(plain)]) == 0
    capsys.readouterr()
    assert dynid.cli.main(["export", str(plain), "--urdf", str(tmp_path / "x.urdf")]) == 2
    assert "not physically consistent" in capsys.readouterr().err
    target = tmp_path / "model.urdf"
    assert dynid.cli.main(["export", "ur5", "--urdf", str(target)]) == 0
    assert dynid.cli.main(["export", "ur5", "--urdf", str(target)]) == 2
    assert "exists" in capsys.readouterr().err
    assert dynid.cli.main(["export", "ur5", "--urdf", str(target), "--overwrite"]) == 0
    q = np.random.default_rng(2).uniform(-2, 2, (10, 6))
    expected = dynid.models.ur5().gravity(q)
    assert np.max(np.abs(dynid.Robot.from_urdf(target).gravity(q) - expected)) <= 1e-12 * np.max(
        np.abs(expected)
    )


def test_prior_only_with_physical(tmp_path, capsys) -> None:
    status = dynid.cli.main(["identify", LOG, "--prior", PRIOR, "--output", str(tmp_path / "o")])
    assert status == 2
    assert "--prior, --prior-weight: only with --physical" in capsys.readouterr().err


def test_residual_command(tmp_path, capsys) -> None:
    """`dynid residual` writes the residual of residual_from_log (the same numbers) and a plot."""
    from dynid.identification.observer import residual_from_log

    out = tmp_path / "residual"
    status = dynid.cli.main(
        [
            "residual",
            "kuka_lwr4",
            LOG,
            "--skip",
            "4000",
            "--gain",
            "10",
            "--threshold",
            "1",
            "--output",
            str(out),
        ]
    )
    assert status == 0
    saved = np.load(out / "residual.npz")
    expected = residual_from_log(dynid.models.kuka_lwr4(), dynid.load_log(LOG, skip=4000), 10.0)
    assert np.array_equal(saved["r"], expected.r)
    assert (out / "residual.png").stat().st_size > 0
    assert "J7" in capsys.readouterr().out
