"""mipraster.Camera against independent pinhole models: look-at, OpenCV calibrations, raw OpenGL
matrices and orthographic views; the projection is checked with numpy maths written here, and by
rendering a tiny triangle around a point and checking which pixel it covers."""
import math

import numpy as np
import pytest

import mipraster as mr

RNG_SEED = 20240611


def normalize(v):
    return v / np.linalg.norm(v)


def random_rotation(rng):
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def covered_pixels(result):
    return {(int(x), int(y)) for y, x in zip(*np.nonzero(result.color[..., 3] > 0))}


def render_triangle(camera, world_vertices, width, height, **kw):
    scene = mr.Scene()
    scene.add(mr.Mesh(world_vertices, [[0, 1, 2]]), **kw)
    return mr.render(scene, camera, width, height, threads=1)


# --- look_at -------------------------------------------------------------------------------------


def pinhole_look_at(eye, target, up, fov_y_deg, width, height):
    """Independent look-at pinhole: camera basis, focal length in pixels, principal point at the centre."""
    w = normalize(np.asarray(target, float) - eye)
    u = normalize(np.cross(w, up))
    v = np.cross(u, w)
    f = (height / 2) / math.tan(math.radians(fov_y_deg) / 2)
    return u, v, w, f


def test_look_at_projects_points_like_a_pinhole_camera():
    rng = np.random.default_rng(RNG_SEED)
    for _ in range(20):
        eye = rng.uniform(-5, 5, 3)
        target = eye + rng.normal(size=3)
        up = rng.normal(size=3)
        fov = rng.uniform(10, 120)
        width, height = int(rng.integers(8, 300)), int(rng.integers(8, 300))
        u, v, w, f = pinhole_look_at(eye, target, up, fov, width, height)
        points = eye + rng.normal(size=(50, 3)) + 3 * w
        rel = points - eye
        xc, yc, zc = rel @ u, rel @ v, rel @ w
        keep = zc > 0.1
        expected_x = width / 2 + f * xc[keep] / zc[keep]
        expected_y = height / 2 - f * yc[keep] / zc[keep]
        got = mr.Camera.look_at(eye, target, up, fov_y=fov).project(points[keep], width, height)
        np.testing.assert_allclose(got[:, 0], expected_x, rtol=1e-9, atol=1e-7)
        np.testing.assert_allclose(got[:, 1], expected_y, rtol=1e-9, atol=1e-7)
        # reverse-Z with an infinite far plane: depth = near / distance along the axis
        np.testing.assert_allclose(got[:, 2], 0.01 / zc[keep], rtol=1e-9)


@pytest.mark.parametrize("pixel", [(0, 0), (12, 3), (47, 29), (30, 17)])
def test_look_at_point_lands_on_its_pixel_when_rendered(pixel):
    width, height, fov = 48, 30, 50.0
    eye, target, up = np.array([1.0, 2.0, 3.0]), np.array([0.2, 0.1, -1.0]), np.array([0.0, 1.0, 0.0])
    u, v, w, f = pinhole_look_at(eye, target, up, fov, width, height)
    i, j = pixel
    depth = 4.0
    direction = w + ((i + 0.5 - width / 2) / f) * u - ((j + 0.5 - height / 2) / f) * v
    point = eye + depth * direction
    # A triangle around the point, 0.3 px in radius on screen: it covers that pixel's centre only.
    r = 0.3 * depth / f
    tri = [point + r * (math.cos(a) * u + math.sin(a) * v) for a in np.radians([90, 210, 330])]
    camera = mr.Camera.look_at(eye, target, up, fov_y=fov)
    np.testing.assert_allclose(camera.project(point, width, height)[:2], [i + 0.5, j + 0.5], atol=1e-9)
    assert covered_pixels(render_triangle(camera, tri, width, height)) == {pixel}


# --- OpenCV ----------------------------------------------------------------------------------------


def opencv_project(K, R, t, points):
    """cv2.projectPoints without distortion: x_cam = R X + t, (u, v) = K x_cam / z."""
    cam = points @ R.T + t
    uvw = cam @ K.T
    return uvw[:, :2] / uvw[:, 2:3], cam[:, 2]


