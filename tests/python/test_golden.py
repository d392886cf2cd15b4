"""Golden images: small renders of each feature compared with the PNGs in tests/golden/ (sRGB8 code
space, idiff-style thresholds: see mipraster.testing), and the golden harness itself (a wrong render
fails and writes actual / expected / diff images, a missing golden fails with the instruction to
create it, --update-goldens writes it).

The goldens are written only by `python3 -m pytest tests/python/test_golden.py --update-goldens`;
tests/golden/README.md says what each one shows.
"""
import math
import os
import pathlib
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from PIL import Image

import mipraster as mr
from mipraster.testing import assert_matches_golden, golden_output_paths

GOLDEN_DIR = pathlib.Path(__file__).resolve().parents[1] / "golden"
BACKGROUND = (0.02, 0.02, 0.03, 1.0)  # opaque near-black: every golden pixel is opaque


def check(name, result, update):
    """Compares ``result`` with tests/golden/<name>.png (or writes it with --update-goldens)."""
    assert result.width <= 128 and result.height <= 96  # goldens stay small
    assert_matches_golden(result, GOLDEN_DIR / f"{name}.png", update=update)


def rotation_z(degrees, tx=0.0, ty=0.0):
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    return np.array([[c, -s, 0, tx], [s, c, 0, ty], [0, 0, 1, 0], [0, 0, 0, 1]])


def rotation_y(degrees, tx=0.0, ty=0.0, tz=0.0):
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    return np.array([[c, 0, s, tx], [0, 1, 0, ty], [-s, 0, c, tz], [0, 0, 0, 1]])


QUAD = [[0, 1, 2], [0, 2, 3]]


def square(half, colors=None):
    return mr.Mesh([[-half, -half, 0], [half, -half, 0], [half, half, 0], [-half, half, 0]], QUAD, colors)


# --- anti-aliasing: one scene at 1 spp, 4x MSAA (rotated grid) and 16x SSAA (4x4 grid) ----------------


def aa_scene():
    """Edges at many slopes: a vertex-coloured triangle, a thin near-horizontal sliver, a rotated
    white square and a fan of thin spokes, under an orthographic camera (1 world unit = 1 pixel)."""
    scene = mr.Scene()
    scene.clear_color = BACKGROUND
    scene.add(mr.Mesh([[-44, -26, 0], [-6, -22, 0], [-30, 20, 0]], [[0, 1, 2]],
                      [[1, 0.1, 0.1], [0.1, 1, 0.1], [0.1, 0.2, 1]]))
    scene.add(mr.Mesh([[-46, 26, 0], [44, 23, 0], [44, 25, 0]], [[0, 1, 2]]), color=(1.0, 0.8, 0.2))
    scene.add(square(9), model=rotation_z(27, 22, 2))
    spokes_pos, spokes_tri = [[12, -26, 0]], []
    for i, angle in enumerate(np.linspace(5, 85, 9)):
        a0, a1 = math.radians(angle - 0.8), math.radians(angle + 0.8)
        spokes_pos += [[12 + 34 * math.cos(a0), -26 + 34 * math.sin(a0), 0],
                       [12 + 34 * math.cos(a1), -26 + 34 * math.sin(a1), 0]]
        spokes_tri.append([0, 1 + 2 * i, 2 + 2 * i])
    scene.add(mr.Mesh(spokes_pos, spokes_tri), color=(0.3, 0.9, 1.0), depth_test=False)
    camera = mr.Camera.orthographic(eye=(0, 0, 5), target=(0, 0, 0), height=64.0, near=0.0, far=10.0)
    return scene, camera


@pytest.mark.parametrize("name, spp, aa, pattern", [
    pytest.param("aa_1spp", 1, "ssaa", "center", id="aa_1spp"),
    pytest.param("aa_msaa4_rotated", 4, "msaa", "rotated", id="aa_msaa4_rotated"),
    pytest.param("aa_ssaa16_grid", 16, "ssaa", "grid", id="aa_ssaa16_grid"),
])
def test_anti_aliasing(name, spp, aa, pattern, update_goldens):
    scene, camera = aa_scene()
    check(name, mr.render(scene, camera, 96, 64, spp=spp, aa=aa, pattern=pattern), update_goldens)


# --- interpolation: a tilted quad with vertex colours, flat / screen / perspective ------------------


