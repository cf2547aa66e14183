"""report.html of `dynid identify` and `dynid validate` (dynid.export.report): parsed with the
standard library's html.parser and checked against result.json / validation.json and against
the logs written here: every section, an <svg> per joint for the torque and one for the
residual histogram, the coefficient table row by row (each printed number within half a unit of
its last printed digit of the file's value, its data-value exactly the file's), the per-joint
errors, the breaks of the torque lines where rows are missing, the escaping of the robot's name;
and the decimation for drawing (bounded, spikes and gaps kept) against a direct computation."""

from __future__ import annotations

import json
from decimal import Decimal
from html.parser import HTMLParser
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import dynid
from dynid.cli import main
from dynid.export.report import REPORT_FILE, write_report
from dynid.export.report_figures import MAX_POINTS, envelope_with_gaps, with_gaps
from dynid.identification.log_identification import LogValidation
from dynid.logs import Log, save_log
from dynid.model.model_files import save_model
from test_cli import _arm
from test_log_identification import fourier_log

NAME = 'arm <&> "2R"'  # a name that must be escaped
SECTIONS = ["summary", "torques", "residuals", "parameters", "metrics", "notes"]
HOLES = (slice(200, 220), slice(400, 405))  # rows removed from the training log
VOID = {"meta", "link", "br", "img", "hr", "input", "col", "area", "base", "source", "wbr"}


# --------------------------------------------------------------------------- an HTML tree


class Node:
    def __init__(self, tag: str, attrs: dict[str, str | None]) -> None:
        self.tag, self.attrs, self.children, self.parts = tag, attrs, [], []

    @property
    def text(self) -> str:
        return "".join(p if isinstance(p, str) else p.text for p in self.parts)

    def iter(self, tag: str | None = None):
        for child in self.children:
            if tag is None or child.tag == tag:
                yield child
            yield from child.iter(tag)

    def find(self, element_id: str) -> Node:
        found = [n for n in self.iter() if n.attrs.get("id") == element_id]
        assert len(found) == 1, f"{len(found)} elements with id {element_id!r}"
        return found[0]


class TreeBuilder(HTMLParser):
    """A tree of the page (html.parser gives events only): SVG's self-closing tags are leaves,
    HTML's void elements too; an end tag closes up to its start tag."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.root = Node("#root", {})
        self.stack = [self.root]

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        node = Node(tag, dict(attrs))
        self.stack[-1].children.append(node)
        self.stack[-1].parts.append(node)
        if tag not in VOID:
            self.stack.append(node)

    def handle_startendtag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        node = Node(tag, dict(attrs))
        self.stack[-1].children.append(node)
        self.stack[-1].parts.append(node)

    def handle_endtag(self, tag: str) -> None:
        if tag in VOID:
            return
        while len(self.stack) > 1:
            if self.stack.pop().tag == tag:
                return

    def handle_data(self, data: str) -> None:
        self.stack[-1].parts.append(data)


def parse(path: Path) -> Node:
    builder = TreeBuilder()
    builder.feed(path.read_text(encoding="utf-8"))
    builder.close()
    return builder.root


def table_rows(page: Node, table_id: str) -> list[list[Node]]:
    body = next(page.find(table_id).iter("tbody"))
    return [list(row.iter("td")) for row in body.iter("tr")]


def check_number(cell: Node, expected: float | None) -> None:
    """The cell shows ``expected`` to its printed precision, and data-value is it exactly (a
    dash and "null" for a null of the JSON file)."""
    if expected is None:
        assert cell.text.strip() == "–" and cell.attrs["data-value"] == "null"
        return
    assert float(cell.attrs["data-value"]) == expected  # exact
    printed = Decimal(cell.text.replace("%", "").strip())
    half_unit = Decimal(10) ** printed.as_tuple().exponent / 2
    assert abs(printed - Decimal(repr(expected))) <= half_unit, (cell.text, expected)


def breaks(path_d: str) -> int:
    """The number of pieces of an SVG path (each starts with M)."""
    return path_d.split().count("M")


def path_points(group: Node) -> list[list[tuple[float, float]]]:
    """The pieces of the (one) path in an SVG group, as lists of (x, y)."""
    (path,) = list(group.iter("path"))
    pieces: list[list[tuple[float, float]]] = []
    tokens = path.attrs["d"].split()
    for k in range(0, len(tokens), 3):
        command, x, y = tokens[k : k + 3]
        if command == "M":
            pieces.append([])
        pieces[-1].append((float(x), float(y)))
    return pieces


def runs(keep: np.ndarray) -> list[tuple[int, int]]:
    """[start, stop) of the runs of True."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], keep.astype(int), [0]])))
    return list(zip(edges[::2], edges[1::2]))


