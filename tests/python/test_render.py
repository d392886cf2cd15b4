"""mipraster.render against numpy oracles: exact coverage of axis-aligned rectangles (top-left rule,
shared diagonals counted once), supersample coverage with the reported pattern, blending, culling;
the result's arrays (zero copy), determinism across threads, the demo, and every error path."""
import concurrent.futures
import os
import select
import shutil
import subprocess
import sysconfig

import numpy as np
import pytest
from PIL import Image

import mipraster as mr

W, H = 24, 16


def screen_camera(width=W, height=H):
    """Orthographic camera where world (x, y) = screen (x − W/2, H/2 − y): 1 world unit per pixel."""
    return mr.Camera.orthographic(eye=(0, 0, 5), target=(0, 0, 0), height=float(height), near=0.0, far=10.0)


def rectangle(x0, y0, x1, y1, width=W, height=H, colors=None):
    """Two triangles covering the screen rectangle [x0, x1] × [y0, y1] (pixels, y down)."""
    corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    positions = [(x - width / 2, height / 2 - y, 0.0) for x, y in corners]
    return mr.Mesh(positions, [[0, 1, 2], [0, 2, 3]], colors)


def coverage_oracle(rects, offsets, width=W, height=H):
    """Per pixel, the number of (rectangle, sample) pairs with the sample inside the rectangle, where
    the left and top edges are inside and the right and bottom edges are not (the top-left rule)."""
    count = np.zeros((height, width, len(offsets)))
    ys, xs = np.mgrid[0:height, 0:width]
    for s, (ox, oy) in enumerate(offsets):
        sx, sy = xs + ox, ys + oy
        for x0, y0, x1, y1 in rects:
            count[..., s] += (x0 <= sx) & (sx < x1) & (y0 <= sy) & (sy < y1)
    return count


def test_rectangle_covers_exactly_the_expected_pixels_with_its_colour():
    # Edges exactly on pixel centres: x = 2.5 (left: in), x = 9.5 (right: out), y = 3.5 (top: in),
    # y = 11.5 (bottom: out).
    scene = mr.Scene()
    scene.add(rectangle(2.5, 3.5, 9.5, 11.5), color=(0.25, 0.5, 0.75, 1.0))
    result = mr.render(scene, screen_camera(), W, H)
    expected = np.zeros((H, W, 4), np.float32)
    expected[3:11, 2:9] = [0.25, 0.5, 0.75, 1.0]
    np.testing.assert_array_equal(result.color, expected)
    assert result.stats["triangles_in"] == 2 and result.stats["triangles_rasterized"] == 2
    assert result.stats["samples_covered"] == 8 * 7


@pytest.mark.parametrize("spp, pattern, aa", [(1, "auto", "ssaa"), (4, "rotated", "msaa"), (16, "grid", "ssaa"),
                                              (8, "stratified", "msaa"), (6, "grid", "msaa")])
def test_additive_rectangles_count_coverage_like_the_oracle(spp, pattern, aa):
    rng = np.random.default_rng(spp)
    rects = []
    for _ in range(12):
        x = np.sort(rng.integers(-8, 8 * (W + 4), 2)) / 8  # multiples of 1/8 px, some off screen
        y = np.sort(rng.integers(-8, 8 * (H + 4), 2)) / 8
        if x[0] < x[1] and y[0] < y[1]:
            rects.append((x[0], y[0], x[1], y[1]))
    scene = mr.Scene()
    for r in rects:
        scene.add(rectangle(*r), blend="add", depth_test=False, color=(1, 1, 1, 1))
    result = mr.render(scene, screen_camera(), W, H, spp=spp, pattern=pattern, aa=aa, seed=7, keep_samples=True)
    assert result.pattern.shape == (spp, 2)
    assert np.all((result.pattern >= 0) & (result.pattern < 1))
    assert np.all(result.pattern * 256 == np.round(result.pattern * 256))
    counts = coverage_oracle(rects, result.pattern)
    np.testing.assert_array_equal(result.samples[..., 0], counts)
    np.testing.assert_allclose(result.color[..., 0], counts.mean(axis=2), rtol=1e-6)
    assert result.sample_depth is None  # no draw tests depth: no depth buffer