def tilted_quad_scene(interpolation):
    """A 2 x 8 floor quad running away from a perspective camera, red / green near, blue / yellow far."""
    scene = mr.Scene()
    scene.clear_color = BACKGROUND
    # triangles (0, 1, 2) and (2, 3, 0): "flat" takes red for the first, blue for the second
    quad = mr.Mesh([[-1, 0, 1], [1, 0, 1], [1, 0, -7], [-1, 0, -7]], [[0, 1, 2], [2, 3, 0]],
                   [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0]])
    scene.add(quad, model=rotation_y(-25), interpolation=interpolation)
    camera = mr.Camera.look_at(eye=(-0.5, 1.4, 3.0), target=(0.6, -0.9, -2.0), fov_y=48)
    return scene, camera


@pytest.mark.parametrize("interpolation", ["flat", "screen", "perspective"])
def test_interpolation(interpolation, update_goldens):
    scene, camera = tilted_quad_scene(interpolation)
    check(f"interp_{interpolation}", mr.render(scene, camera, 96, 64, spp=4, aa="msaa"), update_goldens)


def test_perspective_and_screen_interpolation_differ_where_they_should():
    # A sanity check on the scene, so that the goldens show a difference: equal at the near edge,
    # clearly different inside the quad.
    images = {m: mr.render(*tilted_quad_scene(m), 96, 64).color for m in ("screen", "perspective")}
    assert np.abs(images["screen"] - images["perspective"]).max() > 0.2


# --- blending: translucent overlapping triangles, replace / add / over ------------------------------


def blend_scene(mode):
    """Three overlapping triangles (premultiplied red, green, blue at alpha 0.5; for "add": alpha 0,
    additive light) drawn without depth test over an opaque white bar on the dark background."""
    scene = mr.Scene()
    scene.clear_color = BACKGROUND
    scene.add(mr.Mesh([[-8, -32, 0], [8, -32, 0], [8, 32, 0], [-8, 32, 0]], QUAD), color=(0.9, 0.9, 0.9))
    alpha = 0.0 if mode == "add" else 0.5
    tri = mr.Mesh([[-22, -20, 0], [22, -20, 0], [0, 18, 0]], [[0, 1, 2]])
    for (dx, dy), rgb in zip([(-12, 6), (12, 6), (0, -10)], [(1, 0, 0), (0, 1, 0), (0, 0, 1)]):
        model = np.eye(4)
        model[:2, 3] = dx, dy
        scene.add(tri, model=model, color=tuple(0.5 * c for c in rgb) + (alpha,), blend=mode, depth_test=False)
    camera = mr.Camera.orthographic(eye=(0, 0, 5), target=(0, 0, 0), height=64.0, near=0.0, far=10.0)
    return scene, camera


@pytest.mark.parametrize("mode", ["replace", "add", "over"])
def test_blending(mode, update_goldens):
    scene, camera = blend_scene(mode)
    check(f"blend_{mode}", mr.render(scene, camera, 96, 64, spp=4, aa="msaa"), update_goldens)


# --- clipping: geometry through the near plane ------------------------------------------------------


def near_clip_scene():
    """Three draws crossing the near plane (0.1): a vertex-coloured floor strip that starts behind
    the camera (red) and runs far ahead (blue), a slanted wall triangle with one corner behind the
    camera, and a yellow blade with two corners behind the camera whose cut (its straight lower
    edge) lies inside the view."""
    scene = mr.Scene()
    scene.clear_color = BACKGROUND
    floor = mr.Mesh([[-1.5, -1, 4], [1.5, -1, 4], [1.5, -1, -30], [-1.5, -1, -30]], QUAD,
                    [[1, 0, 0], [1, 0.6, 0], [0, 0.2, 1], [0, 0.8, 1]])
    scene.add(floor)
    wall = mr.Mesh([[0.6, -1, 1.5], [2.5, -1, -8], [1.2, 2, -6]], [[0, 1, 2]],
                   [[1, 1, 1], [0.1, 0.8, 0.2], [0.8, 0.1, 0.8]])
    scene.add(wall)
    blade = mr.Mesh([[-0.09, -0.045, 0.05], [-0.02, -0.045, 0.05], [0.25, 0.35, -2.5]], [[0, 1, 2]],
                    [[1, 0.9, 0.1], [1, 0.9, 0.1], [0.5, 0.1, 0.9]])
    scene.add(blade)
    camera = mr.Camera.look_at(eye=(0, 0, 0), target=(0, -0.1, -1), fov_y=60, near=0.1)
    return scene, camera


