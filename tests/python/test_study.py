"""The error-against-time study end to end on a tiny configuration (timings are reported, never
asserted), its Pareto frontier, its outputs, and the `mipraster study` command."""
import csv
import math
import os
import subprocess
import sys

import pytest

from mipraster import study as st
from mipraster.study_scenes import checker_plane, star, with_filter

from test_cli import EXE


def test_pareto_frontier():
    pts = [(1.0, 0.5), (2.0, 0.6), (2.0, 0.3), (4.0, 0.3), (8.0, 0.1), (0.5, 0.9)]
    assert st.pareto(pts) == [5, 0, 2, 4]


def test_tiny_study_end_to_end(tmp_path):
    logs = []
    rows = st.study(str(tmp_path), scenes=["star", "zone_plate"], width=48, height=32, repeats=1, tiny=True,
                    llvmpipe=False, make_plot=False, reference_quality=0.25, log=logs.append)
    with open(tmp_path / "study.csv") as f:
        table = list(csv.DictReader(f))
    assert len(table) == len(rows) == len(st.tiny_sweep(False)) + len(st.tiny_sweep(True))
    assert set(table[0]) == set(st.FIELDS)
    for r in rows:
        assert r.ms_one_thread > 0 and r.ms_all_threads > 0  # measured (values not asserted)
        assert math.isfinite(r.rmse) and 0 <= r.mean_abs <= r.rmse <= r.max_abs
    by = {(r.scene, r.label): r for r in rows}
    # More samples, less error on the star (its reference is the exact coverage: residual 0).
    assert by["star", "16x"].rmse < by["star", "4x"].rmse < by["star", "1x"].rmse
    assert by["star", "1x"].reference_residual == 0.0
    assert by["zone_plate", "1x"].reference_residual > 0.0  # brute force: stated
    # Every configuration carries the estimate (the probe works at 1 spp too), its standard error,
    # its cost and its ratio to the true error.
    for label in ("1x", "4x"):
        row = by["star", label]
        assert not math.isnan(row.estimate_ratio) and row.estimate_stderr > 0 and row.estimate_ms > 0
    adaptive = [r for r in rows if r.renderer == "mipraster adaptive"]
    assert len(adaptive) == 2 and all(r.notes and r.mean_spp >= 4 for r in adaptive)
    md = (tmp_path / "study.md").read_text()
    for heading in ("# Error against run time", "## star", "## zone_plate", "## Error estimate calibration",
                    "## Adaptive quality", "llvmpipe points left out"):
        assert heading in md
    assert any("reference" in line for line in logs)


def _row(label, rmse, estimate, bound=False, residual=0.0):
    r = st.StudyRow("s", label, "mipraster", 1, "center", "ssaa", "-", 1.0, 0.0, 1.0, 1.0, 2, rmse, rmse, rmse,
                    residual, estimate=estimate, estimate_ratio=estimate / rmse, estimate_stderr=0.1 * estimate,
                    estimate_ms=0.5, estimate_bound=bound)
    return r


def test_calibration_counts_upper_bounds_apart():
    # Point estimates are judged by the factor of 2; upper bounds are listed apart and judged by
    # whether they hold (true RMSE <= bound), and the table prints them as "≤ x".
    rows = [_row("1x", 0.10, 0.12), _row("4x", 0.05, 0.2), _row("16x", 0.001, 0.004, bound=True),
            _row("64x", 0.003, 0.002, bound=True)]
    md = st.markdown(rows, [])
    assert "within a factor of 2 on 1 of 2 configurations" in md
    assert "Upper bounds" in md and "2 configuration(s), not counted above; the bound holds (true RMSE ≤ bound) on 1 of them" in md
    assert "s 16x: true 0.001 ≤ 0.004" in md and "s 64x: true 0.003 > 0.002 (FAILS)" in md
    assert "| ≤ 0.004 |" in md and "| 0.12 ± 0.012 |" in md


def test_plot_is_optional(tmp_path, monkeypatch):
    rows = [st.StudyRow("s", "1x", "mipraster", 1, "center", "ssaa", "-", 1.0, 0.0, 1.0, 1.0, 2, 0.1, 0.05, 0.3, 0.0)]
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # as if it were not installed
    why = st.plot(rows, str(tmp_path / "p.png"))
    assert "matplotlib is not installed" in why
    assert not (tmp_path / "p.png").exists()


