"""MJCF export (dynid.export.mjcf, `dynid export --mjcf`): MuJoCo, reading the file, computes
dynid's dynamics.

MuJoCo is the independent computation: its mass matrix (mj_fullM: rigid body plus armature) must
equal dynid's M(q) (rotor inertia Ia on the diagonal), its bias force (mj_rne without
accelerations) dynid's C(q, qd) qd + g(q), to 1e-9 relative at random states (measured: about
3e-15), and its tool site the pose of dynid's fkine -- for built-in arms in both DH conventions,
a prismatic arm with base and tool transforms and tilted gravity, and an identified model.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
import dynid.cli
from dynid.export.mjcf import mjcf_text, write_mjcf

mujoco = pytest.importorskip("mujoco")

TOLERANCE = 1e-9  # relative; the file holds shortest round-trip decimals, MuJoCo rounds nothing


def mujoco_dynamics(text: str, q: np.ndarray, qd: np.ndarray):
    """(M, bias, tool pose 4x4) of MuJoCo's model of ``text`` at (q, qd)."""
    model = mujoco.MjModel.from_xml_string(text)
    data = mujoco.MjData(model)
    data.qpos[:] = q
    data.qvel[:] = qd
    mujoco.mj_forward(model, data)
    M = np.zeros((model.nv, model.nv))
    try:
        mujoco.mj_fullM(model, data, M)  # MuJoCo >= 4
    except TypeError:
        mujoco.mj_fullM(model, M, data.qM)
    bias = np.zeros(model.nv)
    mujoco.mj_rne(model, data, 0, bias)
    site = model.site("tool").id
    pose = np.eye(4)
    pose[:3, :3] = data.site_xmat[site].reshape(3, 3)
    pose[:3, 3] = data.site_xpos[site]
    return M, bias, pose


def assert_same_dynamics(robot: dynid.Robot, text: str, seed: int = 0, states: int = 10) -> None:
    rng = np.random.default_rng(seed)
    rigid = robot.rigid_body()  # C qd + g: no drive friction, no rotor term without qdd
    for _ in range(states):
        q = rng.uniform(-2.0, 2.0, robot.n)
        q[np.array(robot.joint_types) == "P"] *= 0.1
        qd = rng.uniform(-2.0, 2.0, robot.n)
        M, bias, pose = mujoco_dynamics(text, q, qd)
        expected_M = robot.mass_matrix(q)
        expected_bias = rigid.rnea(q, qd, np.zeros(robot.n))
        np.testing.assert_allclose(M, expected_M, rtol=0, atol=TOLERANCE * np.abs(expected_M).max())
        np.testing.assert_allclose(
            bias, expected_bias, rtol=0, atol=TOLERANCE * np.abs(expected_bias).max()
        )
        np.testing.assert_allclose(pose, robot.fkine(q), rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", ["kuka_lwr4", "panda", "ur5"])
def test_builtin_arms(name):
    robot = getattr(dynid.models, name)()
    assert_same_dynamics(robot, mjcf_text(robot))


def test_drive_terms_are_mujocos_joint_fields():
    robot = dynid.models.kuka_lwr4()  # with rotor inertia and friction
    model = mujoco.MjModel.from_xml_string(mjcf_text(robot))
    np.testing.assert_array_equal(model.dof_armature, robot.Ia)
    np.testing.assert_array_equal(model.dof_damping, robot.Fv)
    np.testing.assert_array_equal(model.dof_frictionloss, robot.Fs)
    np.testing.assert_array_equal(model.opt.gravity, robot.gravity_vector)
    assert model.nu == robot.n
    assert [model.joint(i).name for i in range(robot.n)] == list(robot.joint_names)
    limited = model.jnt_range
    np.testing.assert_array_equal(limited, robot.qlim)
    # Damping is MuJoCo's passive force -Fv qd.
    data = mujoco.MjData(model)
    data.qvel[:] = np.linspace(-1.0, 1.0, robot.n)
    mujoco.mj_forward(model, data)
    np.testing.assert_allclose(data.qfrc_passive, -robot.Fv * data.qvel, rtol=1e-14)


def rotation(axis: str, angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    R = {"x": [[1, 0, 0], [0, c, -s], [0, s, c]], "z": [[c, -s, 0], [s, c, 0], [0, 0, 1]]}[axis]
    T = np.eye(4)
    T[:3, :3] = R
    return T


@pytest.mark.parametrize("convention", ["standard", "modified"])
def test_prismatic_joint_base_tool_and_gravity(convention):
    """A 4-joint arm with a prismatic joint, DH offsets on every row, base and tool transforms,
    gravity not along z, random consistent links, rotor inertia."""
    rng = np.random.default_rng(3)
    dh = np.array(
        [
            [0.1, 0.3, 0.2, 0.4],
            [0.25, -1.2, 0.05, -0.3],
            [0.0, 1.57, 0.3, 0.7],
            [0.05, 0.0, 0.1, 1.1],
        ]
    )
    base = rotation("z", 0.4) @ rotation("x", 0.2)
    base[:3, 3] = [0.1, -0.2, 0.3]
    tool = rotation("x", -0.7)
    tool[:3, 3] = [0.01, 0.02, 0.15]
    robot = dynid.Robot.from_dh(
        dh,
        joint_types="RPRR",
        convention=convention,
        gravity=(1.0, -2.0, -9.5),
        base=base,
        tool=tool,
    )
    for i in range(robot.n):  # a random box: principal moments that a body can have, turned
        m, (a, b, c) = rng.uniform(0.5, 3.0), rng.uniform(0.05, 0.4, 3)
        principal = m / 12 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])
        R, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        robot.set_link(i, m, rng.uniform(-0.1, 0.1, 3), R @ np.diag(principal) @ R.T)
    robot.Ia = rng.uniform(0.0, 0.2, robot.n)
    assert_same_dynamics(robot, mjcf_text(robot), seed=7)