@pytest.mark.parametrize("spp, pattern, aa", [(1, "auto", "ssaa"), (4, "rotated", "msaa"), (8, "stratified", "msaa")])
def test_triangles_between_the_samples_are_counted_and_the_coverage_is_the_oracles(spp, pattern, aa):
    # Rectangles up to a quarter pixel across at multiples of 1/64 px: a rectangle whose box holds no
    # sample position (the pattern's smallest to largest offset, per axis, in some pixel) but meets
    # a pixel of the view gives two triangles between the samples, left out before binning; the
    # samples are still the coverage oracle's.
    rng = np.random.default_rng(40 + spp)
    rects = []
    for _ in range(300):
        x0, y0 = rng.integers(-64, 64 * (W + 1), 2) / 64
        w, h = rng.integers(1, 17, 2) / 64
        rects.append((x0, y0, x0 + w, y0 + h))
    scene = mr.Scene()
    for r in rects:
        scene.add(rectangle(*r), blend="add", depth_test=False, color=(1, 1, 1, 1))
    result = mr.render(scene, screen_camera(), W, H, spp=spp, pattern=pattern, aa=aa, seed=3, keep_samples=True)
    np.testing.assert_array_equal(result.samples[..., 0], coverage_oracle(rects, result.pattern))
    lo, hi = result.pattern.min(axis=0), result.pattern.max(axis=0)

    def meets(a, b, first, last, n):  # some pixel p of n with [p + first, p + last] meeting [a, b]
        return any(p + last >= a and p + first <= b for p in range(n))

    between = sum(meets(x0, x1, 0, 1, W) and meets(y0, y1, 0, 1, H) and
                  not (meets(x0, x1, lo[0], hi[0], W) and meets(y0, y1, lo[1], hi[1], H))
                  for x0, y0, x1, y1 in rects)
    assert between > 0  # (at one sample most of them; the wider patterns leave room for a few)
    assert result.stats["triangles_between_samples"] == 2 * between


def test_over_blending_and_clear_colour():
    scene = mr.Scene()
    scene.add(rectangle(0, 0, 12, 16), blend="over", color=(0.5, 0.0, 0.0, 0.5))  # premultiplied
    result = mr.render(scene, screen_camera(), W, H, clear_color=(0.0, 0.0, 1.0))
    np.testing.assert_array_equal(result.color[:, :12], np.broadcast_to([0.5, 0, 0.5, 1], (H, 12, 4)))
    np.testing.assert_array_equal(result.color[:, 12:], np.broadcast_to([0, 0, 1, 1], (H, 12, 4)))
    scene.clear_color = (0.0, 1.0, 0.0, 1.0)  # used when render() is given no clear colour
    np.testing.assert_array_equal(mr.render(scene, screen_camera(), W, H).color[0, -1], [0, 1, 0, 1])


def test_flat_interpolation_takes_the_first_vertex_colour():
    colors = [[0.2, 0.4, 0.6], [1, 0, 0], [0, 1, 0], [0, 0, 1]]
    scene = mr.Scene()
    scene.add(rectangle(0, 0, W, H, colors=colors), interpolation="flat")
    result = mr.render(scene, screen_camera(), W, H)
    np.testing.assert_allclose(result.color.reshape(-1, 4), [[0.2, 0.4, 0.6, 1.0]] * (W * H), rtol=1e-6)
    smooth = mr.Scene()
    smooth.add(rectangle(0, 0, W, H, colors=colors), interpolation="screen")
    assert len(np.unique(mr.render(smooth, screen_camera(), W, H).color.reshape(-1, 4), axis=0)) > 10


def test_culling_uses_the_on_screen_winding():
    # Counter-clockwise as seen by the viewer (world +x then +y, camera looking down -z): front.
    ccw = mr.Mesh([[-4, -4, 0], [4, -4, 0], [0, 4, 0]], [[0, 1, 2]])
    for cull, drawn in (("none", True), ("back", True), ("front", False)):
        scene = mr.Scene()
        scene.add(ccw, cull=cull)
        result = mr.render(scene, screen_camera(), W, H)
        assert (result.color[..., 3].sum() > 0) == drawn, cull
        assert result.stats["triangles_backface"] == (0 if drawn else 1)


# --- the result's arrays ------------------------------------------------------------------------------