def test_near_plane_clipping(update_goldens):
    scene, camera = near_clip_scene()
    result = mr.render(scene, camera, 96, 64, spp=4, aa="msaa")
    assert result.stats["triangles_clipped"] == 4  # every triangle crosses the near plane
    check("clip_near", result, update_goldens)


# --- depth: intersecting quads ----------------------------------------------------------------------


def depth_scene():
    """Two vertex-coloured quads turned ±35° about the vertical axis cross along a vertical line,
    and a flat quad pierces both: depth testing decides every visible surface."""
    scene = mr.Scene()
    scene.clear_color = BACKGROUND
    scene.add(square(1, [[0.9, 0.2, 0.1], [1, 0.6, 0.1], [1, 0.6, 0.1], [0.9, 0.2, 0.1]]), model=rotation_y(35))
    scene.add(square(1, [[0.1, 0.4, 1], [0.1, 0.9, 0.6], [0.1, 0.9, 0.6], [0.1, 0.4, 1]]), model=rotation_y(-35))
    flat = mr.Mesh([[-1.4, -0.15, -0.9], [1.4, -0.15, -0.9], [1.4, -0.15, 0.9], [-1.4, -0.15, 0.9]], QUAD)
    scene.add(flat, color=(0.85, 0.85, 0.85))
    camera = mr.Camera.look_at(eye=(0.3, 1.1, 3.2), target=(0, 0, 0), fov_y=45)
    return scene, camera


def test_depth_intersecting_quads(update_goldens):
    scene, camera = depth_scene()
    check("depth_intersect", mr.render(scene, camera, 96, 64, spp=4, aa="msaa"), update_goldens)


# --- the built-in demo --------------------------------------------------------------------------------


def test_demo(update_goldens):
    scene, camera = mr.Scene.demo()
    check("demo", mr.render(scene, camera, 128, 72, spp=4, aa="msaa"), update_goldens)


# --- texture filtering: the demo's checker plane to the horizon with each filter -------------------------

PLANE_FILTERS = ["nearest", "bilinear", "trilinear", "anisotropic", "ewa", "sat"]


def plane_scene(sampler):
    """The demo's ground (a 512² checker texture repeated 20 times over a 320-unit quad) alone,
    seen from a low eye towards the horizon, with the given sampler."""
    demo, _ = mr.Scene.demo()
    ground = demo.draws[0]
    scene = mr.Scene()
    scene.clear_color = BACKGROUND
    scene.add(ground.mesh, texture=ground.texture, sampler=sampler)
    camera = mr.Camera.look_at(eye=(0.0, 1.5, 6.0), target=(0.0, 0.0, -20.0), fov_y=50.0)
    return scene, camera


@pytest.mark.parametrize("name", PLANE_FILTERS)
def test_texture_filter(name, update_goldens):
    scene, camera = plane_scene(name)
    check(f"plane_{name}", mr.render(scene, camera, 128, 72), update_goldens)


def test_mip_level_view(update_goldens):
    scene, camera = plane_scene("trilinear")
    check("plane_mip_levels", mr.render(scene, camera, 128, 72, debug_view="mip-level"), update_goldens)


def test_every_golden_has_a_test_and_a_readme_entry():
    names = {p.stem for p in GOLDEN_DIR.glob("*.png")}
    expected = {"aa_1spp", "aa_msaa4_rotated", "aa_ssaa16_grid", "interp_flat", "interp_screen",
                "interp_perspective", "blend_replace", "blend_add", "blend_over", "clip_near",
                "depth_intersect", "demo", "plane_mip_levels"} | {f"plane_{f}" for f in PLANE_FILTERS}
    expected |= {f"synth_{kind}" for kind in ("bricks", "pebbles", "sample_bricks", "sample_pebbles")}  # test_synthesis.py
    stray = {n for n in names if n.endswith((".actual", ".expected", ".diff"))}
    assert names - stray == expected
    readme = (GOLDEN_DIR / "README.md").read_text()
    for name in expected:
        assert f"`{name}.png`" in readme, name
        assert (GOLDEN_DIR / f"{name}.png").stat().st_size < 16384, name  # small: a few KiB, the textured demo 13 KiB


# --- the harness ------------------------------------------------------------------------------------


