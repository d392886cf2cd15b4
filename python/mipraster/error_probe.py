"""A render's error measured against a sparse reference: a few hundred of its pixels rendered again
at reference quality.

The halves estimate (two interleaved halves of each pixel's samples, ``RenderSettings.estimate_error``)
says *where* a render is uncertain, but it cannot see error that both halves share (the blur of a
mip-mapped filter, MSAA's one shade per pixel), it is noisy with few samples per half and it gives
nothing at one sample per pixel. The probe says *how much*, for any scene and configuration:

1. Choose n pixels at random, i.i.d. with probability p_i = ½/N + ½·g_i/Σg, where the guide g is
   where error is likely: the halves map squared and spread over each pixel's 3×3 neighbourhood
   (an edge pixel whose halves happen to agree lies next to one whose halves do not) plus the
   squared colour step to the pixel's 4 neighbours (edges and texture detail, at any spp). Half
   the draws are uniform, so error the guide misses is still found. The generator is seeded; the
   choice does not depend on the thread count.
2. Render those pixels again in K ≥ 2 passes of the C++ renderer (``RenderSettings.pixels``: one
   transform and setup each), each with 64 stratified samples per pixel of its own seed, every
   sample shaded (SSAA) and every texture read at level 0 with bilinear reconstruction: each
   sample is a point of the pixel's box-filtered footprint integral, the quantity the study's
   references integrate. The reference R_i is the mean of the passes; their errors are
   independent, so v_i² = Σ_k (R_i^k − R_i)²/(K·(K − 1)) estimates R_i's own squared error without
   bias (a split of one pass into halves would not: stratified halves overstate it). K = 2, and
   K = 2·S/32 for S > 32 samples per pixel, so the reference stays finer than the render.
3. d_i² = mean over R, G, B of (render_i − R_i)² − v_i² is an unbiased estimate of the pixel's
   squared error (the render's and the reference's sample errors are independent), and
   MSE = (1/n)·Σ_k d_k²/(N·p_k) an unbiased estimate of the image's mean squared error; the
   spread of the n terms gives its standard error.

The cost is n pixels × K × 64 samples plus K setups of the scene, reported in ``ms``; by default
n = W·H·S/(K·256) (a quarter of the render's samples) kept within [64, 1024].
"""
from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

from . import _core

__all__ = ["ErrorProbe", "default_pixel_count", "guide", "measure_error", "reference_passes", "reference_scene",
           "rms", "spread"]

REFERENCE_SPP = 64  # _core.MAX_SAMPLES: the most samples one pass gives a pixel
MIN_PASSES = 2  # independent passes: their disagreement is the reference's own error
# Distinct from any pattern seed a user is likely to pick, so the reference's samples are not the
# render's own (the estimate needs their errors independent).
REFERENCE_SEED = 0x9E3779B97F4A7C15
MIN_PIXELS, MAX_PIXELS = 64, 1024  # enough pixels to find sparse edges; a bounded cost


@dataclass(frozen=True)
class ErrorProbe:
    """What the sparse reference measured.

    Attributes:
        rmse: the estimated RMSE of the image (linear R, G, B); 0 when the estimate of the mean
            squared error came out ≤ 0 (an image more accurate than the probe can tell).
        stderr: the standard error of ``rmse`` (from the spread of the per-pixel terms).
        pixels: the number of draws n (a pixel drawn twice counts twice).
        distinct_pixels: the pixels rendered again.
        reference_spp: samples per pixel of the reference (all passes).
        halves_rmse: the halves estimate of the whole image (None without a halves map).
        ms: wall time of the probe (choice, reference pass, arithmetic) in milliseconds.
    """

    rmse: float
    stderr: float
    pixels: int
    distinct_pixels: int
    reference_spp: int
    halves_rmse: Optional[float]
    ms: float

    def __repr__(self) -> str:
        halves = "" if self.halves_rmse is None else f", halves_rmse={self.halves_rmse:.4g}"
        return (f"ErrorProbe(rmse={self.rmse:.4g} ± {self.stderr:.2g}, pixels={self.pixels} "
                f"({self.distinct_pixels} distinct) at {self.reference_spp} spp{halves}, ms={self.ms:.2f})")


