"""The primitive layer: bring your own transforms, get per-sample visibility back.

:func:`rasterize` clips and rasterizes clip-space triangles (watertight, top-left rule, depth
test) and returns, for every sample, which triangle covers it and where; :func:`interpolate`
turns that into per-sample vertex attributes (and, on request, their analytic screen-space
derivatives); :func:`resolve` averages samples into pixels::

    raster = mr.rasterize(pos_clip, triangles, 256, 256, spp=4)
    uv = mr.interpolate(uvs, raster, triangles)            # (256, 256, 4, 2)
    image = mr.resolve(shade(uv))                          # (256, 256, C)
    uv, duv_dx, duv_dy = mr.interpolate(uvs, raster, triangles, derivatives=True)
"""
from __future__ import annotations

from typing import Any, Dict, Literal, Tuple, Union, overload

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
        pos_clip: ``(N, 4)`` float64 copy of the clip-space vertex positions given to
            :func:`rasterize` (what ``interpolate(derivatives=True)`` needs).
        w: ``(N,)`` float64 clip-space w of the vertices (a view of ``pos_clip[:, 3]``; what
            ``interpolate(mode="screen")`` needs).
    """

    __slots__ = ("triangle_id", "barycentrics", "depth", "pattern", "pattern_kind", "stats", "pos_clip", "w")

    def __init__(self, raw: Dict[str, Any], pos_clip: np.ndarray) -> None:
        self.triangle_id: np.ndarray = raw["triangle_id"]
        self.barycentrics: np.ndarray = raw["barycentrics"]
        self.depth: np.ndarray = raw["depth"]
        self.pattern: np.ndarray = raw["pattern"]
        self.pattern_kind: str = raw["pattern_kind"]
        self.stats: Dict[str, Union[int, float]] = raw["stats"]
        self.pos_clip: np.ndarray = pos_clip
        self.w: np.ndarray = pos_clip[:, 3]

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
    return Raster(_core.rasterize(pos, tri, settings), pos.copy())  # pos may be the caller's array


@overload
def interpolate(attributes: Any, raster: Raster, triangles: Any, mode: str = ...,
                derivatives: Literal[False] = ...) -> np.ndarray: ...


@overload
def interpolate(attributes: Any, raster: Raster, triangles: Any, mode: str,
                derivatives: Literal[True]) -> Tuple[np.ndarray, np.ndarray, np.ndarray]: ...


@overload
def interpolate(attributes: Any, raster: Raster, triangles: Any, mode: str = ..., *,
                derivatives: Literal[True]) -> Tuple[np.ndarray, np.ndarray, np.ndarray]: ...


@overload
def interpolate(attributes: Any, raster: Raster, triangles: Any, mode: str = ...,
                derivatives: bool = ...) -> Union[np.ndarray, Tuple[np.ndarray, np.ndarray, np.ndarray]]: ...


def interpolate(attributes: Any, raster: Raster, triangles: Any, mode: str = "perspective",
                derivatives: bool = False) -> Union[np.ndarray, Tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Vertex attributes at every sample of ``raster``, and optionally their screen-space derivatives.

    Args:
        attributes: ``(N, K)`` (or ``(N,)``) per-vertex values, any real dtype.
        raster: the :class:`Raster` of these ``triangles``.
        triangles: the ``(T, 3)`` indices given to :func:`rasterize`.
        mode: ``"perspective"`` (perspective-correct, the default), ``"screen"`` (affine in screen
            space, the seeds' "perspective-incorrect" interpolation) or ``"flat"`` (the value of each
            triangle's first vertex).
        derivatives: also return the analytic derivatives of the interpolated values with respect
            to screen position, per pixel: ``d_dx`` one pixel to the right, ``d_dy`` one pixel down
            (row 0 is the top row). They are exact derivatives of the interpolation function of the
            submitted (unclipped, unsnapped) triangle at each sample's position (pixel corner +
            :attr:`Raster.pattern` offset), computed in clip space so that triangles crossing the
            near plane need no special care; 0 for ``"flat"``.

    Returns:
        ``(H, W, S, K)`` float32 (``(H, W, S)`` for 1-D attributes); 0 where no triangle covers
        the sample. With ``derivatives=True``, the tuple ``(values, d_dx, d_dy)`` of three such
        arrays.
    """
    if not isinstance(raster, Raster):
        raise TypeError(f"raster: expected a mipraster.Raster (from rasterize), got {type(raster).__name__}")
    attr = _checks.real_array(attributes, "attributes")
    one_d = attr.ndim == 1
    if one_d:
        attr = attr[:, None]
    _checks.check_shape(attr, "attributes", (raster.w.shape[0], None))
    _checks.check_finite(attr, "attributes")
    _checks.check_fits_float32(attr, "attributes")  # (the float32 result would hold inf)
    tri = _triangles(triangles, raster.w.shape[0])
    mode = _checks.choice(mode, "mode", {m: m for m in INTERPOLATION_MODES})
    want_derivatives = _checks.flag(derivatives, "derivatives")
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
        # The stored weights are float32: b1 + b2 may round above 1, and the first weight below 0
        # (values then left the vertex range: [1e6, 0, 0] gave -0.011). Kept convex.
        weights = np.maximum(np.stack([1.0 - b[:, 0] - b[:, 1], b[:, 0], b[:, 1]], axis=1), 0.0)  # (M, 3)
        if mode == "screen":
            # Perspective-correct weights are (λ_i / w_i) normalized: λ_i ∝ weight_i · w_i.
            weights = weights * raster.w[corners]
        weights /= weights.sum(axis=1, keepdims=True)
        result = np.einsum("mi,mik->mk", weights, values)

    def scatter(per_sample: np.ndarray) -> np.ndarray:
        out = np.zeros(ids.shape + (attr.shape[1],), dtype=np.float32)
        out[covered] = per_sample
        return out[..., 0] if one_d else out

    if not want_derivatives:
        return scatter(result)
    if mode == "flat":
        zeros = np.zeros_like(result)
        return scatter(result), scatter(zeros), scatter(zeros)
    d_dx, d_dy = _screen_derivatives(raster, covered, corners, values, mode)
    return scatter(result), scatter(d_dx), scatter(d_dy)


