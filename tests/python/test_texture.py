"""Textures and samplers from Python: construction from numpy arrays of every dtype and layout, every
error path, lookups against an independent numpy oracle (nearest and bilinear with every wrap mode),
mip levels, constant textures under every filter, lazily built levels, the cache and image files."""
import dataclasses
import math
import pickle
import subprocess
import sys

import numpy as np
import pytest

import mipraster as mr
from mipraster import _core

FILTERS = ["nearest", "bilinear", "trilinear", "anisotropic", "ewa", "sat"]
WRAPS = ["repeat", "clamp", "mirror", "border"]


@pytest.fixture
def restore_cache_budget():
    budget = mr.texture_cache_stats()["budget_bytes"]
    yield
    mr.set_texture_cache_budget(budget)


def srgb_decode(codes, max_code=255):
    """The sRGB decoding of integer codes, computed as the C++ does (float32 code / max, then the
    exact piecewise formula), through mipraster.srgb_to_linear."""
    return np.asarray(mr.srgb_to_linear(np.float32(codes) / np.float32(max_code)), dtype=np.float32)


def random_texture(rng, height, width):
    """A premultiplied float texture and its texels (exactly as stored)."""
    texels = rng.random((height, width, 4), dtype=np.float32)
    texels[..., :3] *= texels[..., 3:]
    return mr.Texture(texels, premultiplied=True), texels


# --- construction: dtypes and layouts ------------------------------------------------------------

def test_uint8_is_decoded_from_srgb():
    t = mr.Texture(np.full((1, 1, 3), 188, np.uint8))
    level = t.level(0)
    assert level.shape == (1, 1, 4) and level.dtype == np.float32
    assert level[0, 0, 0] == pytest.approx(0.50289, abs=1e-4)
    np.testing.assert_array_equal(level[0, 0], [*srgb_decode([188, 188, 188]), 1.0])
    # and back: the 8-bit encoding of the decoded value is the code
    assert mr.to_srgb8(level)[0, 0].tolist() == [188, 188, 188, 255]
    linear = mr.Texture(np.full((1, 1, 3), 188, np.uint8), srgb=False).level(0)
    np.testing.assert_array_equal(linear[0, 0], [np.float32(188) / np.float32(255)] * 3 + [1.0])


def test_uint8_alpha_is_straight_and_premultiplied():
    codes = np.array([[[188, 0, 255, 128], [255, 255, 255, 0]]], np.uint8)
    level = mr.Texture(codes).level(0)
    a = np.float32(128) / np.float32(255)
    np.testing.assert_array_equal(level[0, 0], [*(srgb_decode([188, 0, 255]) * a), a])
    np.testing.assert_array_equal(level[0, 1], [0, 0, 0, 0])


@pytest.mark.parametrize("shape", [(3, 2), (3, 2, 1), (3, 2, 2), (3, 2, 3), (3, 2, 4)])
def test_channel_layouts(shape):
    rng = np.random.default_rng(1)
    codes = rng.integers(0, 256, shape, dtype=np.uint8)
    level = mr.Texture(codes).level(0)
    assert level.shape == (3, 2, 4)
    c = codes.reshape(3, 2, -1).astype(np.int64)
    channels = c.shape[2]
    if channels <= 2:
        colour = np.repeat(srgb_decode(c[..., :1]), 3, axis=2)
    else:
        colour = srgb_decode(c[..., :3])
    alpha = np.float32(c[..., -1:]) / np.float32(255) if channels in (2, 4) else np.ones((3, 2, 1), np.float32)
    np.testing.assert_array_equal(level[..., :3], colour * alpha)
    np.testing.assert_array_equal(level[..., 3:], alpha)


def test_uint16():
    codes = np.array([[[0, 32768, 65535, 65535], [65535, 1000, 60000, 32768]]], np.uint16)
    level = mr.Texture(codes).level(0)
    a = np.float32(32768) / np.float32(65535)
    np.testing.assert_array_equal(level[0, 0], [*srgb_decode([0, 32768, 65535], 65535), 1.0])
    np.testing.assert_array_equal(level[0, 1], [*(srgb_decode([65535, 1000, 60000], 65535) * a), a])
    linear = mr.Texture(codes, srgb=False).level(0)
    np.testing.assert_array_equal(linear[0, 0, :3], np.float32([0, 32768, 65535]) / np.float32(65535))
    # 16-bit decoding agrees with 8-bit decoding at the shared codes (code·257)
    eight = mr.Texture(np.array([[[10, 188, 250]]], np.uint8)).level(0)
    sixteen = mr.Texture(np.array([[[10, 188, 250]]], np.uint16) * 257).level(0)
    np.testing.assert_allclose(sixteen, eight, rtol=1e-6)
    # grey uint16 (H, W)
    grey = mr.Texture(np.array([[0, 65535]], np.uint16)).level(0)
    np.testing.assert_array_equal(grey[0], [[0, 0, 0, 1], [1, 1, 1, 1]])


@pytest.mark.parametrize("dtype", [np.float16, np.float32, np.float64])
def test_float_texels_are_linear_straight_alpha_by_default(dtype):
    texels = np.array([[[0.5, 0.25, 1.0, 0.5], [2.0, 0.0, 0.125, 1.0]]], dtype)
    level = mr.Texture(texels).level(0)
    np.testing.assert_array_equal(level[0, 0], [0.25, 0.125, 0.5, 0.5])
    np.testing.assert_array_equal(level[0, 1], [2.0, 0.0, 0.125, 1.0])  # HDR colour is kept
    pre = mr.Texture(texels, premultiplied=True).level(0)
    np.testing.assert_array_equal(pre, texels.astype(np.float32))


def test_float_grey_and_rgb_get_alpha_one():
    np.testing.assert_array_equal(mr.Texture(np.array([[0.25, 0.5]])).level(0)[0],
                                  [[0.25, 0.25, 0.25, 1], [0.5, 0.5, 0.5, 1]])
    np.testing.assert_array_equal(mr.Texture([[[0.1, 0.2, 0.3]]]).level(0)[0, 0], np.float32([0.1, 0.2, 0.3, 1]))


@pytest.mark.parametrize("layout", ["strided", "fortran", "list", "negative stride"])
def test_non_contiguous_input_is_copied(layout):
    rng = np.random.default_rng(2)
    base = rng.random((6, 8, 4), dtype=np.float32)
    a = {"strided": base[::2, ::2], "fortran": np.asfortranarray(base), "list": base.tolist(),
         "negative stride": base[::-1, ::-1]}[layout]
    expected = mr.Texture(np.ascontiguousarray(a, dtype=np.float32), premultiplied=True).level(0)
    np.testing.assert_array_equal(mr.Texture(a, premultiplied=True).level(0), expected)
    codes = (base * 255).astype(np.uint8)
    view = codes[:, ::3]
    np.testing.assert_array_equal(mr.Texture(view).level(0), mr.Texture(view.copy()).level(0))


