"""The KUKA LWR4+ logs of FloBaRoID (tests/data/measurements_{1,2}.npz) as the real-data tests read
them: the first SKIP samples are the start-up transient (docs/real_data.md)."""

from __future__ import annotations

from pathlib import Path

from dynid.io import Log, load_log

DATA = Path(__file__).parent / "data"
SKIP = 500


def lwr4_logs() -> tuple[Log, Log]:
    """(training log, validation log)."""
    return (
        load_log(DATA / "measurements_1.npz", skip=SKIP),
        load_log(DATA / "measurements_2.npz", skip=SKIP),
    )
