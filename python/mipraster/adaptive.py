"""Adaptive quality: more samples only on the tiles whose estimated error needs them.

A first pass renders every tile at the requested samples per pixel S₀ with the error estimate on
(two interleaved halves of each pixel's samples; see :func:`mipraster.render`). With error ∝ 1/√S,
tile t's variance v_t = e_t²·S_t is known, and the fewest samples that bring the image's estimated
RMSE to the target T are S'_t = √v_t·Σ_u √v_u / (N·T²) (minimize Σ S'_t subject to
Σ v_t/S'_t ≤ N·T², N tiles). Each tile that needs more than it has is rendered again with S'_t
rounded up to S₀·2^k (at most 64); tiles that need the same count share one pass (the renderer's
tile mask skips all others). The estimate is measured again and the rounds go on until the image's
estimate meets the target or every tile with any error has 64 samples. Tiles with no estimated error
(nothing but flat colour) are never rendered again.
"""
from __future__ import annotations

import math
from typing import Any, List

import numpy as np

from . import _checks, _core

__all__ = ["tile_rmse", "render_adaptive_settings"]



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
    base = settings.samples
    tile_spp = np.full(per_tile.shape, base, dtype=np.int64)
    count = np.ones_like(per_tile)  # pixels per tile, for the image's mean
    count[:] = np.bincount((np.arange(color.shape[0])[:, None] // tile * per_tile.shape[1]
                            + np.arange(color.shape[1])[None, :] // tile).ravel(),
                           minlength=per_tile.size).reshape(per_tile.shape)
    while True:
        image_mse = float((per_tile ** 2 * count).sum() / count.sum())
        open_tiles = (per_tile > 0) & (tile_spp < _core.MAX_SAMPLES)
        if image_mse <= target * target or not open_tiles.any():
            break
        # The optimal allocation for the image's mean squared error (see the module docstring).
        sd = per_tile * np.sqrt(tile_spp) * np.sqrt(count)
        need = sd / np.sqrt(count) * sd.sum() / (count.sum() * target * target)
        steps = np.ceil(np.log2(np.maximum(need / base, 1.0)) - 1e-9).astype(np.int64)
        wanted = np.minimum(_core.MAX_SAMPLES, base * 2 ** np.minimum(steps, 6))
        wanted = np.where(open_tiles & (wanted > tile_spp), wanted, tile_spp)
        if (wanted == tile_spp).all():
            # The estimate is just above the target and rounding left nothing to do: double the
            # samples of every open tile that holds more than its share of the squared error.
            share = np.where(open_tiles, per_tile ** 2 * count, 0.0)
            big = open_tiles & (share >= share[open_tiles].mean())
            wanted = np.where(big, np.minimum(_core.MAX_SAMPLES, 2 * tile_spp), tile_spp)
        todo = wanted > tile_spp
        if settings.pattern == _core.PatternKind.rotated:
            settings.pattern = _core.PatternKind.grid  # the rotated pattern has 4 samples only
        for spp in sorted(set(wanted[todo].tolist())):
            group = todo & (wanted == spp)
            settings.samples = int(spp)
            settings.tile_mask = group.astype(np.uint8).ravel().tolist()
            again = _core.render(draws, camera, settings)
            for ty, tx in zip(*np.nonzero(group)):
                rows = slice(ty * tile, (ty + 1) * tile)
                cols = slice(tx * tile, (tx + 1) * tile)
                color[rows, cols] = again["color"][rows, cols]
                error_map[rows, cols] = again["error_map"][rows, cols]
                if depth is not None and again["depth"] is not None:
                    depth[rows, cols] = again["depth"][rows, cols]
            for key, value in again["stats"].items():
                if key != "threads":
                    stats[key] += value
            tile_spp[group] = spp
        per_tile = np.where(todo, tile_rmse(error_map, tile), per_tile)
    settings.samples = base
    raw["color"], raw["error_map"], raw["depth"], raw["stats"] = color, error_map, depth, stats
    raw["error_estimate"] = float(np.sqrt(np.mean(np.asarray(error_map, dtype=np.float64) ** 2)))
    raw["tile_spp"] = tile_spp
    return RenderResult(raw)
