"""The image files users bring, decoded by read_image / Texture.from_file and checked against
independent oracles: Pillow's decode (or the codes written) with the sRGB formula written out here.

Conventions under test (README "Images"): integer files are sRGB-encoded (colour decoded, alpha
linear), float files linear; the result is linear premultiplied RGBA; grey is replicated, alpha 1
when absent; transfer metadata in the file and EXIF orientation are not applied.
"""
import struct
import subprocess
import shutil
import zlib

import numpy as np
import pytest
from PIL import Image

import mipraster as mr

OIIOTOOL = shutil.which("oiiotool")
needs_oiiotool = pytest.mark.skipif(OIIOTOOL is None, reason="oiiotool (OpenImageIO tools) is not installed")


# --- oracles ------------------------------------------------------------------------------------

def srgb_decode(encoded):
    """IEC 61966-2-1 decoding of values in [0, 1], in float64."""
    c = np.asarray(encoded, dtype=np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def as_rgba(codes):
    """(H, W[, C]) straight codes with C = 1…4 → (H, W, 4) float64 codes, grey replicated, alpha
    max code when absent."""
    a = np.asarray(codes)
    top = np.iinfo(a.dtype).max
    a = a.astype(np.float64)
    if a.ndim == 2:
        a = a[..., None]
    grey = a.shape[-1] <= 2
    colour = np.repeat(a[..., :1], 3, axis=-1) if grey else a[..., :3]
    alpha = a[..., -1:] if a.shape[-1] in (2, 4) else np.full(a.shape[:2] + (1,), float(top))
    return np.concatenate([colour, alpha], axis=-1), top


def expected_linear(codes, srgb=True):
    """Straight integer codes → linear premultiplied RGBA, the way read_image must decode them."""
    rgba, top = as_rgba(codes)
    alpha = rgba[..., 3:] / top
    colour = rgba[..., :3] / top
    return np.concatenate([(srgb_decode(colour) if srgb else colour) * alpha, alpha], axis=-1)


def assert_decoded(actual, expected):
    """Equal up to float32 rounding of the decode (a 16-bit code step is 1.5e-5, 8-bit 3.9e-3)."""
    assert actual.dtype == np.float32 and actual.shape == expected.shape, (actual.shape, expected.shape)
    np.testing.assert_allclose(actual, expected, rtol=1e-6, atol=1e-7)


def pillow_codes(path):
    """Pillow's decode of `path` as straight RGBA codes (palette and tRNS expanded, CMYK converted)."""
    return np.asarray(Image.open(path).convert("RGBA"))


def random_codes(shape, dtype=np.uint8, seed=0):
    rng = np.random.default_rng(seed)
    codes = rng.integers(0, np.iinfo(dtype).max + 1, shape, dtype=dtype)
    if len(shape) == 3 and shape[-1] in (2, 4):
        codes[0, 0, -1] = 0  # fully transparent: premultiplied colour 0
        codes[-1, -1, -1] = np.iinfo(dtype).max
    return codes


# --- a minimal PNG encoder (Pillow cannot write 16-bit colour PNGs or chosen chunks) ------------

def _chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def write_png(path, codes, chunks=()):
    """Writes (H, W[, C]) uint8/uint16 codes (C = 1 grey, 2 grey+alpha, 3 RGB, 4 RGBA), unfiltered,
    with extra ancillary `chunks` ((type, data) pairs) before the image data."""
    a = np.asarray(codes)
    a = a[..., None] if a.ndim == 2 else a
    h, w, c = a.shape
    depth = 8 * a.dtype.itemsize
    rows = a.astype(">u2" if depth == 16 else np.uint8).reshape(h, -1)
    raw = b"".join(b"\x00" + row.tobytes() for row in rows)
    header = struct.pack(">IIBBBBB", w, h, depth, {1: 0, 2: 4, 3: 2, 4: 6}[c], 0, 0, 0)
    body = [_chunk(b"IHDR", header)] + [_chunk(k, d) for k, d in chunks]
    body += [_chunk(b"IDAT", zlib.compress(raw)), _chunk(b"IEND", b"")]
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + b"".join(body))


# --- PNG ----------------------------------------------------------------------------------------

