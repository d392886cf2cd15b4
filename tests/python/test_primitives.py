"""The primitive layer: rasterize / interpolate / resolve, and render()'s per-pixel depth.

Oracles are geometric identities: interpolating the clip-space positions themselves must land
every sample back on its own position (perspective mode: x/w, y/w is the sample's NDC; screen mode:
interpolated screen coordinates are the sample's). Snapping vertices to 1/256 px moves a triangle
by at most √2/512 px, which bounds the difference.
"""
import numpy as np
import pytest

import mipraster as mr

SNAP_PX = np.sqrt(2) / 512 * 1.05 + 1e-4  # snapping band + float32 barycentric rounding


def random_scene(seed, n=60, size=1.0):
    rng = np.random.default_rng(seed)
    centres = rng.uniform(-1.0, 1.0, (n, 1, 2))
    xy = centres + rng.uniform(-size, size, (n, 3, 2))
    w = rng.uniform(0.4, 5.0, (n, 3))  # a different w per vertex: strongly non-affine
    z = rng.uniform(-0.9, 0.9, (n, 3))
    pos = np.concatenate([xy * w[..., None], (z * w)[..., None], w[..., None]], axis=-1).reshape(-1, 4)
    tris = np.arange(3 * n).reshape(n, 3)
    return pos, tris


def sample_positions(raster, width, height):
    """Screen positions (x right, y down, in pixels) of every sample, (H, W, S, 2)."""
    jj, ii = np.meshgrid(np.arange(height), np.arange(width), indexing="ij")
    corner = np.stack([ii, jj], axis=-1)[:, :, None, :].astype(np.float64)
    return corner + raster.pattern[None, None, :, :]


def to_screen(ndc_xy, width, height):
    return np.stack([(ndc_xy[..., 0] + 1) * width / 2, (1 - ndc_xy[..., 1]) * height / 2], axis=-1)


@pytest.mark.parametrize("spp", [1, 4, 16])
def test_perspective_interpolation_of_clip_positions_returns_each_sample_position(spp):
    W, H = 64, 48
    pos, tris = random_scene(1)
    raster = mr.rasterize(pos, tris, W, H, spp=spp)
    assert raster.triangle_id.shape == (H, W, spp) and raster.triangle_id.dtype == np.int32
    assert raster.barycentrics.shape == (H, W, spp, 2) and raster.barycentrics.dtype == np.float32
    covered = raster.triangle_id >= 0
    assert covered.mean() > 0.5
    clip = mr.interpolate(pos, raster, tris)[covered]  # (M, 4)
    got = to_screen(clip[:, :2] / clip[:, 3:4], W, H)
    err = np.abs(got - sample_positions(raster, W, H)[covered])
    assert err.max() <= SNAP_PX, err.max()


def test_screen_interpolation_of_screen_positions_returns_each_sample_position():
    W, H = 64, 48
    pos, tris = random_scene(2)
    raster = mr.rasterize(pos, tris, W, H, spp=4)
    screen = to_screen(pos[:, :2] / pos[:, 3:4], W, H)
    got = mr.interpolate(screen, raster, tris, mode="screen")
    covered = raster.triangle_id >= 0
    err = np.abs(got - sample_positions(raster, W, H))[covered]
    assert err.max() <= SNAP_PX * 4, err.max()  # screen weights are recovered from float32 ones
    # ... and perspective interpolation of the same values differs (the triangles are tilted).
    persp = mr.interpolate(screen, raster, tris, mode="perspective")
    assert np.abs(persp - got)[covered].max() > 0.5


def test_flat_uses_the_first_vertex_and_empty_samples_are_zero():
    pos, tris = random_scene(3, n=20)
    raster = mr.rasterize(pos, tris, 32, 32, spp=4)
    values = np.arange(pos.shape[0], dtype=np.float64) * 10.0
    flat = mr.interpolate(values, raster, tris, mode="flat")
    ids = raster.triangle_id
    assert flat.shape == ids.shape
    np.testing.assert_array_equal(flat[ids >= 0], values[tris[ids[ids >= 0], 0]])
    assert (flat[ids < 0] == 0).all()
    assert (raster.barycentrics[ids < 0] == 0).all()
    assert (raster.depth[ids < 0] == 1.0).all()


