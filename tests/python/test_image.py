"""Image files and sRGB: RenderResult.save, read_image / write_image, to_srgb8, and their errors."""
import numpy as np
import pytest
from PIL import Image

import mipraster as mr


def grey_render(value=0.5, alpha=1.0, size=(6, 4)):
    """A full-screen quad of linear grey `value` (premultiplied by `alpha`)."""
    w, h = size
    scene = mr.Scene()
    scene.add(mr.Mesh([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], [[0, 1, 2], [0, 2, 3]]),
              color=(value * alpha, value * alpha, value * alpha, alpha))
    camera = mr.Camera.from_matrices(np.eye(4), np.eye(4))  # clip = world: the quad is the viewport
    return mr.render(scene, camera, w, h)


def test_save_png_is_srgb_188_for_linear_half_grey(tmp_path):
    result = grey_render(0.5)
    path = tmp_path / "grey.png"
    result.save(path)  # pathlib.Path is accepted
    png = np.asarray(Image.open(path))
    assert png.shape == (4, 6, 4) and png.dtype == np.uint8
    assert np.all(png == [188, 188, 188, 255])
    np.testing.assert_array_equal(result.to_srgb8(), png)


def test_png_stores_straight_alpha(tmp_path):
    result = grey_render(0.5, alpha=0.5)  # premultiplied (0.25, 0.25, 0.25, 0.5)
    result.save(str(tmp_path / "half.png"))
    assert np.all(np.asarray(Image.open(tmp_path / "half.png")) == [188, 188, 188, 128])


def test_exr_round_trip_is_exact(tmp_path):
    rng = np.random.default_rng(5)
    image = rng.uniform(0, 4, size=(5, 7, 4)).astype(np.float32)
    mr.write_image(tmp_path / "x.exr", image)
    back = mr.read_image(tmp_path / "x.exr")
    assert back.dtype == np.float32 and back.shape == (5, 7, 4)
    np.testing.assert_array_equal(back, image)
    assert not back.flags.owndata and back.flags.writeable  # handed over from C++ without a copy


def test_read_png_decodes_srgb_to_linear(tmp_path):
    Image.fromarray(np.full((3, 2, 3), 188, np.uint8)).save(tmp_path / "g.png")
    back = mr.read_image(str(tmp_path / "g.png"))
    assert back.shape == (3, 2, 4)
    np.testing.assert_allclose(back[..., :3], mr.srgb_to_linear(np.float32(188 / 255)), rtol=1e-6)
    np.testing.assert_array_equal(back[..., 3], 1.0)


def test_write_image_accepts_float64_grey_and_rgb(tmp_path):
    mr.write_image(tmp_path / "grey.png", np.full((2, 3), 0.5))  # data: plain grey, no sRGB
    assert np.all(np.asarray(Image.open(tmp_path / "grey.png")) == 128)
    mr.write_image(tmp_path / "rgb.png", np.full((2, 3, 3), 0.5))
    assert np.all(np.asarray(Image.open(tmp_path / "rgb.png")) == 188)


def test_to_srgb8_and_scalar_transfer_functions():
    np.testing.assert_array_equal(mr.to_srgb8(np.full((1, 2, 4), [0.5, 0.0, 1.0, 1.0])), [[[188, 0, 255, 255]] * 2])
    assert mr.linear_to_srgb8(0.5) == 188
    np.testing.assert_allclose(mr.srgb_to_linear(mr.linear_to_srgb(np.linspace(0, 1, 11))), np.linspace(0, 1, 11),
                               atol=1e-6)


# --- errors -----------------------------------------------------------------------------------------


def test_unwritable_path_raises_os_error_naming_it(tmp_path):
    bad = tmp_path / "no" / "such" / "dir" / "x.png"
    with pytest.raises(OSError) as e:
        grey_render().save(bad)
    assert str(bad) in str(e.value) and e.value.filename == str(bad)
    assert not bad.exists()


def test_unsupported_extension_raises_value_error(tmp_path):
    with pytest.raises(ValueError, match="x.bmpx"):
        grey_render().save(tmp_path / "x.bmpx")


def test_missing_file_raises_file_not_found(tmp_path):
    missing = tmp_path / "missing.png"
    with pytest.raises(FileNotFoundError) as e:
        mr.read_image(missing)
    assert e.value.filename == str(missing)


def test_corrupt_file_raises_os_error_naming_it(tmp_path):
    corrupt = tmp_path / "corrupt.png"
    corrupt.write_bytes(b"\x89PNG\r\n\x1a\n but then nothing sensible")
    with pytest.raises(OSError) as e:
        mr.read_image(corrupt)
    assert str(corrupt) in str(e.value) and e.value.filename == str(corrupt)


@pytest.mark.parametrize(
    "image, error, words",
    [
        (np.zeros((4, 4, 4), np.uint8), TypeError, ["image", "uint8", "srgb_to_linear"]),
        (np.zeros((4, 4, 2)), ValueError, ["image", "(H, W, 3)", "(4, 4, 2)"]),
        (np.zeros(16), ValueError, ["image", "(16,)"]),
        (np.zeros((0, 4, 4)), ValueError, ["empty"]),
    ],
)
def test_write_image_refuses_bad_arrays(tmp_path, image, error, words):
    with pytest.raises(error) as e:
        mr.write_image(tmp_path / "x.png", image)
    for w in words:
        assert w in str(e.value)


def test_bad_path_type():
    with pytest.raises(TypeError, match="path"):
        mr.write_image(42, np.zeros((2, 2, 4)))
