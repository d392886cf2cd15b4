"""The primitive layer: rasterize / interpolate / resolve, and render()'s per-pixel depth.

Oracles are geometric identities: interpolating the clip-space positions themselves must land
every sample back on its own position (perspective mode: x/w, y/w is the sample's NDC; screen mode:
interpolated screen coordinates are the sample's). Snapping vertices to 1/256 px moves a triangle
by at most √2/512 px, which bounds the difference.
"""
import math

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


@pytest.mark.parametrize("mode", ["perspective", "screen"])
def test_interpolated_values_stay_within_the_vertex_values(mode):
    # The raster's weights are float32, and two of them can sum above 1: with vertex values
    # [1e6, 0, 0] the first vertex's weight 1 - b1 - b2 went negative and so did the values
    # (-0.011 in this triangle; its w ranges over 10^7). Random triangles, one vertex value in turn
    # large and the others 0: every covered sample within [0, value].
    W = H = 32
    w = np.array([5.53872139e03, 1.31114414e-04, 8.11186514e02])
    screen = np.array([[-20.61096756124171, -17.911794228962865], [67.6179161557204, 63.42493842030686],
                       [31.705749809553144, 34.13189048408914]])
    ndc = np.stack([screen[:, 0] * 2 / W - 1, 1 - screen[:, 1] * 2 / H], 1)
    tricky = np.stack([ndc[:, 0] * w, ndc[:, 1] * w, np.full(3, 1e-7), w], 1)
    random, _ = random_scene(3, n=40)
    drawn = 0
    for pos in [tricky] + [random[3 * k:3 * k + 3] for k in range(40)]:
        raster = mr.rasterize(pos, [[0, 1, 2]], W, H, spp=4)
        covered = raster.triangle_id == 0
        if not covered.any():
            continue
        drawn += 1
        for corner in range(3):
            values = np.zeros(3)
            values[corner] = 1e6
            got = mr.interpolate(values, raster, [[0, 1, 2]], mode=mode)[covered]
            assert got.min() >= 0.0 and got.max() <= 1e6, (corner, got.min(), got.max())
    assert drawn > 20


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
    big = np.zeros((pos.shape[0], 2))
    big[2, 1] = 1e39  # (float64: the float32 result held inf, with only numpy's overflow warning)
    with pytest.raises(ValueError, match=r"attributes\[2, 1\] = 1e\+39 does not fit in float32"):
        mr.interpolate(big, r, tris)
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


# --- interpolate(derivatives=True) ------------------------------------------------------------------
# Oracles: a double-precision ray cast against the world-space triangle (perspective mode) and 2D
# barycentrics of the projected vertices (screen mode), differentiated by central finite differences
# at the samples' own positions. Neither uses the clip-space plane formula of the implementation.

FD_STEP_PX = 1e-3


def perspective_matrix(fov_y_deg, aspect, near, far):
    f = 1.0 / np.tan(np.radians(fov_y_deg) / 2)
    return np.array([[f / aspect, 0, 0, 0], [0, f, 0, 0],
                     [0, 0, (far + near) / (near - far), 2 * far * near / (near - far)], [0, 0, -1, 0]])


def random_rotation(rng):
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q *= np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def perspective_scene(rng, view_vertices, width, height):
    """World-space triangles seen by a randomly placed camera, and their clip-space positions.
    `view_vertices` (T, 3, 3) are camera-space positions (camera at the origin looking down −z)."""
    view = np.eye(4)
    view[:3, :3] = random_rotation(rng)
    view[:3, 3] = rng.uniform(-3, 3, 3)
    proj = perspective_matrix(rng.uniform(40, 80), width / height, 0.1, 100.0)
    vv = view_vertices.reshape(-1, 3)
    world = (np.linalg.inv(view) @ np.c_[vv, np.ones(len(vv))].T).T[:, :3]
    pos_clip = (proj @ view @ np.c_[world, np.ones(len(world))].T).T
    tris = np.arange(len(vv)).reshape(-1, 3)
    return world, pos_clip, tris, np.linalg.inv(proj @ view)


