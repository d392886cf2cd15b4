"""Image files and sRGB: RenderResult.save, read_image / write_image, to_srgb8, and their errors."""
import math
import os

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


def srgb_decode(codes):
    """IEC 61966-2-1 sRGB decoding of 8-bit codes, written out here as the oracle."""
    c = np.asarray(codes, dtype=np.float64) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


@pytest.mark.parametrize("mode", ["RGB", "L"])
def test_read_jpeg_decodes_srgb_to_linear(tmp_path, mode):
    # A flat colour survives JPEG's lossy coding within a code or two.
    code = (188, 60, 230) if mode == "RGB" else 188
    Image.new(mode, (16, 8), code).save(tmp_path / "flat.jpg", quality=95, subsampling=0)
    back = mr.read_image(tmp_path / "flat.jpg")
    assert back.shape == (8, 16, 4) and back.dtype == np.float32
    codes = np.broadcast_to(np.atleast_1d(code), (3,))
    lo, hi = srgb_decode(np.maximum(codes - 2, 0)), srgb_decode(np.minimum(codes + 2, 255))
    assert ((back[..., :3] >= lo) & (back[..., :3] <= hi)).all(), (back[0, 0], srgb_decode(codes))
    np.testing.assert_array_equal(back[..., 3], 1.0)


@pytest.mark.parametrize("compression", [None, "tga_rle"])
def test_read_tga_with_alpha_gives_premultiplied_linear_colour(tmp_path, compression):
    rng = np.random.default_rng(11)
    rgba8 = rng.integers(0, 256, (5, 7, 4), dtype=np.uint8)
    rgba8[0, 0] = [200, 100, 50, 0]  # fully transparent: premultiplied to 0
    rgba8[0, 1] = [188, 188, 188, 255]
    path = tmp_path / "x.tga"
    Image.fromarray(rgba8, "RGBA").save(path, compression=compression)
    back = mr.read_image(path)
    assert back.shape == (5, 7, 4)  # rows in file order, top row first
    alpha = rgba8[..., 3:4] / 255.0
    np.testing.assert_allclose(back[..., :3], srgb_decode(rgba8[..., :3]) * alpha, rtol=1e-5, atol=1e-7)
    np.testing.assert_allclose(back[..., 3:], alpha, rtol=1e-6)
    np.testing.assert_array_equal(back[0, 0], 0.0)
    # Without alpha: opaque, and the same sRGB decoding.
    Image.fromarray(rgba8[..., :3], "RGB").save(tmp_path / "rgb.tga", compression=compression)
    rgb = mr.read_image(tmp_path / "rgb.tga")
    np.testing.assert_allclose(rgb[..., :3], srgb_decode(rgba8[..., :3]), rtol=1e-5, atol=1e-7)
    np.testing.assert_array_equal(rgb[..., 3], 1.0)


def write_radiance_hdr(path, rgb):
    """A Radiance RGBE file with flat (uncompressed) scanlines, as allowed for widths below 8."""
    h, w, _ = rgb.shape
    assert w < 8
    m = rgb.max(axis=-1)
    mantissa, exponent = np.frexp(m)  # m = mantissa · 2^exponent, mantissa in [0.5, 1)
    scale = np.where(m > 0, 256.0 / np.ldexp(1.0, exponent), 0.0)
    rgbe = np.zeros((h, w, 4), np.uint8)
    rgbe[..., :3] = np.floor(rgb * scale[..., None])
    rgbe[..., 3] = np.where(m > 0, exponent + 128, 0)
    header = f"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {h} +X {w}\n".encode("ascii")
    path.write_bytes(header + rgbe.tobytes())


