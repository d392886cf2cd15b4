"""A render's error measured against a sparse reference: a few hundred of its pixels rendered again
at reference quality.

The probe is C++ (``mipraster/pipeline/error_probe.hpp``), so ``render(..., estimate_error=True)``,
adaptive quality and the command line (``mipraster render --stats``, ``--error-map``) measure with the
same code and report the same numbers. This module names it for Python.

The halves estimate (two interleaved halves of each pixel's samples, ``RenderSettings.estimate_error``)
says *where* a render is uncertain, but it cannot see error that both halves share (the blur of a
mip-mapped filter, MSAA's one shade per pixel), it is noisy with few samples per half and it gives
nothing at one sample per pixel. The probe says *how much*, for any scene and configuration:

1. Choose n pixels at random, i.i.d. with probability p_i = ½/N + ½·g_i/Σg, where the guide g
   (:func:`guide`) is where error is likely: the halves map squared and spread over each pixel's
   3×3 neighbourhood plus the squared colour step to the pixel's 4 neighbours (edges and texture
   detail, at any spp). Half the draws are uniform, so error the guide misses is still found. The
   generator (splitmix64) is seeded; the choice does not depend on the thread count.
2. Render those pixels again in K passes of the C++ renderer (``RenderSettings.pixels``), each
   with 64 stratified samples per pixel of its own seed, every sample shaded (SSAA) and every
   texture read at level 0 with bilinear reconstruction: each sample is a point of the pixel's
   box-filtered footprint integral, the quantity the study's references integrate. The reference
   R_i is the mean of the passes; v_i² = Σ_k (R_i^k − R_i)²/(K·(K − 1)) estimates its own squared
   error without bias. K = max(2, S/16) for S samples per pixel, so the reference stays finer
   than the render.
3. d_i² = mean over R, G, B of (render_i − R_i)² − v_i² is an unbiased estimate of the pixel's
   squared error, and MSE = (1/n)·Σ_k d_k²/(N·p_k) one of the image's mean squared error; the
   spread of the n terms gives its standard error SE.
4. Resolution: when the MSE is not 2 SE above zero and the reference's own squared error is
   larger than it (a very accurate render: the reference's noise hides its error), the passes
   double, up to 16 (1024 samples per pixel), and the estimate is made again. If the reference
   still hides it, the probe reports an upper bound, ``rmse`` = √(max(MSE, 0) + 2·SE) with
   ``upper_bound`` True: the image's RMSE is at most that (one-sided, about 98 %). An MSE that
   is noisy only because few pixels were drawn stays a point estimate with its standard error.
5. Reuse: a drawn pixel's reference depends on the seed, the pass and the pixel, not on the image.
   A :class:`ProbeReference` given to :func:`measure_error` keeps the draws and their passes; a later
   probe of another image of the same scene (adaptive quality after a refinement pass) given it
   renders no reference pixel again and returns exactly what a fresh probe of the same draws
   (the same seed and guide) would.

The cost is n pixels × K × 64 samples plus K setups of the scene, reported in ``ms``; by default
n = W·H·S/(K·256) (a quarter of the render's samples) kept within [512, 4096]: at 1 spp a
320×240 probe then renders 512 × 128 reference samples, 0.85× the render's own; at 32 spp,
4096 × 128, 0.21×.
"""
from __future__ import annotations

import math
from typing import Any, Optional, Sequence

import numpy as np

from . import _core

__all__ = ["ErrorProbe", "ProbeReference", "default_pixel_count", "guide", "measure_error", "reference_passes", "rms"]

#: What the sparse reference measured: ``rmse`` (an upper bound when ``upper_bound``), ``stderr``,
#: ``pixels`` (draws), ``distinct_pixels``, ``reference_spp`` (all passes), ``rendered_passes`` (the
#: passes this probe rendered; 0 when all came from a ProbeReference), ``reference_rmse`` (the
#: reference's own error), ``halves_rmse`` (None without a halves map) and ``ms`` (its cost).
ErrorProbe = _core.ErrorProbe

#: A probe's draws and their reference passes (``draws``, ``distinct_pixels``, ``passes``,
#: ``empty``): ``ProbeReference()`` is empty; the first :func:`measure_error` given it fills it.
ProbeReference = _core.ProbeReference


def reference_passes(spp: int) -> int:
    """Passes of 64 samples the reference of a render with ``spp`` samples per pixel starts with."""
    return _core.probe_reference_passes(spp)


def default_pixel_count(width: int, height: int, spp: int) -> int:
    """The pixels a probe renders by default: a quarter of the render's samples at
    ``reference_passes(spp)`` × 64 samples each, at least 512 and at most 4096."""
    return _core.default_probe_pixels(width, height, spp)


def guide(color: np.ndarray, halves_map: Optional[np.ndarray]) -> np.ndarray:
    """Where error is likely, (H, W) float32 ≥ 0: the halves map squared, spread over 3×3
    neighbourhoods, plus the largest squared half colour step (mean over R, G, B) to the 4 neighbours."""
    return _core.error_guide(np.ascontiguousarray(color, dtype=np.float32), halves_map)


def rms(a: np.ndarray) -> float:
    """The root mean square of ``a``, summed in double precision."""
    flat = np.asarray(a, dtype=np.float64).ravel()  # (not np.dot: BLAS threads stall on a busy machine)
    return math.sqrt(float((flat * flat).sum()) / flat.size) if flat.size else 0.0


def measure_error(draws: Sequence[Any], camera: Any, settings: Any, color: np.ndarray,
                  halves_map: Optional[np.ndarray], pixels: int, seed: int = 0,
                  guide_map: Optional[np.ndarray] = None, reuse: Optional[ProbeReference] = None) -> ErrorProbe:
    """Estimates the RMSE of ``color`` (H, W, 4, linear), the render of the core ``draws`` through
    the core ``camera`` with core ``settings``, from ``pixels`` pixels rendered again at reference
    quality (see the module docstring). ``halves_map`` (H, W) is the render's halves map or None;
    ``guide_map`` is ``guide(color, halves_map)`` when the caller has it; ``seed`` makes another choice.
    ``reuse``: a :class:`ProbeReference`; when filled, its draws and reference passes are measured
    against (``pixels``, ``seed`` and the guide are not used), when empty it is filled.

    Raises ValueError naming a bad input (``probe_pixels`` < 1, a map of another size, a ``reuse``
    filled for another image size)."""
    if not (isinstance(pixels, int) and pixels >= 1):
        raise ValueError(f"probe_pixels: expected a number of pixels >= 1, got {pixels!r}")
    return _core.measure_error(list(draws), camera, settings, color, halves_map, pixels, seed, guide_map, reuse)
