"""Cost growth: frame time against triangle count and against resolution × samples, fitted and plotted.

Two procedural scenes (vertex colours, depth test, OpenGL clip space straight from NDC):

* ``grid``: a screen-covering grid of n triangles (about n/2 shared vertices): the covered area
  stays one screen, so the per-triangle costs grow and the per-sample ones do not;
* ``random``: n random triangles of a fixed size (``RANDOM_EDGE_PX`` edge) at random depths: the
  triangles and the covered samples both grow with n.

Triangle counts 10³ … 10⁷ at ``TRIANGLE_SIZE`` and one sample; then the grid at
``SAMPLE_SWEEP_TRIANGLES`` triangles over resolutions × SSAA sample counts. Each point is the
median of repeated frames (``bench.time_frames``) at one thread. Each series is fitted
(relative least squares) with ``t = a + b·x``, with ``t = a + b·x + c·x·log2 x`` (the superlinear
term's share of the largest point), and with ``t = a + k·x^p`` (the exponent p; 1 is linear);
the marginal cost of each step between sizes shows a superlinear term directly (it would rise).
The study runs on one CPU (``bench.pinned_to_one_cpu``). A point the memory limit refuses is
recorded as skipped, never estimated.
"""
from __future__ import annotations

import json
import math
import os
import statistics
import sys
from dataclasses import asdict, dataclass
from typing import Any, Dict, List, Optional, Sequence

import numpy as np

TRIANGLE_SIZE = (960, 540)
TRIANGLE_COUNTS = [10 ** k for k in range(3, 8)]
QUICK_TRIANGLE_COUNTS = [10 ** k for k in range(3, 6)]
SAMPLE_SWEEP_TRIANGLES = 20_000
SAMPLE_SWEEP_WIDTHS = [240, 480, 960, 1920]  # 16:9
QUICK_SAMPLE_SWEEP_WIDTHS = [120, 240, 480]
SAMPLE_SWEEP_SPP = [1, 4, 16]
QUICK_SAMPLE_SWEEP_SPP = [1, 4]
RANDOM_EDGE_PX = 2.0  # small: at 10⁷ triangles the covered samples are ~30 screens
EXPONENT_RANGE = (0.2, 3.0)  # the power-law exponents the fit scans


@dataclass
class Point:
    """One timed render of a series."""

    series: str
    x: int          # the series' size: triangles, or pixels × samples
    width: int
    height: int
    spp: int
    triangles: int
    median_ms: Optional[float]  # None: refused by the memory limit
    frames: int = 0
    note: str = ""