def test_read_radiance_hdr_returns_linear_values_as_written(tmp_path):
    rng = np.random.default_rng(12)
    rgb = rng.uniform(0.0, 1.0, (3, 5, 3)) * rng.choice([0.01, 1.0, 40.0], (3, 5, 1))  # beyond 1 too
    rgb[0, 0] = [0.0, 0.0, 0.0]
    rgb[0, 1] = [3.7, 0.25, 120.0]
    write_radiance_hdr(tmp_path / "x.hdr", rgb)
    back = mr.read_image(tmp_path / "x.hdr")
    assert back.shape == (3, 5, 4) and back.dtype == np.float32
    # RGBE keeps 8 bits of mantissa below a shared exponent: errors up to ~1% of the largest channel.
    tolerance = 0.01 * rgb.max(axis=-1, keepdims=True)
    assert (np.abs(back[..., :3] - rgb) <= tolerance).all(), np.abs(back[..., :3] - rgb).max()
    np.testing.assert_array_equal(back[0, 0], [0, 0, 0, 1])
    np.testing.assert_array_equal(back[..., 3], 1.0)
    assert back[0, 1, 2] > 100  # not clamped, not sRGB-decoded


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
    assert mr.linear_to_srgb(0.5) == pytest.approx(0.735357, abs=1e-6) and mr.srgb_to_linear(1) == 1.0
    # (The bindings alone read None as 0.)
    for function, name in ((mr.linear_to_srgb, "linear"), (mr.linear_to_srgb8, "linear"),
                           (mr.srgb_to_linear, "encoded")):
        for bad in (None, [None], "0.5", {}):
            with pytest.raises(TypeError, match=name):
                function(bad)


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


@pytest.mark.parametrize("kind", ["device", "fifo", "directory"])
def test_a_path_that_is_not_a_regular_file_raises_os_error_naming_it(tmp_path, kind):
    # /dev/zero: OpenImageIO's readers searched its endless bytes for a header and never returned;
    # a FIFO without a writer blocked the open.
    path = {"device": "/dev/zero", "fifo": tmp_path / "pipe.png", "directory": tmp_path}[kind]
    if kind == "fifo":
        os.mkfifo(path)
    with pytest.raises(OSError, match="not a regular file") as e:
        mr.read_image(path)
    assert str(path) in str(e.value) and e.value.filename == str(path)


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
        # float64 beyond float32: it became inf with only numpy's overflow warning
        (np.full((2, 3, 4), 1.0), None, None),
    ],
)
def test_write_image_refuses_bad_arrays(tmp_path, image, error, words):
    if error is None:  # (the float64 case: one value past float32's largest)
        image[1, 2, 0] = -1e39
        error, words = ValueError, ["image[1, 2, 0] = -1e+39", "does not fit in float32"]
    with pytest.raises(error) as e:
        mr.write_image(tmp_path / "x.png", image)
    for w in words:
        assert w in str(e.value)


def test_write_image_exr_keeps_nan_and_inf_of_float64_images(tmp_path):
    # (check_fits_float32 refuses finite values only: an EXR stores non-finite ones as they are)
    image = np.full((2, 2, 4), 0.5)
    image[0, 0, 0], image[0, 1, 1] = np.nan, np.inf
    mr.write_image(tmp_path / "x.exr", image)
    back = mr.read_image(tmp_path / "x.exr")
    assert np.isnan(back[0, 0, 0]) and back[0, 1, 1] == np.inf


@pytest.mark.parametrize("shape", [(3, 4), (3, 4, 1), (3, 4, 3), (3, 4, 4)])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
@pytest.mark.parametrize("bits", [8, 16])
def test_write_png_refuses_nan_and_inf_naming_the_pixel(tmp_path, shape, bad, bits):
    # A PNG code has no NaN: it was written as 0 (and inf as the clamp limit), a silent wrong image.
    image = np.full(shape, 0.5, np.float32)
    channel = shape[2] - 1 if len(shape) == 3 else 0
    image[(2, 1, channel)[:len(shape)]] = bad
    with pytest.raises(ValueError) as e:
        mr.write_image(tmp_path / "x.png", image, bits=bits)
    assert f"pixel (x=1, y=2) channel {channel} is {bad}" in str(e.value)
    assert "x.png" in str(e.value) and ".exr" in str(e.value)
    assert not (tmp_path / "x.png").exists()