def _screen_derivatives(raster: Raster, covered: np.ndarray, corners: np.ndarray, values: np.ndarray,
                        mode: str) -> Tuple[np.ndarray, np.ndarray]:
    """``(M, K)`` derivatives per pixel (x right, y down) of the interpolated ``values`` ``(M, 3, K)``.

    With the vertices as 2D homogeneous points v_i = (x_i, y_i, w_i) (clip x, y, w) and the sample's
    NDC position p = (X, Y, 1), e_i = (v_j × v_k) · p ((i, j, k) cyclic) is proportional to the
    perspective-correct weight of vertex i (e_i = β_i det(v_0, v_1, v_2) / w at the sample), so
    b_i = e_i / Σe. This holds for any signs of the w_i, so clipped triangles need nothing special.
    Screen-space weights are λ_i = b_i w_i / Σ b_j w_j = e_i w_i / Σ e_j w_j. Both are q_i / Σq
    with q linear in (X, Y): ∂(q_i / Σq) = (∂q_i − (q_i / Σq) Σ∂q) / Σq.
    """
    h, w, _ = covered.shape
    rows, cols, samples = np.nonzero(covered)
    offsets = raster.pattern[samples]  # (M, 2) from the pixel's top-left corner
    ndc_x = (cols + offsets[:, 0]) * (2.0 / w) - 1.0
    ndc_y = 1.0 - (rows + offsets[:, 1]) * (2.0 / h)

    v = raster.pos_clip[corners][:, :, [0, 1, 3]]  # (M, 3 vertices, (x, y, w))
    planes = np.cross(v[:, [1, 2, 0]], v[:, [2, 0, 1]])  # (M, 3, 3): row i = v_j × v_k = (A_i, B_i, C_i)
    q = planes[:, :, 0] * ndc_x[:, None] + planes[:, :, 1] * ndc_y[:, None] + planes[:, :, 2]  # (M, 3)
    q_x, q_y = planes[:, :, 0], planes[:, :, 1]
    if mode == "screen":
        q, q_x, q_y = q * v[:, :, 2], q_x * v[:, :, 2], q_y * v[:, :, 2]
    total = q.sum(axis=1, keepdims=True)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        weights = q / total
        d_dX = (q_x - weights * q_x.sum(axis=1, keepdims=True)) / total  # (M, 3) ∂weight_i / ∂X
        d_dY = (q_y - weights * q_y.sum(axis=1, keepdims=True)) / total
        # NDC → pixels: X = 2x/W − 1, Y = 1 − 2y/H.
        d_dx = np.einsum("mi,mik->mk", d_dX, values) * (2.0 / w)
        d_dy = np.einsum("mi,mik->mk", d_dY, values) * (-2.0 / h)
    # A covered sample has Σq ≠ 0 (its triangle has area and the sample lies in front of the eye);
    # should rounding say otherwise, report 0 rather than let a NaN or Inf through.
    d_dx[~np.isfinite(d_dx)] = 0.0
    d_dy[~np.isfinite(d_dy)] = 0.0
    return d_dx, d_dy


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
