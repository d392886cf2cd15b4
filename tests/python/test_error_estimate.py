"""The per-render error estimate (render(..., estimate_error=True)) and adaptive quality
(render(..., target_error=e)), checked against exact references (mipraster.reference)."""
import math

import numpy as np
import pytest

import mipraster as mr
from mipraster import _core
from mipraster.adaptive import tile_rmse
from mipraster.reference import exact_coverage, image_error
from mipraster.study_scenes import checker_plane, star, with_filter


def test_estimate_needs_two_samples():
    s = star(32, 32)
    with pytest.raises(ValueError, match="spp >= 2"):
        mr.render(s.scene, s.camera, 32, 32, spp=1, estimate_error=True)
    with pytest.raises(ValueError, match="spp >= 2"):
        mr.render(s.scene, s.camera, 32, 32, spp=1, target_error=0.01)


def test_no_estimate_unless_asked():
    s = star(32, 32)
    r = mr.render(s.scene, s.camera, 32, 32, spp=4)
    assert r.error_map is None and r.error_estimate is None and r.tile_spp is None


def test_flat_image_estimates_zero():
    quad = mr.Mesh([[-5, -5, 0], [5, -5, 0], [5, 5, 0], [-5, 5, 0]], [[0, 1, 2], [0, 2, 3]])
    scene = mr.Scene()
    scene.add(quad, color=(0.3, 0.6, 0.9), depth_test=False)
    r = mr.render(scene, mr.Camera.orthographic((0, 0, 1), (0, 0, 0)), 40, 30, spp=8, estimate_error=True)
    assert r.error_map.shape == (30, 40)
    assert r.error_estimate == 0.0
    assert np.all(r.error_map == 0.0)


def test_estimate_is_half_the_disagreement_of_the_halves():
    s = star(48, 40)
    r = mr.render(s.scene, s.camera, 48, 40, spp=16, pattern="stratified", keep_samples=True, estimate_error=True)
    halves = np.array(_core.interleaved_halves(_core.PatternKind.stratified, 16, 0), dtype=bool)
    a = r.samples[:, :, ~halves, :3].astype(np.float64).mean(axis=2)
    b = r.samples[:, :, halves, :3].astype(np.float64).mean(axis=2)
    expected = np.sqrt(np.mean(((a - b) / 2) ** 2, axis=2))
    np.testing.assert_allclose(r.error_map, expected, atol=1e-6)
    assert r.error_estimate == pytest.approx(math.sqrt(np.mean(expected ** 2)), rel=1e-5)
    assert "error_estimate=" in repr(r)


@pytest.mark.parametrize("make, spp, pattern", [(star, 16, "stratified"), (star, 8, "auto"),
                                                (checker_plane, 16, "stratified")])
def test_estimate_calibration(make, spp, pattern):
    # The estimate against the true RMSE (exact / brute-force reference): within a factor of 2 where
    # the error is sampling error: edges, and a texture read at level 0 (bilinear, no mip levels:
    # each sample is a point of the footprint integral). A mip-mapped filter adds a bias that both
    # halves share and the estimate cannot see (the study reports that ratio).
    s = make(64, 48)
    ref, residual, _ = s.reference(1.0)
    scene = with_filter(s.scene, "bilinear")
    r = mr.render(scene, s.camera, s.width, s.height, spp=spp, pattern=pattern, estimate_error=True)
    true = image_error(r.color, ref)["rmse"]
    assert residual < 0.25 * true  # the reference is good enough to judge
    assert 0.5 <= r.error_estimate / true <= 2.0, (r.error_estimate, true)


def _corner_triangle(width, height):
    # One triangle in the top-left tile (pixel coordinates, as the study's star): every other tile
    # is flat background with no error.
    tri = np.array([[(3.0, 4.0), (27.0, 9.0), (9.0, 26.0)]])
    mesh = mr.Mesh(np.c_[tri[0], np.zeros(3)] * [1, -1, 1], [[0, 1, 2]], colors=np.ones((3, 3)))
    scene = mr.Scene()
    scene.add(mesh, depth_test=False)
    camera = mr.Camera.orthographic(eye=(width / 2, -height / 2, 1.0), target=(width / 2, -height / 2, 0.0),
                                    height=float(height), near=0.0, far=2.0)
    return scene, camera, exact_coverage(tri, np.ones((1, 3)), width, height, (0.0, 0.0, 0.0))