def test_big_endian_uint16_is_accepted():
    codes = np.array([[1, 2, 60000]], dtype=">u2")
    np.testing.assert_array_equal(mr.Texture(codes).level(0), mr.Texture(codes.astype(np.uint16)).level(0))


def test_texels_are_copied_in():
    texels = np.full((2, 2, 4), 0.5, np.float32)
    t = mr.Texture(texels, premultiplied=True)
    texels[:] = 0
    assert (t.level(0) == 0.5).all()
    level = t.level(0)
    level[:] = 7  # a copy, too
    assert (t.level(0) == 0.5).all()


def test_properties_and_repr():
    t = mr.Texture(np.zeros((5, 12), np.uint8), name="grid")
    assert (t.width, t.height, t.level_count, t.built_levels, t.name) == (12, 5, 4, 0, "grid")
    assert repr(t) == "Texture('grid', 12x5, 4 levels, 0 built)"
    assert [t.level(k).shape for k in range(4)] == [(5, 12, 4), (2, 6, 4), (1, 3, 4), (1, 1, 4)]
    assert mr.Texture(np.zeros((1, 1), np.uint8)).level_count == 1
    assert mr.Texture(np.zeros((1, 1024), np.uint8)).level_count == 11


def test_equality_is_identity_of_the_shared_texture():
    a = mr.Texture(np.zeros((2, 2), np.uint8))
    b = mr.Texture(np.zeros((2, 2), np.uint8))
    assert a == a and a != b
    again = mr.Texture._from_core(a._texture)
    assert again == a and hash(again) == hash(a) and len({a, again, b}) == 2


# --- construction errors -----------------------------------------------------------------------

@pytest.mark.parametrize("texels, dtype_text", [
    (np.zeros((2, 2), bool), "bool"),
    (np.zeros((2, 2), np.int64), "int64"),
    (np.zeros((2, 2), np.int8), "int8"),
    (np.zeros((2, 2), np.uint32), "uint32"),
    (np.zeros((2, 2), np.complex64), "complex"),
    (np.array([["a", "b"]]), "str"),
    (np.array([[None, 1]], dtype=object), "object"),
    ([[0, 255], [255, 0]], "int64"),  # a list of ints: codes or linear values? refused
])
def test_wrong_dtype_is_a_type_error(texels, dtype_text):
    with pytest.raises(TypeError, match=rf"texels: expected uint8, uint16 or floating-point values, got dtype .*{dtype_text}"):
        mr.Texture(texels)


@pytest.mark.parametrize("shape, got", [
    ((4,), r"\(4,\)"), ((2, 2, 5), r"\(2, 2, 5\)"), ((2, 2, 0), r"\(2, 2, 0\)"), ((1, 2, 2, 4), r"\(1, 2, 2, 4\)"),
    ((), r"\(\)"),
])
def test_wrong_shape(shape, got):
    with pytest.raises(ValueError, match=rf"texels: expected shape \(H, W\) or \(H, W, 1\) .* got {got}"):
        mr.Texture(np.zeros(shape, np.float32))


def test_ragged_list():
    with pytest.raises(ValueError, match="texels: cannot be read as a rectangular array"):
        mr.Texture([[0.0, 1.0], [0.0]])


@pytest.mark.parametrize("shape", [(0, 4), (4, 0, 3), (0, 0, 4)])
def test_empty_texture(shape):
    with pytest.raises(ValueError, match=r"texels: size \d+x\d+ \(width x height\) is empty; expected at least 1x1"):
        mr.Texture(np.zeros(shape, np.uint8))
    with pytest.raises(ValueError, match="texels: expected shape"):
        mr.Texture([])


def test_too_large():
    # broadcast views: nothing of this size is ever allocated (the size is checked first)
    limit = _core.MAX_TEXTURE_DIMENSION
    assert limit == 65536
    with pytest.raises(ValueError, match=rf"texels: size 1x{limit + 1} \(width x height\) exceeds the limit of {limit} per side"):
        mr.Texture(np.broadcast_to(np.uint8(0), (limit + 1, 1)))
    with pytest.raises(ValueError, match=rf"size {limit + 1}x1 .* exceeds"):
        mr.Texture(np.broadcast_to(np.float32(0), (1, limit + 1, 4)))
    with pytest.raises(ValueError, match=r"texels: 65536x65536 needs 65536 MiB as RGBA float; the limit is 8192 MiB"):
        mr.Texture(np.broadcast_to(np.uint8(0), (limit, limit)))


def test_the_core_checks_sizes_too():
    with pytest.raises(ValueError, match="texels: expected shape"):
        _core.Texture.from_uint8(np.zeros((2, 2, 5), np.uint8))
    with pytest.raises(ValueError, match="texels: width 0 is out of range"):
        _core.Texture.from_float(np.zeros((2, 0, 4), np.float32))


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_texels_are_named(bad):
    texels = np.zeros((3, 4, 4), np.float32)
    texels[1, 2, 3] = bad
    with pytest.raises(ValueError, match=rf"texels\[1, 2, 3\] is {bad}; expected a finite number"):
        mr.Texture(texels)
    grey = np.zeros((3, 4))
    grey[2, 0] = bad
    with pytest.raises(ValueError, match=r"texels\[2, 0\] \(row 2, column 0\)"):
        mr.Texture(grey)


def test_float64_beyond_float32():
    with pytest.raises(ValueError, match=r"texels\[0, 1\] = 1e\+300 does not fit in float32"):
        mr.Texture(np.array([[0.0, 1e300]]))


@pytest.mark.parametrize("texel, message", [
    # each value finite and within range, the colour times alpha past ±1e32 or float's range
    ((1e20, 1e20, 1e20, 1e20),
     r"channel 0 is 1e\+20, times its alpha 1e\+20 beyond ±1e\+32 \(texels are premultiplied\)"),
    ((0, -1e17, 0, 1e16), r"channel 1 is -1e\+17, times its alpha 1e\+16 beyond ±1e\+32"),
    # a value itself past the range: named as given, not as its product with alpha
    ((3e38, 0, 0, 2), r"channel 0 is 3e\+38; texel values must lie within ±1e\+32"),
])
def test_premultiplying_into_overflow_is_refused_by_the_core(texel, message):
    # (the C++ check saw only the products, and called an overflowed one "not finite")
    with pytest.raises(ValueError, match=r"texture 'big': texel \(0, 0\) " + message):
        mr.Texture(np.array([[texel]], np.float32), name="big")


