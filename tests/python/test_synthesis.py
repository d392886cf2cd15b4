"""mipraster.synthesize (Efros & Leung): every output pixel occurs in the sample; a perfectly
periodic sample comes out as a shift of itself; the same seed gives the same output; the notes'
kinds of input, a regular pattern (bricks) and a stochastic one (pebbles), as small goldens; the
result used as a texture; the errors for bad input."""
import pathlib

import numpy as np
import pytest

import mipraster as mr
from mipraster.testing import assert_matches_golden

GOLDEN_DIR = pathlib.Path(__file__).resolve().parents[1] / "golden"


def rgb8(h, w, seed):
    return np.random.default_rng(seed).integers(0, 256, (h, w, 3), dtype=np.uint8)


def pixel_set(image):
    """The pixels of an (H, W, C) array as a set of tuples."""
    return set(map(tuple, image.reshape(-1, image.shape[-1]).tolist()))


def test_every_output_pixel_occurs_in_the_sample():
    sample = rgb8(20, 24, 1)
    for periodic in (False, True):
        out, source = mr.synthesize(sample, (30, 26), window=5, seed=3, periodic=periodic, return_source=True)
        assert out.shape == (26, 30, 3) and out.dtype == np.uint8
        assert pixel_set(out) <= pixel_set(sample)
        assert np.array_equal(out, sample[source[..., 0], source[..., 1]])


def periodic_sample(tile_h, tile_w, reps, seed):
    """A tile of distinct random colours repeated reps × reps times."""
    rng = np.random.default_rng(seed)
    codes = rng.choice(256 ** 3, tile_h * tile_w, replace=False)
    tile = np.stack([codes >> 16, (codes >> 8) & 255, codes & 255], axis=-1).astype(np.uint8).reshape(tile_h, tile_w, 3)
    return tile, np.tile(tile, (reps, reps, 1))


@pytest.mark.parametrize("periodic, tileable", [(False, False), (True, False), (True, True)])
def test_a_perfectly_periodic_sample_is_reproduced_as_a_shift_of_itself(periodic, tileable):
    tile, sample = periodic_sample(5, 7, 4, 2)
    size = (35, 30) if tileable else (37, 29)
    out = mr.synthesize(sample, size, window=5, seed=4, periodic=periodic, tileable=tileable)
    # The shift that puts the tile's pixel at output (0, 0): its colours are distinct.
    b, a = np.argwhere((tile == out[0, 0]).all(axis=-1))[0]
    y, x = np.mgrid[0:size[1], 0:size[0]]
    assert np.array_equal(out, tile[(y + b) % 5, (x + a) % 7])


def test_the_same_seed_gives_the_same_output_and_other_seeds_differ():
    sample = rgb8(24, 24, 5)
    one = mr.synthesize(sample, (28, 20), window=7, seed=11, threads=1)
    assert np.array_equal(mr.synthesize(sample, (28, 20), window=7, seed=11, threads=2), one)
    assert np.array_equal(mr.synthesize(sample, (28, 20), window=7, seed=11), one)
    assert not np.array_equal(mr.synthesize(sample, (28, 20), window=7, seed=12), one)


# --- the notes' kinds of input: regular and stochastic, as goldens ------------------------------


def bricks_sample():
    """A regular pattern, 48×48 and periodic: 16×8 bricks in half-offset rows, 1 px mortar, each
    brick its own shade of red with a little per-pixel grain. Linear RGB float."""
    rng = np.random.default_rng(20261122)
    y, x = np.mgrid[0:48, 0:48]
    row = y // 8
    shifted = (x + 8 * (row % 2)) % 48
    brick = row * 3 + shifted // 16
    shade = rng.uniform(0.6, 1.0, 18)[brick]
    mortar = (y % 8 == 7) | (shifted % 16 == 15)
    grain = rng.uniform(0.9, 1.0, (48, 48))
    rgb = np.stack([0.55 * shade, 0.12 * shade, 0.06 * shade], axis=-1) * grain[..., None]
    rgb[mortar] = np.array([0.45, 0.42, 0.38]) * grain[mortar][:, None]
    return rgb.astype(np.float32)


def pebbles_sample():
    """A stochastic pattern, 48×48 and periodic: white noise low-passed in the frequency domain
    (a Gaussian of 2.5 px), thresholded softly into dark gaps between brownish-grey pebbles."""
    rng = np.random.default_rng(99)
    noise = rng.standard_normal((48, 48))
    f = np.fft.fftfreq(48)
    blur = np.exp(-2 * (np.pi * 2.5) ** 2 * (f[:, None] ** 2 + f[None, :] ** 2))
    smooth = np.real(np.fft.ifft2(np.fft.fft2(noise) * blur))
    t = np.clip((smooth - smooth.mean()) / smooth.std() * 0.8 + 0.5, 0.0, 1.0)
    return (np.array([0.03, 0.025, 0.02]) + t[..., None] * np.array([0.45, 0.38, 0.3])).astype(np.float32)