@pytest.mark.parametrize("channels", [1, 2, 3, 4], ids=["grey", "grey-alpha", "rgb", "rgba"])
@pytest.mark.parametrize("dtype", [np.uint8, np.uint16], ids=["8bit", "16bit"])
def test_png_channel_layouts_and_depths(tmp_path, channels, dtype):
    codes = random_codes((5, 7, channels), dtype, seed=channels)
    path = tmp_path / "x.png"
    write_png(path, codes)
    if dtype == np.uint8:  # the encoder agrees with Pillow's decoder
        np.testing.assert_array_equal(pillow_codes(path), as_rgba(codes)[0])
    # 16-bit: exact to float32, so a code step (1/65535) is resolved: nothing is cut to 8 bits.
    assert_decoded(mr.read_image(path), expected_linear(codes))


@pytest.mark.parametrize("transparency", [False, True], ids=["opaque", "trns"])
def test_palette_png_expands_palette_and_trns_alpha(tmp_path, transparency):
    rgb = random_codes((6, 5, 3), seed=3)
    image = Image.fromarray(rgb).quantize(6)
    path = tmp_path / "p.png"
    if transparency:
        image.save(path, transparency=bytes([0, 90, 255, 255, 17, 200]))  # tRNS: one alpha per entry
    else:
        image.save(path)
    expected = pillow_codes(path)
    assert Image.open(path).mode == "P" and (expected[..., 3] < 255).any() == transparency
    assert_decoded(mr.read_image(path), expected_linear(expected))


@pytest.mark.parametrize("chunk", [
    (b"gAMA", struct.pack(">I", 100000)),     # gamma 1.0: OpenImageIO says "linear"
    (b"gAMA", struct.pack(">I", 45455)),      # gamma 1/2.2: "Gamma2.2"
    (b"sRGB", b"\x00"),
    (b"iCCP", b"icc\x00\x00" + zlib.compress(b"\x00" * 128)),
], ids=["gama-1.0", "gama-0.45", "srgb", "iccp"])
def test_png_transfer_chunks_are_ignored(tmp_path, chunk):
    """Integer files are sRGB unless the caller says linear; the file's own claims are not used."""
    codes = random_codes((3, 4, 3), seed=4)
    write_png(tmp_path / "c.png", codes, chunks=[chunk])
    assert_decoded(mr.read_image(tmp_path / "c.png"), expected_linear(codes))


@pytest.mark.parametrize("shape", [(1, 1), (1, 9), (9, 1), (3, 5), (7, 13)])
def test_odd_sizes(tmp_path, shape):
    codes = random_codes(shape + (4,), seed=sum(shape))
    Image.fromarray(codes).save(tmp_path / "odd.png")
    back = mr.read_image(tmp_path / "odd.png")
    assert back.shape == shape + (4,)
    assert_decoded(back, expected_linear(codes))
    texture = mr.Texture.from_file(tmp_path / "odd.png")
    assert (texture.height, texture.width) == shape
    np.testing.assert_array_equal(texture.level(0), back)


# --- JPEG ---------------------------------------------------------------------------------------

@pytest.mark.parametrize("mode, options", [
    ("RGB", {"quality": 90}),
    ("L", {"quality": 90}),
    ("CMYK", {"quality": 95}),
    ("RGB", {"quality": 90, "progressive": True}),
], ids=["rgb", "grey", "cmyk", "progressive"])
def test_jpeg_matches_pillows_decode(tmp_path, mode, options):
    """Both decoders are libjpeg: the same codes (CMYK converted to RGB the way Pillow does)."""
    rgb = random_codes((9, 14, 3), seed=5)
    Image.fromarray(rgb).convert(mode).save(tmp_path / "x.jpg", **options)
    assert Image.open(tmp_path / "x.jpg").mode == mode
    assert_decoded(mr.read_image(tmp_path / "x.jpg"), expected_linear(pillow_codes(tmp_path / "x.jpg")))


@pytest.mark.parametrize("suffix", [".jpg", ".png"])
def test_exif_orientation_is_not_applied(tmp_path, suffix):
    """Pixels come in stored order (as OpenImageIO and Pillow give them): uv (0, 0) is the first
    stored texel, whatever a photo viewer would show."""
    codes = random_codes((4, 6, 3), seed=6)
    exif = Image.Exif()
    exif[0x0112] = 6  # "rotate 90° clockwise to display"
    path = tmp_path / ("o" + suffix)
    Image.fromarray(codes).save(path, exif=exif, **({"quality": 95} if suffix == ".jpg" else {}))
    assert Image.open(path).getexif()[0x0112] == 6
    back = mr.read_image(path)
    assert back.shape == (4, 6, 4)
    assert_decoded(back, expected_linear(pillow_codes(path)))


# --- TIFF, BMP, TGA, GIF, WebP ------------------------------------------------------------------

