"""Textured rendering through the pipeline against numpy oracles: the mip level that screen-aligned
quads select (box-filtered level k at 2^k texels per pixel, the 50/50 blend half a level further),
perspective-correct uv against a ray cast, the debug views, lazily built levels, derivative modes,
and the scene layer's texture arguments and their errors."""
import numpy as np
import pytest

import mipraster as mr

TEX = 64  # texels per side of the test texture


def random_texture(seed=0, size=TEX):
    rng = np.random.default_rng(seed)
    texels = rng.random((size, size, 4), dtype=np.float32)
    texels[..., 3] = 1.0
    return texels


def screen_quad(width, height, uv_max=1.0):
    """A quad covering the whole image, uv (0, 0) at its top-left corner and (uv_max, uv_max) at the
    bottom right, in world units of one pixel (see screen_camera)."""
    positions = [(-width / 2, height / 2, 0), (width / 2, height / 2, 0), (width / 2, -height / 2, 0),
                 (-width / 2, -height / 2, 0)]
    uvs = [(0, 0), (uv_max, 0), (uv_max, uv_max), (0, uv_max)]
    return mr.Mesh(positions, [[0, 1, 2], [0, 2, 3]], uvs=uvs)


def screen_camera(height):
    return mr.Camera.orthographic(eye=(0, 0, 5), target=(0, 0, 0), height=float(height), near=0.0, far=10.0)


def render_quad(texels, size, sampler, **kwargs):
    scene = mr.Scene()
    texture = mr.Texture(texels, premultiplied=True)
    scene.add(screen_quad(size, size), texture=texture, sampler=sampler)
    result = mr.render(scene, screen_camera(size), size, size, **kwargs)
    return result.color, texture


def box_level(texels, k):
    """Level k of a power-of-two texture by its definition: the mean of 2^k × 2^k blocks."""
    n = texels.shape[0] >> k
    return texels.astype(np.float64).reshape(n, 1 << k, n, 1 << k, 4).mean(axis=(1, 3))


def bilinear_repeat(level, u, v):
    """Bilinear lookup of the seeds' formula, i = ⌊u·w − ½⌋, repeat wrap, for arrays of points."""
    h, w = level.shape[:2]
    x, y = u * w - 0.5, v * h - 0.5
    i, j = np.floor(x).astype(int), np.floor(y).astype(int)
    ax, ay = (x - i)[..., None], (y - j)[..., None]
    at = lambda ii, jj: level[jj % h, ii % w]
    top = at(i, j) * (1 - ax) + at(i + 1, j) * ax
    bottom = at(i, j + 1) * (1 - ax) + at(i + 1, j + 1) * ax
    return top * (1 - ay) + bottom * ay


@pytest.mark.parametrize("k", [0, 1, 2, 3, 4])
def test_a_quad_at_2_to_the_k_texels_per_pixel_shows_level_k(k):
    texels = random_texture(k)
    size = TEX >> k  # pixel centres land on the texel centres of level k; λ = k exactly
    color, _ = render_quad(texels, size, "trilinear")
    np.testing.assert_allclose(color, box_level(texels, k), rtol=0, atol=2e-6)


@pytest.mark.parametrize("k, spp", [(2, 16), (3, 4), (3, 16), (4, 64)])
def test_ssaa_samples_read_the_level_of_their_own_spacing(k, spp):
    # 2^k texels per pixel, an N×N grid of samples (N = √spp): each sample stands for a cell of
    # 2^k / N texels, so it reads level k − log2 N, at that level's texel centres, and the pixel is
    # the mean of N×N of them: level k again, exactly. (Filtering each sample at the pixel's
    # footprint would read level k between its texels: a blur.)
    texels = random_texture(k + spp)
    size = TEX >> k
    color, _ = render_quad(texels, size, "trilinear", spp=spp, aa="ssaa", pattern="grid")
    np.testing.assert_allclose(color, box_level(texels, k), rtol=0, atol=2e-6)


@pytest.mark.parametrize("k", [0, 1, 2, 3])
def test_half_a_level_further_trilinear_blends_levels_k_and_k_plus_1_equally(k):
    texels = random_texture(10 + k)
    size = TEX >> k
    color, _ = render_quad(texels, size, mr.Sampler(filter="trilinear", lod_bias=0.5))
    c = (np.arange(size) + 0.5) / size
    u, v = np.meshgrid(c, c)
    expected = 0.5 * box_level(texels, k) + 0.5 * bilinear_repeat(box_level(texels, k + 1), u, v)
    np.testing.assert_allclose(color, expected, rtol=0, atol=2e-6)