def opencv_unproject(K, R, t, uv, z):
    """World points that OpenCV projects to pixel coordinates uv at camera depth z."""
    fx, s, cx, fy, cy = K[0, 0], K[0, 1], K[0, 2], K[1, 1], K[1, 2]
    uv = np.atleast_2d(uv)
    y = (uv[:, 1] - cy) / fy
    x = (uv[:, 0] - cx - s * y) / fx
    cam = np.stack([x * z, y * z, np.full_like(x, z)], axis=1)
    return (cam - t) @ R  # R^T (cam - t), row-wise


def random_opencv_camera(rng, width, height):
    K = np.array([[rng.uniform(30, 200), rng.uniform(-5, 5), rng.uniform(0, width)],
                  [0.0, rng.uniform(30, 200), rng.uniform(0, height)],
                  [0.0, 0.0, 1.0]])
    return K, random_rotation(rng), rng.normal(size=3)


def test_from_opencv_projects_like_opencv_with_pixel_centres_at_integers():
    rng = np.random.default_rng(RNG_SEED + 1)
    for _ in range(20):
        width, height = int(rng.integers(16, 400)), int(rng.integers(16, 400))
        K, R, t = random_opencv_camera(rng, width, height)
        uv = rng.uniform(-10, [width + 10, height + 10], size=(30, 2))
        z = rng.uniform(0.5, 50)
        points = opencv_unproject(K, R, t, uv, z)
        expected_uv, expected_z = opencv_project(K, R, t, points)
        np.testing.assert_allclose(expected_uv, uv, atol=1e-8)  # the oracle is self-consistent
        got = mr.Camera.from_opencv(K, R, t, near=0.1, far=100).project(points, width, height)
        # OpenCV's pixel (i, j) has its centre at (i, j); the library's at (i + 1/2, j + 1/2).
        np.testing.assert_allclose(got[:, :2], expected_uv + 0.5, rtol=1e-9, atol=1e-6)
        # reverse-Z with a finite far plane, in terms of the distance z along the optical axis
        n, f = 0.1, 100.0
        np.testing.assert_allclose(got[:, 2], (n / (f - n)) * (f / expected_z - 1.0), rtol=1e-6, atol=1e-12)


@pytest.mark.parametrize("pixel", [(0, 0), (5, 2), (39, 27), (20, 11)])
def test_from_opencv_point_lands_on_its_pixel_when_rendered(pixel):
    width, height = 40, 28  # not square, so a transposed image would fail
    rng = np.random.default_rng(RNG_SEED + 2)
    K = np.array([[35.0, 1.5, 19.0], [0.0, 31.0, 12.5], [0.0, 0.0, 1.0]])
    R, t = random_rotation(rng), rng.normal(size=3)
    i, j = pixel
    # A triangle 0.3 px around OpenCV pixel (i, j) at depth 3: the library's pixel (i, j).
    offsets = 0.3 * np.array([[0.0, -1.0], [-0.87, 0.5], [0.87, 0.5]])
    tri = opencv_unproject(K, R, t, np.array([i, j]) + offsets, 3.0)
    camera = mr.Camera.from_opencv(K, R, t)
    assert covered_pixels(render_triangle(camera, tri, width, height)) == {pixel}


def test_from_opencv_nearer_surface_wins_in_either_order():
    K = np.array([[20.0, 0, 7.5], [0, 20.0, 7.5], [0, 0, 1]])
    R, t = np.eye(3), np.zeros(3)
    camera = mr.Camera.from_opencv(K, R, t)
    quad = lambda z: mr.Mesh(opencv_unproject(K, R, t, [[-1, -1], [17, -1], [17, 17], [-1, 17]], z),
                             [[0, 1, 2], [0, 2, 3]])
    near_quad, far_quad = quad(2.0), quad(5.0)
    for order in ([near_quad, far_quad], [far_quad, near_quad]):
        scene = mr.Scene()
        for mesh in order:
            scene.add(mesh, color=(1, 0, 0, 1) if mesh is near_quad else (0, 0, 1, 1))
        result = mr.render(scene, camera, 16, 16)
        np.testing.assert_array_equal(result.color.reshape(-1, 4), [[1, 0, 0, 1]] * 256)


