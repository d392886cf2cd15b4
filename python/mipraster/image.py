"""Image files and sRGB encoding.

Files go through ``mipraster._image`` (OpenImageIO), which is imported the first time a file is
read or written, never by ``import mipraster``. sRGB encoding lives in ``mipraster._core``.
"""
from __future__ import annotations

import errno
import math
import os
from types import ModuleType
from typing import Any, Union

import numpy as np

from . import _checks, _core

__all__ = ["read_image", "write_image", "to_srgb8", "srgb_to_linear", "linear_to_srgb", "linear_to_srgb8"]

PathLike = Union[str, bytes, "os.PathLike[str]", "os.PathLike[bytes]"]  # bytes: decoded as os.fsdecode does


def _image_module() -> ModuleType:
    """The OpenImageIO-backed extension module, loaded on first use, with the current memory
    limit (it links its own copy of the core, so the limit set through _core is passed on)."""
    from . import _image
    from ._core import memory_limit

    _image.set_memory_limit(memory_limit())
    return _image


def _path(path: Any) -> str:
    """A path as the C++ side takes it (UTF-8); ValueError for one it would read differently."""
    if isinstance(path, bytes):
        path = os.fsdecode(path)
    try:
        p = os.fspath(path)
    except TypeError:
        raise TypeError(f"path: expected str or os.PathLike, got {type(path).__name__}") from None
    if not isinstance(p, str):
        p = os.fsdecode(p)
    if "\0" in p:  # the C++ side would stop at it: 'a\0b.png' wrote a file named 'a'
        raise ValueError(f"path: {p!r} contains a NUL character")
    try:
        p.encode("utf-8")
    except UnicodeEncodeError:
        raise ValueError(f"path: {p!r} is not valid Unicode (a lone surrogate: a file name in another "
                         "encoding); rename the file") from None
    return p


def _float_image(image: Any, name: str) -> np.ndarray:
    a = _checks.real_array(
        image, name, integers=False,
        hint="; expected linear float values (premultiplied RGBA), e.g. mipraster.srgb_to_linear(rgb8 / 255)",
    )
    _checks.check_shape(a, name, (None, None), (None, None, 1), (None, None, 3), (None, None, 4), letters=("H", "W"))
    _checks.check_fits_float32(a, name)  # (files and the C++ side hold float32: it would become inf)
    return a


def _check_finite_pixels(a: np.ndarray, what: str) -> None:
    """ValueError naming the first NaN or ±inf value of an (H, W[, C]) image by pixel (x, y) and
    channel: an 8- or 16-bit code has no value for it (it became 0 or the clamp limit, a silent
    wrong image). ``what`` starts the message."""
    index = _checks.first_nonfinite(a)
    if index is None:
        return
    y, x, c = index if len(index) == 3 else (*index, 0)
    raise ValueError(f"{what}: pixel (x={x}, y={y}) channel {c} is {a[index]} (image[{', '.join(map(str, index))}]); "
                     "8- and 16-bit codes need finite values (write .exr to keep NaN and inf)")


def read_image(path: PathLike, srgb: bool = True) -> np.ndarray:
    """Reads an image file into ``(H, W, 4)`` float32, linear premultiplied RGBA.

    8- and 16-bit files (PNG, JPEG, ...) are decoded from sRGB, alpha multiplied in linear (colour
    stored premultiplied, as in TIFFs with associated alpha, is divided out first); float files
    (EXR, HDR, float TIFF) are read as they are. Grey becomes (g, g, g, 1), RGB gets alpha 1.
    File transfer metadata (PNG gAMA/iCCP) and EXIF orientation are not applied.
    ``srgb=False`` reads integer files as linear data (code / max code), e.g. normal maps.

    Raises:
        FileNotFoundError: there is no such file.
        OSError: the file cannot be read, or is truncated or corrupt (the message names the path;
            ``.filename`` is set).
    """
    p = _path(path)
    srgb = _checks.flag(srgb, "srgb")
    if not os.path.exists(p):
        raise FileNotFoundError(errno.ENOENT, os.strerror(errno.ENOENT), p)
    return _image_module().read_image(p, srgb)


