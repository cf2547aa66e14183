"""examples/estimators_real_data.py: the criterion and the tables it writes, on hand-made rows
(the real runs need the TX40 recording, which is not in the repository), checked against the
criterion computed by hand."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

EXAMPLE = Path(__file__).parent.parent / "examples" / "estimators_real_data.py"


@pytest.fixture(scope="module")
def example():
    sys.path.insert(0, str(EXAMPLE.parent))
    spec = importlib.util.spec_from_file_location("estimators_real_data", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def row(data, method, fit, error, refused=""):
    r = {"data": data, "method": method, "fit": fit, "relative_rms_percent": error, "seconds": 0.1}
    if refused:
        r["refused"] = refused
    return r


def test_criterion_and_tables(example):
    tx = "TX40, rest velocity auto"
    rows = [
        row(tx, "a", "unconstrained", [10, 20, 30, 40, 50, 60]),
        row(tx, "a", "physical", [11, 20, 30, 40, 50, 60]),  # 1.10 on J1: within
        row(tx, "b", "unconstrained", [10, 20, 30, 40, 50, 70]),  # J6 above FIGAROH's 65
        row(tx, "b", "physical", [10, 20, 30, 40, 50, 77.7]),  # 1.11 on J6: not within
        row("LWR4+", "a", "unconstrained", [10, 1, 5, 2, 20, 30, 20]),
        row("LWR4+", "a", "physical", [12.5, 1, 5, 2, 20, 30, 80]),  # A7 not counted
        row("LWR4+", "b", "unconstrained", None, "period: log 1 (x) is not periodic: ...; ..."),
        row("LWR4+", "b", "physical", None, "period: log 1 (x) is not periodic: ...; ..."),
    ]
    peers = {"one": [12, 25, 35, 45, 55, 65], "two": [11, 30, 31, 41, 60, 99]}
    check = example.criterion(rows, peers)
    assert check["a"]["tx40_within_figaroh"] is True
    assert check["b"]["tx40_within_figaroh"] is False
    assert check["a"][f"{tx}: within 1.1"] is True
    assert check["b"][f"{tx}: within 1.1"] is False
    assert check["a"]["LWR4+: within 1.25"] is True
    assert "LWR4+: within 1.25" not in check["b"]
    text = example.markdown(rows, peers, check)
    assert "| b | physical | refused: log 1 is not periodic |" in text
    assert "| a | yes | 1.10 (J1) | – | 1.25 (A1) | – |" in text
    assert "| b | **no** | **1.11** (J6) |" in text
    assert (
        "| TX40, rest velocity auto | unconstrained | a 10, a 20, a 30, a 40, a 50, a 60 | a 35 |"
        in text
    )