def test_texels_beyond_the_filters_range_are_refused():
    # A checker of ±1.7e38 gave infinity from the anisotropic and EWA sums (and NaN pixels):
    # texel values are limited to ±1e32, and at that limit every filter's result stays finite
    # and within the texels' range.
    with pytest.raises(ValueError, match=r"texture 'big': texel \(1, 0\) channel 2 is 2e\+32; texel values must "
                                         r"lie within ±1e\+32"):
        mr.Texture(np.array([[[0, 0, 0, 1], [0, 0, 2e32, 1]]], np.float32), name="big")
    limit = np.float32(1e32)
    texels = np.ones((16, 16, 4), np.float32)
    texels[..., :3] = limit
    texels[(np.add.outer(np.arange(16), np.arange(16)) % 2) == 0, :3] = -limit
    texture = mr.Texture(texels)
    rng = np.random.default_rng(5)
    uv = rng.uniform(-2, 2, (400, 2))
    for name in ("nearest", "bilinear", "trilinear", "anisotropic", "ewa", "sat"):
        for scale in (0.0, 0.01, 0.3, 3.0, 100.0):
            d = rng.uniform(-scale, scale, (400, 4))
            out = texture.sample(uv, duv_dx=d[:, :2], duv_dy=d[:, 2:], sampler=name)
            assert np.isfinite(out).all(), (name, scale)
            assert np.abs(out[:, :3]).max() <= limit * (1 + 1e-6), (name, scale)


def test_flag_and_name_errors():
    codes = np.zeros((2, 2, 4), np.uint8)
    floats = np.zeros((2, 2, 4), np.float32)
    with pytest.raises(ValueError, match="srgb: float texels are linear"):
        mr.Texture(floats, srgb=True)
    mr.Texture(floats, srgb=False)  # fine: they are linear
    with pytest.raises(ValueError, match="premultiplied: uint8 texels are straight alpha"):
        mr.Texture(codes, premultiplied=True)
    with pytest.raises(TypeError, match="srgb: expected True or False, got str 'no'"):
        mr.Texture(codes, srgb="no")
    with pytest.raises(TypeError, match="premultiplied: expected True or False, got int 1"):
        mr.Texture(floats, premultiplied=1)
    with pytest.raises(TypeError, match="name: expected str, got int"):
        mr.Texture(codes, name=3)


def test_level_errors():
    t = mr.Texture(np.zeros((4, 4), np.uint8))
    for k in (-1, 3, 100):
        with pytest.raises(ValueError, match=rf"k: level {k} is out of range; expected 0 <= k < 3 \(the level count\)"):
            t.level(k)
    with pytest.raises(TypeError, match="k: expected an integer, got float 1.0"):
        t.level(1.0)
    assert t.level(np.int64(2)).shape == (1, 1, 4)
    with pytest.raises(ValueError, match="k: level 3 is out of range"):
        t._texture.level(3)  # the core checks too


def test_core_texture_has_no_constructor():
    with pytest.raises(TypeError):
        _core.Texture()


# --- Sampler -------------------------------------------------------------------------------------

def test_sampler_defaults_and_normalisation():
    s = mr.Sampler()
    assert (s.filter, s.wrap, s.border_color, s.max_anisotropy, s.lod_bias, s.min_lod, s.max_lod) == \
        ("trilinear", ("repeat", "repeat"), (0.0, 0.0, 0.0, 0.0), 16.0, 0.0, 0.0, 1000.0)
    s = mr.Sampler("nearest", wrap="clamp", border_color=(1, 0, 0), max_anisotropy=4, lod_bias=np.float32(0.5))
    assert s.wrap == ("clamp", "clamp") and s.border_color == (1.0, 0.0, 0.0, 1.0)
    assert isinstance(s.max_anisotropy, float) and s.lod_bias == 0.5
    assert mr.Sampler(wrap=["mirror", "border"]).wrap == ("mirror", "border")
    assert s == mr.Sampler("nearest", wrap=("clamp", "clamp"), border_color=(1, 0, 0, 1), max_anisotropy=4.0,
                           lod_bias=0.5)
    assert hash(s) == hash(dataclasses.replace(s))
    assert "filter='nearest'" in repr(s) and "_sampler" not in repr(s)


def test_sampler_is_frozen_and_pickles():
    s = mr.Sampler("ewa", wrap=("clamp", "mirror"), border_color=(0.5, 0.5, 0.5, 0.5), min_filter="nearest")
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.filter = "nearest"
    t = pickle.loads(pickle.dumps(s))
    assert t == s and repr(t._sampler) == repr(s._sampler)
    assert dataclasses.replace(s, wrap="repeat").wrap == ("repeat", "repeat")
    with pytest.raises(ValueError, match="wrap: unknown value 'tile'"):
        dataclasses.replace(s, wrap="tile")  # replace validates too


@pytest.mark.parametrize("name, core", [
    ("nearest", ("nearest", "nearest", "none", "isotropic")),
    ("bilinear", ("linear", "linear", "none", "isotropic")),
    ("trilinear", ("linear", "linear", "linear", "isotropic")),
    ("anisotropic", ("linear", "linear", "linear", "anisotropic")),
    ("ewa", ("linear", "linear", "linear", "ewa")),
    ("sat", ("linear", "linear", "linear", "sat")),
])
def test_sampler_presets(name, core):
    c = mr.Sampler(name)._sampler
    assert (c.mag_filter.name, c.min_filter.name, c.mip_filter.name, c.footprint.name) == core
    assert mr.Sampler(name).uses_mip_levels == (name not in ("nearest", "bilinear"))
    assert mr.Sampler(name).needs_derivatives == (name not in ("nearest", "bilinear"))


def test_sampler_explicit_filters_override_the_preset():
    # glTF minFilter LINEAR_MIPMAP_NEAREST with magFilter NEAREST
    c = mr.Sampler(mag_filter="nearest", min_filter="linear", mip_filter="nearest")._sampler
    assert (c.mag_filter.name, c.min_filter.name, c.mip_filter.name) == ("nearest", "linear", "nearest")
    assert mr.Sampler("bilinear", mag_filter="nearest").needs_derivatives  # mag and min differ: λ matters
    c = mr.Sampler("anisotropic", mip_filter="none")._sampler
    assert (c.footprint.name, c.mip_filter.name) == ("anisotropic", "none")


