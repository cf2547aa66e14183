"""`dynid demo` end to end at small sizes (paper Sect. V-VI on the virtual LWR-IV).

The demo's outputs are checked against independent facts: the true coefficients of the
controller's model (beta @ pi), the 250 g tip, the paper's zero element M_76, the PNG file
signature, and the JSON on disk against the returned report.
"""

from __future__ import annotations

import json
import struct

import numpy as np
import pytest

import dynid
import dynid.cli
from dynid.cli.demo import LINK_FRICTION, TIP_MASS, controller_model, run_demo
from dynid.export.output_folder import MARKER

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
PLOTS = (
    "fig3_joint_motion.png",
    "fig4_torques.png",
    "fig5_final_validation_motion.png",
    "fig6_g2_M11.png",
)


def png_size(path) -> tuple[int, int]:
    """Width and height from the IHDR chunk, after checking the signature."""
    data = path.read_bytes()
    assert data[:8] == PNG_SIGNATURE, path
    assert data[12:16] == b"IHDR", path
    return struct.unpack(">II", data[16:24])


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo") / "out"  # does not exist yet: the demo creates it
    lines: list[str] = []
    report = run_demo(out, train=60, validation=20, progress=lines.append)
    return out, report, lines


def test_demo_writes_json_matching_its_report(demo):
    out, report, _ = demo
    on_disk = json.loads((out / "demo.json").read_text())
    assert on_disk == json.loads(json.dumps(report))
    assert on_disk["settings"]["train"] == 60 and on_disk["settings"]["validation"] == 20
    for key in (
        "coefficients",
        "zero_elements",
        "gravity_errors",
        "inertia_errors",
        "condition_numbers",
        "payload",
        "plots",
    ):
        assert key in on_disk, key


def test_demo_coefficients_are_the_true_ones_up_to_the_noise(demo):
    # Demo noise: relative 1e-5 on g and M, 1e-5 rad on q. Against beta @ pi of the controller's
    # model: within 1e-4 of the largest coefficient of each kind, and within 6 reported std + 1e-6
    # relative each (6 sigma: 51 coefficients should never fail by chance).
    out, _, _ = demo
    coefficients = json.loads((out / "demo.json").read_text())["coefficients"]
    truth = controller_model()
    for kind in ("gravity", "inertia"):
        base = dynid.base_parameters(truth, kind)
        true = dict(zip(base.names, base.values(truth)))
        rows = coefficients[kind]
        assert [r["name"] for r in rows] == base.names
        assert [r["expression"] for r in rows] == base.expressions
        scale = max(abs(v) for v in true.values())
        for r in rows:
            error = abs(r["value"] - true[r["name"]])
            assert error <= 1e-4 * scale, (kind, r)
            assert error <= 6 * r["std"] + 1e-6 * scale, (kind, r)
    assert len(coefficients["gravity"]) == 12  # paper: p_g = 12


def test_demo_payload_estimates_are_near_250_g(demo):
    # Only 60 configurations per arm here, yet the demo's noise (1e-5 relative) leaves ~0.05 %
    # error: require 0.5 % (the brief's bound was 2 %; the paper-sized 1 % test is in
    # test_payload.py).
    _, report, _ = demo
    payload = report["payload"]
    assert payload["true_mass"] == TIP_MASS == 0.25
    assert sorted(e["factor"] for e in payload["estimates"]) == [0.39, 0.4]
    for e in payload["estimates"]:
        assert e["mass"] == pytest.approx(0.25, rel=0.005), e


