"""The robot's fields, listed once.

Every field of a :class:`dynid.Robot` is held by the C++ Model (``cpp/include/dynid/model.hpp``,
a property of ``dynid._core.Model``); the Python class keeps no state of its own, only derived
caches (the base parameters). ``FIELDS`` says for each field what the workflow around the model
needs to know, and everything that goes over all of the robot's fields is derived from it:

- copies, pickles and equality (:mod:`dynid.model.robot`, through ``state``, ``restore`` and
  ``equal`` below);
- model files and the model record of result files (:mod:`dynid.model.model_files`);
- the cache key of the base-parameter structure (:mod:`dynid.model.base_parameters`);
- ``dynid info`` (:mod:`dynid.export.summary`);
- the drive terms that ``rigid_body`` resets and ``link_frames`` carries over (``group``).

Adding a field to the robot means adding it to the C++ Model (member, setter with its argument
check, default in the constructor), its property in ``cpp/bindings/model.cpp``, and one entry
here; ``tests/test_robot_fields.py`` then fails until it has a non-default value to try.

The table holds no robot: defaults are the C++ Model's (``defaults`` builds a fresh model with the
same structure), so that they are written down once too.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

#: Groups of fields. ``structure``: the constructor's arguments, fixed for the robot's life (they
#: decide n and the joint frames); ``label``; ``placement`` (gravity, base and tool transforms);
#: ``limits``; ``links`` (the standard inertial parameters); ``drive`` (the drive terms);
#: ``recording`` (how a motor-side log maps to the joints: no algorithm reads it).
GROUPS = ("structure", "label", "placement", "limits", "links", "drive", "recording")
#: How ``dynid info`` shows a field (:mod:`dynid.export.summary` has one layout per value):
#: ``title``, the first line; ``joint table``, the DH table itself; ``joint columns``, columns
#: of the DH table (one per ``label`` word); ``names``, one line of n words after the ``label``;
#: ``transform``, a 4 x 4 matrix on one line; ``links``, the parameter table; ``per joint``, one
#: line of n numbers; ``matrix``, a titled block of rows.
LAYOUTS = (
    "title",
    "joint table",
    "joint columns",
    "names",
    "transform",
    "links",
    "per joint",
    "matrix",
)


#: Flags a field may carry. ``required``: a model file must hold it. ``omit_default``: model
#: files and ``dynid info`` leave it out while it has its default value. ``identified``: the
#: identification estimates it, so a least-squares result's model record leaves it out (its value
#: in the model was a prior, no part of the identified model). ``structural``: the base-parameter
#: structure (docs/base_parameters.md, "Base parameters") depends on it, so it is part of the
#: structure's cache key.
FLAGS = ("required", "omit_default", "identified", "structural")


@dataclass(frozen=True)
class RobotField:
    """One field of the robot: where it lives, how files hold it, how ``dynid info`` shows it."""

    #: Its name in pickled state and in model and result files; the Robot's property unless
    #: ``attribute`` says otherwise.
    key: str
    #: "text" (a string), "names" (a tuple of ``shape`` strings; a list in files), "array"
    #: (float64 of ``shape``), "limits" (float64 of ``shape``, each > 0 or inf for no limit;
    #: null in files) or "dh" (the DH table, (n, 4): model files hold it as rows of named
    #: values, :mod:`dynid.model.model_files`).
    kind: str
    #: Shape of an array; "n" stands for the number of joints.
    shape: tuple[int | str, ...]
    #: See ``GROUPS``.
    group: str
    #: Space-separated ``FLAGS``.
    flags: str
    #: See ``LAYOUTS``.
    shown: str
    #: ``dynid info`` text: the columns' headings (``joint columns``) or the block's title.
    label: str = ""
    #: The Robot's property, when not ``key`` (``gravity`` is ``gravity_vector``: ``gravity``
    #: is the method g(q)).
    attribute_name: str = ""
    #: Its name in model files, when not ``key`` (the DH table is ``rows``).
    file_name: str = ""

    def __post_init__(self) -> None:
        unknown = set(self.flags.split()) - set(FLAGS)
        if unknown or self.group not in GROUPS or self.shown not in LAYOUTS:
            raise ValueError(f"field {self.key!r}: unknown flag, group or layout")

    @property
    def attribute(self) -> str:
        return self.attribute_name or self.key

    @property
    def file_key(self) -> str:
        return self.file_name or self.key

    @property
    def settable(self) -> bool:
        """Set after construction (everything but the structure)."""
        return self.group != "structure"

    @property
    def required(self) -> bool:
        return "required" in self.flags.split()

    @property
    def omit_default(self) -> bool:
        return "omit_default" in self.flags.split()

    @property
    def identified(self) -> bool:
        return "identified" in self.flags.split()

    @property
    def structural(self) -> bool:
        return "structural" in self.flags.split()

    def shape_for(self, n: int) -> tuple[int, ...]:
        return tuple(n if size == "n" else int(size) for size in self.shape)


# In the order model files list them. Defaults are the C++ Model's (see ``defaults``).
# fmt: off
FIELDS: tuple[RobotField, ...] = (
    #          key             kind     shape       group        flags            dynid info
    RobotField("name",         "text",  (),         "label",     "",              "title"),
    RobotField("convention",   "text",  (),         "structure", "required structural", "title"),
    RobotField("joint_types",  "text",  (),         "structure", "structural",    "title"),
    RobotField("gravity",      "array", (3,),       "placement", "structural",    "title",
               attribute_name="gravity_vector"),
    RobotField("dh",           "dh",    ("n", 4),   "structure", "required structural",
               "joint table", file_name="rows"),
    RobotField("base",         "array", (4, 4),     "placement", "omit_default structural",
               "transform"),
    RobotField("tool",         "array", (4, 4),     "placement", "omit_default",  "transform"),
    # Logs that name their joints (a ROS JointState) are matched to these (docs/data.md).
    RobotField("joint_names",  "names", ("n",),     "label",     "omit_default",  "names",
               label="joint names"),
    # The URDF and MJCF writers name the bodies by these (a URDF's own through from_urdf).
    RobotField("link_names",   "names", ("n",),     "label",     "omit_default",  "names",
               label="link names"),
    RobotField("qlim",         "array", ("n", 2),   "limits",    "",              "joint columns",
               label="qmin qmax"),
    # inf: not known, not limited (the default); files write it as null (dynid.model.model_files).
    RobotField("velocity_limits", "limits", ("n",), "limits",    "omit_default",  "per joint",
               label="velocity limits [rad/s, m/s]"),
    RobotField("effort_limits", "limits", ("n",),   "limits",    "omit_default",  "per joint",
               label="effort limits [N m, N]"),
    RobotField("params",       "array", ("n", 10),  "links",     "identified",    "links"),
    RobotField("Ia",           "array", ("n",),     "drive",     "identified",    "per joint"),
    RobotField("Fv",           "array", ("n",),     "drive",     "identified",    "per joint"),
    RobotField("Fs",           "array", ("n",),     "drive",     "identified",    "per joint"),
    # structural: T couples the drive columns of the regressor (docs/transmission.md).
    RobotField("transmission", "array", ("n", "n"), "drive",     "omit_default structural",
               "matrix", label="transmission T (motor velocities T qd; Ia, Fv, Fs per motor)"),
    # A motor-side log: q = R^-1 theta - joint_offsets, tau = R^T tau_m, R = diag(gear_ratios) T
    # (docs/data.md, "Motor-side logs"; dynid.logs.motor_side). Not structural: the regressor
    # is in joint units.
    RobotField("gear_ratios",  "array", ("n",),     "recording", "omit_default",  "per joint"),
    RobotField("joint_offsets", "array", ("n",),    "recording", "omit_default",  "per joint"),
)
# fmt: on

#: The constructor's arguments, by ``key`` (= the binding's argument names).
STRUCTURE = tuple(f for f in FIELDS if not f.settable)
#: Everything set after construction, in the order files list it.
SETTABLE = tuple(f for f in FIELDS if f.settable)


def state(robot: Any) -> dict[str, Any]:
    """Every field's value by key: what defines the robot (derived caches excluded)."""
    return {f.key: getattr(robot, f.attribute) for f in FIELDS}


