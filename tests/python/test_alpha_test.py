"""Alpha testing (``Scene.add(..., alpha_cutoff=...)``, glTF ``alphaMode: MASK``): a fragment whose shaded
alpha is below the cutoff writes neither colour nor depth; one at or above it is written opaque, its colour
divided by its alpha. The expected images are worked out in numpy from the texels, one texel per pixel
(nearest filtering, texel centres on pixel centres), so every sample of a pixel reads its pixel's texel."""
import base64
import json
import struct
import warnings

import numpy as np
import pytest

import mipraster as mr

W = H = 48  # more than one tile across, fewer than two
BEHIND = np.float32([0.1, 0.2, 0.3, 1.0])


def mask_texels(rng):
    """(H, W, 4) premultiplied linear texels: alpha 1 or 0 in 8×8 squares, and squares of random alphas
    with some exactly at and just around 0.5."""
    alpha = np.where((np.arange(W)[None, :] // 8 + np.arange(H)[:, None] // 8) % 2 == 0, 1.0, 0.0)
    mixed = rng.choice(np.float32([0.0, 0.2, 0.4999, 0.5, 0.5001, 0.7, 1.0]), size=(H, W))
    square = (np.arange(W)[None, :] // 8 + 3 * (np.arange(H)[:, None] // 8)) % 3 == 2
    alpha = np.where(square, mixed, alpha).astype(np.float32)
    straight = rng.uniform(0.05, 1.0, size=(H, W, 3)).astype(np.float32)
    return np.concatenate([straight * alpha[..., None], alpha[..., None]], axis=-1).astype(np.float32)


def quad(z, uvs=True):
    """The square [-1, 1]² at height z, uv (0, 0) at its top-left corner (x = -1, y = 1)."""
    return mr.Mesh([[-1, 1, z], [1, 1, z], [1, -1, z], [-1, -1, z]], [[0, 1, 2], [0, 2, 3]],
                   uvs=[[0, 0], [1, 0], [1, 1], [0, 1]] if uvs else None)


def camera():
    """Orthographic, looking down -z at the square [-1, 1]² exactly."""
    return mr.Camera.orthographic(eye=(0, 0, 5), target=(0, 0, 0), height=2.0, near=0.1, far=10.0)


def mask_scene(texels, cutoff):
    """The alpha-tested quad in front first (depth written where it survives), then an opaque quad behind."""
    scene = mr.Scene()
    scene.add(quad(0.5), texture=mr.Texture(texels, premultiplied=True), sampler=mr.Sampler("nearest", wrap="clamp"),
              alpha_cutoff=cutoff)
    scene.add(quad(-0.5, uvs=False), color=BEHIND)
    return scene


def expected_image(texels, cutoff):
    """Per pixel: the texel's colour divided by its alpha with alpha 1 where alpha >= cutoff, else BEHIND."""
    a = texels[..., 3:]
    with np.errstate(divide="ignore", invalid="ignore"):
        front = np.concatenate([texels[..., :3] / a, np.ones_like(a)], axis=-1)
    return np.where(a >= np.float32(cutoff), front, BEHIND).astype(np.float32)


@pytest.mark.parametrize("spp, aa", [(1, "ssaa"), (4, "msaa"), (4, "ssaa")])
@pytest.mark.parametrize("cutoff", [0.5, 0.3])
def test_masked_quad_shows_what_is_behind_its_holes(spp, aa, cutoff):
    texels = mask_texels(np.random.default_rng(7))
    want = expected_image(texels, cutoff)
    holes = want[..., 3] == 1.0  # (every pixel is opaque; count the ones that show BEHIND)
    shows_behind = np.all(want == BEHIND, axis=-1)
    assert holes.all() and 0.25 < shows_behind.mean() < 0.75
    result = mr.render(mask_scene(texels, cutoff), camera(), W, H, spp=spp, aa=aa, keep_samples=True)
    for s in range(spp):  # every sample of a pixel holds the pixel's colour
        np.testing.assert_array_equal(result.samples[:, :, s], want, err_msg=f"sample {s}")
    # Depth: the front quad's (view depth 4.5) where it survived, the back quad's (5.5) in the holes.
    np.testing.assert_allclose(result.depth, np.where(shows_behind, 5.5, 4.5), rtol=1e-5)
    # Every sample passes exactly once: the front quad's where it survives, the back quad's in the
    # holes; a sample the alpha test discards is not counted (as an OpenGL occlusion query).
    assert result.stats["samples_passed"] == W * H * spp


def test_one_and_two_threads_agree_bit_for_bit():
    texels = mask_texels(np.random.default_rng(3))
    scene = mask_scene(texels, 0.5)
    for spp, aa in [(1, "ssaa"), (4, "msaa"), (4, "ssaa")]:
        one = mr.render(scene, camera(), W, H, spp=spp, aa=aa, threads=1, keep_samples=True)
        two = mr.render(scene, camera(), W, H, spp=spp, aa=aa, threads=2, keep_samples=True)
        assert np.array_equal(one.samples, two.samples) and np.array_equal(one.color, two.color)


def test_without_a_cutoff_the_quad_stays_opaque_and_unchanged():
    texels = mask_texels(np.random.default_rng(5))
    scene = mr.Scene()
    d = scene.add(quad(0.5), texture=mr.Texture(texels, premultiplied=True),
                  sampler=mr.Sampler("nearest", wrap="clamp"))
    scene.add(quad(-0.5, uvs=False), color=BEHIND)
    assert d.alpha_cutoff is None and "alpha_cutoff=None" in repr(d)
    np.testing.assert_array_equal(mr.render(scene, camera(), W, H).color, texels)


def passing_scene(cutoff, sampler):
    """A tilted, vertex-coloured ground that runs from behind the camera (clipped triangles) to far away,
    under an opaque texture, and a quad standing on it: every fragment's alpha is exactly 1."""
    rng = np.random.default_rng(11)
    texels = np.concatenate([rng.uniform(0.0, 1.0, size=(64, 64, 3)), np.ones((64, 64, 1))], axis=-1)
    texture = mr.Texture(texels.astype(np.float32), premultiplied=True)
    ground = mr.Mesh([[-20, 0, 8], [20, 0, 8], [20, 0, -60], [-20, 0, -60]], [[0, 1, 2], [0, 2, 3]],
                     uvs=[[0, 0], [8, 0], [8, 24], [0, 24]], colors=[[1, 0.5, 0.5, 1], [0.5, 1, 0.5, 1],
                                                                      [0.5, 0.5, 1, 1], [1, 1, 1, 1]])
    scene = mr.Scene()
    scene.add(quad(-3.0), texture=texture, sampler=sampler, alpha_cutoff=cutoff)
    scene.add(ground, texture=texture, sampler=sampler, alpha_cutoff=cutoff)
    return scene


@pytest.mark.parametrize("spp, aa", [(1, "ssaa"), (4, "msaa"), (4, "ssaa")])
@pytest.mark.parametrize("sampler", ["trilinear", "anisotropic", "ewa"])
@pytest.mark.parametrize("batched", [True, False])
def test_a_draw_whose_fragments_all_pass_is_the_same_draw_without_a_cutoff(spp, aa, sampler, batched):
    # Alpha 1 everywhere: the test keeps every fragment and divides by 1, so the image is the one the
    # renderer's other paths (sample rows, MSAA vectors, the lookup queue, deferred shading) make, bit
    # for bit, when its lookups go the same way (batched or not).
    camera = mr.Camera.look_at(eye=(0, 1.5, 6), target=(0, 0.5, 0), fov_y=60.0, near=0.1)
    images = []
    for cutoff in (None, 0.0, 1.0):
        result = mr.render(passing_scene(cutoff, mr.Sampler(sampler)), camera, 96, 64, spp=spp, aa=aa,
                           keep_samples=True, batched_lookups=batched)
        images.append(result.samples)
    assert np.isfinite(images[0]).all() and images[0].std() > 0.05
    for got in images[1:]:
        np.testing.assert_array_equal(got, images[0])


def test_untextured_draw_tests_its_colour_alpha():
    scene = mr.Scene()
    scene.add(quad(0.5, uvs=False), color=(0.2, 0.1, 0.05, 0.4), alpha_cutoff=0.5)  # below: discarded
    scene.add(quad(-0.5, uvs=False), color=BEHIND)
    np.testing.assert_array_equal(mr.render(scene, camera(), 8, 8).color, np.broadcast_to(BEHIND, (8, 8, 4)))
    scene = mr.Scene()
    d = scene.add(quad(0.5, uvs=False), color=(0.2, 0.1, 0.05, 0.4), alpha_cutoff=0.4)  # at the cutoff: opaque
    scene.add(quad(-0.5, uvs=False), color=BEHIND)
    assert d.alpha_cutoff == pytest.approx(0.4) and "alpha_cutoff=0.4" in repr(d)
    want = np.float32([0.2, 0.1, 0.05]) / np.float32(0.4)
    got = mr.render(scene, camera(), 8, 8).color
    np.testing.assert_array_equal(got[..., :3], np.broadcast_to(want, (8, 8, 3)))
    assert (got[..., 3] == 1.0).all()


@pytest.mark.parametrize("bad, error", [
    (float("nan"), ValueError), (-0.01, ValueError), (1.01, ValueError), (float("inf"), ValueError),
    ("0.5", TypeError), (True, TypeError), ([0.5], TypeError),
])
def test_bad_cutoff_is_an_error_naming_it(bad, error):
    with pytest.raises(error, match="alpha_cutoff"):
        mr.Scene().add(quad(0.0), alpha_cutoff=bad)


def test_core_draw_refuses_a_bad_cutoff_too():
    with pytest.raises(ValueError, match="alpha_cutoff"):
        mr._core.Draw(quad(0.0)._mesh, alpha_cutoff=1.5)


# --- glTF alphaMode MASK -------------------------------------------------------------------------

# A 2x2 texture, straight linear RGB with alpha: red (1), green (0), blue (0.2), white (0.4).
GLTF_ALPHA = np.float32([[1.0, 0.0], [0.2, 0.4]])
GLTF_RGB = np.float32([[[1, 0, 0], [0, 1, 0]], [[0, 0, 1], [1, 1, 1]]])


def write_masked_gltf(tmp_path, material_extra):
    """A quad filling [-1, 1]² at z = 0 textured with the 2x2 RGBA PNG above (embedded), nearest
    filtering, its material's fields updated with `material_extra`, an orthographic camera at z = 5."""
    mr.write_image(tmp_path / "mask.png", np.concatenate([GLTF_RGB * GLTF_ALPHA[..., None], GLTF_ALPHA[..., None]], -1))
    png = (tmp_path / "mask.png").read_bytes()
    positions = [-1, 1, 0, 1, 1, 0, 1, -1, 0, -1, -1, 0]
    uvs = [0, 0, 1, 0, 1, 1, 0, 1]
    buf = struct.pack("<12f", *positions) + struct.pack("<8f", *uvs) + struct.pack("<6H", 0, 2, 1, 0, 3, 2) + b"\0" * 4
    material = {"doubleSided": True, "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}, **material_extra}
    doc = {
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 0, 5]}],
        "cameras": [{"type": "orthographic", "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}}],
        "materials": [material],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"magFilter": 9728, "minFilter": 9728, "wrapS": 33071, "wrapT": 33071}],
        "images": [{"uri": "data:image/png;base64," + base64.b64encode(png).decode()}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2, "material": 0}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC2"},
            {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"},
        ],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                        {"buffer": 0, "byteOffset": 48, "byteLength": 32},
                        {"buffer": 0, "byteOffset": 80, "byteLength": 12}],
        "buffers": [{"byteLength": len(buf),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(buf).decode()}],
    }
    path = tmp_path / "masked.gltf"
    path.write_text(json.dumps(doc))
    return path


