"""Ground truth for error measurements: what a box-filtered pixel should be.

- :func:`exact_coverage`: flat-coloured 2D triangles in pixel coordinates, each triangle clipped
  against each pixel square in double precision (Sutherland–Hodgman), painter's order (a later
  triangle hides what is below it): the exact area-weighted colour of every pixel.
- :func:`plane_reference`: a textured parallelogram seen through a perspective camera, integrated
  by brute force: n×n jittered points per pixel, each cast as a ray in double precision, the texture
  read at level 0 with bilinear reconstruction (the box-filtered footprint average of the notes).
  Two independent jitters give the integration error, which is returned with it.
- :func:`converged_reference`: any scene, from mipraster itself at many samples (a finer image at
  64 stratified samples per pixel, box-averaged down, textures at level 0 with bilinear
  reconstruction), again with two independent jitters for its residual error.

Colours are linear; the error of an image is measured on R, G, B.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import List, Optional, Sequence, Tuple

import numpy as np

__all__ = [
    "clip_polygon",
    "polygon_area",
    "exact_coverage",
    "TexturedPlane",
    "PerspectiveView",
    "plane_reference",
    "bilinear_level0",
    "converged_reference",
    "image_error",
]

Point = Tuple[float, float]


def polygon_area(polygon: Sequence[Point]) -> float:
    """Unsigned area of a simple polygon (shoelace formula)."""
    n = len(polygon)
    if n < 3:
        return 0.0
    s = 0.0
    for i in range(n):
        x0, y0 = polygon[i]
        x1, y1 = polygon[(i + 1) % n]
        s += x0 * y1 - x1 * y0
    return abs(s) / 2.0


def clip_polygon(polygon: Sequence[Point], a: float, b: float, c: float) -> List[Point]:
    """The part of a convex polygon where a·x + b·y + c ≥ 0 (one Sutherland–Hodgman step)."""
    out: List[Point] = []
    n = len(polygon)
    for i in range(n):
        p, q = polygon[i], polygon[(i + 1) % n]
        fp = a * p[0] + b * p[1] + c
        fq = a * q[0] + b * q[1] + c
        if fp >= 0.0:
            out.append(p)
        if (fp >= 0.0) != (fq >= 0.0):
            t = fp / (fp - fq)
            out.append((p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])))
    return out


def _edges(tri: np.ndarray) -> Optional[List[Tuple[float, float, float]]]:
    """The three half-planes a·x + b·y + c ≥ 0 whose intersection is the triangle (None if degenerate)."""
    (x0, y0), (x1, y1), (x2, y2) = (tuple(map(float, v)) for v in tri)
    twice_area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
    if twice_area == 0.0:
        return None
    sign = 1.0 if twice_area > 0 else -1.0
    edges = []
    for (px, py), (qx, qy) in (((x0, y0), (x1, y1)), ((x1, y1), (x2, y2)), ((x2, y2), (x0, y0))):
        # (q − p) × ((x, y) − p) ≥ 0 on the triangle's side (for positive orientation).
        a, b = -(qy - py) * sign, (qx - px) * sign
        edges.append((a, b, -(a * px + b * py)))
    return edges


def exact_coverage(triangles: np.ndarray, colors: np.ndarray, width: int, height: int,
                   background: Sequence[float]) -> np.ndarray:
    """Exact box-filtered image of flat-coloured triangles drawn in order over a background.

    Args:
        triangles: ``(N, 3, 2)`` vertex positions in pixels (pixel (i, j) covers [i, i+1)×[j, j+1),
            y down), any orientation; degenerate triangles cover nothing.
        colors: ``(N, C)`` linear colour of each triangle.
        width, height: image size.
        background: ``C`` components where no triangle is.

    Returns:
        ``(height, width, C)`` float64: for each pixel, the sum over the visible parts of its
        square of area × colour. Later triangles are on top (painter's order): each pixel's square
        is split front to back into the part inside a triangle (which takes its colour) and the
        convex pieces outside it (which go on to the triangles below).
    """
    tris = np.asarray(triangles, dtype=np.float64).reshape(-1, 3, 2)
    cols = np.asarray(colors, dtype=np.float64).reshape(len(tris), -1)
    bg = np.asarray(background, dtype=np.float64).reshape(-1)
    if bg.shape[0] != cols.shape[1]:
        raise ValueError(f"background: expected {cols.shape[1]} components like colors, got {bg.shape[0]}")
    if not (np.all(np.isfinite(tris)) and np.all(np.isfinite(cols))):
        raise ValueError("triangles, colors: expected finite values")
    out = np.empty((height, width, cols.shape[1]))
    out[:] = bg

    # Which triangles can touch which pixel: bounding boxes, then a corner test per edge.
    touching: dict = {}
    edge_list = [_edges(t) for t in tris]
    for k, (tri, edges) in enumerate(zip(tris, edge_list)):
        if edges is None:
            continue
        x0 = max(0, int(math.floor(tri[:, 0].min())))
        x1 = min(width, int(math.floor(tri[:, 0].max())) + 1)
        y0 = max(0, int(math.floor(tri[:, 1].min())))
        y1 = min(height, int(math.floor(tri[:, 1].max())) + 1)
        if x0 >= x1 or y0 >= y1:
            continue
        ys, xs = np.mgrid[y0:y1, x0:x1]
        maybe = np.ones(xs.shape, dtype=bool)
        for a, b, c in edges:
            # The square is outside the edge when all four corners are.
            corner_max = np.maximum.reduce([a * (xs + dx) + b * (ys + dy) + c for dx in (0, 1) for dy in (0, 1)])
            maybe &= corner_max > 0.0
        for y, x in zip(ys[maybe], xs[maybe]):
            touching.setdefault((int(y), int(x)), []).append(k)

    for (y, x), ks in touching.items():
        pieces: List[List[Point]] = [[(x, y), (x + 1.0, y), (x + 1.0, y + 1.0), (x, y + 1.0)]]
        value = np.zeros(cols.shape[1])
        for k in reversed(ks):  # front to back
            edges = edge_list[k]
            remaining: List[List[Point]] = []
            for piece in pieces:
                inside = piece
                for a, b, c in edges:
                    outside = clip_polygon(inside, -a, -b, -c)
                    if polygon_area(outside) > 0.0:
                        remaining.append(outside)
                    inside = clip_polygon(inside, a, b, c)
                    if len(inside) < 3:
                        break
                value += polygon_area(inside) * cols[k]
            pieces = remaining
            if not pieces:
                break
        uncovered = sum(polygon_area(p) for p in pieces)
        out[y, x] = value + uncovered * bg
    return out


@dataclass(frozen=True)
class PerspectiveView:
    """A look-at perspective camera as :meth:`mipraster.Camera.look_at` builds it (fov_y in degrees)."""

    eye: Tuple[float, float, float]
    target: Tuple[float, float, float]
    up: Tuple[float, float, float] = (0.0, 1.0, 0.0)
    fov_y: float = 60.0

    def rays(self, x: np.ndarray, y: np.ndarray, width: int, height: int) -> np.ndarray:
        """World-space directions (…, 3) of the rays through screen points (x, y) (pixels, y down)."""
        f = np.subtract(self.target, self.eye).astype(np.float64)
        f /= np.linalg.norm(f)
        s = np.cross(f, np.asarray(self.up, dtype=np.float64))
        s /= np.linalg.norm(s)
        u = np.cross(s, f)
        t = math.tan(math.radians(self.fov_y) / 2.0)
        dx = (2.0 * x / width - 1.0) * t * (width / height)
        dy = (1.0 - 2.0 * y / height) * t
        return dx[..., None] * s + dy[..., None] * u + f


@dataclass(frozen=True)
class TexturedPlane:
    """A parallelogram origin + a·edge_a + b·edge_b (0 ≤ a, b ≤ 1) with uv = uv_origin + a·uv_a + b·uv_b.

    ``texels`` is the level-0 texture, (h, w, C) linear float, row 0 at v = 0; ``wrap`` is
    ``"repeat"`` or ``"clamp"`` (both axes).
    """

    origin: Tuple[float, float, float]
    edge_a: Tuple[float, float, float]
    edge_b: Tuple[float, float, float]
    uv_origin: Tuple[float, float]
    uv_a: Tuple[float, float]
    uv_b: Tuple[float, float]
    texels: np.ndarray
    wrap: str = "repeat"


def bilinear_level0(texels: np.ndarray, u: np.ndarray, v: np.ndarray, wrap: str) -> np.ndarray:
    """Bilinear reconstruction at (u, v), the convention of the notes: i = ⌊u·w − ½⌋."""
    h, w = texels.shape[:2]
    x = u * w - 0.5
    y = v * h - 0.5
    i0, j0 = np.floor(x), np.floor(y)
    fx, fy = (x - i0)[..., None], (y - j0)[..., None]
    i0, j0 = i0.astype(np.int64), j0.astype(np.int64)

    def index(i: np.ndarray, n: int) -> np.ndarray:
        return np.mod(i, n) if wrap == "repeat" else np.clip(i, 0, n - 1)

    i1, j1 = index(i0 + 1, w), index(j0 + 1, h)
    i0, j0 = index(i0, w), index(j0, h)
    top = texels[j0, i0] * (1 - fx) + texels[j0, i1] * fx
    bottom = texels[j1, i0] * (1 - fx) + texels[j1, i1] * fx
    return top * (1 - fy) + bottom * fy


def _plane_shade(plane: TexturedPlane, view: PerspectiveView, x: np.ndarray, y: np.ndarray, width: int,
                 height: int, background: np.ndarray) -> np.ndarray:
    d = view.rays(x, y, width, height)
    eye = np.asarray(view.eye, dtype=np.float64)
    ea, eb = np.asarray(plane.edge_a, dtype=np.float64), np.asarray(plane.edge_b, dtype=np.float64)
    o = np.asarray(plane.origin, dtype=np.float64)
    # eye + t·d = o + a·ea + b·eb, by Cramer's rule with the plane normal n = ea × eb.
    n = np.cross(ea, eb)
    denom = d @ n
    with np.errstate(divide="ignore", invalid="ignore"):
        t = ((o - eye) @ n) / denom
        p = eye + t[..., None] * d - o
        a = (np.cross(p, eb) @ n) / (n @ n)
        b = (np.cross(ea, p) @ n) / (n @ n)
    hit = (t > 0) & (a >= 0) & (a <= 1) & (b >= 0) & (b <= 1) & np.isfinite(t)
    a, b = np.where(hit, a, 0.0), np.where(hit, b, 0.0)
    u = plane.uv_origin[0] + a * plane.uv_a[0] + b * plane.uv_b[0]
    v = plane.uv_origin[1] + a * plane.uv_a[1] + b * plane.uv_b[1]
    colour = bilinear_level0(plane.texels, u, v, plane.wrap)
    return np.where(hit[..., None], colour, background)


def plane_reference(plane: TexturedPlane, view: PerspectiveView, width: int, height: int,
                    background: Sequence[float], n: int = 16, seed: int = 1) -> Tuple[np.ndarray, float]:
    """Box-filtered image of a textured plane over a background, by brute force.

    Each pixel averages two independent sets of n×n jittered points (one per stratum), cast as
    rays in double precision, the texture read at level 0 with bilinear reconstruction.

    Returns:
        ``(image, residual)``: the (H, W, C) mean of both sets and the estimated RMSE of that mean
        over R, G, B (half the RMS difference of the two sets): the reference's own error.
    """
    texels = np.asarray(plane.texels, dtype=np.float64)
    plane = TexturedPlane(plane.origin, plane.edge_a, plane.edge_b, plane.uv_origin, plane.uv_a, plane.uv_b,
                          texels, plane.wrap)
    given = np.asarray(background, dtype=np.float64).reshape(-1)[: texels.shape[2]]
    bg = np.ones(texels.shape[2])  # components not given (alpha) are 1
    bg[: len(given)] = given
    rng = np.random.default_rng(seed)
    ys, xs = np.mgrid[0:height, 0:width].astype(np.float64)
    sets = []
    for _ in range(2):
        total = np.zeros((height, width, texels.shape[2]))
        for sy in range(n):
            for sx in range(n):
                jx = (sx + rng.random((height, width))) / n
                jy = (sy + rng.random((height, width))) / n
                total += _plane_shade(plane, view, xs + jx, ys + jy, width, height, bg)
        sets.append(total / (n * n))
    residual = float(np.sqrt(np.mean((sets[0][..., :3] - sets[1][..., :3]) ** 2)) / 2.0)
    return (sets[0] + sets[1]) / 2.0, residual


def converged_reference(scene, camera, width: int, height: int, clear_color=None, upscale: int = 4,
                        threads: int = 0) -> Tuple[np.ndarray, float]:
    """A converged render of any scene, and its own residual error.

    Renders the scene ``upscale``× larger in each direction with 64 stratified samples per pixel
    (SSAA), every texture read at level 0 with bilinear reconstruction (the box-filtered footprint,
    not a mip-map approximation), and box-averages each upscale×upscale block: 64·upscale² samples
    per pixel. Two seeds give two independent images.

    Returns:
        ``(image, residual)``: (H, W, 4) linear premultiplied RGBA (their mean), and the estimated
        RMSE over R, G, B of that mean (half the RMS difference of the two).
    """
    from .render import render
    from .study_scenes import with_filter

    bilinear = with_filter(scene, "bilinear")
    images = []
    for seed in (1, 2):
        big = render(bilinear, camera, width * upscale, height * upscale, spp=64, aa="ssaa", pattern="stratified",
                     seed=seed, threads=threads, clear_color=clear_color, depth=False).color.astype(np.float64)
        images.append(big.reshape(height, upscale, width, upscale, -1).mean(axis=(1, 3)))
    residual = float(np.sqrt(np.mean((images[0][..., :3] - images[1][..., :3]) ** 2)) / 2.0)
    return (images[0] + images[1]) / 2.0, residual


def image_error(image: np.ndarray, reference: np.ndarray) -> dict:
    """RMSE, mean and max absolute error over R, G, B (linear) of ``image`` against ``reference``."""
    d = np.asarray(image, dtype=np.float64)[..., :3] - np.asarray(reference, dtype=np.float64)[..., :3]
    a = np.abs(d)
    return {"rmse": float(np.sqrt(np.mean(d * d))), "mean_abs": float(a.mean()), "max_abs": float(a.max())}