# --------------------------------------------------------------------------- the runs


@pytest.fixture(scope="module")
def runs_done(tmp_path_factory) -> dict[str, Any]:
    """identify on a training log with two holes (rows removed), with --min-velocity, and
    validate on another log whose joint 1 is 20 turns further (the same torques, and dynid's
    warning of positions beyond 100 rad)."""
    folder = tmp_path_factory.mktemp("report")
    arm = _arm()
    model = dynid.models.planar_2r()
    model.name = NAME
    save_model(model, folder / "arm.json")
    full = fourier_log(arm, 1, seconds=6.0)
    kept = np.ones(full.T, dtype=bool)
    for hole in HOLES:
        kept[hole] = False
    train = full.select(kept, note="rows removed for the test")
    save_log(train, folder / "train.npz")
    check = fourier_log(arm, 2, seconds=2.0)
    turned = check.q.copy()
    turned[:, 0] += 40 * np.pi
    save_log(Log(check.t, turned, check.tau, check.qd, check.qdd), folder / "check.npz")
    ident, valid = folder / "ident", folder / "valid"
    min_velocity = 0.05
    argv = ["identify", str(folder / "train.npz"), "--model", str(folder / "arm.json")]
    argv += ["--friction", "--min-velocity", str(min_velocity), "--output", str(ident)]
    assert main(argv) == 0
    assert main(["validate", str(ident), str(folder / "check.npz"), "--output", str(valid)]) == 0
    return {
        "folder": folder,
        "ident": ident,
        "valid": valid,
        "train": train,
        "check": check,
        "min_velocity": min_velocity,
    }


def test_identify_report_has_every_section_and_the_numbers_of_result_json(runs_done) -> None:
    ident = runs_done["ident"]
    page = parse(ident / REPORT_FILE)
    data = json.loads((ident / "result.json").read_text())
    n = len(data["model"]["rows"])
    assert [s.attrs["id"] for s in page.iter("section")] == SECTIONS
    for j in range(1, n + 1):
        assert len(list(page.find(f"torque-log1-j{j}").iter("svg"))) == 1
        assert len(list(page.find(f"histogram-j{j}").iter("svg"))) == 1
    # the coefficients: one row each, in order, every number as in result.json
    rows = table_rows(page, "parameter-table")
    assert len(rows) == len(data["coefficients"])
    for cells, entry in zip(rows, data["coefficients"]):
        assert cells[0].text == entry["name"] and cells[4].text == entry["expression"]
        check_number(cells[1], entry["value"])
        check_number(cells[2], entry["std"])
        check_number(cells[3], entry["relative_std_percent"])
    # the condition number and the rank in the summary
    facts = dict(zip((d.text for d in page.iter("dt")), page.iter("dd")))
    check_number(facts["condition number"], data["condition_number"])
    assert facts["rank"].text == f"{data['rank']} of {len(data['coefficients'])}"
    assert facts["samples"].text == str(data["training"]["samples"])
    # the per-joint errors of the training log
    metrics = data["training"]["metrics"]
    keys = ["rms", "relative_rms", "max_abs", "r2", "mse"]
    rows = table_rows(page, "metrics-table")
    assert len(rows) == n
    for j, cells in enumerate(rows):
        for cell, key in zip(cells[1:], keys):
            check_number(cell, metrics[key][j])
    # the notes of result.json (preparation, rows left out), escaped and back
    notes = [li.text for li in page.find("note-list").iter("li")]
    assert notes == data["training"]["notes"]
    assert any("left out the rows" in note for note in notes)


def test_torque_lines_break_where_rows_are_missing(runs_done) -> None:
    """Joint j's measured line has one piece per run of consecutive rows kept: the log's two
    holes (rows removed) and the rows where |qd_j| < min_velocity (left out of the fit) are
    gaps; the ends of each piece are at the times of its first and last row."""
    train, v = runs_done["train"], runs_done["min_velocity"]
    page = parse(runs_done["ident"] / REPORT_FILE)
    t = train.t - train.t[0]
    step = np.diff(train.t)
    hole = np.concatenate([[False], step > 1.5 * np.median(step)])  # a row after a hole
    assert hole.sum() == len(HOLES)
    for j in range(train.n):
        keep = np.abs(train.qd[:, j]) >= v
        # runs of kept rows, also cut where rows were removed
        pieces = []
        for start, stop in runs(keep):
            cuts = [start, *(k for k in range(start + 1, stop) if hole[k]), stop]
            pieces += list(zip(cuts[:-1], cuts[1:]))
        assert min(b - a for a, b in pieces) >= 2  # each a line (a lone point is no line)
        for name in ("measured", "predicted"):
            drawn = path_points(page.find(f"torque-log1-j{j + 1}-{name}"))
            assert len(drawn) == len(pieces)
            # x is linear in t: the map from the first and the last piece's ends
            x0, x1 = drawn[0][0][0], drawn[-1][-1][0]
            scale = (x1 - x0) / (t[pieces[-1][1] - 1] - t[pieces[0][0]])
            for (a, b), piece in zip(pieces, drawn):
                start = x0 + scale * (t[a] - t[pieces[0][0]])
                end = x0 + scale * (t[b - 1] - t[pieces[0][0]])
                assert abs(piece[0][0] - start) < 1e-3 and abs(piece[-1][0] - end) < 1e-3


