"""Adaptive quality: more samples only on the tiles whose estimated error is above a target.

A first pass renders every tile at the requested samples per pixel with the error estimate on
(two interleaved halves of each pixel's samples; see :func:`mipraster.render`). Each 32×32 tile
whose estimated RMSE exceeds the target is rendered again at 4× the samples (the renderer's tile
mask skips all other tiles), and so on up to 64 samples. A tile that meets the target keeps its
pixels, so the estimate of the whole image meets it too once every tile does (or has 64 samples).
"""
from __future__ import annotations

import math
from typing import Any, List

import numpy as np

from . import _checks, _core

__all__ = ["tile_rmse", "render_adaptive_settings"]

# Each refinement quadruples the samples (halves the standard error of independent samples).
_REFINE_FACTOR = 4


def tile_rmse(error_map: np.ndarray, tile: int = _core.TILE_SIZE) -> np.ndarray:
    """Root mean square of ``error_map`` (H, W) over each ``tile``×``tile`` block, as (tiles_y, tiles_x)."""
    h, w = error_map.shape
    ty, tx = -(-h // tile), -(-w // tile)
    padded = np.zeros((ty * tile, tx * tile), dtype=np.float64)
    counts = np.zeros_like(padded)
    padded[:h, :w] = np.asarray(error_map, dtype=np.float64) ** 2
    counts[:h, :w] = 1.0
    sums = padded.reshape(ty, tile, tx, tile).sum(axis=(1, 3))
    n = counts.reshape(ty, tile, tx, tile).sum(axis=(1, 3))
    return np.sqrt(sums / n)


def render_adaptive_settings(draws: List[Any], camera: Any, settings: Any, target_error: Any) -> Any:
    """Adaptive render of already checked core draws / camera / settings (``mipraster.render`` calls this).

    Raises ValueError for a target that is not a finite number > 0 or with ``keep_samples``.
    """
    from .render import RenderResult

    target = _checks.real(target_error, "target_error")
    if not (math.isfinite(target) and target > 0.0):
        raise ValueError(f"target_error: expected a finite RMSE > 0 (linear colour), got {target!r}")
    if settings.keep_samples:
        raise ValueError("target_error: cannot keep the samples of an adaptive render (tiles differ in samples per pixel)")
    settings.estimate_error = True
    settings.tile_mask = []
    raw = _core.render(draws, camera, settings)
    color, error_map, depth = raw["color"], raw["error_map"], raw["depth"]
    stats = dict(raw["stats"])
    tile = _core.TILE_SIZE
    per_tile = tile_rmse(error_map, tile)
    spp = settings.samples
    tile_spp = np.full(per_tile.shape, spp, dtype=np.int64)
    while spp < _core.MAX_SAMPLES:
        refine = per_tile > target
        if not refine.any():
            break
        spp = min(_core.MAX_SAMPLES, spp * _REFINE_FACTOR)
        settings.samples = spp
        settings.tile_mask = refine.astype(np.uint8).ravel().tolist()
        again = _core.render(draws, camera, settings)
        for ty, tx in zip(*np.nonzero(refine)):
            rows = slice(ty * tile, (ty + 1) * tile)
            cols = slice(tx * tile, (tx + 1) * tile)
            color[rows, cols] = again["color"][rows, cols]
            error_map[rows, cols] = again["error_map"][rows, cols]
            if depth is not None and again["depth"] is not None:
                depth[rows, cols] = again["depth"][rows, cols]
        for key, value in again["stats"].items():
            if key != "threads":
                stats[key] += value
        per_tile = np.where(refine, tile_rmse(error_map, tile), per_tile)
        tile_spp[refine] = spp
    raw["color"], raw["error_map"], raw["depth"], raw["stats"] = color, error_map, depth, stats
    raw["error_estimate"] = float(np.sqrt(np.mean(np.asarray(error_map, dtype=np.float64) ** 2)))
    raw["tile_spp"] = tile_spp
    return RenderResult(raw)