def test_nearest_level_switches_at_half_a_level():
    texels = random_texture(3)
    sampler = mr.Sampler(filter="trilinear", mip_filter="nearest")
    # λ = 1 + 0.49 rounds to level 1, λ = 1 + 0.51 to level 2 (GL: level ⌈λ + ½⌉ − 1).
    low, _ = render_quad(texels, TEX >> 1, mr.Sampler(filter="trilinear", mip_filter="nearest", lod_bias=0.49))
    high, _ = render_quad(texels, TEX >> 1, mr.Sampler(filter="trilinear", mip_filter="nearest", lod_bias=0.51))
    c = (np.arange(TEX >> 1) + 0.5) / (TEX >> 1)
    u, v = np.meshgrid(c, c)
    np.testing.assert_allclose(low, box_level(texels, 1), atol=2e-6)
    np.testing.assert_allclose(high, bilinear_repeat(box_level(texels, 2), u, v), atol=2e-6)
    assert sampler.mip_filter == "nearest"


def test_magnification_and_bilinear_only_draws_build_no_mip_level():
    texels = random_texture(4, size=8)
    _, magnified = render_quad(texels, 64, "trilinear")  # 1/8 texel per pixel: λ < 0 everywhere
    assert magnified.built_levels == 0
    _, bilinear = render_quad(random_texture(5), 16, "bilinear")  # minified, but no mip filter
    assert bilinear.built_levels == 0
    _, trilinear = render_quad(random_texture(6), 16, "trilinear")
    assert trilinear.built_levels >= 2


def test_bilinear_without_mip_levels_samples_level_0_wherever_it_minifies():
    texels = random_texture(7)
    color, _ = render_quad(texels, 16, "bilinear")
    c = (np.arange(16) + 0.5) / 16
    u, v = np.meshgrid(c, c)
    np.testing.assert_allclose(color, bilinear_repeat(texels.astype(np.float64), u, v), atol=2e-6)


def test_quad_and_analytic_derivatives_agree_where_uv_is_affine():
    texels = random_texture(8)
    analytic, _ = render_quad(texels, 24, "anisotropic")
    quad, _ = render_quad(texels, 24, "anisotropic", derivatives="quad")
    np.testing.assert_allclose(quad, analytic, atol=1e-6)


def test_uv_debug_view_shows_fract_uv_at_pixel_centres():
    size = 20
    color, _ = render_quad(random_texture(9), size, "trilinear", debug_view="uv")
    c = (np.arange(size) + 0.5) / size
    u, v = np.meshgrid(c, c)
    np.testing.assert_allclose(color[..., 0], u, atol=1e-6)
    np.testing.assert_allclose(color[..., 1], v, atol=1e-6)
    assert np.all(color[..., 2] == 0) and np.all(color[..., 3] == 1)


def test_mip_level_debug_view_gives_one_colour_per_level():
    colours = []
    for k in range(4):
        color, _ = render_quad(random_texture(k), TEX >> k, "trilinear", debug_view="mip-level")
        flat = color.reshape(-1, 4)
        assert np.all(flat == flat[0]), f"level {k}: the view is not uniform"
        colours.append(tuple(flat[0]))
    assert len(set(colours)) == 4


def test_perspective_correct_uv_of_a_ground_plane_matches_a_ray_cast():
    """A textured plane y = 0 seen from above at a slant; uv = (x, z) / 8. The uv debug view gives
    the rasterizer's perspective-correct uv at each pixel centre; a double-precision ray cast gives
    the exact one."""
    width, height, fov = 48, 32, 50.0
    eye, target = np.array([0.3, 2.0, 6.0]), np.array([0.0, 0.0, 0.0])
    s = 4.0
    positions = [(-s, 0, -s), (s, 0, -s), (s, 0, s), (-s, 0, s)]
    uvs = [((x + s) / 8, (z + s) / 8) for x, _, z in positions]
    scene = mr.Scene()
    scene.add(mr.Mesh(positions, [[0, 2, 1], [0, 3, 2]], uvs=uvs), texture=mr.Texture(random_texture()))
    camera = mr.Camera.look_at(eye, target, fov_y=fov)
    color = mr.render(scene, camera, width, height, debug_view="uv").color

    # Ray cast through pixel centres with the same camera matrices.
    view, proj = camera.matrices(width, height)
    inv = np.linalg.inv(proj @ view)
    ys, xs = np.mgrid[0:height, 0:width] + 0.5
    # Any depth on the ray will do: 0.5 (reverse-Z, so between the near plane and infinity).
    ndc = np.stack([2 * xs / width - 1, 1 - 2 * ys / height, np.full_like(xs, 0.5), np.ones_like(xs)], axis=-1)
    p = ndc @ inv.T
    p = p[..., :3] / p[..., 3:]
    d = p - eye
    t = -eye[1] / d[..., 1]
    hit = eye + t[..., None] * d
    inside = (t > 0) & (np.abs(hit[..., 0]) < s - 0.05) & (np.abs(hit[..., 2]) < s - 0.05)
    u, v = (hit[..., 0] + s) / 8, (hit[..., 2] + s) / 8
    assert inside.sum() > 200
    # Snapping moves each vertex by at most 1/512 px in x and y, which shifts uv by at most
    # |∇uv|·√2/512: the ray cast sees the unsnapped plane. Bound it with the largest gradient.
    grad = max(np.abs(np.diff(u, axis=a))[inside[:-1, :] if a == 0 else inside[:, :-1]].max() for a in (0, 1))
    bound = 2 * grad * np.sqrt(2) / 512 + 1e-6
    assert bound < 5e-4
    np.testing.assert_allclose(color[..., 0][inside], (u - np.floor(u))[inside], rtol=0, atol=bound)
    np.testing.assert_allclose(color[..., 1][inside], (v - np.floor(v))[inside], rtol=0, atol=bound)