def write_image(path: PathLike, image: Any, bits: int = 8) -> None:
    """Writes a linear float image; the format follows the extension.

    Args:
        path: ``.png`` (sRGB; RGBA un-premultiplied to straight alpha; 1 channel written as plain
            grey) or ``.exr`` (32-bit float, values as given).
        image: ``(H, W, 4)`` linear premultiplied RGBA, ``(H, W, 3)`` linear RGB, or ``(H, W)`` /
            ``(H, W, 1)`` data, any float dtype.
        bits: a PNG's bits per channel, 8 (the default) or 16 (codes 256 times finer: smooth
            gradients and dark tones without banding). An EXR takes only the default.

    Raises:
        TypeError: a non-float image.
        ValueError: a wrong shape, a finite value beyond float32's range, NaN or ±inf in a PNG
            (naming the first pixel and channel; an EXR keeps them), an unsupported extension, or
            bits other than 8 or 16 (or than 8 for an EXR).
        OSError: the file cannot be written (the message names the path; ``.filename`` is set).
    """
    p = _path(path)
    if isinstance(bits, bool) or not isinstance(bits, (int, np.integer)) or bits not in (8, 16):
        raise ValueError(f"write_image: bits={bits!r}: a PNG has 8 or 16 bits per channel")
    a = _float_image(image, "image")
    if os.path.splitext(p)[1].lower() == ".png":  # (the C++ side checks too: this names the array index)
        _check_finite_pixels(a, f"write_image: cannot write {p!r}")
    _image_module().write_image(p, np.ascontiguousarray(a, dtype=np.float32), int(bits))


def to_srgb8(image: Any) -> np.ndarray:
    """Linear premultiplied ``(H, W, 4)`` float (or linear ``(H, W, 3)``, ``(H, W)``) → ``(H, W, 4)`` uint8.

    Colour is un-premultiplied and sRGB-encoded (linear 0.5 → 188), alpha stored linearly: the
    bytes a PNG written by :func:`write_image` holds. ValueError for NaN or ±inf, naming the
    first pixel and channel.
    """
    a = _float_image(image, "image")
    _check_finite_pixels(a, "to_srgb8")
    return _core.to_srgb8(np.ascontiguousarray(a, dtype=np.float32))


# The sRGB transfer functions, element by element (a number gives a number, an array an array of
# float32; uint8 for linear_to_srgb8). Checked here: the bindings read None as 0, and the C++
# functions clamp NaN to 0.
def _keep_nan(values: np.ndarray, out: Any) -> Any:
    """``out`` (the C++ function of ``values``) with NaN where ``values`` holds NaN: NaN in, NaN out."""
    if values.dtype.kind != "f":
        return out
    nan = np.isnan(values)
    if not nan.any():
        return out
    if values.ndim == 0:
        return math.nan
    out = np.array(out, dtype=np.float32)
    out[nan] = np.nan
    return out


def srgb_to_linear(encoded: Any) -> Any:
    """sRGB-encoded values (0…1) to linear (NaN stays NaN); TypeError for anything but real numbers."""
    a = _checks.real_array(encoded, "encoded")
    return _keep_nan(a, _core.srgb_to_linear(a))


def linear_to_srgb(linear: Any) -> Any:
    """Linear values to sRGB-encoded ones (0…1; NaN stays NaN); TypeError for anything but real numbers."""
    a = _checks.real_array(linear, "linear")
    return _keep_nan(a, _core.linear_to_srgb(a))


def linear_to_srgb8(linear: Any) -> Any:
    """Linear values to sRGB8 codes (0…255, rounded); TypeError for anything but real numbers,
    ValueError naming the first NaN or ±inf (a code has no value for it)."""
    a = _checks.real_array(linear, "linear")
    index = _checks.first_nonfinite(a)
    if index is not None:
        where = f"linear[{', '.join(map(str, index))}]" if index else "linear"
        raise ValueError(f"{where} is {a[index]}; an sRGB8 code needs a finite number")
    return _core.linear_to_srgb8(a)