@pytest.mark.parametrize("suffix, mode, options", [
    (".tif", "RGB", {}),
    (".tif", "RGBA", {}),                      # ExtraSamples 2: unassociated alpha
    (".tif", "L", {"compression": "tiff_lzw"}),
    (".bmp", "RGB", {}),
    (".bmp", "L", {}),                         # 8-bit palette of greys
    (".tga", "L", {}),
    (".tga", "RGBA", {"compression": "tga_rle"}),
    (".gif", "P", {"transparency": 2}),
    (".webp", "RGB", {"lossless": True}),
], ids=lambda v: v if isinstance(v, str) else "")
def test_integer_formats_match_pillows_decode(tmp_path, suffix, mode, options):
    rgba = random_codes((6, 9, 4), seed=7)
    image = Image.fromarray(rgba).convert("RGB").quantize(8) if mode == "P" else Image.fromarray(rgba).convert(mode)
    path = tmp_path / ("x" + suffix)
    image.save(path, **options)
    assert_decoded(mr.read_image(path), expected_linear(pillow_codes(path)))


def test_16bit_grey_tiff_keeps_16_bits(tmp_path):
    codes = random_codes((4, 5), np.uint16, seed=8)
    Image.fromarray(codes).save(tmp_path / "g16.tif")
    assert np.array_equal(np.asarray(Image.open(tmp_path / "g16.tif")), codes)
    assert_decoded(mr.read_image(tmp_path / "g16.tif"), expected_linear(codes))


def test_webp_alpha_is_premultiplied_once(tmp_path):
    """OpenImageIO premultiplies WebP's 8-bit codes itself (rounding to a code); read_image divides
    that back out before decoding, so colour is premultiplied once, in linear. The rounding costs
    at most half a code of premultiplied colour: compare within that, not exactly."""
    rgba = random_codes((6, 9, 4), seed=9)
    rgba[..., 3] = np.maximum(rgba[..., 3], 32)
    rgba[0, 0, 3] = 0
    Image.fromarray(rgba).save(tmp_path / "a.webp", lossless=True, exact=True)
    np.testing.assert_array_equal(pillow_codes(tmp_path / "a.webp"), rgba)  # lossless
    back = mr.read_image(tmp_path / "a.webp")
    expected = expected_linear(rgba)
    np.testing.assert_allclose(back[..., 3], expected[..., 3], rtol=1e-6)
    a = rgba[..., 3:].astype(np.float64)
    # Straight encoded colour is off by up to 0.5 / alpha code; the sRGB decode's slope is below 2.4.
    bound = np.where(a > 0, 2.4 * 0.5 / np.maximum(a, 1) * expected[..., 3:], 0) + 1e-6
    assert (np.abs(back[..., :3] - expected[..., :3]) <= bound).all(), np.abs(back[..., :3] - expected[..., :3]).max()
    np.testing.assert_array_equal(back[0, 0], 0.0)


def write_bmp32(path, bgra):
    """A 32-bit BI_RGB BMP (40-byte header), rows bottom-up: the fourth byte is whatever is given."""
    h, w, _ = bgra.shape
    pixels = bgra[::-1].tobytes()
    info = struct.pack("<IiiHHIIiiII", 40, w, h, 1, 32, 0, len(pixels), 2835, 2835, 0, 0)
    head = b"BM" + struct.pack("<IHHI", 14 + len(info) + len(pixels), 0, 0, 14 + len(info))
    path.write_bytes(head + info + pixels)


@pytest.mark.parametrize("fourth", ["alpha", "zero"])
def test_32bit_bmp(tmp_path, fourth):
    """The fourth byte of a BI_RGB 32-bit BMP: alpha when any pixel has one (OpenImageIO's and the
    browsers' reading; Pillow ignores it), padding when it is zero everywhere (opaque, as browsers
    and stb_image read it; not a fully transparent image)."""
    rgba = random_codes((5, 6, 4), seed=10)
    if fourth == "zero":
        rgba[..., 3] = 0
    write_bmp32(tmp_path / "x.bmp", np.ascontiguousarray(rgba[..., [2, 1, 0, 3]]))
    np.testing.assert_array_equal(pillow_codes(tmp_path / "x.bmp")[..., :3], rgba[..., :3])  # the file is as meant
    expected = expected_linear(rgba if fourth == "alpha" else rgba[..., :3])
    assert_decoded(mr.read_image(tmp_path / "x.bmp"), expected)