@pytest.mark.parametrize("kwargs", [
    dict(filter="trilinear", wrap=("clamp", "mirror"), border_color=(0.25, 0.5, 0.75, 1.0), max_anisotropy=8,
         lod_bias=-1.5, min_lod=0.5, max_lod=3),
    dict(filter="nearest"), dict(filter="bilinear", mag_filter="nearest"), dict(filter="sat", mip_filter="nearest"),
    dict(mag_filter="nearest", min_filter="nearest", mip_filter="linear"), dict(filter="ewa", min_filter="nearest"),
])
def test_sampler_from_core_round_trip(kwargs):
    s = mr.Sampler(**kwargs)
    back = mr.Sampler._from_core(s._sampler)
    assert repr(back._sampler) == repr(s._sampler)
    assert (back.wrap, back.border_color, back.lod_bias, back.min_lod, back.max_lod) == \
        (s.wrap, s.border_color, s.lod_bias, s.min_lod, s.max_lod)
    assert mr.Sampler._from_core(_core.Sampler()) == mr.Sampler()


@pytest.mark.parametrize("kwargs, error, message", [
    (dict(filter="cubic"), ValueError,
     "filter: unknown value 'cubic'; expected one of 'nearest', 'bilinear', 'trilinear', 'anisotropic', 'ewa', 'sat'"),
    (dict(filter=None), TypeError, "filter: expected one of .* got NoneType None"),
    (dict(mag_filter="bilinear"), ValueError, "mag_filter: unknown value 'bilinear'; expected one of 'nearest', 'linear'"),
    (dict(min_filter=1), TypeError, "min_filter: expected one of 'nearest', 'linear', got int 1"),
    (dict(mip_filter="trilinear"), ValueError, "mip_filter: unknown value 'trilinear'; expected one of 'none', 'nearest', 'linear'"),
    (dict(max_anisotropy=0.5), ValueError, "max_anisotropy: expected a number >= 1, got 0.5"),
    (dict(max_anisotropy="16"), TypeError, "max_anisotropy: expected a number, got str '16'"),
    (dict(max_anisotropy=True), TypeError, "max_anisotropy: expected a number, got bool True"),
    (dict(max_anisotropy=math.nan), ValueError, "max_anisotropy: expected a finite number, got nan"),
    (dict(max_anisotropy=1e39), ValueError, "max_anisotropy: 1e\\+39 does not fit in float32"),
    (dict(wrap="tile"), ValueError, "wrap: unknown value 'tile'; expected one of 'repeat', 'clamp', 'mirror', 'border'"),
    (dict(wrap=("repeat", "tile")), ValueError, r"wrap\[1\]: unknown value 'tile'"),
    (dict(wrap=(None, "repeat")), TypeError, r"wrap\[0\]: expected one of"),
    (dict(wrap=("repeat",)), TypeError, r"wrap: expected a mode name or a \(u, v\) pair"),
    (dict(wrap=3), TypeError, "wrap: expected a mode name or a .* got int 3"),
    (dict(border_color=(1, 0)), ValueError, r"border_color: expected shape \(3,\) or \(4,\), got \(2,\)"),
    (dict(border_color=(0, 0, math.inf, 1)), ValueError, r"border_color\[2\] is inf; expected a finite number"),
    (dict(border_color="red"), TypeError, "border_color: expected float or integer numbers"),
    (dict(border_color=(0, 0, 1e39)), ValueError, r"border_color\[2\] = 1e\+39 does not fit in float32"),
    (dict(lod_bias=math.inf), ValueError, "lod_bias: expected a finite number, got inf"),
    (dict(min_lod=-math.inf), ValueError, "min_lod: expected a finite number, got -inf"),
    (dict(max_lod=None), TypeError, "max_lod: expected a number, got NoneType None"),
    (dict(min_lod=3, max_lod=2), ValueError, r"min_lod \(3.0\) exceeds max_lod \(2.0\)"),
])
def test_sampler_errors(kwargs, error, message):
    with pytest.raises(error, match=message):
        mr.Sampler(**kwargs)


def test_core_sampler_validates():
    s = _core.Sampler()
    s.max_anisotropy = 0.5
    with pytest.raises(ValueError, match="sampler.max_anisotropy is 0.500000; expected >= 1"):
        s.validate()
    t = mr.Texture(np.zeros((2, 2), np.uint8))
    uv = np.zeros((1, 2), np.float32)
    with pytest.raises(ValueError, match="sampler.max_anisotropy"):
        _core.sample_texture(t._texture, s, uv, uv, uv)
    with pytest.raises(ValueError, match="unknown name 'cubic'"):
        _core.Sampler.from_filter_name("cubic")


# --- lookups: argument handling ------------------------------------------------------------------

def test_sample_shapes_and_broadcasting():
    rng = np.random.default_rng(3)
    t, _ = random_texture(rng, 8, 8)
    uv = rng.random((5, 3, 2))
    out = t.sample(uv)
    assert out.shape == (5, 3, 4) and out.dtype == np.float32
    assert t.sample([0.5, 0.5]).shape == (4,)
    assert t.sample(np.zeros((0, 2))).shape == (0, 4)
    assert t.sample(np.zeros((2, 0, 2))).shape == (2, 0, 4)
    # derivatives broadcast: one pair for all, one per column, one per point give the same
    d = np.array([0.3, 0.05])
    full = t.sample(uv, np.broadcast_to(d, uv.shape), np.broadcast_to(d[::-1], uv.shape))
    np.testing.assert_array_equal(t.sample(uv, d, d[::-1]), full)
    np.testing.assert_array_equal(t.sample(uv, np.tile(d, (3, 1)), np.tile(d[::-1], (3, 1))), full)
    # uv broadcast against per-point derivatives
    dx = rng.random((4, 2)) * 0.5
    np.testing.assert_array_equal(t.sample([0.2, 0.7], dx, dx),
                                  t.sample(np.tile([0.2, 0.7], (4, 1)), dx, dx))
    # integer uv is fine, float64 uv is computed as float32
    np.testing.assert_array_equal(t.sample([[0, 1]]), t.sample(np.float32([[0, 1]])))
    np.testing.assert_array_equal(t.sample(uv), t.sample(uv.astype(np.float32)))
    # a large call (threads) gives the same as small ones
    big = rng.random((50000, 2)) * 4 - 2
    bd = rng.random((50000, 2)) * 0.2
    ref = np.concatenate([t.sample(big[i:i + 5000], bd[i:i + 5000], bd[i:i + 5000, ::-1])
                          for i in range(0, 50000, 5000)])
    np.testing.assert_array_equal(t.sample(big, bd, bd[:, ::-1]), ref)