def test_validate_report_has_its_errors_the_result_and_the_warning(runs_done) -> None:
    valid, ident = runs_done["valid"], runs_done["ident"]
    page = parse(valid / REPORT_FILE)
    report = json.loads((valid / "validation.json").read_text())
    data = json.loads((ident / "result.json").read_text())
    n = len(report["metrics"]["rms"])
    order = [*SECTIONS[:3], "metrics", "parameters", "notes"]
    assert [s.attrs["id"] for s in page.iter("section")] == order
    for j in range(1, n + 1):
        assert len(list(page.find(f"torque-log1-j{j}").iter("svg"))) == 1
        assert len(list(page.find(f"histogram-j{j}").iter("svg"))) == 1
    keys = ["rms", "relative_rms", "max_abs", "r2", "mse"]
    for j, cells in enumerate(table_rows(page, "metrics-table")):
        for cell, key in zip(cells[1:], keys):
            check_number(cell, report["metrics"][key][j])
        check_number(cells[6], data["training"]["metrics"]["relative_rms"][j])
    rows = table_rows(page, "parameter-table")
    assert [r[0].text for r in rows] == [c["name"] for c in data["coefficients"]]
    for cells, entry in zip(rows, data["coefficients"]):
        check_number(cells[1], entry["value"])
    warnings = [li.text for li in page.find("warning-list").iter("li")]
    assert len(warnings) == 1 and "q: positions up to" in warnings[0]
    assert warnings[0].startswith("UserWarning: ")


def test_names_are_escaped_and_the_page_is_self_contained(runs_done) -> None:
    for folder in (runs_done["ident"], runs_done["valid"]):
        raw = (folder / REPORT_FILE).read_text(encoding="utf-8")
        assert NAME not in raw and "arm &lt;&amp;&gt; &quot;2R&quot;" in raw
        page = parse(folder / REPORT_FILE)
        (title,) = list(page.iter("title"))
        assert title.text.endswith(NAME)  # unescaped by the parser: the name as given
        assert not list(page.iter("script")) and not list(page.iter("img"))
        assert not list(page.iter("link")) and not list(page.iter("iframe"))
        # every link is to a section of the page, every <use> to a definition in it
        ids = {node.attrs.get("id") for node in page.iter()}
        for node in page.iter():
            for key in ("href", "xlink:href", "src"):
                target = node.attrs.get(key)
                if target is not None:
                    assert target.startswith("#") and target[1:] in ids, (node.tag, target)


def test_no_report_leaves_it_out(runs_done, tmp_path) -> None:
    folder = runs_done["folder"]
    argv = ["identify", str(folder / "train.npz"), "--model", str(folder / "arm.json")]
    assert main([*argv, "--no-report", "--output", str(tmp_path / "out")]) == 0
    assert not (tmp_path / "out" / REPORT_FILE).exists()
    assert (tmp_path / "out" / "result.json").is_file()
    assert "report: false" in (tmp_path / "out" / "run.yaml").read_text()


# --------------------------------------------------------------------------- drawing


def test_with_gaps_breaks_at_dropped_rows_and_left_out_rows() -> None:
    t = np.array([0.0, 1.0, 2.0, 4.0, 5.0, 6.0, 7.0])  # one row missing after t = 2
    y = np.arange(7.0)
    keep = np.array([True, True, True, True, True, False, True])
    t2, y2 = with_gaps(t, y, keep)
    np.testing.assert_array_equal(t2, [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0])
    np.testing.assert_array_equal(y2, [0.0, 1.0, 2.0, np.nan, 3.0, 4.0, np.nan, 6.0])