def test_demo_reports_the_zero_element_and_the_tables(demo):
    _, report, lines = demo
    assert [(z["row"], z["column"]) for z in report["zero_elements"]] == [(6, 5)]
    text = "\n".join(lines)
    for k in range(1, 7):
        assert f"[{k}/6]" in text  # progress of each step
    assert "Table II" in text and "Table III" in text
    assert "M[7,6]" in text and "Ixz7" in text and "Iyz7" in text
    for name in ("TS", "VS", "TVE"):
        errors = report["gravity_errors"][name]
        assert len(errors["mse"]) == 7 and len(errors["max_abs"]) == 7
        assert all(np.isfinite(errors["mse"])) and all(np.isfinite(errors["max_abs"]))
    # Torque validation (eq. (33)), tracked in closed loop: the identified model is exact up to
    # the 1e-5 model noise but has no friction, while tau_J holds the link-side quarter of the
    # joints' friction (LINK_FRICTION). Each joint's maximum error is that friction at the peak
    # speed pi^2 / 14 rad/s, 0.25 (Fv qd_max + Fs) from the model's Fv, Fs (measured ratios
    # 0.98-1.05 with 60 configurations; bound 0.9-1.15: filtered sensor noise ~0.003 N m, filter
    # ends, numerical derivatives), 0.39 N m on J2 as in the paper's Table III (0.37 N m).
    truth = controller_model()
    peak = LINK_FRICTION * (truth.Fv * np.pi**2 / 14 + truth.Fs)
    tve = np.array(report["gravity_errors"]["TVE"]["max_abs"])
    assert np.all((0.9 * peak < tve) & (tve < 1.15 * peak)), tve / peak
    assert report["settings"]["link_friction"] == LINK_FRICTION
    # the position controller lags: a tracking error of a few mrad (measured 1.1-6.6 mrad)
    tracking = np.array(report["tracking_error_max"])
    assert tracking.shape == (7,) and np.all((tracking > 1e-4) & (tracking < 0.02))
    assert "tracking error" in text


def test_demo_writes_four_png_plots(demo):
    out, report, _ = demo
    assert sorted(report["plots"]) == sorted(PLOTS)
    for name in PLOTS:
        path = out / name
        assert path.stat().st_size > 10_000, name  # a real figure, not an empty canvas
        width, height = png_size(path)
        assert width > 300 and height > 300, (name, width, height)


def test_cli_demo_returns_zero_and_writes_its_outputs(tmp_path, capsys):
    out = tmp_path / "cli"
    code = dynid.cli.main(
        ["demo", "--output", str(out), "--train", "60", "--validation", "20", "--seed", "3"]
    )
    assert code == 0
    printed = capsys.readouterr().out
    assert "Table II" in printed and "m_tip" in printed
    report = json.loads((out / "demo.json").read_text())
    assert report["settings"]["seed"] == 3 and report["settings"]["train"] == 60
    for name in PLOTS:
        png_size(out / name)


def test_demo_never_overwrites_results_silently(tmp_path, capsys):
    """A second demo into the same folder is refused (exit 2, one line, the old files kept);
    with --overwrite the folder is replaced as a whole (a stray file of the old one is gone)."""
    out = tmp_path / "demo"
    argv = ["demo", "--output", str(out), "--train", "10", "--validation", "5"]
    assert dynid.cli.main(argv) == 0
    (out / "notes.txt").write_text("mine")
    before = (out / "demo.json").read_bytes()
    capsys.readouterr()
    assert dynid.cli.main(argv) == 2
    error = capsys.readouterr().err.strip()
    assert error.startswith("dynid demo: error: output:") and "--overwrite" in error
    assert (out / "demo.json").read_bytes() == before and (out / "notes.txt").exists()
    assert dynid.cli.main([*argv, "--overwrite"]) == 0
    assert sorted(p.name for p in out.iterdir()) == sorted([MARKER, "demo.json", *PLOTS])
    with pytest.raises(ValueError, match=r"^output:"):
        run_demo(out, train=10, validation=5, progress=lambda _: None)


def test_cli_rejects_an_unknown_command(capsys):
    with pytest.raises(SystemExit) as info:
        dynid.cli.main(["nonsense"])
    assert info.value.code != 0


def test_final_validation_experiment_of_fig5(demo):
    """The paper's Fig. 5 experiment: 500 readings of g(q) and M(q) along a minute of sinusoids;
    the identified model matches them as it matches the random validation set (the same
    controller noise: within twice the validation set's largest error)."""
    _, report, lines = demo
    final = report["final_validation"]
    assert final["samples"] == 500
    gravity_vs = max(v for v in report["gravity_errors"]["VS"]["max_abs"] if v is not None)
    assert max(final["gravity_max_abs"][1:]) <= 2 * gravity_vs
    assert final["inertia_max_abs"] <= 2 * report["inertia_errors"]["VS"]["max_abs"]
    assert any("final validation (Fig. 5)" in line for line in lines)