def test_texture_colour_multiplies_vertex_and_draw_colours():
    texels = np.full((4, 4, 4), 0.5, dtype=np.float32)
    texels[..., 3] = 1
    scene = mr.Scene()
    size = 8
    mesh = screen_quad(size, size)
    colored = mr.Mesh(mesh.positions, mesh.triangles, colors=np.tile([0.5, 1.0, 0.25, 1.0], (4, 1)), uvs=mesh.uvs)
    scene.add(colored, color=(1.0, 0.5, 1.0, 1.0), texture=mr.Texture(texels, premultiplied=True), sampler="nearest")
    color = mr.render(scene, screen_camera(size), size, size).color
    np.testing.assert_allclose(color[3, 3], [0.25, 0.25, 0.125, 1.0], atol=1e-7)


def test_textured_renders_are_identical_for_any_thread_count():
    scene, camera = mr.Scene.demo()
    images = [mr.render(scene, camera, 96, 64, spp=4, aa="msaa", threads=t).color for t in (1, 2, 4)]
    assert np.array_equal(images[0], images[1]) and np.array_equal(images[0], images[2])


def test_material_and_draw_expose_texture_and_sampler():
    texture = mr.Texture(random_texture())
    material = mr.Material(color=(1, 1, 1, 1), texture=texture, sampler="ewa")
    scene = mr.Scene()
    draw = scene.add(screen_quad(4, 4), material=material)
    assert draw.texture == texture
    assert draw.sampler.filter == "ewa"
    plain = scene.add(screen_quad(4, 4))
    assert plain.texture is None


def test_demo_draws_are_textured():
    scene, _ = mr.Scene.demo()
    assert all(d.texture is not None and d.mesh.uvs is not None for d in scene.draws)


def test_texture_argument_errors_name_the_problem():
    scene = mr.Scene()
    no_uvs = mr.Mesh([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [[0, 1, 2]])
    texture = mr.Texture(random_texture())
    with pytest.raises(ValueError, match="no uvs"):
        scene.add(no_uvs, texture=texture)
    with pytest.raises(TypeError, match="texture"):
        scene.add(screen_quad(4, 4), texture=np.zeros((4, 4, 4)))
    with pytest.raises(ValueError, match="filter"):
        scene.add(screen_quad(4, 4), texture=texture, sampler="bogus")
    with pytest.raises(ValueError, match="material"):
        scene.add(screen_quad(4, 4), texture=texture, material=mr.Material(texture=texture))
    with pytest.raises(ValueError, match="uvs"):
        mr.Mesh([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [[0, 1, 2]], uvs=[(0, 0), (1, 0)])
    with pytest.raises(ValueError, match=r"uvs\[1, 0\]"):
        mr.Mesh([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [[0, 1, 2]], uvs=[(0, 0), (np.nan, 0), (0, 1)])
    with pytest.raises(ValueError, match="normals"):
        mr.Mesh([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [[0, 1, 2]], normals=[(0, 0, 1)] * 2)
    good = mr.Scene()
    good.add(screen_quad(4, 4), texture=texture)
    with pytest.raises(ValueError, match="debug_view"):
        mr.render(good, screen_camera(4), 4, 4, debug_view="levels")
    with pytest.raises(ValueError, match="derivatives"):
        mr.render(good, screen_camera(4), 4, 4, derivatives="numeric")


def test_mesh_uvs_and_normals_read_back():
    mesh = mr.Mesh([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [[0, 1, 2]], uvs=np.array([(0, 0), (1, 0), (0, 1)], np.float64),
                   normals=[(0, 0, 1)] * 3)
    assert mesh.uvs.dtype == np.float32 and mesh.uvs.shape == (3, 2)
    assert mesh.normals.shape == (3, 3) and not mesh.normals.flags.writeable
    assert repr(mesh) == "Mesh(vertices=3, triangles=1, uvs, normals)"
