"""The primitive layer: bring your own transforms, get per-sample visibility back.

:func:`rasterize` clips and rasterizes clip-space triangles (watertight, top-left rule, depth
test) and returns, for every sample, which triangle covers it and where; :func:`interpolate`
turns that into per-sample vertex attributes; :func:`resolve` averages samples into pixels::

    raster = mr.rasterize(pos_clip, triangles, 256, 256, spp=4)
    uv = mr.interpolate(uvs, raster, triangles)            # (256, 256, 4, 2)
    image = mr.resolve(shade(uv))                          # (256, 256, C)
"""
from __future__ import annotations

from typing import Any, Dict, Union

import numpy as np

from . import _checks, _core
from .render import PATTERNS, _INT32_MAX, _INT32_MIN, _int_in
from .scene import CULL_MODES

__all__ = ["Raster", "rasterize", "interpolate", "resolve"]

DEPTH_CONVENTIONS = {"opengl": _core.DepthConvention.opengl, "reverse_z": _core.DepthConvention.reverse_z}
INTERPOLATION_MODES = ("perspective", "screen", "flat")
RESOLVE_FILTERS = ("box",)


class Raster:
    """The output of :func:`rasterize`; arrays are indexed ``[row, column, sample]``.

    Attributes:
        triangle_id: ``(H, W, S)`` int32, the index of the nearest triangle covering each sample,
            −1 where none does.
        barycentrics: ``(H, W, S, 2)`` float32, the perspective-correct weights of that triangle's
            2nd and 3rd vertex (the 1st has weight 1 − both); 0 where empty. They refer to the
            submitted triangle also where it was clipped.
        depth: ``(H, W, S)`` float32 window depth (``opengl``: z/w / 2 + ½, 1 where empty;
            ``reverse_z``: z/w, 0 where empty).
        pattern: ``(S, 2)`` float64 sample offsets from the pixel's top-left corner, in pixels.
        pattern_kind: the sample pattern used.
        stats: dict of counters and times, as :attr:`RenderResult.stats`.
        w: ``(N,)`` float64 clip-space w of the vertices (what ``interpolate(mode="screen")`` needs).
    """

    __slots__ = ("triangle_id", "barycentrics", "depth", "pattern", "pattern_kind", "stats", "w")

    def __init__(self, raw: Dict[str, Any], w: np.ndarray) -> None:
        self.triangle_id: np.ndarray = raw["triangle_id"]
        self.barycentrics: np.ndarray = raw["barycentrics"]
        self.depth: np.ndarray = raw["depth"]
        self.pattern: np.ndarray = raw["pattern"]
        self.pattern_kind: str = raw["pattern_kind"]
        self.stats: Dict[str, Union[int, float]] = raw["stats"]
        self.w: np.ndarray = w

    def __repr__(self) -> str:
        h, w, s = self.triangle_id.shape
        return f"Raster({w}x{h}, spp={s} {self.pattern_kind}, samples_covered={self.stats['samples_covered']})"


def _triangles(triangles: Any, n_vertices: int) -> np.ndarray:
    tri = _checks.empty_rows(_checks.integer_array(triangles, "triangles"), 3)
    _checks.check_shape(tri, "triangles", (None, 3), letters=("T",))
    if tri.size:
        flat = int(np.argmin(tri)) if tri.min() < 0 else int(np.argmax(tri))
        bad = tri.flat[flat]
        if bad < 0 or bad >= n_vertices:
            row, corner = divmod(flat, 3)
            raise ValueError(f"triangles[{row}][{corner}] = {bad} is out of range; expected 0 <= index < "
                             f"{n_vertices} (the vertex count)")
    return tri.astype(np.uint32)