@pytest.mark.parametrize("spp, pattern", [(4, "auto"), (4, "stratified"), (2, "auto")])
def test_adaptive_refines_only_where_needed(spp, pattern):
    scene, camera, ref = _corner_triangle(96, 64)
    clear = (0.0, 0.0, 0.0, 1.0)
    base = mr.render(scene, camera, 96, 64, spp=spp, pattern=pattern, estimate_error=True, clear_color=clear)
    assert image_error(base.color, ref)["rmse"] > 0
    target = base.error_estimate / 3
    r = mr.render(scene, camera, 96, 64, spp=spp, pattern=pattern, target_error=target, clear_color=clear)
    assert r.tile_spp.shape == (2, 3)
    # The image's estimate meets the target, or the tile with the edges has run out of samples.
    assert r.error_estimate <= target or r.tile_spp[0, 0] == _core.MAX_SAMPLES
    assert r.tile_spp[0, 0] > spp
    # The flat tiles were not rendered again: base samples, the base render's pixels.
    t = _core.TILE_SIZE
    for ty, tx in [(0, 1), (0, 2), (1, 0), (1, 1), (1, 2)]:
        assert r.tile_spp[ty, tx] == spp
        np.testing.assert_array_equal(r.color[ty * t:(ty + 1) * t, tx * t:(tx + 1) * t],
                                      base.color[ty * t:(ty + 1) * t, tx * t:(tx + 1) * t])
    # And the true error went down.
    assert image_error(r.color, ref)["rmse"] < image_error(base.color, ref)["rmse"]


def test_adaptive_unreachable_target_stops_at_64():
    scene, camera, _ = _corner_triangle(64, 32)
    r = mr.render(scene, camera, 64, 32, spp=4, target_error=1e-9)
    assert r.tile_spp.tolist() == [[_core.MAX_SAMPLES, 4]]


def test_adaptive_bad_input():
    s = star(32, 32)
    for bad in (0.0, -1.0, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="target_error"):
            mr.render(s.scene, s.camera, 32, 32, spp=4, target_error=bad)
    with pytest.raises(TypeError, match="target_error"):
        mr.render(s.scene, s.camera, 32, 32, spp=4, target_error="small")
    with pytest.raises(ValueError, match="keep the samples"):
        mr.render(s.scene, s.camera, 32, 32, spp=4, target_error=0.01, keep_samples=True)


def test_tile_mask_size_is_checked():
    s = star(40, 40)
    settings = _core.RenderSettings()
    settings.width = settings.height = 40
    settings.samples = 4
    settings.tile_mask = [1, 0, 1]
    with pytest.raises(ValueError, match="tile_mask: expected 4 flags"):
        _core.render([d._draw for d in s.scene.draws], s.camera.build(40, 40), settings)


def test_cli_stats_prints_the_estimate(tmp_path):
    from test_cli import EXE
    import subprocess

    r = subprocess.run([EXE, "render", "-o", str(tmp_path / "a.png"), "--size", "64x36", "--spp", "8", "--stats"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    line = [l for l in r.stdout.splitlines() if l.startswith("error estimate")][0]
    assert float(line.split("rmse=")[1].split(",")[0]) > 0  # the demo has edges
    r = subprocess.run([EXE, "render", "-o", str(tmp_path / "b.png"), "--size", "64x36", "--spp", "1", "--stats"],
                       capture_output=True, text=True, timeout=120)
    assert "error estimate: needs --spp 2 or more" in r.stdout


def test_cli_error_map(tmp_path):
    # The map the CLI writes is the one render(..., estimate_error=True) returns for the same demo.
    from test_cli import EXE
    import subprocess

    out = tmp_path / "err.exr"
    r = subprocess.run([EXE, "render", "-o", str(tmp_path / "a.png"), "--size", "64x36", "--spp", "8", "--aa", "ssaa",
                        "--error-map", str(out), "--quiet"], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    written = mr.read_image(out)
    scene, camera = mr.Scene.demo()
    expected = mr.render(scene, camera, 64, 36, spp=8, aa="ssaa", estimate_error=True).error_map
    np.testing.assert_allclose(np.asarray(written).reshape(36, 64, -1)[..., 0], expected, atol=1e-6)
    assert expected.max() > 0
    r = subprocess.run([EXE, "render", "-o", str(tmp_path / "b.png"), "--spp", "1", "--error-map", str(out)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "--error-map" in r.stderr and "--spp 2" in r.stderr
