"""The references of the error study against hand-computed areas and closed forms.

Exact coverage: a half-covered pixel, a triangle's corners (right angle and 45°), painter's order,
a checkerboard of arbitrary cell size and offset (the product of 1D interval overlaps), and the
area of a big random triangle summed over its pixels. Texture footprints: a linear ramp texture on
a plane facing the camera (the box mean of an affine function is its value at the pixel centre)
and on a floor (u = ½ − X/(Y·L) is separable in screen x and y, so its box mean is a product of
closed-form 1D means, one of them a logarithm).
"""
import math

import numpy as np
import pytest

from mipraster.reference import (PerspectiveView, TexturedPlane, bilinear_level0, clip_polygon, exact_coverage,
                                 image_error, plane_reference, polygon_area)

WHITE, BLACK = (1.0, 1.0, 1.0), (0.0, 0.0, 0.0)


def test_clip_polygon_and_area():
    square = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
    assert polygon_area(square) == 1.0
    assert polygon_area(clip_polygon(square, -1.0, 0.0, 0.25)) == pytest.approx(0.25)  # x <= 0.25
    assert polygon_area(clip_polygon(square, 1.0, 1.0, -1.0)) == pytest.approx(0.5)  # x + y >= 1
    assert clip_polygon(square, 1.0, 0.0, -2.0) == []  # x >= 2


def test_half_covered_pixel():
    # A big triangle whose vertical edge x = 1.5 halves the pixels of column 1.
    tri = [[(1.5, -10.0), (20.0, -10.0), (1.5, 20.0)]]
    img = exact_coverage(np.array(tri), np.array([WHITE]), 4, 2, BLACK)
    np.testing.assert_allclose(img[:, :, 0], [[0, 0.5, 1, 1], [0, 0.5, 1, 1]], atol=1e-15)


def test_triangle_corners():
    # Right-angle corner at the centre of pixel (0, 0): a quarter of it.
    img = exact_coverage(np.array([[(0.5, 0.5), (10.0, 0.5), (0.5, 10.0)]]), np.array([WHITE]), 3, 3, BLACK)
    assert img[0, 0, 0] == pytest.approx(0.25, abs=1e-15)
    # A 90° wedge between the diagonals from the centre of pixel (0, 0), opening to the right:
    # the triangle (0.5, 0.5), (1, 0), (1, 1) of area 1/4.
    img = exact_coverage(np.array([[(0.5, 0.5), (10.0, -9.0), (10.0, 10.0)]]), np.array([WHITE]), 2, 1, BLACK)
    assert img[0, 0, 0] == pytest.approx(0.25, abs=1e-15)
    # A small triangle inside one pixel: its own area 0.5·0.5·0.25.
    img = exact_coverage(np.array([[(2.1, 1.2), (2.6, 1.2), (2.1, 1.45)]]), np.array([WHITE]), 4, 3, BLACK)
    assert img[1, 2, 0] == pytest.approx(0.0625, abs=1e-15)
    assert img.sum() == pytest.approx(0.0625 * 3, abs=1e-14)


def test_painters_order():
    blue, red = (0.0, 0.0, 1.0), (1.0, 0.0, 0.0)
    under = [(-5.0, -5.0), (20.0, -5.0), (-5.0, 20.0)]  # covers pixel (0, 0) entirely
    over = [(-5.0, -5.0), (0.25, -5.0), (0.25, 5.0)]
    # Within pixel (0, 0) `over` is x ≤ 0.25: its slanted edge (from (−5, −5) to (0.25, 5)) lies
    # at x = −5 + 0.525·(y + 5) < −1.8 for 0 ≤ y ≤ 1, left of the pixel.
    img = exact_coverage(np.array([under, over]), np.array([blue, red]), 1, 1, BLACK)
    np.testing.assert_allclose(img[0, 0], [0.25, 0.0, 0.75], atol=1e-14)
    img = exact_coverage(np.array([over, under]), np.array([red, blue]), 1, 1, BLACK)  # blue on top
    np.testing.assert_allclose(img[0, 0], [0.0, 0.0, 1.0], atol=1e-14)


def _overlap(a0, a1, b0, b1):
    return max(0.0, min(a1, b1) - max(a0, b0))


@pytest.mark.parametrize("cell, offset", [(1.5, (0.0, 0.0)), (0.7, (0.3, 0.55)), (2.25, (-0.4, 0.1))])
def test_checkerboard(cell, offset):
    # White cells (i + j even) of a checkerboard, two triangles each, on black.
    w = h = 7
    tris, cells = [], []
    n = int(math.ceil((w + 2) / cell)) + 1
    for j in range(-1, n):
        for i in range(-1, n):
            if (i + j) % 2:
                continue
            x0, y0 = offset[0] + i * cell, offset[1] + j * cell
            x1, y1 = x0 + cell, y0 + cell
            tris += [[(x0, y0), (x1, y0), (x1, y1)], [(x0, y0), (x1, y1), (x0, y1)]]
            cells.append((x0, x1, y0, y1))
    img = exact_coverage(np.array(tris), np.ones((len(tris), 3)), w, h, BLACK)
    expected = np.zeros((h, w))
    for py in range(h):
        for px in range(w):
            expected[py, px] = sum(_overlap(x0, x1, px, px + 1) * _overlap(y0, y1, py, py + 1) for x0, x1, y0, y1 in cells)
    np.testing.assert_allclose(img[:, :, 0], expected, atol=1e-12)


