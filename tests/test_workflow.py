"""The campaign of docs/workflow.md end to end on the command line, as a user runs it:
``dynid excite`` -> ``dynid simulate`` (twice: training and validation runs) -> ``dynid
identify`` -> ``dynid validate`` -> ``dynid export``. The simulated arm is the built-in LWR-IV
(rotor inertias, viscous and Coulomb friction), the logs carry 0.05 N m of torque-sensor noise
and the joint velocities at 1 kHz; the identified base parameters must lie within 4 of their
standard deviations of the arm's own (computed from its standard parameters, not by dynid's
fit), the
validation errors must be small, and the exported URDF and MJCF must predict the identified
model's torques."""

from __future__ import annotations

import json

import numpy as np
import pytest

import dynid
from dynid.cli import main
from dynid.export.result_files import load_result

pytestmark = pytest.mark.filterwarnings("ignore::RuntimeWarning")


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    root = tmp_path_factory.mktemp("workflow")
    arm = ["--model", "kuka_lwr4"]
    steps = [
        ["excite", *arm, "--harmonics", "3", "--period", "6", "--periods", "2", "--rotor",
         "--friction", "--maxiter", "25", "--rate", "500", "--output", str(root / "experiment")],
        ["simulate", "kuka_lwr4", str(root / "experiment"), "--rate", "1000", "--sensor-noise",
         "0.05", "--velocities", "--seed", "1", "--output", str(root / "run1")],
        ["simulate", "kuka_lwr4", str(root / "experiment"), "--rate", "1000", "--sensor-noise",
         "0.05", "--velocities", "--seed", "2", "--output", str(root / "run2")],
        ["identify", str(root / "run1" / "log.npz"), *arm, "--rotor", "--friction",
         "--min-velocity", "0.02", "--output", str(root / "identified")],
        ["validate", str(root / "identified"), str(root / "run2" / "log.npz"), "--output",
         str(root / "validated")],
        ["export", str(root / "identified"), "--urdf", str(root / "arm.urdf"), "--mjcf",
         str(root / "arm.xml")],
    ]  # fmt: skip
    for argv in steps:
        assert main(argv) == 0, argv
    return root


def test_the_identified_parameters_are_the_simulated_arm_s(campaign) -> None:
    robot = dynid.models.kuka_lwr4()
    base = dynid.base_parameters(robot, "torque", rotor=True, friction=True)
    truth = base.beta @ robot.parameter_vector(True, True)
    result = load_result(campaign / "identified")
    z = (result.theta - truth) / result.std
    assert np.abs(z).max() < 4.0, result.names[int(np.argmax(np.abs(z)))]
    assert np.abs(result.theta - truth).max() < 0.02 * np.abs(truth).max()


def test_validation_on_a_second_run(campaign) -> None:
    report = json.loads((campaign / "validated" / "validation.json").read_text())
    rms = np.array(report["metrics"]["rms"], dtype=float)
    assert np.all(rms < 0.1)  # N m: the sensor noise (0.05) and the Coulomb band's misfit


def test_the_exported_files_predict_the_identified_model(campaign) -> None:
    result = load_result(campaign / "identified")
    q, qd, qdd = np.random.default_rng(4).uniform(-1.0, 1.0, (3, 30, 7))
    expected = result.regressor(q, qd, qdd) @ result.theta
    urdf = dynid.Robot.from_urdf(campaign / "arm.urdf")
    # The closest physically consistent robot to the noisy estimate (within one std of each base
    # parameter): its torques differ from the estimate's by less than the sensor noise.
    difference = np.abs(urdf.rnea(q, qd, qdd) - expected)
    assert (
        np.sqrt(np.mean(difference**2)) < 0.05 and difference.max() < 0.01 * np.abs(expected).max()
    )
    mujoco = pytest.importorskip("mujoco")
    model = mujoco.MjModel.from_xml_path(str(campaign / "arm.xml"))
    np.testing.assert_allclose(model.dof_armature, urdf.Ia, rtol=1e-12)