def ray_cast(world, tris, inv_view_proj, width, height, ids, px, py, attr):
    """Perspective-correct attribute at screen points (px, py) of triangles `ids`: intersect the
    eye ray with the world-space triangle's plane and take area ratios there."""
    ndc = np.stack([2 * px / width - 1, 1 - 2 * py / height], axis=-1)
    ends = []
    for z in (-1.0, 1.0):
        h = np.c_[ndc, np.full(len(px), z), np.ones(len(px))] @ inv_view_proj.T
        ends.append(h[:, :3] / h[:, 3:4])
    origin, direction = ends[0], ends[1] - ends[0]
    a, b, c = (world[tris[ids, k]] for k in range(3))
    n = np.cross(b - a, c - a)
    t = np.einsum("mi,mi->m", n, a - origin) / np.einsum("mi,mi->m", n, direction)
    hit = origin + t[:, None] * direction
    nn = np.einsum("mi,mi->m", n, n)
    w0 = np.einsum("mi,mi->m", n, np.cross(b - hit, c - hit)) / nn
    w1 = np.einsum("mi,mi->m", n, np.cross(c - hit, a - hit)) / nn
    weights = np.stack([w0, w1, 1 - w0 - w1], axis=1)
    return np.einsum("mi,mik->mk", weights, attr[tris[ids]])


def screen_affine(pos_clip, tris, width, height, ids, px, py, attr):
    """Screen-space (affine) attribute: 2D barycentrics of (px, py) in the projected triangle."""
    s = to_screen(pos_clip[:, :2] / pos_clip[:, 3:4], width, height)[tris[ids]]  # (M, 3, 2)
    p = np.stack([px, py], axis=-1)

    def cross2(u, v):
        return u[..., 0] * v[..., 1] - u[..., 1] * v[..., 0]

    area = cross2(s[:, 1] - s[:, 0], s[:, 2] - s[:, 0])
    weights = np.stack([cross2(s[:, (i + 1) % 3] - p, s[:, (i + 2) % 3] - p) / area for i in range(3)], axis=1)
    return np.einsum("mi,mik->mk", weights, attr[tris[ids]])


def check_derivatives_against(oracle, raster, tris, attr, mode, rng, n_points=400):
    """interpolate(derivatives=True) at random covered samples vs central differences of `oracle`."""
    H, W, S = raster.triangle_id.shape
    values, d_dx, d_dy = mr.interpolate(attr, raster, tris, mode=mode, derivatives=True)
    k = 1 if attr.ndim == 1 else attr.shape[1]
    for a in (values, d_dx, d_dy):
        assert a.dtype == np.float32 and a.shape == (H, W, S) + (() if attr.ndim == 1 else (k,))
    covered = raster.triangle_id >= 0
    assert covered.sum() > 100
    rows, cols, samples = np.nonzero(covered)
    pick = rng.choice(len(rows), size=min(n_points, len(rows)), replace=False)
    rows, cols, samples = rows[pick], cols[pick], samples[pick]
    ids = raster.triangle_id[rows, cols, samples]
    px = cols + raster.pattern[samples, 0]
    py = rows + raster.pattern[samples, 1]
    a2 = attr.reshape(attr.shape[0], -1).astype(np.float64)

    def f(x, y):
        return oracle(ids, x, y, a2)

    h = FD_STEP_PX
    fd_x = (f(px + h, py) - f(px - h, py)) / (2 * h)
    fd_y = (f(px, py + h) - f(px, py - h)) / (2 * h)
    got_x = d_dx[rows, cols, samples].reshape(len(pick), -1)
    got_y = d_dy[rows, cols, samples].reshape(len(pick), -1)
    scale = max(np.abs(fd_x).max(), np.abs(fd_y).max())
    np.testing.assert_allclose(got_x, fd_x, rtol=1e-5, atol=1e-6 * scale)
    np.testing.assert_allclose(got_y, fd_y, rtol=1e-5, atol=1e-6 * scale)
    # The values themselves come from the (snapped) raster: equal to the oracle within the snap band.
    got = values[rows, cols, samples].reshape(len(pick), -1)
    slack = (np.abs(fd_x) + np.abs(fd_y)) * SNAP_PX * 1.5 + 1e-5 * np.abs(f(px, py)).max() + 1e-6
    assert (np.abs(got - f(px, py)) <= slack).all()
    return fd_x, fd_y