def test_plot_writes_png(tmp_path):
    import matplotlib  # noqa: F401  (installed by `bash .ci/dev test`: a missing one fails, never skips)

    rows = [st.StudyRow("s", f"{n}x", "mipraster", n, "grid", "ssaa", "-", 1.0, 0.0, n, n, 2, 0.1 / n, 0.05 / n,
                        0.3, 0.0) for n in (1, 4, 16)]
    assert st.plot(rows, str(tmp_path / "p.png")) is None
    assert (tmp_path / "p.png").stat().st_size > 1000


def test_with_filter_keeps_the_rest():
    s = checker_plane(32, 24)
    other = with_filter(s.scene, "trilinear", lod_bias=1.0)
    (d0,), (d1,) = s.scene.draws, other.draws
    assert d1.sampler.filter == "trilinear" and d1.sampler.lod_bias == 1.0
    assert d1.sampler.wrap == d0.sampler.wrap and d1.sampler.max_anisotropy == d0.sampler.max_anisotropy
    assert d1.texture == d0.texture and d1.depth_test == d0.depth_test
    untextured = with_filter(star(16, 16).scene, "nearest")
    assert untextured.draws[0].texture is None


def test_study_bad_input(tmp_path):
    with pytest.raises(ValueError, match="unknown scene 'teapot'"):
        st.study(str(tmp_path), scenes=["teapot"])
    with pytest.raises(FileNotFoundError, match="nothing.obj"):
        st.study(str(tmp_path), scenes=[], scene_files=[str(tmp_path / "nothing.obj")])


def test_cli_hands_study_to_python(tmp_path):
    r = subprocess.run([EXE, "study", "--help"], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert "--tiny" in r.stdout and "--no-llvmpipe" in r.stdout
    r = subprocess.run([EXE, "study", "--scenes", "teapot", "-o", str(tmp_path)], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 2 and "teapot" in r.stderr
    assert "study" in subprocess.run([EXE, "--help"], capture_output=True, text=True).stdout


def test_llvmpipe_says_why_or_renders():
    from mipraster import llvmpipe

    why = llvmpipe.unavailable_reason()
    if why is not None:
        assert any(word in why for word in ("moderngl", "EGL", "llvmpipe"))
        return
    s = star(48, 32)
    ref, _, _ = s.reference()
    image, ms = llvmpipe.render_timed(s, "msaa4", threads=1, repeats=1)
    assert image.shape == (32, 48, 4) and ms > 0
    # llvmpipe's 4x MSAA of the same triangles is close to the exact coverage, not equal.
    assert 0 < st.image_error(image, ref)["rmse"] < 0.1


def test_converged_reference_agrees_with_exact_coverage():
    # The converged render (for scene files) against the exact coverage of the same star: within a
    # factor 2 of its own stated residual (plus the 1/256 px vertex snapping, far smaller here).
    from mipraster.reference import converged_reference, image_error

    s = star(40, 30)
    exact, _, _ = s.reference()
    image, residual = converged_reference(s.scene, s.camera, 40, 30, clear_color=s.clear_color, upscale=2)
    assert 0 < residual < 5e-3
    assert image_error(image, exact)["rmse"] <= 2 * residual


def test_study_of_a_scene_file(tmp_path):
    path = tmp_path / "tri.obj"
    path.write_text("v 0 0 0 1 0.5 0\nv 1 0 0 1 0.5 0\nv 0.2 1 0 1 0.5 0\nf 1 2 3\n")
    rows = st.study(str(tmp_path / "out"), scenes=[], scene_files=[str(path)], width=32, height=24, repeats=1,
                    tiny=True, llvmpipe=False, make_plot=False, reference_quality=0.25, log=lambda *_: None)
    assert {r.scene for r in rows} == {"tri"}
    assert len(rows) == len(st.tiny_sweep(False))
    by = {r.label: r for r in rows}
    assert by["16x"].rmse < by["1x"].rmse  # converged reference: more samples, closer
    assert rows[0].reference_residual > 0