def construct(cls: Any, values: dict[str, Any]) -> Any:
    """A ``cls`` (Robot or the C++ Model) with the structure of ``values`` (keys of STRUCTURE)
    and every other field at its default."""
    return cls(**{f.key: values[f.key] for f in STRUCTURE})


def restore(cls: Any, values: dict[str, Any]) -> Any:
    """A ``cls`` from ``state``'s dict; a settable field absent from it (state pickled before
    the field existed) or None keeps its default."""
    robot = construct(cls, values)
    for f in SETTABLE:
        if values.get(f.key) is not None:
            setattr(robot, f.attribute, values[f.key])
    return robot


def defaults(robot: Any) -> Any:
    """A model with ``robot``'s structure and every other field at the C++ Model's default."""
    return construct(type(robot), state(robot))


def equal(a: Any, b: Any) -> bool:
    """Every field the same (exact comparison)."""
    return all(_same(getattr(a, f.attribute), getattr(b, f.attribute)) for f in FIELDS)


def is_default(robot: Any, field: RobotField, fresh: Any) -> bool:
    """Whether ``robot``'s ``field`` has the value it has in ``fresh`` (from ``defaults``)."""
    return _same(getattr(robot, field.attribute), getattr(fresh, field.attribute))


def copy_group(source: Any, target: Any, group: str) -> None:
    """Set ``target``'s fields of ``group`` to ``source``'s."""
    if group not in GROUPS or group == "structure":
        raise ValueError(f"group: expected one of {GROUPS[1:]}, got {group!r}")
    for f in SETTABLE:
        if f.group == group:
            setattr(target, f.attribute, getattr(source, f.attribute))


def structure_key(robot: Any) -> tuple[Any, ...]:
    """The values the base-parameter structure depends on, hashable (arrays as bytes)."""
    values = (getattr(robot, f.attribute) for f in FIELDS if f.structural)
    return tuple(v.tobytes() if isinstance(v, np.ndarray) else v for v in values)


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return bool(np.array_equal(a, b))
    return bool(a == b)