def rasterize(pos_clip: Any, triangles: Any, width: int, height: int, spp: int = 1, pattern: str = "auto",
              seed: int = 0, threads: int = 0, depth: str = "opengl", cull: str = "none") -> Raster:
    """Clips and rasterizes triangles given by clip-space vertex positions.

    Args:
        pos_clip: ``(N, 4)`` clip-space positions (x, y, z, w), any real dtype; NDC is (x, y, z)/w with
            y up; pixel centres sit at NDC ((i + ½)·2/W − 1, 1 − (j + ½)·2/H).
        triangles: ``(T, 3)`` vertex indices, any integer dtype.
        width, height: image size in pixels, 1…32768 each.
        spp: samples per pixel, 1…64; ``pattern`` and ``seed`` as in :func:`render`.
        threads: worker threads, 0 = all cores. The output does not depend on it.
        depth: the clip-space depth convention: ``"opengl"`` (−w ≤ z ≤ w, nearer = smaller z) or
            ``"reverse_z"`` (0 ≤ z ≤ w, nearer = larger z). Triangles are clipped to that range.
        cull: ``"none"``, ``"back"`` or ``"front"`` (front faces are counter-clockwise on screen).

    Returns:
        A :class:`Raster`. The arrays own the C++ buffers (nothing was copied).

    Raises:
        TypeError / ValueError naming the argument (shape, dtype, NaN or infinite positions with
        their row, out-of-range indices with their row and corner, sizes, option names).
    """
    pos = _checks.empty_rows(_checks.real_array(pos_clip, "pos_clip"), 4)
    _checks.check_shape(pos, "pos_clip", (None, 4))
    _checks.check_finite(pos, "pos_clip")
    pos = np.ascontiguousarray(pos, dtype=np.float64)
    tri = _triangles(triangles, pos.shape[0])
    settings = _core.RasterizeSettings()
    settings.width = _int_in(width, "width", _INT32_MIN, _INT32_MAX, f"1 to {_core.MAX_DIMENSION} pixels")
    settings.height = _int_in(height, "height", _INT32_MIN, _INT32_MAX, f"1 to {_core.MAX_DIMENSION} pixels")
    settings.samples = _int_in(spp, "spp", _INT32_MIN, _INT32_MAX, f"1 to {_core.MAX_SAMPLES}")
    settings.pattern = _checks.choice(pattern, "pattern", PATTERNS)
    settings.pattern_seed = _int_in(seed, "seed", 0, 2**64 - 1, "0 <= seed < 2**64")
    settings.threads = _int_in(threads, "threads", _INT32_MIN, _INT32_MAX, f"0 (all cores) to {_core.MAX_THREADS}")
    settings.depth_convention = _checks.choice(depth, "depth", DEPTH_CONVENTIONS)
    settings.cull = _checks.choice(cull, "cull", CULL_MODES)
    return Raster(_core.rasterize(pos, tri, settings), pos[:, 3].copy())


def interpolate(attributes: Any, raster: Raster, triangles: Any, mode: str = "perspective") -> np.ndarray:
    """Vertex attributes at every sample of ``raster``.

    Args:
        attributes: ``(N, K)`` (or ``(N,)``) per-vertex values, any real dtype.
        raster: the :class:`Raster` of these ``triangles``.
        triangles: the ``(T, 3)`` indices given to :func:`rasterize`.
        mode: ``"perspective"`` (perspective-correct, the default), ``"screen"`` (affine in screen
            space, the seeds' "perspective-incorrect" interpolation) or ``"flat"`` (the value of each
            triangle's first vertex).

    Returns:
        ``(H, W, S, K)`` float32 (``(H, W, S)`` for 1-D attributes); 0 where no triangle covers
        the sample.
    """
    if not isinstance(raster, Raster):
        raise TypeError(f"raster: expected a mipraster.Raster (from rasterize), got {type(raster).__name__}")
    attr = _checks.real_array(attributes, "attributes")
    one_d = attr.ndim == 1
    if one_d:
        attr = attr[:, None]
    _checks.check_shape(attr, "attributes", (raster.w.shape[0], None))
    _checks.check_finite(attr, "attributes")
    tri = _triangles(triangles, raster.w.shape[0])
    mode = _checks.choice(mode, "mode", {m: m for m in INTERPOLATION_MODES})
    ids = raster.triangle_id
    if ids.size and ids.max() >= tri.shape[0]:
        raise ValueError(f"triangles: the raster refers to triangle {int(ids.max())} but only {tri.shape[0]} were "
                         "given; pass the triangles given to rasterize")
    covered = ids >= 0
    corners = tri[ids[covered]].astype(np.int64)  # (M, 3) vertex indices of each covered sample
    values = attr.astype(np.float64)[corners]  # (M, 3, K)
    if mode == "flat":
        result = values[:, 0, :]
    else:
        b = raster.barycentrics[covered].astype(np.float64)
        weights = np.stack([1.0 - b[:, 0] - b[:, 1], b[:, 0], b[:, 1]], axis=1)  # (M, 3)
        if mode == "screen":
            # Perspective-correct weights are (λ_i / w_i) normalized: λ_i ∝ weight_i · w_i.
            weights = weights * raster.w[corners]
            weights /= weights.sum(axis=1, keepdims=True)
        result = np.einsum("mi,mik->mk", weights, values)
    out = np.zeros(ids.shape + (attr.shape[1],), dtype=np.float32)
    out[covered] = result
    return out[..., 0] if one_d else out


def resolve(samples: Any, filter: str = "box") -> np.ndarray:
    """Reconstructs pixels from ``(H, W, S, K)`` (or ``(H, W, S)``) samples: ``"box"`` is the mean of
    each pixel's samples. Returns ``(H, W, K)`` (or ``(H, W)``) float32."""
    _checks.choice(filter, "filter", {f: f for f in RESOLVE_FILTERS})
    a = _checks.real_array(samples, "samples")
    if a.ndim not in (3, 4):
        raise ValueError(f"samples: expected an (H, W, S) or (H, W, S, K) array, got shape {a.shape}")
    if a.shape[2] == 0:
        raise ValueError("samples: expected at least one sample per pixel (axis 2), got 0")
    return a.astype(np.float64).mean(axis=2).astype(np.float32)