# --- raw OpenGL matrices ------------------------------------------------------------------------------


def gl_look_at(eye, target, up):
    f = normalize(np.asarray(target, float) - eye)
    s = normalize(np.cross(f, up))
    u = np.cross(s, f)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = s, u, -f
    m[:3, 3] = -m[:3, :3] @ eye
    return m


def gl_perspective(fov_y_deg, aspect, n, f):
    c = 1.0 / math.tan(math.radians(fov_y_deg) / 2)
    return np.array([[c / aspect, 0, 0, 0], [0, c, 0, 0],
                     [0, 0, (f + n) / (n - f), 2 * f * n / (n - f)], [0, 0, -1, 0]])


def test_from_matrices_uses_opengl_depth_and_matches_look_at():
    width, height = 32, 24
    eye, target, up = np.array([0.5, 1.0, 4.0]), np.zeros(3), np.array([0.0, 1.0, 0.0])
    camera = mr.Camera.from_matrices(gl_look_at(eye, target, up), gl_perspective(40, width / height, 0.5, 20))
    assert camera.depth_convention == "opengl"
    reference = mr.Camera.look_at(eye, target, up, fov_y=40)
    points = np.random.default_rng(RNG_SEED + 3).normal(size=(20, 3))
    np.testing.assert_allclose(camera.project(points, width, height)[:, :2],
                               reference.project(points, width, height)[:, :2], rtol=1e-9, atol=1e-9)

    # depth LESS: the nearer quad wins whatever the order; sample depth is z_ndc / 2 + 1/2. The
    # camera faces the quads here, so each has one depth everywhere.
    camera = mr.Camera.from_matrices(gl_look_at(np.array([0.0, 0.0, 4.0]), target, up),
                                     gl_perspective(40, width / height, 0.5, 20))

    def quad(z):
        return mr.Mesh([[-5, -5, z], [5, -5, z], [5, 5, z], [-5, 5, z]], [[0, 1, 2], [0, 2, 3]])

    near_quad, far_quad = quad(0.5), quad(-0.5)
    for order in ([near_quad, far_quad], [far_quad, near_quad]):
        scene = mr.Scene()
        for mesh in order:
            scene.add(mesh, color=(1, 0, 0, 1) if mesh is near_quad else (0, 0, 1, 1))
        result = mr.render(scene, camera, width, height, keep_samples=True)
        np.testing.assert_array_equal(result.color[..., :3].reshape(-1, 3), [[1, 0, 0]] * (width * height))
    n, f, distance = 0.5, 20.0, 3.5
    z_ndc = ((f + n) / (n - f) * -distance + 2 * f * n / (n - f)) / distance
    np.testing.assert_allclose(camera.project([0.3, -0.2, 0.5], width, height)[2], z_ndc / 2 + 0.5, rtol=1e-12)
    np.testing.assert_allclose(result.sample_depth, np.float32(z_ndc / 2 + 0.5), rtol=1e-6)


# --- orthographic --------------------------------------------------------------------------------------


def test_orthographic_maps_world_units_linearly():
    camera = mr.Camera.orthographic(eye=(1, 2, 10), target=(1, 2, 0), height=8.0, near=1, far=20)
    width, height = 40, 16  # 2 px per world unit vertically and horizontally
    got = camera.project([[1, 2, 0], [3, 3, -5], [-1, 0, 9]], width, height)
    np.testing.assert_allclose(got[:, :2], [[20, 8], [24, 6], [16, 12]], atol=1e-12)
    # reverse-Z: near (distance 1) -> 1, far (distance 20) -> 0, linear in between
    np.testing.assert_allclose(got[:, 2], [(20 - 10) / 19, (20 - 15) / 19, (20 - 1) / 19], rtol=1e-12)


