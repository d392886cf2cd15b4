"""Texture synthesis by non-parametric sampling (Efros & Leung): :func:`synthesize`.

The output grows pixel by pixel from a random 3×3 seed patch of the sample, in onion-skin order
(pixels with the most known neighbours first). Each pixel's known neighbourhood (a window × window
square, Gaussian-weighted with σ = window / 6.4, unknown pixels ignored) is compared with every
neighbourhood of the sample by the sum of squared differences, and the pixel copies the centre of
a match drawn at random (seeded) among those within (1 + ε) of the best. Every output pixel is a
sample pixel. The search runs in C++ over a padded, one-plane-per-channel copy of the sample that
lets it sweep candidates in contiguous memory, split across threads.
"""
from __future__ import annotations

from typing import Any, Tuple, Union

import numpy as np

from . import _checks, _core
from .resample import _image, _size, decode_codes

__all__ = ["synthesize"]


def synthesize(sample: Any, size: Any, window: int = 11, seed: int = 0, epsilon: float = 0.1,
               periodic: bool = False, tileable: bool = False, srgb: bool = True, threads: int = 0,
               return_source: bool = False) -> Union[np.ndarray, Tuple[np.ndarray, np.ndarray]]:
    """Synthesizes a ``size = (width, height)`` texture that looks like ``sample``.

    Args:
        sample: ``(H, W)`` or ``(H, W, C)`` with C = 1…4: ``uint8`` / ``uint16`` codes (colour
            sRGB-encoded unless ``srgb=False``; distances are measured on linear values) or floats
            (linear, used as given).
        size: ``(width, height)`` of the output, 1…8192 each.
        window: the neighbourhood's side: odd, at least 1, at most the sample's width and height.
            It should hold the texture's largest regular element; larger is slower.
        seed: the random seed (0 ≤ seed < 2**64). The same seed gives the same output, for any
            thread count.
        epsilon: matches within (1 + ε) times the best distance are candidates (≥ 0; 0 picks
            among the exact best only).
        periodic: the sample tiles (is periodic): its neighbourhoods wrap around its edges, so
            every sample pixel can be copied. Otherwise only windows inside the sample count.
        tileable: the output tiles: its neighbourhoods wrap around its edges, so it can be repeated
            (e.g. as a texture with ``wrap="repeat"``) without seams. Needs window ≤ the output's sides.
        srgb: integer samples: colour is sRGB-encoded (default). Ignored for float samples.
        threads: worker threads, 0 = all cores.
        return_source: also return the ``(height, width, 2)`` int array of the sample pixel
            (row, column) each output pixel copies.

    Returns:
        ``(height, width[, C])`` with the sample's dtype and channels: every value is a sample
        pixel, bit for bit. With ``return_source``, ``(image, source)``.

    Raises:
        TypeError: a wrong kind of argument.
        ValueError: a wrong shape, an empty sample, a NaN or infinite value, an even window or one
            larger than the sample, a size out of range, a negative or non-finite ε.

    A 128×128 output from a 64×64 sample with an 11×11 window takes about 1.5 s of CPU time; with
    threads, pixels of a layer that lie outside each other's windows are searched in parallel
    (see the README for time against output size).
    """
    a = _image(sample, "sample")
    width, height = _size(size, "size", _core.MAX_SYNTHESIS_DIMENSION)
    n = _checks.integer(window, "window")
    if n < 1 or n % 2 == 0:
        raise ValueError(f"window: {n}; expected an odd size >= 1 (1, 3, 5, ...)")
    if n > min(a.shape[0], a.shape[1]):
        raise ValueError(f"window: {n} is larger than the sample ({a.shape[1]}x{a.shape[0]})")
    s = _checks.integer(seed, "seed")
    if not 0 <= s < 2**64:
        raise ValueError(f"seed: expected 0 <= seed < 2**64, got {s}")
    eps = _checks.real(epsilon, "epsilon")
    if not (np.isfinite(eps) and eps >= 0):
        raise ValueError(f"epsilon: expected a finite number >= 0, got {eps!r}")
    periodic = _checks.flag(periodic, "periodic")
    tileable = _checks.flag(tileable, "tileable")
    if tileable and n > min(width, height):
        raise ValueError(f"window: {n} is larger than the tileable output ({width}x{height})")
    srgb = _checks.flag(srgb, "srgb")
    n_threads = _checks.integer(threads, "threads")
    if not 0 <= n_threads <= _core.MAX_THREADS:
        raise ValueError(f"threads: expected 0 (all cores) to {_core.MAX_THREADS}, got {n_threads}")
    return_source = _checks.flag(return_source, "return_source")

    values = _checks.to_float32(a, "sample") if a.dtype.kind == "f" else decode_codes(a, srgb)
    settings = _core.SynthesisSettings()
    settings.width, settings.height, settings.window, settings.seed = width, height, n, s
    settings.epsilon, settings.periodic_sample, settings.tileable, settings.threads = eps, periodic, tileable, n_threads
    raw = _core.synthesize(np.ascontiguousarray(values), settings)
    flat = raw["source"]
    rows, cols = flat // a.shape[1], flat % a.shape[1]
    out = a[rows, cols]  # gathered from the sample itself: bit-exact in its own dtype
    if return_source:
        return out, np.stack([rows, cols], axis=-1)
    return out