def test_envelope_is_bounded_and_keeps_spikes_and_gaps() -> None:
    """1e6 samples with a spike each way and a hole 20 buckets long: at most MAX_POINTS + 2
    points, every one a sample; each hole-free bucket's minimum and maximum (computed here
    directly) among them; nothing drawn inside the hole, and the line broken there."""
    rng = np.random.default_rng(7)
    T = 1_000_000
    t = np.arange(T) * 1e-3
    y = np.sin(t) + 0.01 * rng.normal(size=T)
    y[123_457], y[654_321] = 9.0, -7.0
    size = -(-T // (MAX_POINTS // 8))
    hole = slice(300_000, 300_000 + 20 * size)
    y[hole] = np.nan
    y[777_777] = np.nan  # a one-row hole inside a bucket
    tx, yx = envelope_with_gaps(t, y)
    assert tx.size <= MAX_POINTS + 2
    finite = np.isfinite(yx)
    index = np.rint(tx / 1e-3).astype(int)
    np.testing.assert_array_equal(t[index], tx)
    np.testing.assert_array_equal(y[index][finite], yx[finite])
    assert 9.0 in yx and -7.0 in yx
    for lo in range(0, T, size):
        part = y[lo : lo + size]
        if np.isfinite(part).all():
            assert part.min() in yx[(tx >= t[lo]) & (tx <= t[min(lo + size, T) - 1])]
            assert part.max() in yx[(tx >= t[lo]) & (tx <= t[min(lo + size, T) - 1])]
    inside = (tx > t[hole.start]) & (tx < t[hole.stop - 1])
    assert not np.isfinite(yx[inside]).any()
    assert (~finite & (tx >= t[hole.start]) & (tx <= t[hole.stop - 1])).any()
    # the one-row hole: a break between the samples drawn on its two sides
    before, after = tx < t[777_777], tx > t[777_777]
    assert np.isnan(yx[~before & ~after]).all() and (~before & ~after).any()


def test_report_of_a_long_log_stays_small(tmp_path) -> None:
    """A 1e6-sample, 7-joint validation: the page is a few MB at most (the lines decimated)."""
    T, n = 1_000_000, 7
    t = np.arange(T) * 1e-3
    rng = np.random.default_rng(3)
    tau = np.sin(t[:, None] * (1 + np.arange(n))) + 0.01 * rng.normal(size=(T, n))
    log = Log(t, np.zeros((T, n)), tau, np.zeros((T, n)), np.zeros((T, n)), source="long")
    predicted = tau + 0.01
    validation = LogValidation(log, predicted, {"rms": np.full(n, 0.01)}, {}, [])
    path = write_report(validation, tmp_path)
    assert path.stat().st_size < 3_000_000
    page = parse(path)
    assert len(list(page.iter("svg"))) == 2 * n


def test_write_report_refuses_what_it_cannot_report(tmp_path) -> None:
    with pytest.raises(ValueError, match=r"^result_or_validation: expected"):
        write_report("result.json", tmp_path)  # type: ignore[arg-type]


def test_the_python_functions_write_it_only_when_asked(runs_done, tmp_path) -> None:
    """save_result and save_validation as before by default (no report.html); report=True adds
    it, and a result read from its file (no log kept) says so in place of the figures."""
    from dynid.export.result_files import load_result, save_result, save_validation
    from dynid.identification.log_identification import run_validation

    result = load_result(runs_done["ident"])
    validation = run_validation(result, runs_done["check"])
    save_validation(validation, tmp_path / "v")
    save_result(result, tmp_path / "r")
    assert not (tmp_path / "v" / REPORT_FILE).exists()
    assert not (tmp_path / "r" / REPORT_FILE).exists()
    save_validation(validation, tmp_path / "v2", report=True, result=result)
    save_result(result, tmp_path / "r2", report=True)
    assert (tmp_path / "v2" / REPORT_FILE).is_file()
    page = parse(tmp_path / "r2" / REPORT_FILE)
    assert "No log kept" in page.find("torques").text and not list(page.iter("svg"))
    assert len(table_rows(page, "parameter-table")) == result.theta.size


def test_several_training_logs_each_get_their_figures_and_errors(runs_done, tmp_path) -> None:
    """identify on two logs: a torque figure per joint and log, the errors on all samples and
    on each log, as result.json's training.metrics and training.logs[k].metrics."""
    folder = runs_done["folder"]
    out = tmp_path / "two"
    argv = ["identify", str(folder / "train.npz"), str(folder / "check.npz")]
    assert main([*argv, "--model", str(folder / "arm.json"), "--output", str(out)]) == 0
    page = parse(out / REPORT_FILE)
    data = json.loads((out / "result.json").read_text())
    for k in (1, 2):
        for j in (1, 2):
            assert len(list(page.find(f"torque-log{k}-j{j}").iter("svg"))) == 1
        rows = table_rows(page, f"metrics-table-log{k}")
        for j, cells in enumerate(rows):
            check_number(cells[1], data["training"]["logs"][k - 1]["metrics"]["rms"][j])
    for j, cells in enumerate(table_rows(page, "metrics-table")):
        check_number(cells[1], data["training"]["metrics"]["rms"][j])