def test_write_png_refuses_nan_in_the_cpp_module_too(tmp_path):
    # The extension module's own check (the C++ API and the CLI write through it): ValueError
    # naming the first non-finite pixel, not a PNG with 0 in its place.
    from mipraster import _image

    image = np.full((3, 4, 4), 0.5, np.float32)
    image[1, 2, 3] = np.nan
    with pytest.raises(ValueError, match=r"pixel \(x=2, y=1\) channel 3 is nan"):
        _image.write_image(str(tmp_path / "x.png"), image, 8)
    assert not (tmp_path / "x.png").exists()


def test_to_srgb8_and_transfer_functions_do_not_turn_nan_into_codes():
    image = np.full((2, 3, 4), 0.5, np.float32)
    image[1, 2, 0] = np.nan
    with pytest.raises(ValueError, match=r"to_srgb8: pixel \(x=2, y=1\) channel 0 is nan"):
        mr.to_srgb8(image)
    image[1, 2, 0] = -np.inf
    with pytest.raises(ValueError, match=r"channel 0 is -inf"):
        mr.to_srgb8(image)
    with pytest.raises(ValueError, match="linear is nan"):
        mr.linear_to_srgb8(float("nan"))
    with pytest.raises(ValueError, match=r"linear\[1\] is inf"):
        mr.linear_to_srgb8([0.5, np.inf])
    # Float to float: NaN in, NaN out (it was 0.0); the rest as before.
    assert math.isnan(mr.srgb_to_linear(float("nan"))) and math.isnan(mr.linear_to_srgb(float("nan")))
    out = mr.srgb_to_linear(np.array([0.5, np.nan, 1.0], np.float32))
    assert out.dtype == np.float32 and np.isnan(out[1]) and out[2] == 1.0 and out[0] == mr.srgb_to_linear(0.5)
    assert np.isnan(mr.linear_to_srgb([[np.nan, 0.5]])[0, 0])


def test_bad_path_type():
    with pytest.raises(TypeError, match="path"):
        mr.write_image(42, np.zeros((2, 2, 4)))


@pytest.mark.parametrize("name, words", [("a\0b.png", "contains a NUL character"),
                                         ("a\udcffb.png", "is not valid Unicode")])
def test_path_the_file_system_would_read_differently(tmp_path, name, words):
    # The C++ side stopped at a NUL ('a\0b.png' wrote a file named 'a'); a lone surrogate gave
    # pybind11's 'incompatible function arguments'.
    path = str(tmp_path / name)
    for call in (lambda: mr.write_image(path, np.zeros((2, 2, 4))), lambda: mr.read_image(path),
                 lambda: mr.load_scene(path)):
        with pytest.raises(ValueError, match=words):
            call()
    assert list(tmp_path.iterdir()) == []


# --- 16-bit PNG ---------------------------------------------------------------------------------

def decode_png(path):
    """An independent PNG decoder for the 16-bit files below (zlib and the five row filters of the
    PNG specification): (H, W, C) uint16 codes. Non-interlaced grey, RGB and RGBA only."""
    import struct
    import zlib

    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    at, idat, header = 8, b"", None
    while at < len(data):
        length, kind = struct.unpack(">I4s", data[at:at + 8])
        body = data[at + 8:at + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        at += 12 + length
    w, h, depth, colour_type, _, _, interlace = header
    assert depth == 16 and interlace == 0
    channels = {0: 1, 2: 3, 6: 4}[colour_type]
    bpp, stride = 2 * channels, 2 * channels * w
    raw = zlib.decompress(idat)
    rows, prev = [], bytearray(stride)
    for y in range(h):
        kind, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if kind == 1:
                line[i] = (line[i] + a) & 255
            elif kind == 2:
                line[i] = (line[i] + b) & 255
            elif kind == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line))
        prev = line
    return np.frombuffer(b"".join(rows), dtype=">u2").reshape(h, w, channels).astype(np.uint16)


