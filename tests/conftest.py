"""Shared fixtures: seeded random states and random, physically consistent DH arms."""

from __future__ import annotations

import os
import sys
from pathlib import Path

# The suite's linear algebra is small (tens of columns): BLAS threads only contend for the two
# cores of CI. Set before NumPy loads its BLAS.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

from cpp_programs import CppTests, shared_build
from reference_model import Arm, params_to_physical

SEED = 20240611

# Table I of the paper (standard DH, [a, alpha, d, theta_offset]), d1 = 0.4, d2 = 0.39
# (docs/models.md).
LWR_DH = np.array(
    [
        [0.0, np.pi / 2, 0.0, 0.0],
        [0.0, -np.pi / 2, 0.0, 0.0],
        [0.0, -np.pi / 2, 0.4, 0.0],
        [0.0, np.pi / 2, 0.0, 0.0],
        [0.0, np.pi / 2, 0.39, 0.0],
        [0.0, -np.pi / 2, 0.0, 0.0],
        [0.0, 0.0, 0.0, 0.0],
    ]
)


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    """Uniformly distributed rotation matrix (QR of a Gaussian matrix, det fixed to +1)."""
    qmat, rmat = np.linalg.qr(rng.normal(size=(3, 3)))
    qmat = qmat * np.sign(np.diag(rmat))
    if np.linalg.det(qmat) < 0:
        qmat[:, 0] = -qmat[:, 0]
    return qmat


def random_pose(rng: np.random.Generator, scale: float = 0.5) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, :3] = random_rotation(rng)
    pose[:3, 3] = rng.uniform(-scale, scale, 3)
    return pose


def random_inertia_com(rng: np.random.Generator, mass: float) -> np.ndarray:
    """A rotated inertia about the CoM with strict triangle inequalities.

    Principal moments (b+c, a+c, a+b) of second moments a, b, c > 0 satisfy
    I1 + I2 > I3 for every permutation; the tensor is R diag R^T.
    """
    a, b, c = mass * rng.uniform(0.002, 0.05, 3)
    rot = random_rotation(rng)
    inertia = rot @ np.diag([b + c, a + c, a + b]) @ rot.T
    return 0.5 * (inertia + inertia.T)  # exactly symmetric (R D R^T is only up to roundoff)


def random_joint_types(rng: np.random.Generator, n: int) -> str:
    """A random mix of R and P with at least one of each (n >= 2)."""
    types = ["R"] * n
    n_prismatic = int(rng.integers(1, max(2, n // 2 + 1)))
    for i in rng.choice(n, size=n_prismatic, replace=False):
        types[i] = "P"
    if "R" not in types:
        types[0] = "R"
    return "".join(types)


def random_arm(
    rng: np.random.Generator,
    n: int,
    convention: str = "standard",
    joint_types: str | None = None,
    with_base_tool: bool = True,
) -> Arm:
    """An arbitrary DH chain: random table, joint types, links, drive terms, gravity, base, tool."""
    if joint_types is None:
        joint_types = random_joint_types(rng, n)
    dh = np.column_stack(
        [
            rng.uniform(-0.5, 0.5, n),
            rng.uniform(-np.pi, np.pi, n),
            rng.uniform(-0.5, 0.5, n),
            rng.uniform(-np.pi, np.pi, n),
        ]
    )
    mass = rng.uniform(0.5, 5.0, n)
    gravity = rng.normal(size=3)
    gravity *= 9.81 / np.linalg.norm(gravity)
    return Arm(
        dh=dh,
        joint_types=joint_types,
        convention=convention,
        mass=mass,
        com=rng.uniform(-0.3, 0.3, (n, 3)),
        inertia_com=np.array([random_inertia_com(rng, m) for m in mass]),
        Ia=rng.uniform(0.0, 0.5, n),
        Fv=rng.uniform(0.0, 2.0, n),
        Fs=rng.uniform(0.0, 1.0, n),
        gravity=gravity,
        base=random_pose(rng) if with_base_tool else np.eye(4),
        tool=random_pose(rng, 0.2) if with_base_tool else np.eye(4),
    )


def random_state(rng: np.random.Generator, arm_or_types: Arm | str, count: int | None = None):
    """(q, qd, qdd): revolute q in (-pi, pi), prismatic q in (-0.5, 0.5) m, qd in (-2, 2), qdd in
    (-3, 3)."""
    types = arm_or_types if isinstance(arm_or_types, str) else arm_or_types.joint_types
    n = len(types)
    shape = (n,) if count is None else (count, n)
    span = np.array([np.pi if t == "R" else 0.5 for t in types])
    q = rng.uniform(-1.0, 1.0, shape) * span
    qd = rng.uniform(-2.0, 2.0, shape)
    qdd = rng.uniform(-3.0, 3.0, shape)
    return q, qd, qdd


def lwr_model():
    """dynid.models.kuka_lwr4() (the contract's model)."""
    import dynid.model.models

    return dynid.models.kuka_lwr4()


def lwr_arm(rng: np.random.Generator) -> Arm:
    """Paper table I with the links of dynid.models.kuka_lwr4() and random drive terms."""
    params = np.asarray(lwr_model().params, dtype=float)
    links = [params_to_physical(p) for p in params]
    return Arm(
        dh=LWR_DH.copy(),
        joint_types="R" * 7,
        convention="standard",
        mass=np.array([link[0] for link in links]),
        com=np.array([link[1] for link in links]),
        inertia_com=np.array([link[2] for link in links]),
        Ia=rng.uniform(0.0, 0.5, 7),
        Fv=rng.uniform(0.0, 2.0, 7),
        Fs=rng.uniform(0.0, 1.0, 7),
    )


ARM_CASES = ("lwr", "random_standard", "random_modified", "random_prismatic_first")


def make_arm(case: str) -> Arm:
    rng = np.random.default_rng(SEED)
    if case == "lwr":
        return lwr_arm(rng)
    if case == "random_standard":
        return random_arm(rng, 6, "standard", "RPRRPR")
    if case == "random_modified":
        return random_arm(rng, 5, "modified", "RRPRP")
    if case == "random_prismatic_first":
        return random_arm(np.random.default_rng(SEED + 1), 4, "modified", "PPRR")
    raise KeyError(case)


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(SEED)


@pytest.fixture(params=ARM_CASES)
def arm(request: pytest.FixtureRequest) -> Arm:
    """A reference arm (known table and links) of each kind."""
    return make_arm(request.param)


# ------------------------------------------------------------------ the C++ test programs


@pytest.fixture(scope="session")
def cpp_tests(tmp_path_factory: pytest.TempPathFactory) -> CppTests:
    """tests/cpp built once per run against the installed package (tests/cpp_programs.py)."""
    root = tmp_path_factory.getbasetemp()
    if os.environ.get("PYTEST_XDIST_WORKER"):
        root = root.parent  # the folder the workers of this run share
    return shared_build(root / "cpp-tests")