def test_sample_argument_errors():
    t = mr.Texture(np.zeros((2, 2), np.uint8))
    with pytest.raises(ValueError, match=r"uv: expected shape \(\.\.\., 2\) \(u, v pairs\), got \(3,\)"):
        t.sample([0.1, 0.2, 0.3])
    with pytest.raises(ValueError, match=r"uv: expected shape \(\.\.\., 2\) \(u, v pairs\), got \(4, 3\)"):
        t.sample(np.zeros((4, 3)))
    with pytest.raises(ValueError, match=r"uv: expected shape \(\.\.\., 2\) \(u, v pairs\), got \(\)"):
        t.sample(0.5)
    with pytest.raises(TypeError, match="uv: expected float or integer numbers, got dtype <U1"):
        t.sample(["a", "b"])
    with pytest.raises(TypeError, match="uv: expected float or integer numbers, got dtype bool"):
        t.sample([True, False])
    with pytest.raises(ValueError, match=r"duv_dx: expected shape \(\.\.\., 2\)"):
        t.sample(np.zeros((4, 2)), np.zeros(3))
    with pytest.raises(ValueError, match=r"uv, duv_dx, duv_dy: shapes do not broadcast: uv \(4, 2\), duv_dx \(3, 2\), duv_dy \(2,\)"):
        t.sample(np.zeros((4, 2)), np.zeros((3, 2)))
    with pytest.raises(TypeError, match="sampler: expected a mipraster.Sampler or a filter name, got dict"):
        t.sample([0, 0], sampler={"filter": "nearest"})
    with pytest.raises(ValueError, match="filter: unknown value 'cubic'"):
        t.sample([0, 0], sampler="cubic")
    with pytest.raises(ValueError, match=r"uv: expected shape \(N, 2\)"):
        _core.sample_texture(t._texture, _core.Sampler(), np.zeros((3, 3), np.float32), np.zeros((1, 2), np.float32),
                             np.zeros((1, 2), np.float32))
    with pytest.raises(ValueError, match=r"duv_dy: expected shape \(3, 2\) or \(1, 2\), got \(2, 2\)"):
        _core.sample_texture(t._texture, _core.Sampler(), np.zeros((3, 2), np.float32), np.zeros((1, 2), np.float32),
                             np.zeros((2, 2), np.float32))


@pytest.mark.parametrize("name", FILTERS)
@pytest.mark.parametrize("wrap", WRAPS)
def test_non_finite_uv_returns_the_border_colour(name, wrap):
    rng = np.random.default_rng(4)
    t, _ = random_texture(rng, 5, 7)
    border = (0.125, 0.25, 0.375, 0.5)
    s = mr.Sampler(name, wrap=wrap, border_color=border)
    uv = np.array([[np.nan, 0.5], [0.5, np.inf], [-np.inf, -np.inf], [np.nan, np.nan], [1e39, 0.5]])
    d = np.array([[0.1, 0.0], [0.0, 10.0], [np.inf, 0], [np.nan, 0.2], [0.01, 0.01]])
    out = t.sample(uv, d, d[:, ::-1], sampler=s)  # 1e39 is beyond float32: inf, so the border too
    np.testing.assert_array_equal(out, np.tile(np.float32(border), (5, 1)))


# --- lookups against a numpy oracle ----------------------------------------------------------------

def wrap_index(i, n, mode):
    """Texel index along one axis after wrapping; -1 for the border."""
    if mode == "repeat":
        return np.mod(i, n)
    if mode == "mirror":
        m = np.mod(i, 2 * n)
        return np.where(m < n, m, 2 * n - 1 - m)
    if mode == "clamp":
        return np.clip(i, 0, n - 1)
    return np.where((i < 0) | (i >= n), -1, i)


def fetch(texels, i, j, wrap, border):
    h, w = texels.shape[:2]
    x, y = wrap_index(i, w, wrap[0]), wrap_index(j, h, wrap[1])
    inside = (x >= 0) & (y >= 0)
    out = texels[np.where(inside, y, 0), np.where(inside, x, 0)].astype(np.float64)
    out[~inside] = border
    return out


def oracle_nearest(texels, uv, wrap, border):
    h, w = texels.shape[:2]
    u, v = uv[:, 0].astype(np.float64), uv[:, 1].astype(np.float64)
    return fetch(texels, np.floor(u * w).astype(np.int64), np.floor(v * h).astype(np.int64), wrap, border)


def oracle_bilinear(texels, uv, wrap, border):
    h, w = texels.shape[:2]
    x = uv[:, 0].astype(np.float64) * w - 0.5
    y = uv[:, 1].astype(np.float64) * h - 0.5
    i, j = np.floor(x).astype(np.int64), np.floor(y).astype(np.int64)
    ax, ay = (x - i)[:, None], (y - j)[:, None]
    a, b = fetch(texels, i, j, wrap, border), fetch(texels, i + 1, j, wrap, border)
    c, d = fetch(texels, i, j + 1, wrap, border), fetch(texels, i + 1, j + 1, wrap, border)
    top, bottom = a * (1 - ax) + b * ax, c * (1 - ax) + d * ax
    return top * (1 - ay) + bottom * ay


def random_uv(rng, n):
    uv = (rng.random((n, 2)) * 7 - 3.5).astype(np.float32)
    # texel edges and centres exactly, and the unit square's edges
    uv[:40] = np.float32(rng.integers(-14, 28, (40, 2))) / np.float32(8)
    uv[40:44] = [[0, 0], [1, 1], [0, 1], [1, 0]]
    return uv


ALL_WRAPS = [(a, b) for a in WRAPS for b in WRAPS if a == b] + [("clamp", "mirror"), ("border", "repeat")]


@pytest.mark.parametrize("wrap", ALL_WRAPS, ids=lambda w: "-".join(w))
@pytest.mark.parametrize("size", [(8, 4), (5, 7)], ids=["8x4", "5x7"])
def test_nearest_matches_the_oracle(wrap, size):
    rng = np.random.default_rng(5)
    t, texels = random_texture(rng, *size)
    uv = random_uv(rng, 2000)
    border = (0.5, 0.0, 0.25, 0.75)
    out = t.sample(uv, sampler=mr.Sampler("nearest", wrap=wrap, border_color=border))
    np.testing.assert_array_equal(out, oracle_nearest(texels, uv, wrap, border).astype(np.float32))
    # nearest ignores derivatives (no mip levels) and builds nothing
    d = rng.random((2000, 2)) * 3
    np.testing.assert_array_equal(t.sample(uv, d, d, sampler=mr.Sampler("nearest", wrap=wrap, border_color=border)),
                                  out)
    assert t.built_levels == 0