def small_render(color=(0.2, 0.6, 0.9)):
    scene = mr.Scene()
    scene.clear_color = BACKGROUND
    scene.add(mr.Mesh([[-6, -5, 0], [7, -4, 0], [0, 6, 0]], [[0, 1, 2]]), color=color)
    camera = mr.Camera.orthographic(eye=(0, 0, 5), target=(0, 0, 0), height=16.0, near=0.0, far=10.0)
    return mr.render(scene, camera, 24, 16, spp=4, aa="msaa")


def test_harness_passes_an_identical_render_and_returns_the_report(tmp_path):
    golden = tmp_path / "g.png"
    assert assert_matches_golden(small_render(), golden, update=True) is None
    report = assert_matches_golden(small_render(), golden)
    assert report.passed and report.max_abs_error == 0 and report.psnr == math.inf
    assert not any(p.exists() for p in golden_output_paths(golden))


def test_harness_wrong_render_fails_and_writes_actual_expected_and_diff(tmp_path):
    golden = tmp_path / "g.png"
    assert_matches_golden(small_render(), golden, update=True)
    with pytest.raises(AssertionError) as info:
        assert_matches_golden(small_render(color=(0.9, 0.2, 0.1)), golden)
    message = str(info.value)
    actual, expected, diff = golden_output_paths(golden)
    assert (actual.name, expected.name, diff.name) == ("g.actual.png", "g.expected.png", "g.diff.png")
    for p in (actual, expected, diff):
        assert p.parent == tmp_path and p.is_file() and str(p) in message
    assert "FAIL" in message and "worst: x" in message and "PSNR" in message and "--update-goldens" in message
    assert expected.read_bytes() == golden.read_bytes()
    np.testing.assert_array_equal(np.asarray(Image.open(actual)), small_render(color=(0.9, 0.2, 0.1)).to_srgb8())
    # the diff is opaque RGB, 8x the code difference (clipped): bright where the triangle is, black elsewhere
    d = np.asarray(Image.open(diff))
    a8, e8 = small_render(color=(0.9, 0.2, 0.1)).to_srgb8(), small_render().to_srgb8()
    np.testing.assert_array_equal(d, np.minimum(255, 8 * np.abs(a8[..., :3].astype(int) - e8[..., :3])))
    assert d[8, 12].max() == 255 and d[0, 0].max() == 0
    # a passing run removes the stale failure images
    assert_matches_golden(small_render(), golden)
    assert not any(p.exists() for p in (actual, expected, diff))


def test_harness_thresholds_are_in_srgb8_codes(tmp_path):
    golden = tmp_path / "g.png"
    base = np.full((8, 8, 4), 1.0, np.float32)
    base[..., :3] = mr.srgb_to_linear(np.float32(100 / 255))
    mr.write_image(golden, base)
    for codes, passes in ((2, True), (3, False)):  # default: more than 2 codes fails (no fraction allowed here)
        shifted = base.copy()
        shifted[0, 0, 1] = mr.srgb_to_linear(np.float32((100 + codes) / 255))
        if passes:
            assert assert_matches_golden(shifted, golden, out_dir=tmp_path / "out", fail_fraction=0).passed
        else:
            with pytest.raises(AssertionError, match="differ by more than"):
                assert_matches_golden(shifted, golden, out_dir=tmp_path / "out", fail_fraction=0)
            assert (tmp_path / "out" / "g.diff.png").is_file()
    # a small fraction of values may fail; any value past the hard threshold fails regardless
    shifted = base.copy()
    shifted[0, 0, 0] = mr.srgb_to_linear(np.float32(110 / 255))  # 1 of 256 values, 10 codes off
    assert assert_matches_golden(shifted, golden, fail_fraction=1 / 256).passed
    with pytest.raises(AssertionError, match="beyond the hard limit"):
        assert_matches_golden(shifted, golden, fail_fraction=1 / 256, hard_fail_threshold=9 / 255)


def test_harness_missing_golden_fails_with_the_instruction(tmp_path):
    golden = tmp_path / "sub" / "missing.png"
    with pytest.raises(AssertionError) as info:
        assert_matches_golden(small_render(), golden, out_dir=tmp_path / "out")
    message = str(info.value)
    assert "does not exist" in message and "--update-goldens" in message and str(golden) in message
    assert "test_golden.py::test_harness_missing_golden_fails_with_the_instruction" in message
    assert not golden.exists()
    assert (tmp_path / "out" / "missing.actual.png").is_file()  # the render, to look at