def reference_passes(spp: int) -> int:
    """Passes of 64 samples the reference of a render with ``spp`` samples per pixel gets."""
    return max(MIN_PASSES, 2 * spp // 32)


def default_pixel_count(width: int, height: int, spp: int) -> int:
    """The pixels a probe renders by default: a quarter of the render's samples at
    ``reference_passes(spp)`` × 64 samples each, at least 64 and at most 1024."""
    budget = width * height * spp / (4 * REFERENCE_SPP * reference_passes(spp))
    return int(min(MAX_PIXELS, max(MIN_PIXELS, round(budget))))


def guide(color: np.ndarray, halves_map: Optional[np.ndarray]) -> np.ndarray:
    """Where error is likely, (H, W) ≥ 0: the halves map squared, spread over 3×3 neighbourhoods,
    plus the largest squared half colour step (mean over R, G, B) to the 4 neighbours."""
    planes = np.moveaxis(np.asarray(color, dtype=np.float32)[..., :3], 2, 0).copy()  # R, G, B planes
    step = np.zeros(planes.shape[1:], dtype=np.float32)
    down = np.zeros((step.shape[0] - 1, step.shape[1]), dtype=np.float32)
    right = np.zeros((step.shape[0], step.shape[1] - 1), dtype=np.float32)
    for p in planes:  # mean over R, G, B of (half the step)²
        d = p[1:] - p[:-1]
        down += d * d / 12
        d = p[:, 1:] - p[:, :-1]
        right += d * d / 12
    np.maximum(step[1:], down, out=step[1:])
    np.maximum(step[:-1], down, out=step[:-1])
    np.maximum(step[:, 1:], right, out=step[:, 1:])
    np.maximum(step[:, :-1], right, out=step[:, :-1])
    if halves_map is None:
        return step
    m = np.asarray(halves_map, dtype=np.float32)
    return step + spread(m * m)


def rms(a: np.ndarray) -> float:
    """The root mean square of ``a``, summed in double precision."""
    flat = np.asarray(a, dtype=np.float64).ravel()  # (not np.dot: BLAS threads stall on a busy machine)
    return math.sqrt(float((flat * flat).sum()) / flat.size) if flat.size else 0.0


def spread(a: np.ndarray) -> np.ndarray:
    """The mean of ``a`` (H, W) over each pixel's 3×3 neighbourhood (zero outside the image)."""
    h, w = a.shape
    padded = np.pad(a, 1)
    rows = padded[:-2] + padded[1:-1] + padded[2:]  # separable: 3 rows, then 3 columns
    return (rows[:, :-2] + rows[:, 1:-1] + rows[:, 2:]) / 9


def reference_scene(scene: Any) -> Any:
    """A copy of ``scene`` whose textured draws read level 0 with bilinear reconstruction (wrap,
    border colour and everything else kept)."""
    from .scene import Scene

    out = Scene()
    out.clear_color = scene.clear_color
    for d in scene.draws:
        sampler = None
        if d.texture is not None:
            sampler = dataclasses.replace(d.sampler, filter="bilinear", mag_filter=None, min_filter=None,
                                          mip_filter=None)
        out.add(d.mesh, model=d.model, color=d.color, depth_test=d.depth_test, depth_write=d.depth_write,
                blend=d.blend, interpolation=d.interpolation, cull=d.cull, texture=d.texture, sampler=sampler)
    return out


def measure_error(scene: Any, camera: Any, settings: Any, color: np.ndarray, halves_map: Optional[np.ndarray],
                  pixels: int, seed: int = 0, guide_map: Optional[np.ndarray] = None) -> ErrorProbe:
    """Estimates the RMSE of ``color`` (H, W, ≥3, linear), the render of ``scene`` (a
    :class:`mipraster.Scene`) through the core ``camera`` with core ``settings``, from ``pixels``
    pixels rendered again at reference quality (see the module docstring). ``halves_map`` (H, W)
    is the render's halves map or None; ``guide_map`` is ``guide(color, halves_map)`` when the
    caller has it; ``seed`` makes another choice."""
    from .scene import _core_draws

    start = time.perf_counter()
    h, w = color.shape[:2]
    n_all = w * h
    if not (isinstance(pixels, int) and pixels >= 1):
        raise ValueError(f"probe_pixels: expected a number of pixels >= 1, got {pixels!r}")
    halves_rmse = None if halves_map is None else rms(halves_map)
    g = (guide(color, halves_map) if guide_map is None else guide_map).astype(np.float64).ravel()
    total = g.sum()
    weight = 0.5 / n_all + 0.5 * g / total if total > 0 else np.full(n_all, 1.0 / n_all)
    cdf = np.cumsum(weight)
    p = weight / cdf[-1]  # the probability of drawing each pixel
    rng = np.random.Generator(np.random.PCG64([seed, w, h, pixels]))
    chosen = np.minimum(np.searchsorted(cdf, rng.random(pixels) * cdf[-1], side="right"), n_all - 1)
    distinct = np.unique(chosen)

    ref = _core.RenderSettings()
    ref.width, ref.height, ref.samples = w, h, REFERENCE_SPP
    ref.pattern = _core.PatternKind.stratified
    ref.anti_aliasing = _core.AntiAliasing.ssaa
    ref.threads, ref.clear_color = settings.threads, settings.clear_color
    ref.derivatives, ref.debug_view = settings.derivatives, settings.debug_view
    ref.pixels = distinct.tolist()
    draws = _core_draws(reference_scene(scene))
    ys, xs = np.divmod(chosen, w)
    k_passes = reference_passes(settings.samples)
    passes = []
    for k in range(k_passes):
        ref.pattern_seed = (REFERENCE_SEED + k) ^ seed
        passes.append(_core.render(draws, camera, ref)["color"][ys, xs, :3].astype(np.float64))
    reference = sum(passes) / k_passes
    # E[own] = the reference's squared error (the sample variance of the passes' mean).
    own = (sum((q - reference) ** 2 for q in passes).mean(axis=1)) / (k_passes * (k_passes - 1))
    diff = np.asarray(color)[ys, xs, :3].astype(np.float64) - reference
    terms = ((diff * diff).mean(axis=1) - own) / (n_all * p[chosen])
    mse = float(terms.mean())
    mse_se = float(terms.std(ddof=1) / math.sqrt(pixels)) if pixels > 1 else math.inf
    rmse = math.sqrt(max(mse, 0.0))
    # The delta method where the RMSE is well above its noise; √(standard error of the MSE) near 0.
    stderr = mse_se / (2.0 * rmse) if rmse > 0 and mse_se < mse else math.sqrt(mse_se)
    return ErrorProbe(rmse=rmse, stderr=stderr, pixels=pixels, distinct_pixels=int(distinct.size),
                      reference_spp=REFERENCE_SPP * k_passes, halves_rmse=halves_rmse,
                      ms=(time.perf_counter() - start) * 1000.0)
