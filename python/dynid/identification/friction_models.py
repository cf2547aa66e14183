"""Joint friction models of the identification regressor: none, symmetric, asymmetric.

The symmetric model is the lecture's (Robotics 2 notes p. 11, "Adding dynamic terms":
viscous and dry friction at the joints; the paper neglects friction in its link equations):
tau_f,j = Fv_j qd_j + Fs_j sign(qd_j), columns of :meth:`dynid.Robot.regressor`
(``friction=True``) and drive terms of the robot. The asymmetric model lets each coefficient
depend on the direction of motion; its viscous part is FloBaRoID's asymmetric viscous friction
("identifySymmetricVelFriction: 0": Fv+ for qd > 0, Fv- for qd < 0, both >= 0 in its SDP), and
the Coulomb level is split the same way:

    tau_f,j = Fv_j+ max(qd_j, 0) + Fv_j- min(qd_j, 0) + Fs_j+ [qd_j > 0] - Fs_j- [qd_j < 0]

Four linear columns per joint, in row j only; every coefficient is >= 0 for a friction that
dissipates (tau_f,j qd_j >= 0), which the physically consistent fit imposes. At qd_j = 0 the
model gives 0, as sign(0) = 0 does in the symmetric one. With symmetric friction
(Fv+ = Fv- = Fv, Fs+ = Fs- = Fs) it is the symmetric model.

Asymmetric Coulomb friction and a constant torque offset are the same columns on every moving
sample: [qd > 0] + [qd < 0] = 1, so off + Fs+ [qd > 0] - Fs- [qd < 0] is
(off + c) + (Fs+ - c) [qd > 0] - (Fs- + c) [qd < 0] for any c, and a fit with both is rank
deficient (only samples at exactly qd_j = 0, where this model says friction is 0 and real
stiction is anything in [-Fs-, Fs+], would separate them). With ``offset=True`` the asymmetric
model therefore keeps one symmetric Coulomb column, Fs_j sign(qd_j), and the offset carries the
asymmetry: while moving, the constant torque is off_j + Fs_j forwards and off_j - Fs_j
backwards, i.e. Fs+ - Fs- = 2 off_j as in the symmetric model with offsets
(docs/identification.md, "Friction models"). In the physically consistent fit the two forms
also have the same feasible set: Fs+, Fs- >= 0 with a free offset allows exactly the forward
level >= the backward level, as Fs >= 0 with a free offset does.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .. import _core

#: Suffixes of the asymmetric coefficients' names: "Fv1+" (qd > 0), "Fv1-" (qd < 0).
POSITIVE, NEGATIVE = "+", "-"


def asymmetric_count(n: int, offset: bool) -> int:
    """Number of asymmetric friction columns of an n-joint robot: 4 n (Fv+, Fv-, Fs+, Fs-), or
    3 n (Fv+, Fv-, Fs) with offsets (module docstring)."""
    return (3 if offset else 4) * n


def asymmetric_columns(qd: NDArray[np.float64], offset: bool) -> NDArray[np.float64]:
    """(T, n, 4 n) columns of the asymmetric friction model for joint velocities ``qd`` (T, n):
    blocks of n columns max(qd_j, 0) (Fv+), min(qd_j, 0) (Fv-), [qd_j > 0] (Fs+) and
    -[qd_j < 0] (Fs-), each in row j only; with ``offset`` (T, n, 3 n): Fv+, Fv-, then
    sign(qd_j) (Fs). The law's one home is the C++ core (``dynid::asymmetric_friction_regressor``,
    cpp/src/friction.cpp), looped over the samples there."""
    qd = np.asarray(qd, dtype=float)
    if qd.ndim == 1:
        qd = qd[None]
    columns: NDArray[np.float64] = _core._asymmetric_friction_columns(qd, bool(offset))
    return columns


def asymmetric_names(n: int, offset: bool) -> tuple[list[str], list[str]]:
    """Names and expressions of the coefficients of :func:`asymmetric_columns`: "Fv1+" ...,
    "Fv1-" ..., then "Fs1+" ..., "Fs1-" ... (or "Fs1" ... with ``offset``)."""
    joints = range(1, n + 1)
    names = [f"Fv{j}{POSITIVE}" for j in joints] + [f"Fv{j}{NEGATIVE}" for j in joints]
    expressions = [f"viscous friction of joint {j} for qd{j} > 0" for j in joints]
    expressions += [f"viscous friction of joint {j} for qd{j} < 0" for j in joints]
    if offset:
        names += [f"Fs{j}" for j in joints]
        expressions += [
            f"Coulomb friction of joint {j}, mean of both directions (Fs+ - Fs- = 2 off{j})"
            for j in joints
        ]
    else:
        names += [f"Fs{j}{POSITIVE}" for j in joints] + [f"Fs{j}{NEGATIVE}" for j in joints]
        expressions += [f"Coulomb friction of joint {j} for qd{j} > 0" for j in joints]
        expressions += [f"Coulomb friction of joint {j} for qd{j} < 0" for j in joints]
    return names, expressions