def test_color_is_the_renderers_buffer_not_a_copy_and_is_writable():
    scene = mr.Scene()
    scene.add(rectangle(1, 1, 5, 5))
    result = mr.render(scene, screen_camera(), W, H, spp=4, keep_samples=True)
    for array in (result.color, result.samples):
        assert array.dtype == np.float32 and array.flags.c_contiguous
        assert not array.flags.owndata  # numpy did not allocate it ...
        assert type(array.base).__name__ == "PyCapsule"  # ... the C++ vector, owned by a capsule, holds it
        assert array.flags.writeable
    assert result.color.shape == (H, W, 4) and result.samples.shape == (H, W, 4, 4)
    assert result.sample_depth.shape == (H, W, 4) and result.sample_depth.dtype == np.float32
    result.color[0, 0] = 7.0
    assert result.color[0, 0, 0] == 7.0
    view = result.color[2:4]
    del result
    assert view.base.base is not None and view[0, 0, 3] == 0.0  # the buffer outlives the result


def test_samples_resolve_to_the_colour_with_a_box_filter():
    scene, camera = mr.Scene.demo()
    result = mr.render(scene, camera, 40, 24, spp=5, pattern="stratified", aa="ssaa", keep_samples=True)
    np.testing.assert_allclose(result.samples.mean(axis=2), result.color, rtol=1e-5, atol=1e-7)
    assert np.all((result.sample_depth >= 0) & (result.sample_depth <= 1))  # reverse-Z window depth


def test_stats_and_repr():
    scene, camera = mr.Scene.demo()
    result = mr.render(scene, camera, 32, 18, threads=2)
    assert set(result.stats) == {
        "triangles_in", "triangles_clipped", "triangles_outside", "triangles_between_samples", "triangles_backface",
        "triangles_degenerate",
        "triangles_nonfinite", "triangles_rasterized", "samples_covered", "samples_passed",
        "shader_invocations", "depth_blocks_rejected", "tiles_deferred", "tiles_empty", "threads", "transform_ms", "setup_ms", "raster_ms", "total_ms"}
    assert result.stats["triangles_in"] == sum(d.mesh.triangle_count for d in scene.draws)
    assert result.stats["threads"] == 2
    assert (result.width, result.height, result.spp, result.pattern_kind) == (32, 18, 1, "center")
    assert repr(result).startswith("RenderResult(32x18, spp=1 center")
    assert repr(scene).startswith("Scene(draws=2, triangles=")


def test_thread_count_does_not_change_the_image():
    scene, camera = mr.Scene.demo()
    for kw in (dict(spp=4, aa="msaa"), dict(spp=8, aa="ssaa", pattern="stratified", seed=3)):
        one = mr.render(scene, camera, 160, 96, threads=1, **kw)
        two = mr.render(scene, camera, 160, 96, threads=2, **kw)
        np.testing.assert_array_equal(one.color, two.color)


def test_concurrent_renders_from_python_threads_agree():
    scene, camera = mr.Scene.demo()
    # The threads race to build the fresh scene's mip levels; a second, separate scene renders alone.
    with concurrent.futures.ThreadPoolExecutor(4) as pool:
        results = list(pool.map(lambda _: mr.render(scene, camera, 64, 40, spp=4, threads=1).color, range(4)))
    alone_scene, alone_camera = mr.Scene.demo()
    sequential = mr.render(alone_scene, alone_camera, 64, 40, spp=4, threads=1).color
    for r in results:
        np.testing.assert_array_equal(r, sequential)


def test_concurrent_two_thread_renders_and_a_forked_child_agree():
    """Renders keep their thread pools idle for the next render: concurrent renders each get their
    own, and a child forked after renders (without the parent's workers) renders with new ones."""
    scene, camera = mr.Scene.demo()
    expected = mr.render(scene, camera, 96, 64, spp=4, threads=2).color
    with concurrent.futures.ThreadPoolExecutor(3) as pool:
        results = list(pool.map(lambda _: mr.render(scene, camera, 96, 64, spp=4, threads=2).color, range(6)))
    for r in results:
        np.testing.assert_array_equal(r, expected)
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: render on two threads, report whether the image matches
        try:
            same = np.array_equal(mr.render(scene, camera, 96, 64, spp=4, threads=2).color, expected)
            os.write(write, b"1" if same else b"0")
        finally:
            os._exit(0)
    os.close(write)
    deadline = 60.0
    ready, _, _ = select.select([read], [], [], deadline)
    if not ready:
        os.kill(pid, 9)
        os.waitpid(pid, 0)
        pytest.fail(f"the forked child's two-thread render did not finish in {deadline:.0f} s")
    answer = os.read(read, 1)
    os.close(read)
    os.waitpid(pid, 0)
    assert answer == b"1"