def grid_mesh(n: int, aspect: float) -> tuple:
    """(positions, triangles, colours) of a grid of about n triangles covering NDC [-1, 1]²."""
    quads = max(1, n // 2)
    ny = max(1, round(math.sqrt(quads / aspect)))
    nx = max(1, quads // ny)
    xs, ys = np.linspace(-1.0, 1.0, nx + 1), np.linspace(-1.0, 1.0, ny + 1)
    X, Y = np.meshgrid(xs, ys)
    positions = np.stack([X, Y, np.zeros_like(X)], axis=-1).reshape(-1, 3).astype(np.float32)
    v00 = (np.arange(ny)[:, None] * (nx + 1) + np.arange(nx)[None, :]).ravel()
    v01 = v00 + nx + 1
    tris = np.empty((2 * nx * ny, 3), np.int64)
    tris[0::2] = np.stack([v00, v01, v00 + 1], axis=1)
    tris[1::2] = np.stack([v00 + 1, v01, v01 + 1], axis=1)
    colors = np.ones((positions.shape[0], 4), np.float32)
    colors[:, 0] = (positions[:, 0] + 1) / 2
    colors[:, 1] = (positions[:, 1] + 1) / 2
    return positions, tris, colors


def random_mesh(n: int, width: int, height: int, seed: int = 7) -> tuple:
    """(positions, triangles, colours) of n random triangles with edges of about RANDOM_EDGE_PX
    pixels, centres uniform over the screen, depths uniform in NDC (-0.9, 0.9)."""
    rng = np.random.default_rng(seed)
    centres = rng.uniform(-1.0, 1.0, (n, 1, 2))
    angle = rng.uniform(0, 2 * math.pi, (n, 1)) + np.array([0.0, 2.0, 4.0]) * math.pi / 3
    radius = RANDOM_EDGE_PX / math.sqrt(3)  # an equilateral triangle's circumradius, in pixels
    offsets = np.stack([np.cos(angle) * radius * 2 / width, np.sin(angle) * radius * 2 / height], axis=-1)
    xy = (centres + offsets).reshape(-1, 2)
    z = np.repeat(rng.uniform(-0.9, 0.9, n), 3)
    positions = np.column_stack([xy, z]).astype(np.float32)
    colors = np.repeat(np.column_stack([rng.uniform(0.2, 1.0, (n, 3)), np.ones(n)]), 3, axis=0).astype(np.float32)
    return positions, np.arange(3 * n, dtype=np.int64).reshape(n, 3), colors


def make_scene(kind: str, n: int, width: int, height: int) -> tuple:
    """(Scene, Camera, triangle count) of the `kind` ('grid' or 'random') scene with about n
    triangles."""
    import mipraster as mr

    if kind == "grid":
        positions, tris, colors = grid_mesh(n, width / height)
    elif kind == "random":
        positions, tris, colors = random_mesh(n, width, height)
    else:
        raise ValueError(f"kind: expected 'grid' or 'random', got {kind!r}")
    scene = mr.Scene()
    scene.add(mr.Mesh(positions, tris, colors=colors), depth_test=True)
    return scene, mr.Camera.from_matrices(np.eye(4), np.eye(4), depth_convention="opengl"), len(tris)


def time_point(series: str, kind: str, n: int, width: int, height: int, spp: int, x: int,
               min_frames: int, min_time: float, max_frames: int) -> Point:
    """Median frame time of one scene at one size (one thread)."""
    import mipraster as mr
    from .bench import time_frames

    scene, camera, triangles = make_scene(kind, n, width, height)
    try:
        times = time_frames(lambda: mr.render(scene, camera, width, height, spp=spp, threads=1, depth=False),
                            min_frames, min_time, max_frames)
    except mr.MemoryLimitError as e:
        return Point(series, x, width, height, spp, triangles, None, 0, f"skipped: {e}")
    return Point(series, x, width, height, spp, triangles, statistics.median(times) * 1e3, len(times))


# ---- fits ------------------------------------------------------------------------------------------

def _relative_lstsq(columns: Sequence[np.ndarray], t: np.ndarray) -> np.ndarray:
    """Coefficients minimizing the relative residuals Σ((model − t)/t)²."""
    A = np.column_stack(columns) / t[:, None]
    return np.linalg.lstsq(A, np.ones_like(t), rcond=None)[0]


def power_law_exponent(x: np.ndarray, t: np.ndarray) -> float:
    """p of the best fit t = a + k·x^p (relative least squares): a scan of p, then a finer one."""
    def residual(p: float) -> float:
        coef = _relative_lstsq([np.ones_like(x), x ** p], t)
        return float(np.sum(((coef[0] + coef[1] * x ** p) / t - 1.0) ** 2))

    best = EXPONENT_RANGE[0]
    for step in (1e-2, 1e-4, 1e-6):
        lo, hi = (EXPONENT_RANGE if step == 1e-2 else (best - 100 * step, best + 100 * step))
        grid = np.arange(lo, hi + step / 2, step)
        best = float(grid[int(np.argmin([residual(p) for p in grid]))])
    return best


def fit(x: Sequence[float], t: Sequence[float]) -> Dict[str, Any]:
    """Fits of times t (any unit) against sizes x: linear (a, b); with an x·log2 x term (a2, b2,
    c2 and ``superlinear_share``, c2·x·log2 x over the fitted time at the largest x: negative
    when the curve bends down); the exponent p of t = a + k·x^p (1 is linear); and the marginal
    cost of each step between sizes (growing marginal costs would mean a superlinear term)."""
    x_arr, t_arr = np.asarray(x, np.float64), np.asarray(t, np.float64)
    if x_arr.size < 3:
        raise ValueError(f"fit: need at least 3 points, got {x_arr.size}")
    ones = np.ones_like(x_arr)
    a, b = _relative_lstsq([ones, x_arr], t_arr)
    xlogx = x_arr * np.log2(x_arr)
    a2, b2, c2 = _relative_lstsq([ones, x_arr, xlogx], t_arr)
    i = int(np.argmax(x_arr))
    share = c2 * xlogx[i] / (a2 + b2 * x_arr[i] + c2 * xlogx[i])
    order = np.argsort(x_arr, kind="stable")
    dx, dt = np.diff(x_arr[order]), np.diff(t_arr[order])
    marginal = dt[dx > 0] / dx[dx > 0]  # steps between distinct sizes
    return {"a": float(a), "b": float(b), "a2": float(a2), "b2": float(b2), "c2": float(c2),
            "superlinear_share": float(share), "exponent": power_law_exponent(x_arr, t_arr),
            "marginal": [float(m) for m in marginal]}


# ---- report ------------------------------------------------------------------------------------------

def fits_by_series(points: Sequence[Point]) -> Dict[str, Dict[str, Any]]:
    """A fit per series with at least 3 timed points."""
    out = {}
    for series in dict.fromkeys(p.series for p in points):
        timed = [(p.x, p.median_ms) for p in points if p.series == series and p.median_ms is not None]
        if len(timed) >= 3:
            out[series] = fit([x for x, _ in timed], [t for _, t in timed])
    return out


def markdown(points: Sequence[Point], fits: Dict[str, Dict[str, Any]]) -> str:
    """The points table and the fits table."""
    rows = ["| series | size | triangles | samples (W·H·S) | median ms | ns per unit |", "|---|---|---|---|---|---|"]
    for p in points:
        ms = "skipped" if p.median_ms is None else f"{p.median_ms:,.2f}"
        per = "–" if p.median_ms is None else f"{p.median_ms * 1e6 / p.x:,.1f}"
        rows.append(f"| {p.series} | {p.width}×{p.height}×{p.spp} | {p.triangles:,} | "
                    f"{p.width * p.height * p.spp:,} | {ms} | {per} |")
    rows += ["", "| series | t = a + b·x: a ms, b ns | + c·x·log2 x: its share at the largest x | "
             "p of t = a + k·x^p | marginal ns per unit, step by step |", "|---|---|---|---|---|"]
    for series, f in fits.items():
        marginal = " → ".join(f"{m * 1e6:,.0f}" for m in f["marginal"])
        rows.append(f"| {series} | {f['a']:.3f}, {f['b'] * 1e6:.3f} | {f['superlinear_share'] * 100:+.0f}% | "
                    f"{f['exponent']:.3f} | {marginal} |")
    return "\n".join(rows) + "\n"


def plot(points: Sequence[Point], fits: Dict[str, Dict[str, Any]], path: str) -> None:
    """Log-log plots of both sweeps with their linear fits, as a small palette PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from PIL import Image

    fig, axes = plt.subplots(1, 2, figsize=(8, 3.2), dpi=80)
    for ax, kind, label in ((axes[0], "triangles", "triangles"), (axes[1], "samples", "pixels × samples")):
        for series in fits:
            if not series.startswith(kind) or series == "samples:grid all":
                continue
            pts = [p for p in points if p.series == series and p.median_ms is not None]
            x = np.array([p.x for p in pts], np.float64)
            line = ax.loglog(x, [p.median_ms for p in pts], "o", ms=4, label=series.split(":", 1)[1])[0]
            xs = np.geomspace(x.min(), x.max(), 50)
            ax.loglog(xs, fits[series]["a"] + fits[series]["b"] * xs, "-", lw=1, color=line.get_color())
        ax.set_xlabel(label)
        ax.set_ylabel("ms per frame (1 thread)")
        ax.grid(True, which="major", lw=0.3)
        ax.legend(fontsize=8)
    axes[0].set_title("time vs triangles (lines: a + b·n)", fontsize=9)
    axes[1].set_title("time vs resolution × samples", fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    Image.open(path).convert("RGB").quantize(colors=32).save(path, optimize=True)


def sweep(counts: Sequence[int], widths: Sequence[int], spps: Sequence[int], frames: tuple) -> List[Point]:
    """The timed points of both sweeps, on one CPU."""
    from .bench import pinned_to_one_cpu

    w, h = TRIANGLE_SIZE
    points: List[Point] = []
    with pinned_to_one_cpu():
        for kind in ("grid", "random"):
            for n in counts:
                points.append(time_point(f"triangles:{kind}", kind, n, w, h, 1, n, *frames))
                print(f"growth {points[-1]}", file=sys.stderr)
        for spp in spps:
            for width in widths:
                height = width * 9 // 16
                points.append(time_point(f"samples:grid {spp} spp", "grid", SAMPLE_SWEEP_TRIANGLES, width, height,
                                         spp, width * height * spp, *frames))
                print(f"growth {points[-1]}", file=sys.stderr)
    return points


def run(out_dir: str, quick: bool = False) -> Dict[str, object]:
    """Both sweeps: prints and writes growth.md, growth.json and cost_growth.png to out_dir."""
    points = sweep(QUICK_TRIANGLE_COUNTS if quick else TRIANGLE_COUNTS,
                   QUICK_SAMPLE_SWEEP_WIDTHS if quick else SAMPLE_SWEEP_WIDTHS,
                   QUICK_SAMPLE_SWEEP_SPP if quick else SAMPLE_SWEEP_SPP,
                   (3, 0.2, 5) if quick else (3, 1.0, 9))
    # One series over every resolution and sample count together: time against W·H·S.
    points += [Point("samples:grid all", p.x, p.width, p.height, p.spp, p.triangles, p.median_ms, p.frames, p.note)
               for p in list(points) if p.series.startswith("samples:grid ")]
    fits = fits_by_series(points)
    table = markdown([p for p in points if p.series != "samples:grid all"], fits)
    print(table)
    with open(os.path.join(out_dir, "growth.md"), "w") as f:
        f.write(table)
    report: Dict[str, object] = {"points": [asdict(p) for p in points], "fits": fits}
    with open(os.path.join(out_dir, "growth.json"), "w") as f:
        json.dump(report, f, indent=1)
    plot(points, fits, os.path.join(out_dir, "cost_growth.png"))
    return report