def test_random_triangle_area_is_conserved():
    rng = np.random.default_rng(5)
    for _ in range(5):
        tri = rng.uniform(0.0, 12.0, size=(3, 2))
        (ax, ay), (bx, by) = tri[1] - tri[0], tri[2] - tri[0]
        area = abs(ax * by - ay * bx) / 2
        img = exact_coverage(tri[None], np.array([WHITE]), 12, 12, BLACK)
        assert img[:, :, 0].sum() == pytest.approx(area, rel=1e-12)
        assert img.max() <= 1.0 + 1e-12


def test_bad_input_names_it():
    with pytest.raises(ValueError, match="background"):
        exact_coverage(np.zeros((1, 3, 2)), np.ones((1, 3)), 2, 2, (0.0, 0.0))
    with pytest.raises(ValueError, match="finite"):
        exact_coverage(np.full((1, 3, 2), np.nan), np.ones((1, 3)), 2, 2, BLACK)


def _ramp(w: int = 64) -> np.ndarray:
    # Texel i holds (i + ½)/w, so bilinear reconstruction gives exactly u inside [½/w, 1 − ½/w].
    t = np.zeros((4, w, 4))
    t[..., :3] = ((np.arange(w) + 0.5) / w)[None, :, None]
    t[..., 3] = 1.0
    return t


def test_bilinear_reconstructs_ramp():
    u = np.linspace(0.02, 0.98, 50)
    np.testing.assert_allclose(bilinear_level0(_ramp(), u, np.full_like(u, 0.5), "clamp")[:, 0], u, atol=1e-12)


def test_ramp_facing_camera_is_value_at_centre():
    # Camera at the origin looking down −z at a 4×4 square at z = −2: u is affine in screen x.
    w, h = 24, 16
    plane = TexturedPlane((-2.0, -2.0, -2.0), (4.0, 0.0, 0.0), (0.0, 4.0, 0.0), (0.0, 0.5), (1.0, 0.0), (0.0, 0.0),
                          _ramp(), "clamp")
    view = PerspectiveView(eye=(0.0, 0.0, 0.0), target=(0.0, 0.0, -1.0), fov_y=60.0)
    img, residual = plane_reference(plane, view, w, h, (0.0, 0.0, 0.0), n=8)
    t = math.tan(math.radians(30.0))
    x_world = (2 * (np.arange(w) + 0.5) / w - 1) * t * (w / h) * 2.0  # at depth 2
    expected = x_world / 4.0 + 0.5
    # Jittered points average an affine function to its centre value up to the jitter's own mean
    # offset, which the stated residual (the reference's estimated RMSE) must account for.
    diff = img[:, :, 0] - expected[None, :]
    assert np.abs(diff).max() < 2e-3
    assert 0 < residual < 2e-3
    assert np.sqrt(np.mean(diff ** 2)) <= 2 * residual


def test_ramp_on_floor_matches_closed_form():
    # Floor y = −1 under a camera at the origin looking down −z; u = x_world / L + ½ along x.
    w, h, L = 32, 32, 40.0
    fov = 60.0
    plane = TexturedPlane((-L / 2, -1.0, 0.0), (L, 0.0, 0.0), (0.0, 0.0, -1000.0), (0.0, 0.0), (1.0, 0.0),
                          (0.0, 1.0), _ramp(), "clamp")
    view = PerspectiveView(eye=(0.0, 0.0, 0.0), target=(0.0, 0.0, -1.0), fov_y=fov)
    img, residual = plane_reference(plane, view, w, h, (0.0, 0.0, 0.0), n=12)
    # A ray (X, Y, −1) with X = (2x/W − 1)·T·W/H, Y = (1 − 2y/H)·T meets the floor at x_world = −X/Y.
    # The box mean over a pixel of u = ½ − X/(Y·L) is ½ − mean(X)·mean(1/Y)/L (separable), with
    # mean(1/Y) over [y0, y0 + 1] = −H/(2T)·(ln|1 − 2(y0+1)/H| − ln|1 − 2y0/H|).
    T = math.tan(math.radians(fov / 2))
    rows = np.arange(h // 2 + 2, h)  # below the horizon, where u stays inside the ramp
    mean_x = (2 * (np.arange(w) + 0.5) / w - 1) * T * (w / h)
    mean_inv_y = -h / (2 * T) * (np.log(np.abs(1 - 2 * (rows + 1) / h)) - np.log(np.abs(1 - 2 * rows / h)))
    expected = 0.5 - np.outer(mean_inv_y, mean_x) / L
    assert expected.min() > 1 / 64 and expected.max() < 1 - 1 / 64
    diff = img[rows, :, 0] - expected
    assert np.abs(diff).max() < 2e-3
    # The stated integration error (over the whole image, horizon included) covers the error here.
    assert 0 < residual < 2e-3
    assert np.sqrt(np.mean(diff ** 2)) <= 2 * residual
    # Above the horizon there is no floor: the background.
    np.testing.assert_array_equal(img[: h // 2 - 1, :, 0], 0.0)


def test_image_error():
    a = np.zeros((2, 2, 4))
    b = np.zeros((2, 2, 4))
    b[0, 0, :3] = 0.3
    b[1, 1, 3] = 1.0  # alpha does not count
    e = image_error(a, b)
    assert e["max_abs"] == pytest.approx(0.3)
    assert e["mean_abs"] == pytest.approx(0.3 * 3 / 12)
    assert e["rmse"] == pytest.approx(math.sqrt(0.09 * 3 / 12))
