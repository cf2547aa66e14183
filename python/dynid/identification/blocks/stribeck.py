"""The smooth Stribeck friction block: Coulomb, stiction and viscous levels per joint and per
direction of motion, with a velocity scale for the smooth sign and one for the Stribeck dip.

The law, on the velocity w_k of drive k (w = T qd, T the robot's transmission; w = qd for
decoupled drives), is the static Stribeck curve with a Gaussian decay of Armstrong-Helouvry,
Dupont and Canudas de Wit (Automatica 30(7), 1994, eq. (2): "exponential model" with exponent
2) and of Olsson et al. (Eur. J. Control 4, 1998, eq. (7), g(v) = Fc + (Fs - Fc) e^{-(v/vs)^2}),
its sign(w) made smooth by tanh(w / vc) as in the simulators' Coulomb law
(docs/conventions.md, "Where the laws live"):

    tau_f,k = [Fc_k (1 - e_k) + Fst_k e_k] tanh(w_k / vc_k) + Fv_k w_k,   e_k = exp(-(w_k/vs_k)^2)

with Fc, Fst, Fv taken per direction (the "+" coefficient where w_k > 0, the "-" one where
w_k < 0), as the asymmetric block does (:mod:`dynid.identification.friction_models`). Written
this way, Fc (1 - e) + Fst e is the textbook Fc + (Fst - Fc) e, and the two levels are linear
coefficients whose columns, (1 - e) tanh and e tanh, have the sign of w: friction dissipates
(tau_f w >= 0 at every w) exactly when Fc, Fst, Fv >= 0 (the bracket is a convex combination
of Fc and Fst), which is what the physically consistent fit imposes. At w = 0 the law gives 0.

With ``offset`` the Coulomb and stiction levels are one per joint (Fc sign-ish + off: the
offset carries their asymmetry, as in the asymmetric block; both at once are near-collinear,
|tanh(w / vc)| being 1 on every sample faster than a few vc).

The 2 n nonlinear parameters vc_k, vs_k (rad/s, or m/s for a prismatic joint) are estimated on
the training data by separable least squares (:mod:`dynid.identification.separable`); the block
records them in result.json (``options.stribeck``) with their standard deviations, and the
prediction uses them. The law's one home is this module: no C++ algorithm (RNEA, simulators)
models Stribeck friction, so it has no copy in the core.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .base import Block, Context, Nonlinear

#: Starting velocity scales (rad/s) before the estimate: a smooth sign over ~1 % of a typical
#: joint speed of 1 rad/s, a Stribeck dip over ~10 %.
START_VC, START_VS = 0.01, 0.1
#: The (vc, vs) pairs the estimate starts from, each for every drive (the first the block's
#: values): the objective has local minima where vs is below or above every speed of a drive.
STARTS = ((START_VC, START_VS), (0.003, 0.03), (0.03, 0.3), (0.003, 0.3))
#: Bounds of both scales (rad/s): below 1e-3 rad/s tanh(w / vc) is sign(w) on every sample of a
#: sampled log and e = 0 on every moving one (the stiction column vanishes); above 1 rad/s the
#: "dip" spans the whole speed range and Fc has no column left.
LOWER, UPPER = 1e-3, 1.0
#: The suffixes of the per-direction coefficients, as in the asymmetric block.
POSITIVE, NEGATIVE = "+", "-"


@dataclass(frozen=True)
class StribeckFriction(Block):
    """Per drive: Fc+, Fc-, Fst+, Fst-, Fv+, Fv- (``offset``: Fc, Fst, Fv+, Fv-), all >= 0 in
    the physical fit; nonlinear vc_k, vs_k (module docstring)."""

    key = "stribeck_friction"
    friction_model = "stribeck"
    version = 3
    n: int
    offset: bool
    transmission: tuple[tuple[float, ...], ...]  #: T, motor velocities w = T qd
    vc: tuple[float, ...]
    vs: tuple[float, ...]
    vc_std: tuple[float, ...]
    vs_std: tuple[float, ...]
    estimated: bool = False

    @classmethod
    def build(cls, context: Context) -> StribeckFriction | None:
        if context.friction != cls.friction_model:
            return None
        n = context.robot.n
        T = tuple(tuple(float(x) for x in row) for row in np.asarray(context.robot.transmission))
        unknown = (float("inf"),) * n  # no standard deviation before the estimate
        return cls(n, context.offset, T, (START_VC,) * n, (START_VS,) * n, unknown, unknown)

    @classmethod
    def from_record(cls, options: Mapping[str, Any], n: int) -> StribeckFriction | None:
        if options.get("friction_model") != cls.friction_model:
            return None
        entry = options.get("stribeck")
        if not isinstance(entry, Mapping):
            raise ValueError(
                "options.stribeck: expected the Stribeck friction's velocity scales "
                f"(vc, vs, vc_std, vs_std, transmission), got {entry!r}"
            )
        values = {}
        for key in ("vc", "vs", "vc_std", "vs_std"):
            values[key] = _numbers(entry.get(key), f"options.stribeck.{key}", n)
        for key in ("vc", "vs"):
            if not all(LOWER <= v <= UPPER for v in values[key]):
                raise ValueError(
                    f"options.stribeck.{key}: expected values in [{LOWER:g}, {UPPER:g}], "
                    f"got {list(values[key])}"
                )
        rows = entry.get("transmission")
        if not isinstance(rows, list) or len(rows) != n:
            raise ValueError(f"options.stribeck.transmission: expected {n} rows, got {rows!r}")
        T = tuple(_numbers(row, "options.stribeck.transmission", n) for row in rows)
        return cls(
            n,
            options.get("offset") is True,
            T,
            values["vc"],
            values["vs"],
            values["vc_std"],
            values["vs_std"],
            entry.get("estimated") is True,
        )

    def record(self) -> dict[str, Any]:
        return {
            "friction_model": self.friction_model,
            "stribeck": {
                "vc": list(self.vc),
                "vs": list(self.vs),
                "vc_std": [_json(x) for x in self.vc_std],
                "vs_std": [_json(x) for x in self.vs_std],
                "estimated": self.estimated,
                "transmission": [list(row) for row in self.transmission],
            },
        }

    def names(self) -> list[str]:
        return _names(self.n, self.offset)[0]

    def expressions(self) -> list[str]:
        return _names(self.n, self.offset)[1]

    def nonnegative(self) -> NDArray[np.bool_]:
        return np.ones(self.size, dtype=bool)  # friction dissipates (module docstring)

    def describe(self) -> str:
        return f"{self.size} Stribeck friction coefficients (+ {2 * self.n} velocity scales)"

    # ------------------------------------------------------------------ the law

    def _motor(self, qd: NDArray[np.float64]) -> NDArray[np.float64]:
        """(T, n) the drives' velocities w = T qd."""
        return np.asarray(qd, dtype=float) @ np.asarray(self.transmission).T

    def _to_joints(self, motor: NDArray[np.float64]) -> NDArray[np.float64]:
        """(..., T, n, size) columns of the drives' rows mapped to the joints' rows, T^T C
        (the drive torques' virtual work, as the regressor's friction columns;
        docs/transmission.md)."""
        return np.einsum("kj,...tks->...tjs", np.asarray(self.transmission), motor)

    def _parts(
        self, w: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """tanh(w / vc), e = exp(-(w / vs)^2) and w, each (T, n)."""
        vc, vs = np.asarray(self.vc), np.asarray(self.vs)
        return np.tanh(w / vc), np.exp(-((w / vs) ** 2)), w

    def _assemble(
        self,
        w: NDArray[np.float64],
        coulomb: NDArray[np.float64],
        stiction: NDArray[np.float64],
        viscous: NDArray[np.float64],
    ) -> NDArray[np.float64]:
        """(T, n, size) drive-row columns from the per-drive values of the Coulomb, stiction
        and viscous columns (T, n), split by direction (one column each with ``offset`` for the
        first two)."""
        T, n = w.shape
        up, down = w > 0, w < 0
        if self.offset:
            groups = [coulomb, stiction]
        else:
            groups = [coulomb * up, coulomb * down, stiction * up, stiction * down]
        groups += [viscous * up, viscous * down]
        out = np.zeros((T, n, len(groups) * n))
        rows = np.arange(n)
        for g, values in enumerate(groups):
            out[:, rows, g * n + rows] = values
        return out

    def columns(self, q: NDArray[np.float64], qd: NDArray[np.float64]) -> NDArray[np.float64]:
        w = self._motor(np.asarray(qd, dtype=float).reshape(np.shape(q)))
        smooth, e, _ = self._parts(w)
        return self._to_joints(self._assemble(w, (1 - e) * smooth, e * smooth, w))

    def nonlinear(self) -> Nonlinear:
        n = self.n
        return Nonlinear(
            names=tuple(f"vc{j}" for j in range(1, n + 1))
            + tuple(f"vs{j}" for j in range(1, n + 1)),
            values=self.vc + self.vs,
            lower=(LOWER,) * 2 * n,
            upper=(UPPER,) * 2 * n,
            std=self.vc_std + self.vs_std,
            estimated=self.estimated,
            starts=(
                self.vc + self.vs,
                *((vc,) * n + (vs,) * n for vc, vs in STARTS if (vc, vs) != (START_VC, START_VS)),
            ),
        )

    def with_parameters(
        self, values: NDArray[np.float64], std: NDArray[np.float64]
    ) -> StribeckFriction:
        values, std = np.asarray(values, dtype=float), np.asarray(std, dtype=float)
        if values.shape != (2 * self.n,) or std.shape != (2 * self.n,):
            raise ValueError(
                f"values, std: expected {2 * self.n} velocity scales (vc then vs), got "
                f"{values.shape} and {std.shape}"
            )
        if not np.all((values >= LOWER) & (values <= UPPER)):
            raise ValueError(f"values: expected velocity scales in [{LOWER:g}, {UPPER:g}]")
        n = self.n
        return replace(
            self,
            vc=tuple(values[:n].tolist()),
            vs=tuple(values[n:].tolist()),
            vc_std=tuple(std[:n].tolist()),
            vs_std=tuple(std[n:].tolist()),
            estimated=True,
        )

    def torque_derivatives(
        self,
        q: NDArray[np.float64],
        qd: NDArray[np.float64],
        coefficients: NDArray[np.float64],
    ) -> NDArray[np.float64]:
        """d/d log vc_k and d/d log vs_k of the block's torque: with x = w / vc,
        v d tanh(w / v)/dv = -x (1 - tanh^2 x); with y = w / vs, v d e/dv = 2 y^2 e. The
        parameters of drive k change drive k's friction only, which acts on the joints through
        row k of T (T^T e_k)."""
        w = self._motor(np.asarray(qd, dtype=float).reshape(np.shape(q)))
        smooth, e, _ = self._parts(w)
        d_smooth = -(w / np.asarray(self.vc)) * (1 - smooth**2)  # by log vc
        d_e = 2 * (w / np.asarray(self.vs)) ** 2 * e  # by log vs
        coulomb, stiction = self._levels(w, np.asarray(coefficients, dtype=float))
        by_vc = (coulomb * (1 - e) + stiction * e) * d_smooth  # (T, n): drive k's friction
        by_vs = (stiction - coulomb) * d_e * smooth
        T = np.asarray(self.transmission)
        out = np.concatenate([by_vc, by_vs], axis=1).T  # (2 n, T)
        return out[:, :, None] * np.concatenate([T, T])[:, None, :]

    def _levels(
        self, w: NDArray[np.float64], coefficients: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """(T, n) Fc and Fst of each drive at each sample: the coefficient of the direction of
        w (either one where w = 0, where the law is 0)."""
        n = self.n
        if coefficients.shape != (self.size,):
            raise ValueError(
                f"coefficients: expected {self.size} values, got shape {coefficients.shape}"
            )
        if self.offset:
            return np.broadcast_to(coefficients[:n], w.shape), np.broadcast_to(
                coefficients[n : 2 * n], w.shape
            )
        up = w > 0
        c = coefficients
        return np.where(up, c[:n], c[n : 2 * n]), np.where(up, c[2 * n : 3 * n], c[3 * n : 4 * n])


def _names(n: int, offset: bool) -> tuple[list[str], list[str]]:
    joints = range(1, n + 1)
    names: list[str] = []
    expressions: list[str] = []
    levels = (("Fc", "Coulomb friction"), ("Fst", "stiction (Stribeck) level"))
    for symbol, what in levels:
        if offset:
            names += [f"{symbol}{j}" for j in joints]
            expressions += [f"{what} of drive {j}, both directions" for j in joints]
            continue
        for suffix, side in ((POSITIVE, "> 0"), (NEGATIVE, "< 0")):
            names += [f"{symbol}{j}{suffix}" for j in joints]
            expressions += [f"{what} of drive {j} for its velocity {side}" for j in joints]
    for suffix, side in ((POSITIVE, "> 0"), (NEGATIVE, "< 0")):
        names += [f"Fv{j}{suffix}" for j in joints]
        expressions += [f"viscous friction of drive {j} for its velocity {side}" for j in joints]
    return names, expressions


def _numbers(value: Any, name: str, n: int) -> tuple[float, ...]:
    """``n`` numbers (JSON null read as inf: no finite standard deviation, as the
    coefficients' std in result.json)."""
    if not isinstance(value, list) or len(value) != n:
        raise ValueError(f"{name}: expected a list of {n} numbers, got {value!r}")
    out = []
    for x in value:
        if x is None:
            out.append(float("inf"))
        elif isinstance(x, (int, float)) and not isinstance(x, bool):
            out.append(float(x))
        else:
            raise ValueError(f"{name}: expected a list of {n} numbers, got {value!r}")
    return tuple(out)


def _json(x: float) -> float | None:
    return float(x) if np.isfinite(x) else None