@pytest.mark.parametrize("wrap", ALL_WRAPS, ids=lambda w: "-".join(w))
@pytest.mark.parametrize("size", [(8, 4), (5, 7)], ids=["8x4", "5x7"])
def test_bilinear_matches_the_oracle(wrap, size):
    rng = np.random.default_rng(6)
    t, texels = random_texture(rng, *size)
    uv = random_uv(rng, 2000)
    border = (0.5, 0.0, 0.25, 0.75)
    s = mr.Sampler("bilinear", wrap=wrap, border_color=border)
    np.testing.assert_allclose(t.sample(uv, sampler=s), oracle_bilinear(texels, uv, wrap, border), rtol=0, atol=1e-6)
    # trilinear at zero derivatives magnifies: bilinear on level 0
    tri = mr.Sampler("trilinear", wrap=wrap, border_color=border)
    np.testing.assert_array_equal(t.sample(uv, sampler=tri), t.sample(uv, sampler=s))
    # mag_filter="nearest" makes it the nearest filter
    np.testing.assert_array_equal(t.sample(uv, sampler=dataclasses.replace(tri, mag_filter="nearest")),
                                  oracle_nearest(texels, uv, wrap, border).astype(np.float32))


def test_bilinear_at_texel_centres_returns_the_texels():
    rng = np.random.default_rng(7)
    t, texels = random_texture(rng, 4, 16)  # power-of-two sizes: the centres are exact in float32
    j, i = np.mgrid[0:4, 0:16]
    uv = np.stack([(i + 0.5) / 16, (j + 0.5) / 4], axis=-1)
    np.testing.assert_array_equal(t.sample(uv, sampler="bilinear"), texels)


# --- mip levels and level of detail ---------------------------------------------------------------

def test_levels_are_box_filtered():
    rng = np.random.default_rng(8)
    t, texels = random_texture(rng, 6, 8)
    l1 = texels.astype(np.float64).reshape(3, 2, 4, 2, 4).mean(axis=(1, 3))
    np.testing.assert_allclose(t.level(1), l1, rtol=0, atol=1e-6)
    # 3 rows → 1: every row weighs 1/3; 4 columns → 2: pairs
    l2 = l1.reshape(1, 3, 2, 2, 4).mean(axis=(1, 3))
    np.testing.assert_allclose(t.level(2), l2, rtol=0, atol=1e-6)
    np.testing.assert_allclose(t.level(3), l2.mean(axis=(0, 1), keepdims=True), rtol=0, atol=1e-6)
    assert t.level_count == 4
    # odd widths: 5 → 2, each output cell 2.5 texels wide, the middle texel split
    u, u_texels = random_texture(rng, 1, 5)
    x = u_texels[0].astype(np.float64)
    expected = np.stack([(x[0] + x[1] + 0.5 * x[2]) / 2.5, (0.5 * x[2] + x[3] + x[4]) / 2.5])
    np.testing.assert_allclose(u.level(1)[0], expected, rtol=0, atol=1e-6)
    # the mean is kept down the chain
    np.testing.assert_allclose(u.level(2)[0, 0], x.mean(axis=0), rtol=0, atol=1e-6)


def test_trilinear_checker_minified_to_one_texel_is_srgb_188():
    checker = np.array([[0, 255], [255, 0]], np.uint8)  # black and white, sRGB
    t = mr.Texture(checker)
    assert t.level_count == 2
    np.testing.assert_array_equal(t.level(1), [[[0.5, 0.5, 0.5, 1.0]]])
    # one pixel covers the whole texture: ρ = 2 texels, λ = 1, the 1×1 level
    dx, dy = [1.0, 0.0], [0.0, 1.0]
    assert t.lod(dx, dy) == 1.0
    rng = np.random.default_rng(9)
    uv = rng.random((100, 2))
    out = t.sample(uv, dx, dy, sampler="trilinear")
    np.testing.assert_array_equal(out, np.tile(np.float32([0.5, 0.5, 0.5, 1.0]), (100, 1)))
    assert (mr.to_srgb8(out[None])[0] == [188, 188, 188, 255]).all()
    # halfway (λ = 0.5) is the mean of level 0's bilinear value and 0.5
    half = t.sample([0.25, 0.25], [0.5 * 2 ** 0.5, 0], [0, 0.5 * 2 ** 0.5])
    assert t.lod([0.5 * 2 ** 0.5, 0], [0, 0.5 * 2 ** 0.5]) == pytest.approx(0.5)
    np.testing.assert_allclose(half[:3], 0.25, atol=1e-6)  # level 0 at a texel centre: black
    # the nearest mip filter picks level 1 from λ > 1/2
    s = mr.Sampler(mip_filter="nearest")
    np.testing.assert_array_equal(t.sample([0.25, 0.25], [0.75, 0], [0, 0.75], sampler=s), [0.5, 0.5, 0.5, 1])
    np.testing.assert_array_equal(t.sample([0.25, 0.25], [0.6, 0], [0, 0.6], sampler=s)[:3], [0, 0, 0])


def test_lod():
    t = mr.Texture(np.zeros((64, 256), np.uint8))
    assert t.level_count == 9
    lod = t.lod([[1 / 256, 0], [4 / 256, 0], [1, 0], [1e-9, 0], [np.inf, 0], [np.nan, 0]], [0, 2 / 64])
    np.testing.assert_allclose(lod, [1, 2, 8, 1, 8, 8])
    np.testing.assert_allclose(t.lod([1 / 256, 0], [0, 0]), 0)
    assert t.lod([1 / 256, 0], [0, 0], sampler=mr.Sampler(lod_bias=2.5)) == 2.5
    assert t.lod([1 / 256, 0], [0, 0], sampler=mr.Sampler(min_lod=3)) == 3
    assert t.lod([1, 0], [0, 0], sampler=mr.Sampler(max_lod=1.5)) == 1.5
    # anisotropic: the footprint per probe (Pmax / N): 16 texels long, 1 wide → 16 probes at λ = 0
    assert t.lod([16 / 256, 0], [0, 1 / 64], sampler="anisotropic") == 0
    assert t.lod([16 / 256, 0], [0, 1 / 64], sampler=mr.Sampler("anisotropic", max_anisotropy=4)) == 2
    assert t.lod(np.zeros((3, 5, 2)), [0, 0]).shape == (3, 5)


def constant_texture(value, shape=(13, 7)):
    return mr.Texture(np.broadcast_to(np.float32(value), shape + (4,)), premultiplied=True)