# --- errors and repr ------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "make, error, words",
    [
        (lambda: mr.Camera.look_at((0, 0, 1), (0, 0, 1)), ValueError, ["eye and target coincide"]),
        # finite, but target - eye (or its cross product with up) overflows: was "up is parallel"
        (lambda: mr.Camera.look_at((1e308, 0, 0), (-1e308, 0, 0)), ValueError, ["eye and target are too far apart"]),
        (lambda: mr.Camera.look_at((0, 0, 1), (0, 0, 0), up=(1e308, 1e308, 0)), ValueError,
         ["up and the view direction are too large"]),
        (lambda: mr.Camera.look_at((0, 0, 1), (0, 0, 0), up=(0, 0, 2)), ValueError, ["up", "parallel"]),
        (lambda: mr.Camera.look_at((0, 0, 1), (0, 0, 0), fov_y=180), ValueError, ["fov_y", "(0, 180)", "180"]),
        (lambda: mr.Camera.look_at((0, 0, 1), (0, 0, 0), fov_y=0), ValueError, ["fov_y"]),
        (lambda: mr.Camera.look_at((0, 0, 1), (0, 0, 0), near=0), ValueError, ["near", "> 0"]),
        (lambda: mr.Camera.look_at((0, 0, 1), (0, 0, 0), near=1, far=1), ValueError, ["far", "near"]),
        (lambda: mr.Camera.look_at((0, 0), (0, 0, 0)), ValueError, ["eye", "(3,)", "(2,)"]),
        (lambda: mr.Camera.look_at((0, np.nan, 1), (0, 0, 0)), ValueError, ["eye[1]", "nan"]),
        (lambda: mr.Camera.look_at((0, 0, 1), (0, 0, 0), fov_y="wide"), TypeError, ["fov_y"]),
        (lambda: mr.Camera.orthographic((0, 0, 1), (0, 0, 0), height=0), ValueError, ["height"]),
        (lambda: mr.Camera.orthographic((0, 0, 1), (0, 0, 0), near=5, far=5), ValueError, ["near", "far"]),
        # finite bounds whose difference overflows: the depth scale was 0, every sample failed its test
        (lambda: mr.Camera.orthographic((0, 0, 1), (0, 0, 0), near=-9e307, far=9e307), ValueError,
         ["near", "far", "far - near"]),
        (lambda: mr._core.orthographic(-1e308, 1e308, -1, 1, 0, 1), ValueError, ["orthographic", "r - l"]),
        (lambda: mr._core.orthographic(-1, 1, 0, 1e-310, 0, 1), ValueError, ["orthographic", "t - b"]),
        (lambda: mr.Camera.from_matrices(np.eye(4), np.eye(3)), ValueError, ["projection", "(4, 4)", "(3, 3)"]),
        (lambda: mr.Camera.from_matrices(np.full((4, 4), np.inf), np.eye(4)), ValueError, ["view[0, 0]", "inf"]),
        (lambda: mr.Camera.from_matrices(np.eye(4), np.eye(4), "directx"), ValueError,
         ["depth_convention", "'directx'", "'reverse_z'", "'opengl'"]),
        (lambda: mr.Camera.from_opencv(np.eye(3) * 2, np.eye(3), np.zeros(3)), ValueError, ["K", "[0, 0, 1]"]),
        (lambda: mr.Camera.from_opencv([[10, 0, 5], [0, -10, 5], [0, 0, 1]], np.eye(3), np.zeros(3)), ValueError,
         ["fy=-10"]),
        (lambda: mr.Camera.from_opencv(np.eye(3), np.eye(3) * 2, np.zeros(3)), ValueError, ["R", "rotation"]),
        (lambda: mr.Camera.from_opencv(np.eye(3), np.diag([1.0, 1.0, -1.0]), np.zeros(3)), ValueError,
         ["det R"]),
        (lambda: mr.Camera.from_opencv(np.eye(3), [0.1, 0.2, 0.3], np.zeros(3)), ValueError,
         ["R", "(3, 3)", "(3,)"]),
        (lambda: mr.Camera.from_opencv(np.eye(3), np.eye(3), np.zeros(4)), ValueError, ["t", "(3,)", "(4,)"]),
        (lambda: mr.Camera.from_opencv(np.eye(3), np.eye(3), np.zeros(3), near=-1), ValueError, ["near"]),
        # A near below float32's smallest normal number: depth near / distance rounded to 0, the
        # clear depth, and the image was blank (near=1e-45), or lost precision (near=1e-40).
        (lambda: mr.Camera.look_at((0, 0, 3), (0, 0, 0), near=1e-45), ValueError,
         ["near = 1e-45 is too small", ">= 1.17549435e-38"]),
        (lambda: mr.Camera.look_at((0, 0, 3), (0, 0, 0), near=1e-40), ValueError, ["near", ">= 1.17549435e-38"]),
        (lambda: mr.Camera.look_at((0, 0, 3), (0, 0, 0), near=1e-300, far=1), ValueError, ["near", "1.17549435e-38"]),
        (lambda: mr.Camera.from_opencv(np.eye(3), np.eye(3), np.zeros(3), near=1e-45), ValueError,
         ["near", ">= 1.17549435e-38"]),
        (lambda: mr._core.perspective(1.0, 1.0, 1e-320), ValueError, ["near", ">= 1.17549435e-38"]),
        (lambda: mr._core.frustum(-1, 1, -1, 1, 1e-39, 1, mr._core.DepthConvention.opengl), ValueError,
         ["near", ">= 1.17549435e-38"]),
        (lambda: mr._core.Camera.look_at_perspective((0, 0, 3), (0, 0, 0), (0, 1, 0), 1.0, 1.0, 1e-45), ValueError,
         ["near", ">= 1.17549435e-38"]),
    ],
)
def test_bad_camera_arguments(make, error, words):
    with pytest.raises(error) as e:
        make()
    for w in words:
        assert w in str(e.value)


