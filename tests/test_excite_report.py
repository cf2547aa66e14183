"""report.html of ``dynid excite`` (issue 21, item 5: "identify, validate and excite write a
self-contained report.html"): the summary's condition number is trajectory.json's, one figure
per joint (q, qd, qdd, tau with the limits), and each joint's extremes in the limits table agree
with trajectory.csv, written separately at 1 kHz (to the difference of the two grids), and stay
within the limits; --no-report leaves it out."""

from __future__ import annotations

import json

import numpy as np
import pytest

from dynid.cli import main
from test_report import parse, table_rows


@pytest.fixture(scope="module")
def designed(tmp_path_factory):
    out = tmp_path_factory.mktemp("excite") / "plan"
    argv = ["excite", "--model", "planar_2r", "--harmonics", "3", "--period", "4", "--maxiter",
            "20", "--tau-max", "60", "--output", str(out)]  # fmt: skip
    assert main(argv) == 0
    return out


def test_the_page_has_its_sections_and_the_numbers_of_the_files(designed) -> None:
    page = parse(designed / "report.html")
    data = json.loads((designed / "trajectory.json").read_text())
    summary = page.find("summary-facts")
    values = {dt.text: dd for dt, dd in zip(summary.iter("dt"), summary.iter("dd"))}
    assert float(values["condition number"].attrs["data-value"]) == data["condition_number"]
    assert len(list(page.iter("svg"))) == 2  # one figure per joint
    for j in (1, 2):
        page.find(f"figure-joint-{j}")
    csv = np.loadtxt(designed / "trajectory.csv", delimiter=",", comments="#", skiprows=3)
    rows = table_rows(page, "limits-table")
    assert len(rows) == 2
    limits = {"q": None, "qd": data["limits"]["qd_max"], "qdd": data["limits"]["qdd_max"],
              "tau": [60.0, 60.0]}  # fmt: skip
    for j, row in enumerate(rows):
        cells = row[1:]
        for k, quantity in enumerate(("q", "qd", "qdd", "tau")):
            low, high, used = cells[3 * k : 3 * k + 3]
            column = csv[:, 1 + 2 * k + j]
            scale = np.abs(column).max()
            assert abs(float(low.attrs["data-value"]) - column.min()) <= 1e-3 * scale
            assert abs(float(high.attrs["data-value"]) - column.max()) <= 1e-3 * scale
            share = float(used.attrs["data-value"])
            assert 0 < share <= 100.0 + 1e-6, (quantity, share)
            if limits[quantity] is not None:
                bound = limits[quantity][j]
                expected = 100 * max(abs(column.min()), abs(column.max())) / bound
                assert abs(share - expected) <= 0.2


def test_no_report_leaves_it_out(tmp_path) -> None:
    out = tmp_path / "plan"
    argv = ["excite", "--model", "planar_2r", "--harmonics", "2", "--period", "4", "--maxiter",
            "5", "--no-report", "--output", str(out)]  # fmt: skip
    assert main(argv) == 0
    assert not (out / "report.html").exists() and (out / "trajectory.json").exists()
