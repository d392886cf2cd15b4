"""Textures and samplers: :class:`Texture`, :class:`Sampler` and the texture cache.

A texture holds linear, premultiplied RGBA float texels (level 0, row 0 at v = 0, the top). Its
mip levels (each half the size of the one before, down to 1×1, box-filtered) and its summed-area
table are built in C++ the first time a lookup needs them, and kept in a process-wide cache with
a byte budget (:func:`set_texture_cache_budget`); least recently used textures lose their derived
data first and rebuild it identically when needed again.

Texture coordinates: u runs along a row (left to right), v down the rows; [0, 1)² covers the
texture once and texel (i, j) covers [i/w, (i+1)/w) × [j/h, (j+1)/h). ``nearest`` picks texel
⌊u·w⌋, ``bilinear`` blends the four texel centres around the point (i = ⌊u·w − ½⌋).
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import Any, Dict, Optional, Tuple, Union

import numpy as np

from . import _checks, _core

__all__ = ["Texture", "Sampler", "texture_cache_stats", "set_texture_cache_budget", "clear_texture_cache"]

PathLike = Union[str, "os.PathLike[str]"]

#: Filter presets (``Sampler.filter``), in order of cost.
FILTERS = ("nearest", "bilinear", "trilinear", "anisotropic", "ewa", "sat")
TEXEL_FILTERS = {"nearest": _core.TexelFilter.nearest, "linear": _core.TexelFilter.linear}
MIP_FILTERS = {"none": _core.MipFilter.none, "nearest": _core.MipFilter.nearest, "linear": _core.MipFilter.linear}
WRAP_MODES = {
    "repeat": _core.WrapMode.repeat,
    "clamp": _core.WrapMode.clamp,
    "mirror": _core.WrapMode.mirror,
    "border": _core.WrapMode.border,
}

_SIZE_MAX = 2**64 - 1


def _float32(value: Any, name: str) -> float:
    """A finite real number that stays finite as float32 (the C++ sampler stores floats)."""
    v = _checks.real(value, name)
    if not math.isfinite(v):
        raise ValueError(f"{name}: expected a finite number, got {v!r}")
    if abs(v) > _checks.FLOAT32_MAX:
        raise ValueError(f"{name}: {v!r} does not fit in float32")
    return v


def _wrap_modes(value: Any) -> Tuple[str, str]:
    """One wrap mode for both axes, or a (u, v) pair."""
    if isinstance(value, str):
        _checks.choice(value, "wrap", WRAP_MODES)
        return (value, value)
    if not isinstance(value, (tuple, list)) or len(value) != 2:
        raise TypeError(f"wrap: expected a mode name or a (u, v) pair of names "
                        f"({', '.join(repr(k) for k in WRAP_MODES)}), got {type(value).__name__} {value!r}")
    u, v = value
    _checks.choice(u, "wrap[0]", WRAP_MODES)
    _checks.choice(v, "wrap[1]", WRAP_MODES)
    return (u, v)


@dataclass(frozen=True)
class Sampler:
    """How a texture is read (immutable; validated when made, so every Sampler is usable).

    Args:
        filter: the preset: ``"nearest"`` (nearest texel, level 0 only), ``"bilinear"`` (level 0
            only), ``"trilinear"`` (bilinear on the two nearest mip levels, blended),
            ``"anisotropic"`` (up to ``max_anisotropy`` trilinear probes along the footprint's
            major axis, EXT_texture_filter_anisotropic), ``"ewa"`` (elliptical weighted average:
            a Gaussian over the footprint ellipse) or ``"sat"`` (summed-area table: the exact mean
            over the footprint's bounding box).
        mag_filter: overrides the preset's filter when magnifying (λ ≤ 0): ``"nearest"`` or
            ``"linear"`` (glTF ``magFilter``).
        min_filter: overrides the preset's filter within a level when minifying (λ > 0):
            ``"nearest"`` or ``"linear"``.
        mip_filter: overrides the preset's filter between levels: ``"none"`` (level 0 only),
            ``"nearest"`` or ``"linear"``. With ``min_filter`` this spells glTF's ``minFilter``
            (e.g. LINEAR_MIPMAP_NEAREST = min ``"linear"``, mip ``"nearest"``).
        max_anisotropy: anisotropic: the most probes per lookup; ewa: the largest ratio of the
            footprint ellipse's axes. A number ≥ 1.
        wrap: ``"repeat"``, ``"clamp"`` (clamp to edge), ``"mirror"`` (mirrored repeat) or
            ``"border"``, for both axes, or a ``(u, v)`` pair.
        border_color: what ``"border"`` wrapping reads outside the texture, and what a lookup
            at a NaN or infinite uv returns: 3 (alpha 1) or 4 components, linear premultiplied.
        lod_bias: added to the level of detail λ (log2 of the footprint in texels) before it is
            clamped.
        min_lod, max_lod: λ is clamped to [min_lod, max_lod] (and to the levels the texture has).

    Raises:
        TypeError: a field of the wrong kind (a number that is a string or bool, a name that is
            not a string, ...).
        ValueError: an unknown name (the message lists the accepted ones), a non-finite number,
            ``max_anisotropy < 1`` or ``min_lod > max_lod``.
    """

    filter: str = "trilinear"
    mag_filter: Optional[str] = None
    min_filter: Optional[str] = None
    mip_filter: Optional[str] = None
    max_anisotropy: float = 16.0
    wrap: Union[str, Tuple[str, str]] = ("repeat", "repeat")
    border_color: Tuple[float, ...] = (0.0, 0.0, 0.0, 0.0)
    lod_bias: float = 0.0
    min_lod: float = 0.0
    max_lod: float = 1000.0
    _sampler: Any = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        set_field = object.__setattr__
        core = _core.Sampler.from_filter_name(_checks.choice(self.filter, "filter", {f: f for f in FILTERS}))
        if self.mag_filter is not None:
            core.mag_filter = _checks.choice(self.mag_filter, "mag_filter", TEXEL_FILTERS)
        if self.min_filter is not None:
            core.min_filter = _checks.choice(self.min_filter, "min_filter", TEXEL_FILTERS)
        if self.mip_filter is not None:
            core.mip_filter = _checks.choice(self.mip_filter, "mip_filter", MIP_FILTERS)

        max_anisotropy = _float32(self.max_anisotropy, "max_anisotropy")
        if max_anisotropy < 1:
            raise ValueError(f"max_anisotropy: expected a number >= 1, got {max_anisotropy!r}")
        wrap = _wrap_modes(self.wrap)
        border = _checks.rgba(self.border_color, "border_color")
        lod_bias = _float32(self.lod_bias, "lod_bias")
        min_lod = _float32(self.min_lod, "min_lod")
        max_lod = _float32(self.max_lod, "max_lod")
        if min_lod > max_lod:
            raise ValueError(f"min_lod ({min_lod!r}) exceeds max_lod ({max_lod!r})")

        core.max_anisotropy = max_anisotropy
        core.wrap_u, core.wrap_v = WRAP_MODES[wrap[0]], WRAP_MODES[wrap[1]]
        core.border_color = border
        core.lod_bias = lod_bias
        core.min_lod = min_lod
        core.max_lod = max_lod
        core.validate()

        set_field(self, "max_anisotropy", max_anisotropy)
        set_field(self, "wrap", wrap)
        set_field(self, "border_color", border)
        set_field(self, "lod_bias", lod_bias)
        set_field(self, "min_lod", min_lod)
        set_field(self, "max_lod", max_lod)
        set_field(self, "_sampler", core)

    @classmethod
    def _from_core(cls, core: _core.Sampler) -> "Sampler":
        """The Sampler equal to a C++ sampler: the preset that needs the fewest explicit filters."""
        presets = ("nearest", "bilinear", "trilinear") if core.footprint == _core.FootprintFilter.isotropic \
            else (core.footprint.name,)
        best: Optional[Tuple[int, str, Tuple[Optional[str], ...]]] = None
        for name in presets:
            preset = _core.Sampler.from_filter_name(name)
            overrides = tuple(None if getattr(preset, f) == getattr(core, f) else getattr(core, f).name
                              for f in ("mag_filter", "min_filter", "mip_filter"))
            count = sum(o is not None for o in overrides)
            if best is None or count < best[0]:
                best = (count, name, overrides)
        assert best is not None
        _, name, (mag, mn, mip) = best
        return cls(filter=name, mag_filter=mag, min_filter=mn, mip_filter=mip, max_anisotropy=core.max_anisotropy,
                   wrap=(core.wrap_u.name, core.wrap_v.name), border_color=core.border_color, lod_bias=core.lod_bias,
                   min_lod=core.min_lod, max_lod=core.max_lod)

    def __reduce__(self) -> Tuple[Any, Tuple[Any, ...]]:
        # The C++ sampler does not pickle: rebuild it from the fields.
        return (Sampler, (self.filter, self.mag_filter, self.min_filter, self.mip_filter, self.max_anisotropy,
                          self.wrap, self.border_color, self.lod_bias, self.min_lod, self.max_lod))

    @property
    def needs_derivatives(self) -> bool:
        """True when a lookup's result depends on the uv derivatives (some filter varies with λ)."""
        return self._sampler.needs_derivatives()

    @property
    def uses_mip_levels(self) -> bool:
        """True when lookups may read (and so build) mip levels beyond level 0."""
        return self._sampler.uses_mip_levels()


_DEFAULT_SAMPLER = Sampler()


def _sampler(value: Any) -> Sampler:
    if value is None:
        return _DEFAULT_SAMPLER
    if isinstance(value, str):
        return Sampler(filter=value)
    if not isinstance(value, Sampler):
        raise TypeError(f"sampler: expected a mipraster.Sampler or a filter name, got {type(value).__name__}")
    return value


def _pairs(value: Any, name: str) -> np.ndarray:
    """A real array of shape (..., 2)."""
    a = _checks.real_array(value, name)
    if a.ndim == 0 or a.shape[-1] != 2:
        raise ValueError(f"{name}: expected shape (..., 2) (u, v pairs), got {_checks._shape_text(a.shape)}")
    return a


def _as_rows(a: np.ndarray, lead: Tuple[int, ...]) -> np.ndarray:
    """``a`` (..., 2) as C-contiguous float32 rows: (1, 2) when it is one pair for every point,
    else broadcast to (N, 2). Values beyond float32 become ±inf (a non-finite uv reads the border)."""
    with np.errstate(over="ignore", invalid="ignore"):
        if math.prod(a.shape[:-1]) == 1:
            return np.ascontiguousarray(a.reshape(1, 2), dtype=np.float32)
        return np.ascontiguousarray(np.broadcast_to(a, lead + (2,)).reshape(-1, 2), dtype=np.float32)


def _lead_shape(arrays: Dict[str, np.ndarray]) -> Tuple[int, ...]:
    try:
        return tuple(np.broadcast_shapes(*(a.shape[:-1] for a in arrays.values())))
    except ValueError:
        shapes = ", ".join(f"{k} {_checks._shape_text(a.shape)}" for k, a in arrays.items())
        raise ValueError(f"{', '.join(arrays)}: shapes do not broadcast: {shapes}") from None


class Texture:
    """An immutable texture: linear, premultiplied RGBA float texels with lazily built mip levels.

    Args:
        texels: ``(H, W, C)`` with C = 1 (grey), 2 (grey, alpha), 3 (RGB) or 4 (RGBA), or
            ``(H, W)`` grey; row 0 is the top (v = 0). The dtype says how values are read:

            - ``uint8``: codes 0–255; colour decoded from sRGB (code 188 → linear 0.5029),
              unless ``srgb=False`` (code / 255); alpha is code / 255, straight.
            - ``uint16``: the same with code / 65535.
            - any float dtype (stored as float32): linear values; alpha straight unless
              ``premultiplied``.

            Colour is multiplied by alpha as the texture is made. Lists, non-contiguous and
            Fortran-order arrays are accepted (copied once). Other integer dtypes are refused:
            convert 8-bit codes with ``.astype(np.uint8)``.
        srgb: integer texels: decode colour from sRGB (default True). Float texels are linear;
            ``srgb=True`` is refused for them (decode with :func:`mipraster.srgb_to_linear`).
        premultiplied: float texels: colour already includes alpha (default False: straight
            alpha, premultiplied here). Integer texels are always straight alpha.
        name: identifies the texture in messages and ``repr``.

    Textures are shared and immutable: wrappers of one texture (e.g. a draw's ``texture`` and the
    texture given to :meth:`Scene.add`) compare equal.

    Raises:
        TypeError: texels of another dtype (bool, int64, object, ...), or a flag that is not a bool.
        ValueError: a wrong shape, an empty or too large texture (more than
            ``MAX_TEXTURE_DIMENSION`` = 65536 texels per side or 8 GiB as RGBA float), a NaN or
            infinite texel, or one beyond ±1e32 once premultiplied (named by index; so that every
            filter's sums stay finite), ``srgb=True`` with float texels or ``premultiplied=True``
            with integer texels.
    """

    __slots__ = ("_texture",)

    def __init__(self, texels: Any, srgb: Optional[bool] = None, premultiplied: bool = False,
                 name: str = "texture") -> None:
        if not isinstance(name, str):
            raise TypeError(f"name: expected str, got {type(name).__name__}")
        premultiplied = _checks.flag(premultiplied, "premultiplied")
        if srgb is not None:
            srgb = _checks.flag(srgb, "srgb")
        a = _checks.as_array(texels, "texels")
        kind = a.dtype.kind
        unsigned = kind == "u" and a.dtype.itemsize in (1, 2)
        if not unsigned and kind != "f":
            raise TypeError(
                f"texels: expected uint8, uint16 or floating-point values, got dtype {_checks._dtype_name(a)}; "
                "convert 8-bit codes with .astype(np.uint8), or linear values with .astype(np.float32)")
        _checks.check_shape(a, "texels", (None, None), (None, None, 1), (None, None, 2), (None, None, 3),
                            (None, None, 4), letters=("H", "W"))
        _check_size(a.shape[0], a.shape[1])

        if kind == "f":
            if srgb:
                raise ValueError("srgb: float texels are linear; decode sRGB-encoded values with "
                                 "mipraster.srgb_to_linear first, or pass uint8/uint16 codes")
            _checks.check_finite(a, "texels")
            self._texture = _core.Texture.from_float(_checks.to_float32(a, "texels"), premultiplied, name)
            return
        if premultiplied:
            raise ValueError(f"premultiplied: {a.dtype} texels are straight alpha (as PNG stores them); "
                             "pass premultiplied values as floats")
        if a.dtype.itemsize == 1:
            self._texture = _core.Texture.from_uint8(np.ascontiguousarray(a, dtype=np.uint8), srgb is not False, name)
        else:
            self._texture = _core.Texture.from_uint16(np.ascontiguousarray(a, dtype=np.uint16), srgb is not False, name)

    @classmethod
    def from_file(cls, path: PathLike, srgb: bool = True, name: Optional[str] = None) -> "Texture":
        """Reads an image file with :func:`mipraster.read_image` into a texture.

        Args:
            path: any file OpenImageIO reads (PNG, JPEG, EXR, HDR, TIFF, ...).
            srgb: for files of integer values (8- and 16-bit PNG, JPEG, ...): colour is
                sRGB-encoded (the default), or, with False, linear data such as normal or
                roughness maps, read as code / max code (any format). Float files (EXR, HDR, PFM,
                float TIFF) are linear whatever ``srgb`` says.
            name: defaults to the path.

        Raises:
            FileNotFoundError: there is no such file.
            OSError: the file cannot be read.
        """
        from .image import _path, read_image

        p = _path(path)
        srgb = _checks.flag(srgb, "srgb")
        if name is not None and not isinstance(name, str):
            raise TypeError(f"name: expected str or None, got {type(name).__name__}")
        rgba = read_image(p, srgb=srgb)  # linear premultiplied RGBA float32
        return cls(rgba, premultiplied=True, name=p if name is None else name)

    @classmethod
    def _from_core(cls, texture: _core.Texture) -> "Texture":
        """Wraps an existing C++ texture without copying it."""
        self = cls.__new__(cls)
        self._texture = texture
        return self

    @property
    def width(self) -> int:
        """Width of level 0 in texels."""
        return self._texture.width

    @property
    def height(self) -> int:
        """Height of level 0 in texels."""
        return self._texture.height

    @property
    def level_count(self) -> int:
        """Number of mip levels, level 0 included: level k is max(1, ⌊W/2^k⌋) × max(1, ⌊H/2^k⌋), down to 1×1."""
        return self._texture.level_count

    @property
    def built_levels(self) -> int:
        """How many levels beyond 0 are built now (they are built on first use and may be evicted)."""
        return self._texture.built_levels

    @property
    def name(self) -> str:
        """The name given when the texture was made (the path for :meth:`from_file`)."""
        return self._texture.name

    def level(self, k: int) -> np.ndarray:
        """Level ``k`` (0 ≤ k < ``level_count``) as a new ``(H_k, W_k, 4)`` float32 array, linear
        premultiplied RGBA; the level (and those above it) is built if it is not yet."""
        k = _checks.integer(k, "k")
        n = self.level_count
        if not 0 <= k < n:
            raise ValueError(f"k: level {k} is out of range; expected 0 <= k < {n} (the level count)")
        return self._texture.level(k)

    def sample(self, uv: Any, duv_dx: Any = None, duv_dy: Any = None,
               sampler: Union[Sampler, str, None] = None) -> np.ndarray:
        """Filtered lookups at many points at once.

        Args:
            uv: ``(..., 2)`` texture coordinates (u, v) (any real dtype; computed as float32). A
                NaN or infinite coordinate gives the sampler's border colour.
            duv_dx, duv_dy: ``(..., 2)`` change of uv per pixel step along screen x and y: the
                footprint that chooses the mip level and the anisotropic / EWA / SAT filter
                region. Broadcast against ``uv``; default zero (magnification: level 0). Infinite
                or NaN derivatives select the coarsest level.
            sampler: a :class:`Sampler`, a filter name (``Sampler(filter=name)``) or None for
                ``Sampler()`` (trilinear, repeat).

        Returns:
            ``(..., 4)`` float32, linear premultiplied RGBA (the broadcast shape of the inputs).
            The work runs in C++ with the GIL released (on all cores for large inputs).

        Raises:
            TypeError: non-real arrays or a sampler of the wrong type.
            ValueError: arrays whose last axis is not 2, or shapes that do not broadcast.
        """
        s = _sampler(sampler)
        arrays = {"uv": _pairs(uv, "uv")}
        arrays["duv_dx"] = np.zeros(2) if duv_dx is None else _pairs(duv_dx, "duv_dx")
        arrays["duv_dy"] = np.zeros(2) if duv_dy is None else _pairs(duv_dy, "duv_dy")
        lead = _lead_shape(arrays)
        with np.errstate(over="ignore", invalid="ignore"):
            uv_rows = np.ascontiguousarray(np.broadcast_to(arrays["uv"], lead + (2,)).reshape(-1, 2), dtype=np.float32)
        out = _core.sample_texture(self._texture, s._sampler, uv_rows, _as_rows(arrays["duv_dx"], lead),
                                   _as_rows(arrays["duv_dy"], lead))
        return out.reshape(lead + (4,))

    def lod(self, duv_dx: Any, duv_dy: Any, sampler: Union[Sampler, str, None] = None) -> np.ndarray:
        """The level of detail λ that :meth:`sample` uses for these derivatives (``(..., 2)`` each,
        broadcast): log2 of the footprint in texels (anisotropic: of the footprint per probe), plus
        ``lod_bias``, clamped to [min_lod, max_lod] and [0, level_count − 1]. λ ≤ 0 means
        magnification. Returns float64 of the broadcast shape."""
        s = _sampler(sampler)
        arrays = {"duv_dx": _pairs(duv_dx, "duv_dx"), "duv_dy": _pairs(duv_dy, "duv_dy")}
        lead = _lead_shape(arrays)
        with np.errstate(over="ignore", invalid="ignore"):
            dx = np.ascontiguousarray(np.broadcast_to(arrays["duv_dx"], lead + (2,)).reshape(-1, 2), dtype=np.float32)
            dy = np.ascontiguousarray(np.broadcast_to(arrays["duv_dy"], lead + (2,)).reshape(-1, 2), dtype=np.float32)
        return _core.texture_lod(self._texture, s._sampler, dx, dy).reshape(lead)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Texture):
            return NotImplemented
        return self._texture.identity == other._texture.identity

    def __hash__(self) -> int:
        return hash(self._texture.identity)

    def __repr__(self) -> str:
        return repr(self._texture)