def test_the_nearest_triangle_wins_in_both_depth_conventions():
    # Two full-screen quads at different depths; the second one submitted is nearer.
    quad = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], dtype=np.float64) * 1.5
    tris = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])
    for convention, far_z, near_z in (("opengl", 0.5, -0.5), ("reverse_z", 0.2, 0.8)):
        pos = np.zeros((8, 4))
        pos[:4, :2], pos[4:, :2] = quad, quad
        pos[:4, 2], pos[4:, 2] = far_z, near_z
        pos[:, 3] = 1.0
        raster = mr.rasterize(pos, tris, 16, 8, spp=4, depth=convention)
        assert set(np.unique(raster.triangle_id)) <= {2, 3}, convention
        expected = near_z / 2 + 0.5 if convention == "opengl" else near_z
        np.testing.assert_allclose(raster.depth, expected, rtol=1e-7)


def test_triangles_crossing_the_near_plane_keep_their_submitted_weights():
    W, H = 48, 48
    pos = np.array([[-0.5, -0.5, 0.5, 1.0], [0.6, -0.4, 1.0, 2.0], [0.1, 0.8, 0.5, -1.0]])
    tris = np.array([[0, 1, 2]])
    raster = mr.rasterize(pos, tris, W, H, spp=4)
    assert raster.stats["triangles_clipped"] == 1
    covered = raster.triangle_id >= 0
    assert covered.sum() > 200
    clip = mr.interpolate(pos, raster, tris)[covered]
    assert (clip[:, 3] > 0).all()  # only the part in front of the eye draws
    assert (clip[:, 2] >= -clip[:, 3] - 1e-6).all()  # and behind the near plane: nothing
    got = to_screen(clip[:, :2] / clip[:, 3:4], W, H)
    assert np.abs(got - sample_positions(raster, W, H)[covered]).max() <= SNAP_PX


def test_thread_counts_and_dtypes_give_identical_rasters():
    pos, tris = random_scene(4, n=400, size=0.3)
    a = mr.rasterize(pos, tris, 80, 60, spp=4, threads=1)
    b = mr.rasterize(pos.astype(np.float32).astype(np.float64), tris.astype(np.int16), 80, 60, spp=4, threads=2)
    c = mr.rasterize(np.asfortranarray(pos), tris.tolist(), 80, 60, spp=4, threads=2)
    np.testing.assert_array_equal(a.triangle_id, c.triangle_id)
    np.testing.assert_array_equal(a.barycentrics, c.barycentrics)
    np.testing.assert_array_equal(a.depth, c.depth)
    assert b.triangle_id.shape == a.triangle_id.shape


def test_outputs_own_the_cpp_buffers():
    pos, tris = random_scene(5, n=5)
    r = mr.rasterize(pos, tris, 8, 8)
    for a in (r.triangle_id, r.barycentrics, r.depth):
        assert not a.flags.owndata and a.base is not None and a.flags.writeable


def test_resolve_is_the_mean_of_each_pixels_samples():
    rng = np.random.default_rng(6)
    s = rng.uniform(-1, 2, (5, 7, 9, 3)).astype(np.float32)
    np.testing.assert_allclose(mr.resolve(s), s.astype(np.float64).mean(axis=2), rtol=1e-6, atol=1e-7)
    assert mr.resolve(s[..., 0]).shape == (5, 7)
    with pytest.raises(ValueError, match="samples"):
        mr.resolve(s[0, 0])
    with pytest.raises(ValueError, match="tent"):
        mr.resolve(s, filter="tent")