# --- associated alpha in integer files ----------------------------------------------------------

def stored_codes(path, size, channels):
    """The integer codes of an image file as `oiiotool --dumpdata` prints them ("Pixel (x, y): c c c c (...)")."""
    text = subprocess.run([OIIOTOOL, "--dumpdata", str(path)], check=True, capture_output=True, text=True).stdout
    codes = np.zeros(size + (channels,))
    for line in text.splitlines():
        line = line.strip()
        if line.startswith("Pixel ("):
            where, values = line[len("Pixel ("):].split("):")
            x, y = (int(v) for v in where.split(","))
            codes[y, x] = [float(v) for v in values.split("(")[0].split()]
    return codes


@needs_oiiotool
@pytest.mark.parametrize("depth", ["uint8", "uint16"])
def test_tiff_with_associated_alpha_is_not_premultiplied_twice(tmp_path, depth):
    """oiiotool (like compositing tools) writes TIFF alpha as associated (ExtraSamples 1): the colour
    codes are already multiplied by alpha in their encoded space. read_image divides by alpha,
    decodes, and multiplies in linear."""
    rng = np.random.default_rng(11)
    straight = rng.uniform(0, 1, (4, 6, 3))
    alpha = rng.uniform(0.2, 1, (4, 6, 1))
    alpha[0, 0] = 0
    mr.write_image(tmp_path / "p.exr", np.concatenate([straight * alpha, alpha], -1).astype(np.float32))
    subprocess.run([OIIOTOOL, str(tmp_path / "p.exr"), "-d", depth, "-o", str(tmp_path / "a.tif")], check=True)
    assert Image.open(tmp_path / "a.tif").tag_v2[338] in (1, (1,))  # ExtraSamples: associated alpha
    # The codes as stored, printed by oiiotool (Pillow un-premultiplies 8-bit ones and reads 16-bit
    # RGBA as 8 bits).
    top = float(np.iinfo(depth).max)
    stored = stored_codes(tmp_path / "a.tif", straight.shape[:2], 4)
    assert (stored[..., :3] <= stored[..., 3:]).all()  # premultiplied
    a = stored[..., 3:] / top
    encoded = np.where(a > 0, np.minimum(stored[..., :3] / top / np.where(a > 0, a, 1), 1), 0)
    expected = np.concatenate([srgb_decode(encoded) * a, a], -1)
    assert_decoded(mr.read_image(tmp_path / "a.tif"), expected)


# --- float formats ------------------------------------------------------------------------------

def linear_rgba(shape, seed):
    rng = np.random.default_rng(seed)
    rgba = rng.uniform(0, 4, shape + (4,)).astype(np.float32)  # HDR values beyond 1 too
    rgba[..., 3] = rng.uniform(0, 1, shape)
    rgba[..., :3] *= rgba[..., 3:]
    return rgba


@needs_oiiotool
@pytest.mark.parametrize("channels", ["RGBA", "RGB", "Y", "YA"])
@pytest.mark.parametrize("depth", ["float", "half"])
def test_exr_is_linear_and_kept_as_stored(tmp_path, channels, depth):
    rgba = linear_rgba((3, 5), seed=12)
    mr.write_image(tmp_path / "f.exr", rgba)
    select = {"RGBA": "R,G,B,A", "RGB": "R,G,B", "Y": "Y=R", "YA": "Y=R,A"}[channels]
    subprocess.run([OIIOTOOL, str(tmp_path / "f.exr"), "--ch", select, "-d", depth, "-o", str(tmp_path / "x.exr")],
                   check=True)
    stored = rgba.astype(np.float16).astype(np.float32) if depth == "half" else rgba
    colour = stored[..., [0, 0, 0]] if channels.startswith("Y") else stored[..., :3]
    alpha = stored[..., 3:] if channels.endswith("A") else np.ones_like(stored[..., 3:])
    np.testing.assert_array_equal(mr.read_image(tmp_path / "x.exr"), np.concatenate([colour, alpha], -1))


def test_float_tiff_is_linear(tmp_path):
    values = np.random.default_rng(13).uniform(0, 2, (4, 3)).astype(np.float32)
    Image.fromarray(values, "F").save(tmp_path / "f.tif")
    expected = np.concatenate([np.repeat(values[..., None], 3, -1), np.ones((4, 3, 1), np.float32)], -1)
    for srgb in (True, False):
        np.testing.assert_array_equal(mr.Texture.from_file(tmp_path / "f.tif", srgb=srgb).level(0), expected)
    np.testing.assert_array_equal(mr.read_image(tmp_path / "f.tif"), expected)