def random_view_triangles(rng, n):
    """Camera-space triangles in front of the camera with strongly varying depth."""
    centre_z = rng.uniform(-8.0, -1.5, (n, 1, 1))
    z = centre_z + rng.uniform(-1.2, 1.2, (n, 3, 1))
    z = np.minimum(z, -0.5)
    xy = rng.uniform(-0.6, 0.6, (n, 1, 2)) * -centre_z + rng.uniform(-0.5, 0.5, (n, 3, 2)) * -z
    return np.concatenate([xy, z], axis=-1)


@pytest.mark.parametrize("spp, pattern", [(1, "center"), (4, "stratified"), (16, "stratified")])
@pytest.mark.parametrize("k", [1, 3])
def test_perspective_derivatives_match_finite_differences_of_a_ray_cast(spp, pattern, k):
    W, H = 64, 48
    rng = np.random.default_rng(100 + spp + k)
    world, pos, tris, inv_vp = perspective_scene(rng, random_view_triangles(rng, 12), W, H)
    assert np.ptp(pos[:, 3]) > 2.0  # w varies: the interpolation is far from affine
    raster = mr.rasterize(pos, tris, W, H, spp=spp, pattern=pattern, seed=spp)
    attr = rng.uniform(-2, 2, (len(pos), k))
    attr = attr[:, 0] if k == 1 else attr
    fd_x, fd_y = check_derivatives_against(
        lambda ids, x, y, a: ray_cast(world, tris, inv_vp, W, H, ids, x, y, a), raster, tris, attr, "perspective", rng)
    assert np.abs(fd_x).max() > 1e-2 and np.abs(fd_y).max() > 1e-2  # the test measures something


@pytest.mark.parametrize("k", [1, 2])
def test_screen_derivatives_match_finite_differences_of_screen_barycentrics(k):
    W, H = 64, 48
    rng = np.random.default_rng(200 + k)
    world, pos, tris, inv_vp = perspective_scene(rng, random_view_triangles(rng, 12), W, H)
    raster = mr.rasterize(pos, tris, W, H, spp=4, pattern="stratified")
    attr = rng.uniform(-2, 2, (len(pos), k))
    attr = attr[:, 0] if k == 1 else attr
    check_derivatives_against(lambda ids, x, y, a: screen_affine(pos, tris, W, H, ids, x, y, a),
                              raster, tris, attr, "screen", rng)
    # Screen-space interpolation is affine on screen: its derivatives are constant per triangle,
    # and they differ from the perspective-correct ones.
    _, sx, sy = mr.interpolate(attr, raster, tris, mode="screen", derivatives=True)
    _, px_, py_ = mr.interpolate(attr, raster, tris, derivatives=True)
    ids = raster.triangle_id
    for t in np.unique(ids[ids >= 0]):
        vals = sx[ids == t]
        np.testing.assert_allclose(vals, np.broadcast_to(vals[0], vals.shape), rtol=1e-5, atol=1e-7)
    assert np.abs(px_ - sx).max() > 1e-2 or np.abs(py_ - sy).max() > 1e-2


@pytest.mark.parametrize("mode", ["perspective", "screen"])
def test_derivatives_of_a_triangle_crossing_the_near_plane(mode):
    W, H = 48, 40
    rng = np.random.default_rng(300)
    # One vertex behind the camera (camera-space z > 0, so clip w < 0): rasterize clips the triangle.
    view_tri = np.array([[[-1.0, -0.8, -2.0], [1.2, -0.5, -3.0], [0.2, 0.4, 1.0]]])
    world, pos, tris, inv_vp = perspective_scene(rng, view_tri, W, H)
    assert pos[2, 3] < 0 < min(pos[0, 3], pos[1, 3])
    raster = mr.rasterize(pos, tris, W, H, spp=4, pattern="stratified")
    assert raster.stats["triangles_clipped"] == 1
    attr = rng.uniform(-1, 1, (3, 3))
    if mode == "perspective":
        oracle = lambda ids, x, y, a: ray_cast(world, tris, inv_vp, W, H, ids, x, y, a)  # noqa: E731
    else:
        oracle = lambda ids, x, y, a: screen_affine(pos, tris, W, H, ids, x, y, a)  # noqa: E731
    check_derivatives_against(oracle, raster, tris, attr, mode, rng)
    _, d_dx, d_dy = mr.interpolate(attr, raster, tris, mode=mode, derivatives=True)
    assert np.isfinite(d_dx).all() and np.isfinite(d_dy).all()


