"""Whether the data support the standard deviations reported for the drive gains: a block
jackknife over the recording.

The standard deviations of :func:`dynid.identify_drive_gains` come from the fit's likelihood:
right when the model holds and the current noise is white. A torque the model misses (friction
near zero velocity, a Stribeck peak, cogging) biases the gains by more than them and leaves no
trace in them: on a UR5 with Stribeck friction and the default preparation the gains were off
by up to 7 of their standard deviations (docs/drive_gains.md, "Checking the standard deviations").
Residual whiteness tests did not see it: the missing torque is smooth along the motion.

The block jackknife (Kuensch, Ann. Statist. 17(3), 1989) estimates the gains again without each
of B contiguous blocks of samples in turn, x_(b); the spread of these estimates,

    std_J = sqrt((B - 1) / B * sum_b (x_(b) - mean_b x_(b))^2),

follows how the estimate actually varies along the recording -- unmodelled terms, correlated
noise and all -- and equals the likelihood's standard deviation, up to its sampling error, when
the model holds. Each refit starts from the whole fit on the blocks' triangular factors
(``dynid.identification._qr``), so the check never returns to the samples.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from ._qr import GroupedTriangularFactors
from .identify import RankDeficientError

#: Blocks of the jackknife over all runs (at least 2 per run, so that leaving one out keeps
#: every run, the loaded ones included, in the fit).
BLOCKS = 8
#: std_J / std above which the reported deviations are called overconfident. With 8 blocks
#: std_J has 7 degrees of freedom: under a correct model the ratio exceeds 3 with probability
#: below 1e-9 (chi-square); measured on simulated UR5 runs with the true friction model it was
#: 0.8-2.3, with unmodelled Stribeck friction 3.1-9.4 (docs/drive_gains.md).
RATIO_LIMIT = 3.0
#: A spread below this fraction of the estimate is rounding (noise-free data: both deviations
#: are ~1e-13 relative and their ratio means nothing).
ROUNDING = 1e-9


def block_edges(samples: int, blocks: int) -> list[tuple[int, int]]:
    """[start, stop) of ``blocks`` contiguous blocks of nearly equal size covering the samples."""
    edges = np.linspace(0, samples, blocks + 1).astype(int)
    return [(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:]) if b > a]


def jackknife_std(
    blocks: list[GroupedTriangularFactors],
    refit: Callable[[GroupedTriangularFactors], NDArray[np.float64]],
) -> NDArray[np.float64] | None:
    """The block-jackknife standard deviation of the estimate ``refit`` returns, or None when
    leaving a block out leaves data that fix no estimate (too few blocks, a rank-deficient or
    diverging refit)."""
    if len(blocks) < 2:
        return None
    estimates = []
    for b in range(len(blocks)):
        rest = GroupedTriangularFactors.merged(blocks[:b] + blocks[b + 1 :])
        try:
            estimates.append(refit(rest))
        except RankDeficientError:
            return None
    x = np.array(estimates)
    count = len(blocks)
    return np.sqrt((count - 1) / count * np.sum((x - x.mean(axis=0)) ** 2, axis=0))


def overconfidence(
    names: list[str],
    values: NDArray[np.float64],
    std: NDArray[np.float64],
    spread: NDArray[np.float64] | None,
    method: str,
) -> str | None:
    """A warning's text when the jackknife spread of ``values`` exceeds RATIO_LIMIT times their
    reported standard deviation for some of ``names`` (a spread above rounding), else None."""
    if spread is None:
        return None
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(std > 0, spread / std, np.inf)
    ratio[spread <= ROUNDING * np.abs(values)] = 0.0
    worst = [k for k in np.argsort(-ratio) if ratio[k] > RATIO_LIMIT]
    if not worst:
        return None
    listed = ", ".join(f"{names[k]} {ratio[k]:.1f}x" for k in worst)
    return (
        f"the estimates vary along the recording more than their standard deviations say "
        f"(block jackknife over {BLOCKS} blocks: {listed}): the model misses a torque the data "
        "hold, e.g. friction near zero velocity (try preparation min_velocity / --min-velocity, "
        "or friction/offset columns)"
        + ("" if method == "nls" else f", or the bias of method {method!r} (use 'nls')")
        + "; read the gains' errors from gains_std_blocks, not gains_std"
    )