def test_the_smallest_near_plane_still_draws_and_orders():
    # The smallest near accepted renders the same triangle as near=0.01 (reverse-Z, depth
    # near / distance: 3.9e-39 at distance 3, still above 0), and the depth contract's near 1e-3
    # is accepted (test_depth.cpp checks its ordering).
    smallest = float(np.finfo(np.float32).tiny)
    scene = mr.Scene()
    scene.add(mr.Mesh([[-1, -1, 0], [1, -1, 0], [0, 1, 0]], [[0, 1, 2]]))
    reference = mr.render(scene, mr.Camera.look_at((0, 0, 3), (0, 0, 0)), 16, 16).color
    got = mr.render(scene, mr.Camera.look_at((0, 0, 3), (0, 0, 0), near=smallest), 16, 16).color
    np.testing.assert_array_equal(got, reference)
    mr.Camera.look_at((0, 0, 3), (0, 0, 0), near=1e-3)
    # Orthographic depth is linear in distance: any near, 0 and negative included.
    mr.Camera.orthographic((0, 0, 3), (0, 0, 0), near=1e-45, far=10).build(4, 4)


def test_opencv_column_vector_t_is_accepted():
    K = np.array([[10.0, 0, 5], [0, 10, 5], [0, 0, 1]])
    a = mr.Camera.from_opencv(K, np.eye(3), np.array([[0.1], [0.2], [0.3]]))
    b = mr.Camera.from_opencv(K, np.eye(3), [0.1, 0.2, 0.3])
    np.testing.assert_array_equal(a.matrices(10, 10)[0], b.matrices(10, 10)[0])


def test_build_checks_the_size():
    camera = mr.Camera.look_at((0, 0, 1), (0, 0, 0))
    with pytest.raises(ValueError, match="height: expected 1 to 32768 pixels, got 0"):
        camera.build(10, 0)
    with pytest.raises(TypeError, match="width"):
        camera.build(10.0, 10)
    assert camera.build(16, 9).depth_convention == mr._core.DepthConvention.reverse_z


def test_repr_names_the_constructor_and_its_arguments():
    assert repr(mr.Camera.look_at((0, 0, 1), (0, 0, 0), fov_y=45)) == (
        "Camera.look_at(eye=(0, 0, 1), target=(0, 0, 0), up=(0, 1, 0), fov_y=45, near=0.01, far=inf)")
    assert repr(mr.Camera.from_matrices(np.eye(4), np.eye(4))) == "Camera.from_matrices(depth_convention='opengl')"
    assert repr(mr.Camera.from_opencv(np.array([[10.0, 0, 5], [0, 10, 5], [0, 0, 1]]), np.eye(3), np.zeros(3))) == (
        "Camera.from_opencv(fx=10, fy=10, cx=5, cy=5, skew=0, near=0.01, far=1000)")