def srgb_encode(linear):
    """IEC 61966-2-1's encoding, in float64 (the test's own formula)."""
    x = np.clip(np.nan_to_num(np.asarray(linear, np.float64), nan=0.0), 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)


def test_png_16_bits_holds_srgb_codes_of_65535_steps(tmp_path):
    # Linear premultiplied RGBA over [0, 1] (and beyond, clamped): the file holds straight-alpha
    # sRGB codes round(encode(c / a) · 65535), alpha round(a · 65535), within one code of the
    # float64 formula (the library encodes in float).
    rng = np.random.default_rng(16)
    straight = rng.uniform(-0.1, 1.1, size=(9, 11, 3))
    alpha = rng.uniform(0.05, 1.0, size=(9, 11, 1))
    alpha[0, 0] = 1.0
    image = np.concatenate([straight * alpha, alpha], axis=-1).astype(np.float32)
    mr.write_image(tmp_path / "deep.png", image, bits=16)
    codes = decode_png(tmp_path / "deep.png")
    assert codes.shape == (9, 11, 4)
    want_colour = np.round(srgb_encode(image[..., :3].astype(np.float64) / image[..., 3:]) * 65535)
    assert np.abs(codes[..., :3] - want_colour).max() <= 1
    assert np.abs(codes[..., 3] - np.round(image[..., 3].astype(np.float64) * 65535)).max() <= 1
    # 256 times finer than 8 bits: the 8-bit file's codes are these, rounded to 8 bits.
    mr.write_image(tmp_path / "shallow.png", image)
    shallow = np.asarray(Image.open(tmp_path / "shallow.png")).astype(np.int64)
    assert np.abs(shallow - codes.astype(np.int64) / 257).max() <= 0.51


@pytest.mark.parametrize("channels", [1, 3])
def test_png_16_bits_grey_and_rgb(tmp_path, channels):
    # RGB is sRGB-encoded without alpha; one channel is plain grey data, round(clamp(v) · 65535).
    rng = np.random.default_rng(channels)
    image = rng.uniform(-0.1, 1.1, size=(5, 6, channels)).astype(np.float32)
    mr.write_image(tmp_path / "x.png", image, bits=16)
    codes = decode_png(tmp_path / "x.png")
    assert codes.shape == (5, 6, channels)
    if channels == 1:
        want = np.round(np.clip(image.astype(np.float64), 0, 1) * 65535)
    else:
        want = np.round(srgb_encode(image) * 65535)
    assert np.abs(codes - want).max() <= 1


def test_png_16_bits_reads_back_within_a_65535th(tmp_path):
    # read_image decodes 16-bit files from sRGB: a round trip within the 16-bit quantization
    # (8 bits: within 1/255).
    rng = np.random.default_rng(3)
    image = rng.uniform(0.0, 1.0, size=(6, 7, 4)).astype(np.float32)
    image[..., 3] = 1.0
    mr.write_image(tmp_path / "x.png", image, bits=16)
    back = mr.read_image(tmp_path / "x.png")
    # (sRGB decoding's slope is at most 2.4 / 1.055 ≈ 2.27, at 1: half a code step gives < 1.2 / 65535)
    assert np.abs(back - image).max() < 2.5 / 65535


def test_save_writes_16_bit_png(tmp_path):
    result = grey_render(0.5)
    result.save(tmp_path / "grey.png", bits=16)
    assert np.all(decode_png(tmp_path / "grey.png") == [round(srgb_encode(0.5).item() * 65535)] * 3 + [65535])


@pytest.mark.parametrize("path, bits, words", [
    ("x.png", 12, ["bits", "12", "8 or 16"]),
    ("x.png", True, ["bits", "8 or 16"]),
    ("x.exr", 16, ["bits", "PNG", ".exr"]),
])
def test_write_image_refuses_bad_bit_depths(tmp_path, path, bits, words):
    with pytest.raises(ValueError) as e:
        mr.write_image(tmp_path / path, np.zeros((2, 2, 4), np.float32), bits=bits)
    for w in words:
        assert w in str(e.value), str(e.value)
    assert not (tmp_path / path).exists()