def _cli():
    if os.environ.get("MIPRASTER_EXE"):  # e.g. the sanitized build of .ci/sanitize
        return os.environ["MIPRASTER_EXE"]
    for d in (sysconfig.get_path("scripts"), sysconfig.get_path("scripts", f"{os.name}_user")):
        p = os.path.join(d, "mipraster")
        if os.access(p, os.X_OK):
            return p
    return shutil.which("mipraster")


def test_demo_matches_the_command_line_renderer(tmp_path):
    exe = _cli()
    assert exe, "the mipraster executable is not installed"
    out = tmp_path / "cli.png"
    subprocess.run([exe, "render", "-o", str(out), "--size", "96x64"], check=True, capture_output=True)
    scene, camera = mr.Scene.demo()
    result = mr.render(scene, camera, 96, 64, spp=4, aa="msaa")  # the command's defaults
    np.testing.assert_array_equal(result.to_srgb8(), np.asarray(Image.open(out)))
    assert result.color[..., 3].min() == 1.0  # sky and ground cover everything


# --- errors -----------------------------------------------------------------------------------------------


def one_draw_scene():
    scene = mr.Scene()
    scene.add(rectangle(1, 1, 5, 5))
    return scene


@pytest.mark.parametrize(
    "kwargs, words",
    [
        (dict(blend="xor"), ["blend", "'xor'", "'replace'", "'add'", "'over'"]),
        (dict(interpolation="linear"), ["interpolation", "'linear'", "'perspective'", "'screen'", "'flat'"]),
        (dict(cull="cw"), ["cull", "'cw'", "'none'", "'back'", "'front'"]),
        (dict(model=np.eye(3)), ["model", "(4, 4)", "(3, 3)"]),
        (dict(model=np.diag([1, 1, np.nan, 1])), ["model[2, 2]", "nan"]),
        (dict(color=(1, 1)), ["color", "(3,) or (4,)", "(2,)"]),
        (dict(color=(1, np.inf, 1)), ["color[1]", "inf"]),
        (dict(color=(1.0, 1.0, 1e39)), ["color[2] = 1e+39", "does not fit in float32"]),
    ],
)
def test_scene_add_refuses_bad_values(kwargs, words):
    with pytest.raises(ValueError) as e:
        mr.Scene().add(rectangle(0, 0, 1, 1), **kwargs)
    for w in words:
        assert w in str(e.value)


@pytest.mark.parametrize(
    "kwargs, words",
    [
        (dict(blend=None), ["blend"]),
        (dict(depth_test="yes"), ["depth_test", "True or False"]),
        (dict(depth_write=1), ["depth_write"]),
    ],
)
def test_scene_add_refuses_wrong_types(kwargs, words):
    with pytest.raises(TypeError) as e:
        mr.Scene().add(rectangle(0, 0, 1, 1), **kwargs)
    for w in words:
        assert w in str(e.value)
    with pytest.raises(TypeError, match="mesh: expected a mipraster.Mesh"):
        mr.Scene().add(np.zeros((3, 3)))