@pytest.mark.parametrize(
    "pos, tris, kwargs, error, words",
    [
        ([[0, 0, 0, 1], [1, 0, 0, np.nan], [0, 1, 0, 1]], [[0, 1, 2]], {}, ValueError, ["pos_clip", "1"]),
        ([[0, 0, 0, 1], [1, 0, 0, 1], [0, 1, 0, 1]], [[0, 1, 3]], {}, ValueError, ["triangles[0][2]", "3"]),
        ([[0, 0, 0, 1], [1, 0, 0, 1], [0, 1, 0, 1]], [[0, -1, 2]], {}, ValueError, ["triangles[0][1]"]),
        ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], {}, ValueError, ["pos_clip", "4"]),
        ([[0, 0, 0, 1], [1, 0, 0, 1], [0, 1, 0, 1]], [[0.0, 1.0, 2.0]], {}, TypeError, ["triangles"]),
        ([["a", 0, 0, 1]], [[0, 0, 0]], {}, TypeError, ["pos_clip"]),
        ([[0, 0, 0, 1], [1, 0, 0, 1], [0, 1, 0, 1]], [[0, 1, 2]], {"spp": 65}, ValueError, ["samples", "65"]),
        ([[0, 0, 0, 1], [1, 0, 0, 1], [0, 1, 0, 1]], [[0, 1, 2]], {"depth": "d3d"}, ValueError, ["d3d", "opengl"]),
        ([[0, 0, 0, 1], [1, 0, 0, 1], [0, 1, 0, 1]], [[0, 1, 2]], {"cull": "left"}, ValueError, ["left", "back"]),
    ],
)
def test_bad_input_names_the_argument(pos, tris, kwargs, error, words):
    with pytest.raises(error) as e:
        mr.rasterize(pos, tris, 8, 8, **kwargs)
    for w in words:
        assert w in str(e.value)


def test_interpolate_checks_its_inputs():
    pos, tris = random_scene(7, n=4)
    r = mr.rasterize(pos, tris, 8, 8)
    with pytest.raises(ValueError, match="attributes"):
        mr.interpolate(np.zeros((pos.shape[0] + 1, 2)), r, tris)
    with pytest.raises(ValueError, match="mode"):
        mr.interpolate(np.zeros(pos.shape[0]), r, tris, mode="linear")
    with pytest.raises(TypeError, match="raster"):
        mr.interpolate(np.zeros(pos.shape[0]), {"triangle_id": r.triangle_id}, tris)
    if (r.triangle_id >= 0).any():
        with pytest.raises(ValueError, match="triangles"):
            mr.interpolate(np.zeros(pos.shape[0]), r, tris[:0])


def test_render_depth_is_view_distance_of_the_nearest_surface_and_inf_where_empty():
    # A square facing the camera at distance 5 covering the image centre only.
    quad = mr.Mesh(positions=[[-1, -1, -5], [1, -1, -5], [1, 1, -5], [-1, 1, -5]], triangles=[[0, 1, 2], [0, 2, 3]])
    scene = mr.Scene()
    scene.add(quad)
    cam = mr.Camera.look_at(eye=(0, 0, 0), target=(0, 0, -1), fov_y=60)
    for spp in (1, 4):
        r = mr.render(scene, cam, 40, 40, spp=spp)
        assert r.depth.shape == (40, 40) and r.depth.dtype == np.float32
        covered = np.isfinite(r.depth)
        assert covered[20, 20] and not covered[0, 0]
        np.testing.assert_allclose(r.depth[covered], 5.0, rtol=1e-6)
        assert (r.depth[~covered] == np.inf).all()
        # The covered pixels are those whose alpha is non-zero.
        np.testing.assert_array_equal(covered, r.color[..., 3] > 0)
    assert mr.render(scene, cam, 8, 8, depth=False).depth is None
    no_test = mr.Scene()
    no_test.add(quad, depth_test=False)
    assert mr.render(no_test, cam, 8, 8).depth is None