def random_derivatives(rng, n):
    """Random signs and magnitudes from 1e-4 to 1e2 uv units per pixel, with zeros, infinities and NaNs."""
    d = rng.choice([-1, 1], (n, 2)) * 10 ** rng.uniform(-4, 2, (n, 2))
    d[rng.random((n, 2)) < 0.05] = 0
    d[rng.random((n, 2)) < 0.03] = np.inf
    d[rng.random((n, 2)) < 0.03] = -np.inf
    d[rng.random((n, 2)) < 0.03] = np.nan
    return d


@pytest.mark.parametrize("name", FILTERS)
@pytest.mark.parametrize("wrap", WRAPS)
def test_constant_textures_are_returned_exactly(name, wrap):
    rng = np.random.default_rng(10)
    value = np.float32([0.1, 0.7, 0.3, 0.9])
    t = constant_texture(value)
    n = 3000
    uv = (rng.random((n, 2)) * 10 - 5).astype(np.float32)
    s = mr.Sampler(name, wrap=wrap, border_color=tuple(value.tolist()), max_anisotropy=8)
    out = t.sample(uv, random_derivatives(rng, n), random_derivatives(rng, n), sampler=s)
    np.testing.assert_array_equal(out, np.tile(value, (n, 1)))
    # and with LOD controls moved around
    s = mr.Sampler(name, wrap=wrap, border_color=tuple(value.tolist()), lod_bias=1.5, min_lod=0.5, max_lod=2.0)
    out = t.sample(uv, random_derivatives(rng, n), random_derivatives(rng, n), sampler=s)
    np.testing.assert_array_equal(out, np.tile(value, (n, 1)))


@pytest.mark.parametrize("name", [f for f in FILTERS if f != "ewa"])
def test_huge_finite_derivatives(name):
    value = np.float32([0.25, 0.5, 0.75, 1.0])
    t = constant_texture(value, (5, 3))
    d = np.array([[1e3, 0.1], [1e6, 0], [1e10, 1e10], [1e30, -1e30], [3e38, 1]])
    out = t.sample([[0.3, 0.7]] * 5, d, d[:, ::-1], sampler=name)
    np.testing.assert_array_equal(out, np.tile(value, (5, 1)))


def test_ewa_with_huge_finite_derivatives_returns_promptly():
    """EWA bounds its footprint (beyond it, a bilinear lookup on the level stands in). Run in a child
    process so that a regression fails the test instead of hanging the suite."""
    code = (
        "import numpy as np, mipraster as mr\n"
        "t = mr.Texture(np.full((5, 3, 4), 0.5, np.float32), premultiplied=True)\n"
        "d = np.array([[1e6, 0.1], [1e10, 1e10], [1e30, -1e30]])\n"
        "print(t.sample([[0.3, 0.7]] * 3, d, d[:, ::-1], sampler='ewa').tolist())\n"
        "s = mr.Sampler('ewa', max_lod=1)\n"  # footprints of the whole texture, on level 1
        "big = mr.Texture(np.full((1024, 1024), 0.5, np.float32))\n"
        "assert big.sample([[0.3, 0.7]] * 3, d, d[:, ::-1], sampler=s).tolist() == [[0.5, 0.5, 0.5, 1.0]] * 3\n"
    )
    try:
        r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=8)
    except subprocess.TimeoutExpired:
        pytest.fail("EWA lookups with huge derivatives did not finish within 8 s")
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == str([[0.5] * 4] * 3)


def test_minification_averages():
    """Far minified, every filter that uses mip levels (or the table) gives the texture's mean."""
    rng = np.random.default_rng(11)
    t, texels = random_texture(rng, 16, 16)
    mean = texels.astype(np.float64).mean(axis=(0, 1))
    uv = rng.random((50, 2))
    for name in ["trilinear", "anisotropic", "ewa", "sat"]:
        out = t.sample(uv, [1.0, 0.0], [0.0, 1.0], sampler=name)
        np.testing.assert_allclose(out, np.tile(mean, (50, 1)), atol=2e-3 if name == "ewa" else 1e-5, err_msg=name)
    # the summed-area table over exactly the whole texture (a box of 16×16 texels) is the exact mean
    sat = t.sample([0.5, 0.5], [1.0, 0.0], [0.0, 1.0], sampler="sat")
    np.testing.assert_allclose(sat, mean, atol=1e-6)


# --- lazily built levels and the cache -----------------------------------------------------------

def test_levels_are_built_lazily():
    rng = np.random.default_rng(12)
    t, _ = random_texture(rng, 64, 64)
    uv = rng.random((100, 2))
    big = np.full((100, 2), 0.5)
    assert t.built_levels == 0 and t.level_count == 7
    for name in ("nearest", "bilinear"):  # level 0 only, whatever the derivatives
        t.sample(uv, big, big, sampler=name)
    t.sample(uv, sampler="trilinear")  # zero derivatives: magnification
    t.sample(uv, [1 / 128, 0], [0, 1 / 128], sampler="trilinear")  # λ = -1
    assert t.built_levels == 0 and not t._texture.has_summed_area_table
    before = mr.texture_cache_stats()
    t.sample(uv, [4 / 64, 0], [0, 4 / 64], sampler="trilinear")  # λ = 2 exactly: levels 1 and 2
    assert t.built_levels == 2
    assert mr.texture_cache_stats()["levels_built"] - before["levels_built"] == 2
    assert t._texture.derived_bytes == (32 * 32 + 16 * 16) * 16
    t.level(5)
    assert t.built_levels == 5
    t.sample(uv, [0.1, 0], [0, 0.1], sampler="sat")
    assert t._texture.has_summed_area_table
    assert mr.texture_cache_stats()["tables_built"] - before["tables_built"] == 1


def test_cache_stats_budget_and_clear(restore_cache_budget):
    stats = mr.texture_cache_stats()
    assert set(stats) == {"budget_bytes", "derived_bytes", "levels_built", "tables_built", "evictions",
                          "keyed_textures"}
    assert all(isinstance(v, int) for v in stats.values())
    rng = np.random.default_rng(13)
    a, _ = random_texture(rng, 32, 32)
    b, _ = random_texture(rng, 32, 32)
    uv = rng.random((200, 2))
    d = [1.0, 0.0], [0.0, 0.05]  # λ = 5: every level
    first = a.sample(uv, *d)
    assert a.built_levels == 5
    mr.set_texture_cache_budget(0)
    assert mr.texture_cache_stats()["budget_bytes"] == 0
    assert a.built_levels == 0  # setting the budget evicts what is not in use
    evictions = mr.texture_cache_stats()["evictions"]
    a.sample(uv, *d)  # rebuilt while the lookup pins it, dropped as soon as it is released
    assert a.built_levels == 0
    assert mr.texture_cache_stats()["evictions"] == evictions + 1
    b.sample(uv, *d)
    assert b.built_levels == 0 and mr.texture_cache_stats()["evictions"] == evictions + 2
    np.testing.assert_array_equal(a.sample(uv, *d), first)  # rebuilt identically
    mr.set_texture_cache_budget(1 << 30)
    a.sample(uv, *d)
    b.sample(uv, *d)
    assert a.built_levels == 5 and b.built_levels == 5
    mr.clear_texture_cache()
    assert a.built_levels == 0 and b.built_levels == 0
    assert mr.texture_cache_stats()["budget_bytes"] == 1 << 30  # clearing keeps the budget
    mr.set_texture_cache_budget(2**70)  # more than size_t: saturates
    assert mr.texture_cache_stats()["budget_bytes"] == 2**64 - 1


