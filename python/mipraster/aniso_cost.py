"""What anisotropic filtering costs against trilinear (issue 7's target: 16× at 1080p at most 2×).

The shared benchmark's plane (1920×1080, a 1024² checkerboard from the bottom of the screen to the
horizon, repeat) rendered with its trilinear sampler and with anisotropic filtering at max
anisotropy 2, 4, 8 and 16: one thread on one CPU, the variants alternating frame by frame after a
warm-up frame of each, so that all see the same background load. For each: the median frame time,
its ratio to trilinear's, and the mean |difference| of its linear RGB from trilinear's image (the
detail towards the horizon that trilinear blurs away; zero would mean the sampler was not used).
"""
from __future__ import annotations

import dataclasses
import json
import os
import statistics
import time
from dataclasses import asdict, dataclass, field
from typing import List, Optional

import numpy as np

from .bench import find_bench_dir, load_scenes_module, pinned_to_one_cpu, to_mipraster

TARGET_RATIO = 2.0  # 16× anisotropic at most this many times trilinear's frame time
ANISOTROPIES = (1.0, 2.0, 4.0, 8.0, 16.0)  # 1: the trilinear sampler
SIZE = (1920, 1080)
QUICK_SIZE = (480, 270)


@dataclass
class Row:
    """One sampler's measurement."""

    max_anisotropy: float
    filter: str
    median_ms: float
    ratio: float  # median_ms / trilinear's median_ms
    mean_abs_difference: float  # from trilinear's image, linear RGB
    frames_ms: List[float] = field(default_factory=list)


def measure(width: int, height: int, frames: int, bench_dir: Optional[str] = None) -> List[Row]:
    """Times every sampler of ANISOTROPIES on the plane at width × height, `frames` rounds."""
    import mipraster as mr

    scenes_module = load_scenes_module(find_bench_dir(bench_dir))
    plane = scenes_module.scene_plane(width, height)
    variants = [to_mipraster(dataclasses.replace(plane, max_anisotropy=a)) for a in ANISOTROPIES]

    def frame(i: int) -> np.ndarray:
        scene, camera = variants[i]
        return mr.render(scene, camera, width, height, threads=1, clear_color=plane.clear_color, depth=False).color

    times: List[List[float]] = [[] for _ in variants]
    with pinned_to_one_cpu():
        images = [frame(i) for i in range(len(variants))]  # warm-up
        for _ in range(frames):
            for i in range(len(variants)):
                t0 = time.perf_counter()
                frame(i)
                times[i].append((time.perf_counter() - t0) * 1e3)
    trilinear_ms = statistics.median(times[0])
    return [Row(max_anisotropy=a, filter="trilinear" if a == 1.0 else "anisotropic",
                median_ms=statistics.median(t), ratio=statistics.median(t) / trilinear_ms,
                mean_abs_difference=float(np.mean(np.abs(image[..., :3] - images[0][..., :3]))), frames_ms=t)
            for a, t, image in zip(ANISOTROPIES, times, images)]


def markdown(rows: List[Row], width: int, height: int) -> str:
    """The table, with the target's verdict for the largest anisotropy."""
    lines = [f"Anisotropic filtering against trilinear: the plane at {width}×{height}, one thread, "
             f"{len(rows[0].frames_ms)} alternating rounds (median ms)", "",
             "| sampler | ms | × trilinear | mean abs difference from trilinear |", "|---|---|---|---|"]
    for r in rows:
        name = "trilinear" if r.filter == "trilinear" else f"anisotropic {r.max_anisotropy:g}×"
        lines.append(f"| {name} | {r.median_ms:.2f} | {r.ratio:.2f} | {r.mean_abs_difference:.4f} |")
    last = rows[-1]
    verdict = "met" if last.ratio <= TARGET_RATIO else "not met"
    lines += ["", f"Target: {last.max_anisotropy:g}× anisotropic at most {TARGET_RATIO:g}× trilinear: "
                  f"{last.ratio:.2f}×, {verdict}."]
    return "\n".join(lines) + "\n"


def run(out_dir: str, quick: bool = False, bench_dir: Optional[str] = None) -> List[Row]:
    """Measures the table; prints it and writes aniso_cost.md and aniso_cost.json to out_dir."""
    width, height = QUICK_SIZE if quick else SIZE
    rows = measure(width, height, 3 if quick else 7, bench_dir)
    table = markdown(rows, width, height)
    print(table)
    with open(os.path.join(out_dir, "aniso_cost.md"), "w") as f:
        f.write(table)
    with open(os.path.join(out_dir, "aniso_cost.json"), "w") as f:
        json.dump({"width": width, "height": height, "target_ratio": TARGET_RATIO,
                   "rows": [asdict(r) for r in rows]}, f, indent=1)
    return rows