def _check_size(height: int, width: int) -> None:
    limit = _core.MAX_TEXTURE_DIMENSION
    if width < 1 or height < 1:
        raise ValueError(f"texels: size {width}x{height} (width x height) is empty; expected at least 1x1")
    if width > limit or height > limit:
        raise ValueError(f"texels: size {width}x{height} (width x height) exceeds the limit of {limit} per side")
    needed = width * height * 16
    if needed > _core.MAX_TEXTURE_BYTES:
        raise ValueError(f"texels: {width}x{height} needs {needed >> 20} MiB as RGBA float; the limit is "
                         f"{_core.MAX_TEXTURE_BYTES >> 20} MiB")


# --- the texture cache ---------------------------------------------------------------------------

def texture_cache_stats() -> Dict[str, int]:
    """The process-wide texture cache: a dict with ``budget_bytes``, ``derived_bytes`` (bytes of
    the mip levels ≥ 1 and summed-area tables held now, all textures), and the counts since the
    process started: ``levels_built``, ``tables_built``, ``evictions`` (textures whose derived
    data was dropped), with ``keyed_textures`` (live textures shared by file name)."""
    return _core.texture_cache_stats()


def set_texture_cache_budget(budget_bytes: int) -> None:
    """Bounds the bytes of derived data (mip levels ≥ 1, summed-area tables) kept for textures not
    in use (default 1 GiB). Over budget, the least recently used textures' derived data is dropped
    (rebuilt identically when needed again); data of textures being sampled is never dropped.
    Raises TypeError for a non-integer, ValueError for a negative budget."""
    b = _checks.integer(budget_bytes, "budget_bytes")
    if b < 0:
        raise ValueError(f"budget_bytes: expected a number of bytes >= 0, got {b}")
    _core.set_texture_cache_budget(min(b, _SIZE_MAX))


def clear_texture_cache() -> None:
    """Drops the derived data of every texture not in use (it is rebuilt when needed again)."""
    _core.clear_texture_cache()
