"""The robot model: a DH chain with its inertial parameters and drive terms.

`Robot` is the C++ model itself (`dynid._core.Model`) with the Python conveniences added on top,
so a dynamics call such as ``robot.rnea(q, qd, qdd)`` goes straight to C++ with no Python frame in
between. One sample is an (n,) array, a trajectory a (T, n) array; batches are looped in C++ with
the GIL released.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks as checks
from .. import _core
from . import linearization, operational_space, robot_fields

PARAMETER_FIELDS = ("m", "mx", "my", "mz", "Ixx", "Ixy", "Ixz", "Iyy", "Iyz", "Izz")


class Robot(_core.Model):
    """A serial arm described by a Denavit-Hartenberg table.

    Build one with :meth:`Robot.from_dh` or take one from :mod:`dynid.model.models`. The dynamics
    methods (``rnea``, ``mass_matrix``, ``gravity``, ``coriolis``, ``coriolis_matrix``,
    ``friction``, ``forward_dynamics``, ``kinetic_energy``, ``potential_energy``, ``fkine``,
    ``jacobian``, and docs/uses.md's ``rnea_derivatives``, ``jacobian_dot``, ``linearize``,
    ``cartesian_inertia``, ``cartesian_dynamics``) accept one sample (n,) or T samples (T, n).

    Every field (``name``, ``joint_names``, the DH table, gravity, ``base``, ``tool``, ``qlim``,
    ``params``, the drive terms, ``transmission``) is held by the C++ model;
    :mod:`dynid.model.robot_fields` lists them once for copies, pickles, equality, files and
    ``dynid info``.
    """

    @classmethod
    def from_dh(
        cls,
        dh: ArrayLike,
        joint_types: str | None = None,
        convention: str = "standard",
        gravity: ArrayLike = (0.0, 0.0, -9.81),
        params: ArrayLike | None = None,
        base: ArrayLike | None = None,
        tool: ArrayLike | None = None,
        qlim: ArrayLike | None = None,
        name: str | None = None,
        transmission: ArrayLike | None = None,
        joint_names: Sequence[str] | None = None,
    ) -> Robot:
        """Build a robot from a DH table.

        Parameters
        ----------
        dh
            (n, 4) rows ``[a, alpha, d, theta]``. For ``convention="modified"`` row i holds
            ``(a_{i-1}, alpha_{i-1}, d_i, theta_i)``. The joint variable adds to theta (revolute)
            or d (prismatic).
        joint_types
            One letter per joint, ``"R"`` or ``"P"``; default all revolute.
        convention
            ``"standard"`` (A = Rz Tz Tx Rx) or ``"modified"`` (A = Rx Tx Rz Tz).
        gravity
            Gravity acceleration in world coordinates.
        params
            Standard parameters, (n, 10) or (10n,); None means zeros.
        base, tool
            4x4 homogeneous transforms world -> frame 0 and frame n -> tool.
        qlim
            (n, 2) joint limits; default (-pi, pi) for revolute and (-1, 1) m for prismatic joints.
        name
            A label for printing.
        transmission
            (n, n) transmission coupling T, motor velocities theta_dot = T qd (coupled wrists;
            docs/transmission.md); None means the identity (decoupled drives).
        joint_names
            n distinct non-empty names, matched to the names of a log's joints (a ROS
            JointState, docs/data.md); None means ``q1``..``qn``.
        """
        expected = "dh: expected shape (n, 4) with rows [a, alpha, d, theta], got"
        try:
            shape = np.shape(dh)
        except ValueError:
            raise ValueError(f"{expected} a ragged sequence") from None
        if isinstance(dh, str) or len(shape) != 2:
            raise ValueError(f"{expected} {shape}")
        n = shape[0]
        if joint_types is None:
            joint_types = "R" * n
        joint_types = checks.text(joint_types, "joint_types", "a string of 'R'/'P'")
        convention = checks.text(convention, "convention", "'standard' or 'modified'")
        robot = cls(dh, joint_types.upper(), convention, gravity, base, tool)
        if params is not None:
            robot.params = params
        if qlim is not None:
            robot.qlim = qlim
        if name:
            robot.name = name
        if transmission is not None:
            robot.transmission = transmission
        if joint_names is not None:
            robot.joint_names = joint_names
        return robot

    @classmethod
    def from_urdf(
        cls,
        urdf: str | Path,
        base_link: str | None = None,
        tip_link: str | None = None,
        convention: str = "standard",
        gravity: ArrayLike = (0.0, 0.0, -9.81),
        check_physical: bool = True,
    ) -> Robot:
        """Build a robot from the serial chain of a URDF (docs/urdf.md).

        ``urdf`` is a path or the XML text. The chain runs from ``base_link`` (default: the root
        link) to ``tip_link`` (default: the single leaf reached through movable joints). Its
        revolute, continuous and prismatic joints are the n joints and **q is the URDF joint
        position** (same zero, same sign); fixed joints are merged. The DH table (``convention``)
        has z along each joint axis, theta/d offsets, and base and tool transforms such that
        ``fkine(q)`` is the pose of ``tip_link`` in ``base_link``'s frame (the world). Inertials
        become standard parameters in the DH frames, ``<limit>`` goes to ``qlim`` (continuous
        joints: (-pi, pi)), ``<dynamics damping friction>`` to ``Fv`` and ``Fs``, the joints' names
        to ``joint_names``.

        ValueError (naming the joint, link or argument) for malformed XML, a branched tree
        without ``tip_link``, floating, planar or mimic joints on the chain, more than 64 movable
        joints on it, an axis of zero length; and, unless ``check_physical=False``, for what
        :meth:`to_urdf` refuses: a moving body (a link with those fixed to it merged: a massless
        frame link such as ``tool0`` is fine) without m > 0 and an inertia about its centre of
        mass that is positive definite and satisfies the triangle inequalities, a joint with
        negative damping, friction or rotor inertia. ``check_physical=False`` reads such a file
        as it is, to repair it (``set_link``, ``params``, ``Fv``, ``Fs``).
        """
        from .urdf import dh_model_from_urdf  # on first use: import dynid stays fast

        model = dh_model_from_urdf(urdf, base_link, tip_link, convention, check_physical)
        robot = cls.from_dh(
            model.dh,
            model.joint_types,
            convention,
            gravity,
            model.params,
            model.base,
            model.tool,
            model.qlim,
            model.name,
            joint_names=model.joint_names,
        )
        robot.Ia, robot.Fv, robot.Fs = model.Ia, model.Fv, model.Fs
        robot.link_names = model.link_names
        robot.velocity_limits, robot.effort_limits = model.velocity_limits, model.effort_limits
        return robot

    def to_urdf(
        self, name: str = "robot", path: str | Path | None = None, overwrite: bool = False
    ) -> str:
        """The robot as URDF text (docs/urdf.md); with ``path`` also written there
        (atomically; an existing file only with ``overwrite=True``).

        One URDF link per DH link with its inertial about the centre of mass, joints with axis
        z, ``qlim`` as limits, Fv and Fs as ``<dynamics damping friction>``, the base and tool
        transforms as fixed placements, and Ia (no URDF field) as a ``dynid: Ia`` comment that
        :meth:`from_urdf` reads back. ValueError naming the first link that is not physically
        consistent or joint with negative Fv, Fs or Ia (the rule :meth:`from_urdf` applies), or
        naming ``transmission`` when the drives are coupled (URDF has no place for T; a model
        file keeps it).
        """
        from .urdf import urdf_text, write_urdf  # on first use: import dynid stays fast

        text = urdf_text(self, name)
        if path is not None:
            write_urdf(text, path, overwrite)
        return text

    def __repr__(self) -> str:
        return (
            f"Robot({getattr(self, 'name', '?')!r}, n={self.n}, joints={self.joint_types!r}, "
            f"convention={self.convention!r})"
        )

    # ---- parameters ---------------------------------------------------------------------------
    def set_link(self, i: int, mass: float, com: ArrayLike, inertia_com: ArrayLike) -> None:
        """Set link ``i`` (0-based) from its physical form.

        ``com`` is the centre of mass in DH frame i and ``inertia_com`` the 3x3 inertia tensor
        about the centre of mass in frame-i axes; Steiner's theorem gives the standard parameters.
        Raises ValueError unless m > 0 and the inertia is positive definite and satisfies the
        triangle inequalities.
        """
        i = checks.index(i, "i", self.n)
        try:
            mass_value = float(mass)
        except (TypeError, ValueError):
            raise ValueError(f"mass: expected a number, got {mass!r}") from None
        self._set_link_physical(int(i), mass_value, com, inertia_com)

    def is_physically_consistent(self) -> bool:
        """True when every link has m > 0 and an inertia about its centre of mass that is
        positive definite and satisfies the triangle inequalities."""
        return all(self._link_inconsistency(i) == "" for i in range(self.n))

    def parameter_vector(self, rotor: bool = False, friction: bool = False) -> NDArray[np.float64]:
        """The parameter vector pi matching the regressor's columns: the 10n standard parameters,
        then Ia (n) if ``rotor``, then Fv (n) and Fs (n) if ``friction``."""
        checks.flag(rotor, "rotor")
        checks.flag(friction, "friction")
        parts = [self.params.reshape(-1)]
        if rotor:
            parts.append(self.Ia)
        if friction:
            parts += [self.Fv, self.Fs]
        return np.concatenate(parts)

    def parameter_names(self, rotor: bool = False, friction: bool = False) -> list[str]:
        """Names of :meth:`parameter_vector`'s entries: m1, mx1, ..., Izz_n, Ia1.., Fv1.., Fs1.."""
        checks.flag(rotor, "rotor")
        checks.flag(friction, "friction")
        links = range(1, self.n + 1)
        names = [f"{field}{i}" for i in links for field in PARAMETER_FIELDS]
        if rotor:
            names += [f"Ia{i}" for i in links]
        if friction:
            names += [f"Fv{i}" for i in links] + [f"Fs{i}" for i in links]
        return names

    # ---- copies, pickling, equality (multiprocessing, Dask and Ray pickle what they send) -----
    # All three go over dynid.model.robot_fields.FIELDS, so that they cover every field.
    def _state(self) -> dict[str, Any]:
        """Everything that defines the robot (derived caches such as base parameters excluded)."""
        return robot_fields.state(self)

    def __reduce__(self) -> tuple[object, tuple[dict[str, Any]]]:
        return (_robot_from_state, (self._state(),))

    def __eq__(self, other: object) -> bool:
        """Every field the same (dynid.model.robot_fields: name, DH table, joint types, convention,
        gravity, transforms, limits, parameters, drive terms, transmission; exact comparison)."""
        if not isinstance(other, Robot):
            return NotImplemented
        return robot_fields.equal(self, other)

    # Unhashable (parameters are settable); mypy objects to None in place of the inherited method.
    __hash__ = None  # type: ignore[assignment]

    @property
    def coupled(self) -> bool:
        """True when the drives are coupled: a ``transmission`` other than the identity."""
        return not np.array_equal(self.transmission, np.eye(self.n))

    def copy(self) -> Robot:
        """An independent copy (every field of dynid.model.robot_fields)."""
        return _robot_from_state(self._state())

    def with_payload(self, mass: float, com: ArrayLike, inertia: ArrayLike | None = None) -> Robot:
        """A copy carrying a rigid payload on the last link (notes, "Rule of change in dynamic
        parameters").

        ``com`` is the payload's centre of mass in the last DH frame and ``inertia`` its inertia
        tensor about that centre of mass in frame-n axes (None: a point mass). Only link n's
        parameters change, additively: m_n + m_L, m_n c_n + m_L c_L and, with both tensors taken
        about the origin of frame n, I_n + I_L.
        """
        try:
            mass_value = float(mass)
        except (TypeError, ValueError):
            raise ValueError(f"mass: expected a number, got {mass!r}") from None
        if not (np.isfinite(mass_value) and mass_value > 0.0):
            raise ValueError(f"mass: a payload needs a positive, finite mass, got {mass!r}")
        if inertia is None:
            inertia = np.zeros((3, 3))
        else:
            inertia = _as_finite(inertia, "inertia")
            if inertia.shape != (3, 3):
                raise ValueError(f"inertia: expected shape (3, 3), got {inertia.shape}")
            why = _core.physical_inconsistency(mass_value, inertia)
            if why:
                raise ValueError(f"inertia: the payload is not physically possible: {why}")
        com = _as_finite(com, "com")
        payload = _core.standard_parameters(mass_value, com, inertia)
        other = self.copy()
        params = other.params.copy()
        with np.errstate(over="ignore", invalid="ignore"):
            params[-1] += payload
        if not np.all(np.isfinite(params[-1])):
            raise ValueError(
                "com: the payload's parameters about frame n overflow "
                "(m |com|^2 is not a finite number); check mass and com"
            )
        other.params = params
        return other

    def rigid_body(self) -> Robot:
        """A copy without drive terms (Ia = Fv = Fs = 0, transmission identity): the links alone,
        e.g. the link equation of an arm with elastic joints (paper eq. (7))."""
        other = self.copy()
        robot_fields.copy_group(robot_fields.defaults(self), other, "drive")
        return other

    # ---- uses of the model (docs/uses.md) ---------------------------------------------------
    def linearize(
        self, q: ArrayLike, qd: ArrayLike | None = None, qdd: ArrayLike | None = None
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(A, B) of the dynamics linearized at (q, qd, qdd), x = (q, qd), u = tau (notes
        p. 44-47): (2n, 2n), (2n, n), or (T, 2n, 2n), (T, 2n, n). qd, qdd default to zeros (an
        equilibrium). See :mod:`dynid.model.linearization`."""
        return linearization.linearize(self, q, qd, qdd)

    def cartesian_inertia(
        self, q: ArrayLike, rows: str | Sequence[int] | None = None
    ) -> NDArray[np.float64]:
        """Operational-space inertia (J M^-1 J^T)^-1 of the tool point, (6, 6) or (T, 6, 6);
        ``rows`` selects task rows ("position", "orientation" or indices). ValueError naming
        ``q`` at a singular configuration. See :mod:`dynid.model.operational_space`."""
        return operational_space.cartesian_inertia(self, q, rows)

    def cartesian_dynamics(
        self, q: ArrayLike, qd: ArrayLike, rows: str | Sequence[int] | None = None
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """(Lam, mu, p) with Lam xdd + mu + p = F, xdd = J qdd + Jdot qd (Khatib):
        mu = Lam (J M^-1 c - Jdot qd), p = Lam J M^-1 g. See
        :mod:`dynid.model.operational_space`."""
        return operational_space.cartesian_dynamics(self, q, qd, rows)

    def cartesian_coriolis_matrix(
        self, q: ArrayLike, qd: ArrayLike, rows: str | Sequence[int] | None = None
    ) -> NDArray[np.float64]:
        """S_p with mu = S_p xd and Lamdot - 2 S_p skew-symmetric (notes p. 49), for a square
        Jacobian (n task rows). See :mod:`dynid.model.operational_space`."""
        return operational_space.cartesian_coriolis_matrix(self, q, qd, rows)

    def random_configurations(self, count: int, seed: int | None = 0) -> NDArray[np.float64]:
        """``count`` configurations drawn uniformly within the joint limits, (count, n)."""
        count = checks.count(count, "count", 0, "a number of configurations")
        rng = np.random.default_rng(seed)
        low, high = self.qlim[:, 0], self.qlim[:, 1]
        return low + (high - low) * rng.random((count, self.n))


def _robot_from_state(state: dict[str, Any]) -> Robot:
    """Rebuild a pickled robot (see ``Robot.__reduce__``); fields absent from ``state`` (pickled
    before they existed, e.g. ``transmission``) keep their defaults."""
    robot: Robot = robot_fields.restore(Robot, state)
    return robot


def _as_finite(value: ArrayLike, name: str) -> NDArray[np.float64]:
    try:
        array = np.array(value, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"{name}: expected an array of real numbers, got {value!r}") from None
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name}: contains NaN or inf")
    return array