# --- data textures ------------------------------------------------------------------------------

@pytest.mark.parametrize("channels", [1, 4])
def test_16bit_data_texture_is_code_over_65535(tmp_path, channels):
    codes = random_codes((4, 5, channels), np.uint16, seed=14)
    write_png(tmp_path / "d.png", codes)
    assert_decoded(mr.Texture.from_file(tmp_path / "d.png", srgb=False).level(0), expected_linear(codes, srgb=False))


# --- write_image round trips --------------------------------------------------------------------

@pytest.mark.parametrize("channels", [1, 3, 4])
def test_exr_round_trip(tmp_path, channels):
    rgba = linear_rgba((4, 7), seed=15)
    image = {1: rgba[..., 0], 3: rgba[..., :3], 4: rgba}[channels]
    mr.write_image(tmp_path / "r.exr", image)
    colour = rgba[..., [0, 0, 0]] if channels == 1 else rgba[..., :3]
    alpha = rgba[..., 3:] if channels == 4 else np.ones_like(rgba[..., 3:])
    np.testing.assert_array_equal(mr.read_image(tmp_path / "r.exr"), np.concatenate([colour, alpha], -1))


@pytest.mark.parametrize("channels", [3, 4])
def test_png_round_trip_is_srgb8(tmp_path, channels):
    """PNG holds to_srgb8's codes (Pillow reads them back), and read_image decodes exactly those."""
    rgba = linear_rgba((4, 7), seed=16)
    rgba[0, 0] = [0.25, 0.5, 0.125, 0.5]
    image = rgba if channels == 4 else np.clip(rgba[..., :3], 0, 1)
    mr.write_image(tmp_path / "r.png", image)
    codes = np.asarray(Image.open(tmp_path / "r.png"))
    assert codes.shape == (4, 7, channels)
    np.testing.assert_array_equal(codes, mr.to_srgb8(image)[..., :channels])
    assert_decoded(mr.read_image(tmp_path / "r.png"), expected_linear(codes))


# --- corrupt files ------------------------------------------------------------------------------

def _sample_file(tmp_path, suffix):
    codes = random_codes((32, 32, 4), seed=17)
    path = tmp_path / ("whole" + suffix)
    if suffix == ".exr":
        mr.write_image(path, codes.astype(np.float32) / 255)
    else:
        Image.fromarray(codes if suffix in (".png", ".tif", ".tga", ".webp") else codes[..., :3]).save(path)
    return path.read_bytes()


@pytest.mark.parametrize("suffix", [".png", ".jpg", ".tif", ".bmp", ".tga", ".webp", ".exr"])
@pytest.mark.parametrize("keep", [0.5, 0.9])
def test_truncated_file_raises_os_error_naming_it(tmp_path, suffix, keep):
    """A cut-off file is refused; OpenImageIO decodes a truncated JPEG (grey padding) or TIFF
    (zero strips) with only an error recorded, which read_image must not pass off as pixels."""
    data = _sample_file(tmp_path, suffix)
    path = tmp_path / ("cut" + suffix)
    path.write_bytes(data[: int(len(data) * keep)])
    with pytest.raises(OSError, match="cut" + suffix.replace(".", r"\.")) as info:
        mr.read_image(path)
    assert info.value.filename == str(path)
    with pytest.raises(OSError, match="cut"):
        mr.Texture.from_file(path)


# --- linear data from any integer format --------------------------------------------------------

@pytest.mark.parametrize("suffix, options", [
    (".png", {}), (".tga", {}), (".bmp", {}), (".tif", {}), (".webp", {"lossless": True, "exact": True}),
], ids=lambda v: v if isinstance(v, str) else "")
def test_srgb_false_reads_codes_as_linear_data(tmp_path, suffix, options):
    """Normal and roughness maps: code / 255, exactly, in every format (alpha still premultiplies)."""
    codes = random_codes((5, 6, 4 if suffix != ".bmp" else 3), seed=18)
    if suffix == ".webp":
        codes[..., 3] = 255  # OpenImageIO premultiplies WebP in 8 bits: exact only when opaque
    Image.fromarray(codes).save(tmp_path / ("d" + suffix), **options)
    expected = expected_linear(codes, srgb=False)
    assert_decoded(mr.read_image(tmp_path / ("d" + suffix), srgb=False), expected)
    assert_decoded(mr.Texture.from_file(tmp_path / ("d" + suffix), srgb=False).level(0), expected)