@pytest.mark.parametrize("name, make, window", [("bricks", bricks_sample, 11), ("pebbles", pebbles_sample, 9)])
def test_synthesis_golden(name, make, window, update_goldens):
    # The sample is a golden too (made by the generator above); the synthesis reads the stored
    # PNG, so the output golden depends only on the library.
    sample_path = GOLDEN_DIR / f"synth_sample_{name}.png"
    assert_matches_golden(make(), sample_path, update=update_goldens)
    sample = mr.read_image(sample_path)[..., :3]
    out = mr.synthesize(sample, (96, 64), window=window, seed=1, periodic=True)
    assert pixel_set(out) <= pixel_set(sample)
    assert_matches_golden(out, GOLDEN_DIR / f"synth_{name}.png", update=update_goldens)


def test_a_tileable_synthesized_texture_renders_as_a_texture():
    tile, sample = periodic_sample(4, 4, 6, 7)
    out = mr.synthesize(sample, (32, 32), window=5, tileable=True, periodic=True)
    texture = mr.Texture(out)  # uint8: sRGB codes
    assert np.allclose(texture.level(0)[..., :3], mr.srgb_to_linear(out / 255.0), atol=1e-6)
    # Nearest lookups at the texel centres of the second repeat read the texels back.
    v, u = (np.mgrid[0:32, 0:32] + 0.5) / 32 + 1.0
    looked_up = texture.sample(np.stack([u, v], axis=-1), sampler=mr.Sampler("nearest", wrap="repeat"))
    assert np.array_equal(looked_up, texture.level(0))
    quad = mr.Mesh([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], [[0, 1, 2], [0, 2, 3]],
                   uvs=[[0, 2], [2, 2], [2, 0], [0, 0]])
    scene = mr.Scene()
    scene.add(quad, texture=texture, sampler=mr.Sampler("trilinear"))
    image = mr.render(scene, mr.Camera.from_matrices(np.eye(4), np.eye(4)), 32, 32, spp=4).color
    assert abs(image[..., :3].mean() - texture.level(0)[..., :3].mean()) < 0.01


def test_bad_input_is_refused_with_a_message_naming_it():
    sample = rgb8(8, 10, 9)
    with pytest.raises(ValueError, match="window: 4; expected an odd size"):
        mr.synthesize(sample, (8, 8), window=4)
    with pytest.raises(ValueError, match="window: -1"):
        mr.synthesize(sample, (8, 8), window=-1)
    with pytest.raises(ValueError, match=r"window: 9 is larger than the sample \(10x8\)"):
        mr.synthesize(sample, (8, 8), window=9)
    with pytest.raises(ValueError, match="larger than the tileable output"):
        mr.synthesize(sample, (4, 4), window=5, tileable=True)
    with pytest.raises(ValueError, match="size: width 0"):
        mr.synthesize(sample, (0, 8), window=3)
    with pytest.raises(ValueError, match="size: height 9000"):
        mr.synthesize(sample, (8, 9000), window=3)
    with pytest.raises(TypeError, match="size"):
        mr.synthesize(sample, 8, window=3)
    with pytest.raises(TypeError, match="window"):
        mr.synthesize(sample, (8, 8), window=3.0)
    with pytest.raises(ValueError, match="epsilon"):
        mr.synthesize(sample, (8, 8), window=3, epsilon=-0.1)
    with pytest.raises(ValueError, match="epsilon"):
        mr.synthesize(sample, (8, 8), window=3, epsilon=float("inf"))
    with pytest.raises(ValueError, match="seed"):
        mr.synthesize(sample, (8, 8), window=3, seed=-1)
    with pytest.raises(TypeError, match="sample: expected uint8 / uint16"):
        mr.synthesize(sample.astype(np.int32), (8, 8), window=3)
    bad = sample.astype(np.float32)
    bad[2, 3, 1] = np.nan
    with pytest.raises(ValueError, match=r"sample\[2, 3, 1\] is nan"):
        mr.synthesize(bad, (8, 8), window=3)
    with pytest.raises(ValueError, match="sample: expected shape"):
        mr.synthesize(np.zeros((8, 8, 6), np.float32), (8, 8), window=3)
