"""Image resampling with reconstruction filters: :func:`resample`.

The notes' reconstruction + resampling: the pixels are reconstructed into a continuous image with a
separable filter and sampled on the new grid (pixel centres at i + ½ in both). When the image
shrinks, the filter is widened by the reduction factor, so it also removes the detail the new grid
cannot hold (no aliasing). Filtering happens in linear colour: 8- and 16-bit images are decoded
from sRGB (colour) and premultiplied by alpha first, and encoded back afterwards.
"""
from __future__ import annotations

from typing import Any, Tuple

import numpy as np

from . import _checks, _core

__all__ = ["resample", "RESAMPLE_FILTERS", "decode_codes", "encode_codes"]

#: Reconstruction filters, from the notes' constant and linear ones to the better cubic and windowed-sinc ones.
RESAMPLE_FILTERS = ("box", "tent", "mitchell", "catmull-rom", "lanczos3")


def _size(size: Any, name: str, limit: int) -> Tuple[int, int]:
    """A (width, height) pair of integers in 1…limit."""
    if isinstance(size, (str, bytes)) or not hasattr(size, "__len__") or len(size) != 2:
        raise TypeError(f"{name}: expected a (width, height) pair of integers, got {type(size).__name__} {size!r}")
    w = _checks.integer(size[0], f"{name}[0] (width)")
    h = _checks.integer(size[1], f"{name}[1] (height)")
    for v, what in ((w, "width"), (h, "height")):
        if not 1 <= v <= limit:
            raise ValueError(f"{name}: {what} {v} is out of range; expected 1 to {limit}")
    return w, h


def _image(image: Any, name: str) -> np.ndarray:
    """An (H, W) or (H, W, C ≤ 4) array of uint8, uint16 or floats, at least 1×1, finite."""
    a = _checks.as_array(image, name)
    if not (a.dtype.kind == "f" or a.dtype in (np.uint8, np.uint16)):
        raise TypeError(f"{name}: expected uint8 / uint16 (sRGB codes) or floating-point (linear) values, "
                        f"got dtype {_checks._dtype_name(a)}")
    _checks.check_shape(a, name, (None, None), (None, None, 1), (None, None, 2), (None, None, 3), (None, None, 4),
                        letters=("H", "W"))
    if a.shape[0] < 1 or a.shape[1] < 1:
        raise ValueError(f"{name}: empty ({a.shape[1]}x{a.shape[0]}); expected at least 1x1 pixels")
    _checks.check_finite(a, name)
    return a


def _has_alpha(a: np.ndarray) -> bool:
    return a.ndim == 3 and a.shape[2] in (2, 4)


def decode_codes(a: np.ndarray, srgb: bool = True) -> np.ndarray:
    """uint8 / uint16 codes → linear float32: colour decoded from sRGB (or code / max when
    ``srgb`` is False), alpha (the last channel of 2- and 4-channel images) code / max, straight."""
    scale = float(np.iinfo(a.dtype).max)
    values = a.astype(np.float32) / np.float32(scale)
    if srgb:
        colour = values[..., :-1] if _has_alpha(a) else values
        colour[...] = _core.srgb_to_linear(colour)
    return values


def encode_codes(values: np.ndarray, dtype: np.dtype, srgb: bool = True) -> np.ndarray:
    """The inverse of :func:`decode_codes`: clamped to [0, 1], sRGB-encoded colour, rounded codes."""
    scale = float(np.iinfo(dtype).max)
    v = np.clip(values, 0.0, 1.0).astype(np.float64)
    if srgb:
        colour = v[..., :-1] if _has_alpha(values) else v
        colour[...] = _core.linear_to_srgb(colour)
    return np.rint(v * scale).astype(dtype)


def resample(image: Any, size: Any, filter: str = "mitchell", srgb: bool = True, threads: int = 0) -> np.ndarray:
    """Resizes an image to ``size = (width, height)`` with a reconstruction filter.

    Args:
        image: ``(H, W)`` or ``(H, W, C)``, C = 1 (grey), 2 (grey, alpha), 3 (RGB) or 4 (RGBA).
            Float values are linear and filtered as given (premultiply RGBA first, as
            :func:`render` does). ``uint8`` / ``uint16`` values are codes: colour is decoded from
            sRGB (``srgb=True``) or read as code / max, alpha is straight; colour is premultiplied
            by alpha for the filtering and the result encoded back to the same dtype.
        size: ``(width, height)`` of the result, 1…65536 each.
        filter: ``"box"`` (constant reconstruction), ``"tent"`` (linear: bilinear when enlarging),
            ``"mitchell"`` (Mitchell–Netravali, B = C = ⅓: little ringing, slightly soft),
            ``"catmull-rom"`` (an interpolating cubic, sharper) or ``"lanczos3"`` (windowed sinc:
            sharpest, some ringing). When shrinking by a factor s, the filter is s times wider.
        srgb: integer images: colour is sRGB-encoded (default). Ignored for float images.
        threads: worker threads, 0 = all cores; the result does not depend on it.

    Returns:
        The resized image, same channels and dtype as the input (float input gives float32). The
        same size returns a copy of the input. Float results are not clamped: cubic and Lanczos
        filters may overshoot next to sharp edges; integer results are clamped to the code range.

    Raises:
        TypeError: a wrong kind of argument (e.g. an int64 image, a size that is not a pair).
        ValueError: a wrong shape, an empty image, a NaN or infinite value (named by index), a size
            out of range, an unknown filter name.
    """
    a = _image(image, "image")
    width, height = _size(size, "size", _core.MAX_RESAMPLE_DIMENSION)
    _checks.choice(filter, "filter", {f: f for f in RESAMPLE_FILTERS})
    srgb = _checks.flag(srgb, "srgb")
    n_threads = _checks.integer(threads, "threads")
    if not 0 <= n_threads <= _core.MAX_THREADS:
        raise ValueError(f"threads: expected 0 (all cores) to {_core.MAX_THREADS}, got {n_threads}")
    if a.dtype.kind == "f":
        out = _core.resample(_checks.to_float32(a, "image"), width, height, filter, n_threads)
        return out.reshape(height, width) if a.ndim == 2 else out

    linear = decode_codes(a, srgb)
    if _has_alpha(a):
        linear[..., :-1] *= linear[..., -1:]
    out = _core.resample(np.ascontiguousarray(linear), width, height, filter, n_threads)
    if _has_alpha(a):
        alpha = np.clip(out[..., -1:], 0.0, 1.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            out[..., :-1] = np.where(alpha > 0, out[..., :-1] / alpha, 0.0)
    if a.ndim == 2:
        out = out.reshape(height, width)
    return encode_codes(out, a.dtype, srgb)