def test_cache_budget_errors():
    with pytest.raises(ValueError, match="budget_bytes: expected a number of bytes >= 0, got -1"):
        mr.set_texture_cache_budget(-1)
    with pytest.raises(TypeError, match="budget_bytes: expected an integer, got str '1'"):
        mr.set_texture_cache_budget("1")
    with pytest.raises(TypeError, match="budget_bytes: expected an integer, got float 1.5"):
        mr.set_texture_cache_budget(1.5)
    with pytest.raises(TypeError, match="budget_bytes: expected an integer, got bool True"):
        mr.set_texture_cache_budget(True)


def test_dropped_textures_release_their_bytes():
    mr.clear_texture_cache()
    base = mr.texture_cache_stats()["derived_bytes"]
    t = constant_texture(0.5, (64, 64))
    t.level(6)
    assert mr.texture_cache_stats()["derived_bytes"] - base == t._texture.derived_bytes > 0
    del t
    assert mr.texture_cache_stats()["derived_bytes"] == base


# --- image files ---------------------------------------------------------------------------------

def test_from_file_png(tmp_path):
    pil = pytest.importorskip("PIL.Image")
    rng = np.random.default_rng(14)
    codes = rng.integers(0, 256, (5, 6, 4), dtype=np.uint8)
    codes[0, 0] = [188, 188, 188, 255]
    codes[0, 1, 3] = 0
    path = tmp_path / "rgba.png"
    pil.fromarray(codes, "RGBA").save(path)
    t = mr.Texture.from_file(path)
    assert (t.width, t.height, t.name) == (6, 5, str(path))
    np.testing.assert_array_equal(t.level(0), mr.Texture(codes).level(0))
    assert t.level(0)[0, 0, 0] == pytest.approx(0.50289, abs=1e-4)
    # data textures: the codes as linear values (read_image's decoding undone, within rounding)
    data = mr.Texture.from_file(str(path), srgb=False, name="data")
    assert data.name == "data"
    np.testing.assert_allclose(data.level(0), mr.Texture(codes, srgb=False).level(0), rtol=0, atol=2e-6)
    # grey
    pil.fromarray(codes[..., 0], "L").save(tmp_path / "grey.png")
    np.testing.assert_array_equal(mr.Texture.from_file(tmp_path / "grey.png").level(0),
                                  mr.Texture(codes[..., 0]).level(0))


def test_from_file_tiff(tmp_path):
    pil = pytest.importorskip("PIL.Image")
    rng = np.random.default_rng(16)
    codes = rng.integers(0, 256, (3, 5, 3), dtype=np.uint8)
    pil.fromarray(codes, "RGB").save(tmp_path / "rgb.tif")
    data = mr.Texture.from_file(tmp_path / "rgb.tif", srgb=False)
    np.testing.assert_allclose(data.level(0), mr.Texture(codes, srgb=False).level(0), rtol=0, atol=2e-6)
    values = rng.random((3, 5), dtype=np.float32)
    pil.fromarray(values, "F").save(tmp_path / "float.tif")  # SampleFormat 3 (IEEE float)
    for srgb in (True, False):
        np.testing.assert_array_equal(mr.Texture.from_file(tmp_path / "float.tif", srgb=srgb).level(0),
                                      mr.Texture(values).level(0))


def test_from_file_srgb_false_reads_any_format(tmp_path):
    pil = pytest.importorskip("PIL.Image")
    codes = np.arange(12, dtype=np.uint8).reshape(2, 2, 3) * 20
    pil.fromarray(codes, "RGB").save(tmp_path / "x.tga")  # a format without a magic number
    np.testing.assert_array_equal(mr.Texture.from_file(tmp_path / "x.tga", srgb=False).level(0),
                                  mr.Texture(codes, srgb=False).level(0))


def test_from_file_written_by_write_image(tmp_path):
    rng = np.random.default_rng(15)
    linear = rng.random((4, 4, 3), dtype=np.float32)
    mr.write_image(tmp_path / "rgb.png", linear)
    t = mr.Texture.from_file(tmp_path / "rgb.png")
    np.testing.assert_array_equal(t.level(0), mr.read_image(tmp_path / "rgb.png"))
    np.testing.assert_allclose(t.level(0)[..., :3], linear, atol=0.01)  # sRGB8 quantization
    # EXR is linear and premultiplied: kept as it is, srgb or not
    rgba = rng.random((4, 4, 4), dtype=np.float32)
    rgba[..., :3] *= rgba[..., 3:]
    mr.write_image(tmp_path / "rgba.exr", rgba)
    for srgb in (True, False):
        np.testing.assert_array_equal(mr.Texture.from_file(tmp_path / "rgba.exr", srgb=srgb).level(0), rgba)


def test_from_file_errors(tmp_path):
    with pytest.raises(FileNotFoundError):
        mr.Texture.from_file(tmp_path / "missing.png")
    bad = tmp_path / "bad.png"
    bad.write_bytes(b"not a png")
    with pytest.raises(OSError, match="bad.png"):
        mr.Texture.from_file(bad)
    with pytest.raises(TypeError, match="path: expected str or os.PathLike, got int"):
        mr.Texture.from_file(3)
    with pytest.raises(TypeError, match="srgb: expected True or False"):
        mr.Texture.from_file(bad, srgb="yes")


def test_texture_module_does_not_load_openimageio():
    code = (
        "import sys, numpy as np, mipraster as mr\n"
        "t = mr.Texture(np.zeros((4, 4, 4), np.uint8))\n"
        "t.sample([[0.5, 0.5]], [0.3, 0], [0, 0.3], sampler='ewa')\n"
        "print('mipraster._image' in sys.modules, 'libOpenImageIO' in open('/proc/self/maps').read())\n"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == ["False", "False"]