def render_with_backdrop(path):
    """The file's scene, then an opaque quad behind it (drawn after: it shows only where no depth was
    written), through the file's camera; the loaded draw and the 32x32 colour image."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        scene, cameras = mr.load_scene(path)
    (d,) = scene.draws
    scene.add(quad(-1.0, uvs=False), color=BEHIND)
    return d, mr.render(scene, cameras[0], 32, 32).color


def quadrants(color):
    return np.array([color[8, 8], color[8, 24], color[24, 8], color[24, 24]])


def test_gltf_mask_material_renders_holes_below_its_cutoff(tmp_path):
    d, color = render_with_backdrop(write_masked_gltf(tmp_path, {"alphaMode": "MASK", "alphaCutoff": 0.3}))
    assert d.alpha_cutoff == pytest.approx(0.3) and d.blend == "replace"
    texels = d.texture.level(0).reshape(4, 4)  # the alpha is kept (premultiplied), not dropped
    np.testing.assert_allclose(texels[:, 3], GLTF_ALPHA.reshape(4), atol=1 / 255)
    got = quadrants(color)
    # alpha 1 and 0.4 >= 0.3: the texel's colour, opaque; alpha 0 and 0.2: the quad behind.
    for q in (0, 3):
        np.testing.assert_allclose(got[q, :3], texels[q, :3] / texels[q, 3], atol=1e-6, err_msg=f"quadrant {q}")
        np.testing.assert_allclose(got[q, :3], GLTF_RGB.reshape(4, 3)[q], atol=0.02, err_msg=f"quadrant {q}")
        assert got[q, 3] == 1.0
    for q in (1, 2):
        np.testing.assert_array_equal(got[q], BEHIND, err_msg=f"quadrant {q}")


def test_gltf_mask_default_cutoff_is_one_half(tmp_path):
    d, color = render_with_backdrop(write_masked_gltf(tmp_path, {"alphaMode": "MASK"}))
    assert d.alpha_cutoff == 0.5
    got = quadrants(color)
    np.testing.assert_array_equal(got[1], BEHIND)
    np.testing.assert_array_equal(got[2], BEHIND)
    np.testing.assert_array_equal(got[3], BEHIND)  # alpha 0.4 < 0.5
    np.testing.assert_allclose(got[0], [1, 0, 0, 1], atol=1e-6)


@pytest.mark.parametrize("extra", [{}, {"alphaMode": "OPAQUE", "alphaCutoff": 0.3}])
def test_gltf_opaque_material_ignores_alpha_and_cutoff(tmp_path, extra):
    d, color = render_with_backdrop(write_masked_gltf(tmp_path, extra))
    assert d.alpha_cutoff is None
    # The quadrants show the texture's straight colour, opaque: no holes, the quad behind hidden (the
    # alpha-0 texel's colour did not survive the PNG's straight alpha: not compared).
    np.testing.assert_allclose(quadrants(color)[[0, 2, 3], :3], GLTF_RGB.reshape(4, 3)[[0, 2, 3]], atol=0.02)
    assert (color[..., 3] == 1.0).all()
    assert not np.any(np.all(color == BEHIND, axis=-1))