@pytest.fixture(scope="module")
def physical_result(tmp_path_factory):
    """An identified, physically consistent LWR4+ model from the real log (as test_cli_export)."""
    out = tmp_path_factory.mktemp("mjcf") / "physical"
    argv = ["identify", "tests/data/measurements_1.npz", "--skip", "3000", "--rotor"]
    argv += ["--friction", "--physical", "--prior", "tests/data/urdf/kuka_lwr4.urdf"]
    assert dynid.cli.main([*argv, "--output", str(out)]) == 0
    return out


def test_cli_exports_an_identified_model(physical_result, tmp_path, capsys):
    mjcf, urdf = tmp_path / "lwr.xml", tmp_path / "lwr.urdf"
    argv = ["export", str(physical_result), "--mjcf", str(mjcf), "--urdf", str(urdf)]
    assert dynid.cli.main(argv) == 0
    assert f"wrote {urdf}, {mjcf}" in capsys.readouterr().out
    robot = dynid.load_result(physical_result).robot
    assert robot.Ia.min() >= 0 and robot.Ia.max() > 0  # armature is exercised
    assert_same_dynamics(robot, mjcf.read_text(), seed=11)
    # An existing file is kept (and nothing else written) unless --overwrite.
    before = mjcf.read_text()
    assert (
        dynid.cli.main([*argv[:2], "--mjcf", str(mjcf), "--urdf", str(tmp_path / "new.urdf")]) == 2
    )
    assert mjcf.read_text() == before and not (tmp_path / "new.urdf").exists()
    assert dynid.cli.main([*argv, "--overwrite"]) == 0


def test_refusals(tmp_path, capsys):
    assert dynid.cli.main(["export", "kuka_lwr4"]) == 2
    assert "give at least one file to write" in capsys.readouterr().err
    puma = dynid.models.puma560()  # link 1 massless: no MuJoCo body
    with pytest.raises(ValueError, match="robot: link 1 is not physically consistent"):
        mjcf_text(puma)
    lwr = dynid.models.kuka_lwr4()
    lwr.Fv = -lwr.Fv
    with pytest.raises(ValueError, match=r"robot: joint 1 has negative damping \(Fv\)"):
        mjcf_text(lwr)
    coupled = dynid.models.kuka_lwr4()
    T = np.eye(7)
    T[6, 5] = 1.0
    coupled.transmission = T
    with pytest.raises(ValueError, match="transmission: a robot with coupled drives"):
        mjcf_text(coupled)
    with pytest.raises(ValueError, match="name: expected a non-empty model name"):
        mjcf_text(dynid.models.kuka_lwr4(), name=" ")
    target = tmp_path / "x.xml"
    write_mjcf(dynid.models.planar_2r(), target)
    with pytest.raises(ValueError, match="exists; pass overwrite=True"):
        write_mjcf(dynid.models.planar_2r(), target)