def test_harness_size_mismatch_fails_without_a_diff(tmp_path):
    golden = tmp_path / "g.png"
    mr.write_image(golden, np.ones((4, 4, 4), np.float32))
    with pytest.raises(AssertionError, match="sizes differ .actual 24x16, golden 4x4"):
        assert_matches_golden(small_render(), golden)
    actual, expected, diff = golden_output_paths(golden)
    assert actual.is_file() and expected.is_file() and not diff.exists()


def test_harness_out_dir_from_the_environment(tmp_path, monkeypatch):
    monkeypatch.setenv("MIPRASTER_GOLDEN_OUT", str(tmp_path / "env_out"))
    assert golden_output_paths(tmp_path / "x.png")[2] == tmp_path / "env_out" / "x.diff.png"
    assert golden_output_paths(tmp_path / "x.png", out_dir=tmp_path / "o")[0] == tmp_path / "o" / "x.actual.png"
    monkeypatch.delenv("MIPRASTER_GOLDEN_OUT")
    assert golden_output_paths(tmp_path / "x.png")[1] == tmp_path / "x.expected.png"


def test_harness_update_does_not_rewrite_an_identical_golden(tmp_path):
    golden = tmp_path / "g.png"
    assert_matches_golden(small_render(), golden, update=True)
    golden.write_bytes(golden.read_bytes())  # same bytes, new mtime
    before = golden.stat().st_mtime_ns
    assert_matches_golden(small_render(), golden, update=True)
    assert golden.stat().st_mtime_ns == before
    assert_matches_golden(small_render(color=(1, 1, 1)), golden, update=True)  # changed: rewritten
    np.testing.assert_array_equal(np.asarray(Image.open(golden)), small_render(color=(1, 1, 1)).to_srgb8())


def test_harness_bad_arguments(tmp_path):
    with pytest.raises(TypeError, match="actual"):
        assert_matches_golden(np.zeros((4, 4, 4), np.uint8), tmp_path / "g.png")
    with pytest.raises(ValueError, match="actual: expected shape"):
        assert_matches_golden(np.zeros((4, 4), np.float32), tmp_path / "g.png")
    with pytest.raises(ValueError, match="fail_fraction"):
        assert_matches_golden(small_render(), tmp_path / "g.png", fail_fraction=2)
    with pytest.raises(TypeError, match="update"):
        assert_matches_golden(small_render(), tmp_path / "g.png", update="yes")
    assert not any(tmp_path.iterdir())  # nothing written


def test_update_goldens_option_end_to_end(tmp_path):
    """pytest --update-goldens (the option and fixture of conftest.py) writes the golden; a later run
    without it compares with it; a run without it and without the golden fails."""
    (tmp_path / "conftest.py").write_text((pathlib.Path(__file__).parent / "conftest.py").read_text())
    (tmp_path / "test_it.py").write_text(textwrap.dedent(f"""
        import pathlib
        import mipraster as mr
        from mipraster.testing import assert_matches_golden

        def test_it(update_goldens):
            scene = mr.Scene()
            scene.add(mr.Mesh([[-1, -1, 0], [1, -1, 0], [0, 1, 0]], [[0, 1, 2]]), color=(0.5, 0.25, 1.0))
            camera = mr.Camera.from_matrices([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]],
                                             [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
            result = mr.render(scene, camera, 16, 12)
            assert_matches_golden(result, pathlib.Path({str(tmp_path)!r}) / "golden" / "tri.png",
                                  update=update_goldens)
    """))
    golden = tmp_path / "golden" / "tri.png"

    def run(*args):
        # no third-party plugins: they are not needed and some take most of a second to import
        env = dict(os.environ, PYTEST_DISABLE_PLUGIN_AUTOLOAD="1")
        return subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "--rootdir",
                               str(tmp_path), str(tmp_path / "test_it.py"), *args],
                              cwd=tmp_path, env=env, capture_output=True, text=True, timeout=120)

    missing = run()
    assert missing.returncode == 1 and "does not exist" in missing.stdout and "--update-goldens" in missing.stdout
    assert not golden.exists()
    written = run("--update-goldens")
    assert written.returncode == 0, written.stdout + written.stderr
    assert golden.is_file() and Image.open(golden).size == (16, 12)
    compared = run()
    assert compared.returncode == 0, compared.stdout + compared.stderr