def test_derivatives_of_an_affine_ramp_are_its_slope_in_pixels():
    # w = 1 everywhere: NDC x grows by 2/W per pixel to the right, NDC y by −2/H per pixel down.
    W, H = 16, 10
    pos = np.array([[-1, -1, 0, 1], [3, -1, 0, 1], [-1, 3, 0, 1]], dtype=np.float64)
    tris = [[0, 1, 2]]
    raster = mr.rasterize(pos, tris, W, H, spp=4)
    assert (raster.triangle_id == 0).all()
    for mode in ("perspective", "screen"):
        values, d_dx, d_dy = mr.interpolate(pos[:, :2], raster, tris, mode=mode, derivatives=True)
        np.testing.assert_allclose(d_dx, np.broadcast_to([2 / W, 0], d_dx.shape), atol=1e-7)
        np.testing.assert_allclose(d_dy, np.broadcast_to([0, -2 / H], d_dy.shape), atol=1e-7)
        _, sx, sy = mr.interpolate(to_screen(pos[:, :2], W, H)[:, 1], raster, tris, mode=mode, derivatives=True)
        assert sx.shape == (H, W, 4)
        np.testing.assert_allclose(sx, 0, atol=1e-6)
        np.testing.assert_allclose(sy, 1, rtol=1e-6)  # screen y per pixel down


def test_derivatives_keep_values_and_are_zero_for_flat_and_uncovered_samples():
    pos, tris = random_scene(8, n=20, size=0.4)
    raster = mr.rasterize(pos, tris, 40, 30, spp=4)
    covered = raster.triangle_id >= 0
    assert 0 < covered.mean() < 1
    attr = np.random.default_rng(8).uniform(-1, 1, (len(pos), 3))
    for mode in ("perspective", "screen", "flat"):
        for a in (attr, attr[:, 1]):
            plain = mr.interpolate(a, raster, tris, mode=mode)
            values, d_dx, d_dy = mr.interpolate(a, raster, tris, mode=mode, derivatives=True)
            np.testing.assert_array_equal(values, plain)
            assert d_dx.shape == d_dy.shape == plain.shape and d_dx.dtype == d_dy.dtype == np.float32
            assert (d_dx[~covered] == 0).all() and (d_dy[~covered] == 0).all()
            if mode == "flat":
                assert (d_dx == 0).all() and (d_dy == 0).all()
            else:
                assert np.abs(d_dx[covered]).max() > 0 and np.abs(d_dy[covered]).max() > 0
    assert mr.interpolate(attr, raster, tris, derivatives=False).shape == (30, 40, 4, 3)
    with pytest.raises(TypeError, match="derivatives"):
        mr.interpolate(attr, raster, tris, derivatives="yes")


def test_raster_keeps_a_copy_of_the_clip_positions():
    pos, tris = random_scene(9, n=4)
    raster = mr.rasterize(pos, tris, 8, 8)
    np.testing.assert_array_equal(raster.pos_clip, pos)
    np.testing.assert_array_equal(raster.w, pos[:, 3])
    pos[:] = 0.0  # the caller's array (already float64 and contiguous) may change afterwards
    assert (raster.pos_clip[:, 3] > 0).all()