@pytest.mark.parametrize(
    "kwargs, message",
    [
        # messages from C++ (std::invalid_argument -> ValueError)
        (dict(width=0), "width: expected 1 to 32768 pixels, got 0"),
        (dict(height=40000), "height: expected 1 to 32768 pixels, got 40000"),
        (dict(spp=0), "samples per pixel: expected 1 to 64, got 0"),
        (dict(spp=65), "samples per pixel: expected 1 to 64, got 65"),
        # 32768² pixels × (16 bytes of colour + 4 of depth output): 20 GiB, over the default 16
        (dict(width=32768, height=32768, spp=64), "a render of 32768x32768 pixels at 64 samples per pixel needs 20.0 GiB"),
        (dict(spp=8, pattern="rotated"), "pattern 'rotated' has 4 samples; got samples=8"),
        (dict(spp=2, pattern="center"), "pattern 'center' has 1 sample; got samples=2"),
        (dict(threads=-1), "threads: expected 0 (all cores) to 256, got -1"),
        (dict(threads=1000), "threads: expected 0 (all cores) to 256, got 1000"),
        # checked in Python (C++ could not even take the value)
        (dict(width=2**40), "width: expected 1 to 32768 pixels, got 1099511627776"),
        (dict(seed=-1), "seed"),
        (dict(aa="fxaa"), "aa: unknown value 'fxaa'; expected one of 'ssaa', 'msaa'"),
        (dict(pattern="poisson"), "pattern: unknown value 'poisson'; expected one of 'auto', 'center', 'grid'"),
        (dict(clear_color=(0, 0)), "clear_color"),
        (dict(clear_color=(0.0, float("nan"), 0.0)), "clear_color[1] is nan; expected a finite number"),
        (dict(clear_color=[0.0, 0.0, 0.0, float("inf")]), "clear_color[3] is inf; expected a finite number"),
        (dict(clear_color=[0.0] * 5), "clear_color: expected shape (3,) or (4,), got (5,)"),
        # finite as a double, infinite as the float32 the framebuffer holds (the fast path and numpy's)
        (dict(clear_color=(1e39, 0.0, 0.0, 1.0)), "clear_color[0] = 1e+39 does not fit in float32"),
        (dict(clear_color=np.array([0.0, 0.0, -3.5e38])), "clear_color[2] = -3.5e+38 does not fit in float32"),
    ],
)
def test_render_refuses_bad_settings_with_value_error(kwargs, message):
    args = dict(width=W, height=H)
    args.update(kwargs)
    with pytest.raises(ValueError) as e:
        mr.render(one_draw_scene(), screen_camera(), **args)
    assert message in str(e.value)


@pytest.mark.parametrize(
    "args, kwargs, words",
    [
        ((None, "camera"), {}, ["scene", "NoneType"]),
        (("scene", None), {}, ["camera", "NoneType"]),
        (("scene", "camera"), dict(width=8.0), ["width", "integer", "float"]),
        (("scene", "camera"), dict(spp=True), ["spp", "bool"]),
        (("scene", "camera"), dict(keep_samples="no"), ["keep_samples"]),
        (("scene", "camera"), dict(aa=4), ["aa"]),
    ],
)
def test_render_refuses_wrong_types(args, kwargs, words):
    values = {"scene": one_draw_scene(), "camera": screen_camera(), None: None}
    call = dict(width=W, height=H)
    call.update(kwargs)
    with pytest.raises(TypeError) as e:
        mr.render(values[args[0]], values[args[1]], **call)
    for w in words:
        assert w in str(e.value)


def test_numpy_integers_are_accepted_for_sizes():
    result = mr.render(one_draw_scene(), screen_camera(), np.int64(W), np.int32(H), spp=np.uint8(4))
    assert result.color.shape == (H, W, 4) and result.spp == 4


def test_depth_blocks_behind_an_occluder_drawn_first_are_skipped_and_the_image_is_unchanged():
    def screen_quad(z, color):
        positions = [(x - W / 2, H / 2 - y, z) for x, y in [(0, 0), (W, 0), (W, H), (0, H)]]
        return mr.Mesh(positions, [[0, 1, 2], [0, 2, 3]], [color] * 4)

    occluder = screen_quad(1.0, (0.2, 0.4, 0.6, 1.0))
    behind = [screen_quad(-1.0 + 0.05 * i, (0.9, 0.1 * i, 0.0, 1.0)) for i in range(10)]  # each nearer
    front_first, back_first = mr.Scene(), mr.Scene()
    for mesh in [occluder] + behind:
        front_first.add(mesh)
    for mesh in behind + [occluder]:
        back_first.add(mesh)
    a = mr.render(front_first, screen_camera(), W, H, spp=4, threads=1)
    b = mr.render(back_first, screen_camera(), W, H, spp=4, threads=2)
    # 10 full-screen quads behind, each 2 triangles over 3 x 2 blocks of 8 x 8 pixels (W x H = 24 x 16),
    # each block fully inside one triangle or shared by both.
    assert a.stats["depth_blocks_rejected"] > 0
    assert b.stats["depth_blocks_rejected"] == 0  # every quad is nearer than what it covers
    assert a.stats["samples_covered"] == b.stats["samples_covered"] == 11 * W * H * 4
    assert a.stats["samples_passed"] == W * H * 4
    np.testing.assert_array_equal(a.color, b.color)