def exact_coverage(pos, width, height, band=0.01):
    """Whether each pixel centre lies inside the triangle pos (clip space, every w > 0), by exact
    rational arithmetic on the given doubles; None within `band` px of an edge's line (snapping
    to 1/256 px may move a centre that close across it)."""
    from fractions import Fraction

    screen = [((Fraction(x) / Fraction(w) + 1) * width / 2, (1 - Fraction(y) / Fraction(w)) * height / 2)
              for x, y, _, w in pos]
    (ax, ay), (bx, by), (cx, cy) = screen
    orientation = 1 if (bx - ax) * (cy - ay) - (by - ay) * (cx - ax) > 0 else -1
    out = np.empty((height, width), dtype=object)
    for row in range(height):
        for col in range(width):
            px, py = Fraction(2 * col + 1, 2), Fraction(2 * row + 1, 2)
            inside, near = True, False
            for (x0, y0), (x1, y1) in zip(screen, screen[1:] + screen[:1]):
                cross = (x1 - x0) * (py - y0) - (y1 - y0) * (px - x0)
                near |= cross * cross < Fraction(band) ** 2 * ((x1 - x0) ** 2 + (y1 - y0) ** 2)  # (beyond float)
                inside &= cross * orientation >= 0
            out[row, col] = None if near else inside
    return out


@pytest.mark.parametrize("seed, lowest, highest", [(7, 15, 30), (8, 30, 300)])
def test_edges_between_vertices_far_beyond_the_guard_band_cross_the_image_exactly(seed, lowest, highest):
    # An edge whose two vertices lie 10^15 to 10^300 px out on opposite sides, its line through the
    # image: its crossings of the guard band are small differences of huge numbers (10^21 px
    # covered nothing, 10^22 a quarter of the pixels; beyond 10^40, where binary128 no longer held
    # the crossing's parameter, half the image was lost, and from 10^155 the triangle was dropped
    # as degenerate). Lines through the centre at any angle, or along a row or a column; scaling by
    # powers of two keeps the intended line exact.
    rng = np.random.default_rng(seed)
    W, H = 24, 16
    for trial in range(60):
        e = rng.uniform(lowest, highest)
        angle = rng.uniform(0, 2 * np.pi)
        d = 10**e * np.array([np.cos(angle), np.sin(angle)])
        if trial % 3 == 0:
            v0, v1 = d, -d * 2.0 ** rng.integers(-3, 4)
        else:
            axis = trial % 3 - 1  # the coordinate that runs far out
            v0 = np.full(2, rng.uniform(-0.9, 0.9))
            v0[axis] = 10**e
            v1 = v0.copy()
            v1[axis] = -(10**e) * 2.0 ** rng.integers(-3, 4)
        # The third vertex's offset from the edge's line: up to 10^28 times smaller than the edge
        # is long (double cannot tell such a sliver from a line, binary128 can).
        side = 10 ** np.clip(e + rng.uniform(-28, 15), lowest, highest) * np.array([-np.sin(angle), np.cos(angle)])
        ndc = np.array([v0, v1, side + rng.uniform(-0.3, 0.3) * d])
        w = 2.0 ** rng.integers(-3, 4, 3).astype(float)
        pos = np.concatenate([ndc * w[:, None], rng.uniform(-0.5, 0.5, (3, 1)) * w[:, None], w[:, None]], axis=1)
        expected = exact_coverage(pos, W, H)
        got = mr.rasterize(pos, [[0, 1, 2]], W, H).triangle_id[..., 0] >= 0
        decided = expected != None  # noqa: E711 (element-wise)
        assert decided.sum() > W * H // 2
        assert np.array_equal(got[decided], expected[decided].astype(bool)), (trial, pos)


def test_huge_triangle_through_a_camera_covers_what_a_small_one_does():
    # The same triangle scaled by 10^3 … 10^30 (and by its model matrix to 10^300), and a camera
    # zoomed in 10^20 times: the upper half of the image each time.
    camera = mr.Camera.look_at((0, 0, 3), (0, 0, 0))
    triangle = np.array([[-1, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    for k in (1e3, 1e20, 1e21, 1e22, 1e30):
        scene = mr.Scene()
        scene.add(mr.Mesh(triangle * k, [[0, 1, 2]]))
        alpha = mr.render(scene, camera, 16, 16).color[..., 3]
        assert np.array_equal(alpha, np.repeat([[1.0], [0.0]], 8, axis=0) * np.ones((16, 16))), k
    # Beyond float32 through the model matrix (10^50: half the image; 10^160: nothing), and the
    # same triangle 10^50 times larger through a w scaled down (within 10^-30 of the eye in clip
    # space: cut away by the plane w ≥ 10^-30 before it was scaled up for clipping).
    mesh = mr.Mesh(triangle, [[0, 1, 2]])
    for model in (np.diag([1e39, 1e39, 1e39, 1]), np.diag([1e50, 1e50, 1e50, 1]), np.diag([1e160, 1e160, 1e160, 1]),
                  np.diag([1e300, 1e300, 1e300, 1]), np.diag([1, 1, 1, 1e-50])):
        scene = mr.Scene()
        scene.add(mesh, model=model)
        alpha = mr.render(scene, camera, 16, 16).color[..., 3]
        assert np.array_equal(alpha, np.repeat([[1.0], [0.0]], 8, axis=0) * np.ones((16, 16))), model
    scene = mr.Scene()
    scene.add(mesh)
    zoomed = mr.render(scene, mr.Camera.look_at((0, 0, 3), (0, 0, 0), fov_y=1e-20), 16, 16).color[..., 3]
    assert zoomed[:8].all() and not zoomed[8:].any()


def test_surfaces_a_millionth_apart_stay_ordered_wherever_their_vertices_snap():
    # DESIGN.md §2.3: surfaces 10⁻⁶ apart (relative) ordered at distances 10⁻² … 10⁵ with near 10⁻³.
    # Two parallel quads tilted 30°, moved 0-1 % of the distance off the view axis so that their
    # vertices snap to different points: with each vertex's own depth interpolated over the snapped
    # triangle, the farther quad won every pixel in 10 of 60 placements. Oracle: a double ray cast
    # of each plane through every pixel centre (reverse-Z depth near / t), and the colour.
    size, near, fov = 48, 1e-3, 0.5
    f = 1 / math.tan(fov / 2)
    projection = np.zeros((4, 4))
    projection[0, 0] = projection[1, 1] = f
    projection[2, 3], projection[3, 2] = near, -1  # reverse-Z, infinite far
    camera = mr.Camera.from_matrices(np.eye(4), projection, depth_convention="reverse_z")
    quad = mr.Mesh(np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32), [[0, 1, 2], [0, 2, 3]])
    c, s = math.cos(math.pi / 6), math.sin(math.pi / 6)
    tilt = np.array([[c, 0, s, 0], [0, 1, 0, 0], [-s, 0, c, 0], [0, 0, 0, 1]])
    centres = (np.arange(size) + 0.5) / size * 2 - 1
    rays = np.stack([*np.meshgrid(centres / f, -centres / f), -np.ones((size, size))], axis=-1)
    rng = np.random.default_rng(11)
    for trial in range(60):
        d = 10.0 ** rng.choice([-2, 0, 2, 5])
        shift = rng.uniform(0, 0.01) * d * np.array([np.cos(a := rng.uniform(0, 2 * np.pi)), np.sin(a)])
        k = d * math.tan(fov) * 2

        def model(z):
            m = np.eye(4)
            m[:3, 3] = (shift[0], shift[1], -z)
            return m @ tilt @ np.diag([k, k, k, 1])

        nearer, farther = model(d), model(d * (1 + 1e-6))
        for first, second in ((nearer, farther), (farther, nearer)):
            scene = mr.Scene()
            scene.add(quad, model=first, color=(0, 1, 0) if first is nearer else (1, 0, 0))
            scene.add(quad, model=second, color=(0, 1, 0) if second is nearer else (1, 0, 0))
            image = mr.render(scene, camera, size, size, threads=1).color
            assert not (image[..., 0] > 0.5).any(), (trial, d, shift)
        scene = mr.Scene()
        scene.add(quad, model=nearer)
        got = mr.render(scene, camera, size, size, threads=1, keep_samples=True).sample_depth[..., 0]
        normal = nearer[:3, :3] @ np.array([0, 0, 1.0])
        exact = near / ((nearer[:3, 3] @ normal) / (rays @ normal))
        assert np.abs(got / exact - 1).max() < 2e-7, (trial, d, shift)
