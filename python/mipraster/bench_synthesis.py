"""Times texture synthesis and resampling against output size: ``python -m mipraster.bench_synthesis``.

Synthesis: a 64×64 stochastic sample (low-passed noise, periodic), window 11 (or ``--window``),
output sizes 32² … 256² (``--sizes``), on one thread and on all cores. Resampling: a 2048² RGBA
image to 512² and 4096² with each filter. Prints a Markdown table; timing lives here, never in tests.
"""
from __future__ import annotations

import argparse
import os
import time
from typing import List, Optional, Tuple

import numpy as np

from .resample import RESAMPLE_FILTERS, resample
from .synthesis import synthesize


def _sample(n: int = 64) -> np.ndarray:
    rng = np.random.default_rng(1)
    f = np.fft.fftfreq(n)
    blur = np.exp(-2 * (np.pi * 2.0) ** 2 * (f[:, None] ** 2 + f[None, :] ** 2))
    channels = [np.real(np.fft.ifft2(np.fft.fft2(rng.standard_normal((n, n))) * blur)) for _ in range(3)]
    rgb = np.stack(channels, axis=-1)
    return ((rgb - rgb.min()) / (rgb.max() - rgb.min())).astype(np.float32)


def _best_of(repeat: int, call) -> float:
    return _best_of_with_cpu(repeat, call)[0]


def _best_of_with_cpu(repeat: int, call) -> Tuple[float, float]:
    """The best wall time of ``repeat`` calls, and the CPU time (all threads) of that call."""
    best = (float("inf"), float("inf"))
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        call()
        best = min(best, (time.perf_counter() - t0, time.process_time() - c0))
    return best


def main(argv: Optional[List[str]] = None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sizes", default="32,64,128,256", help="output sides, comma-separated")
    p.add_argument("--window", type=int, default=11)
    p.add_argument("--repeat", type=int, default=1, help="runs per figure (the best is shown)")
    a = p.parse_args(argv)
    sample = _sample()
    cores = os.cpu_count() or 1
    print(f"synthesis: 64x64 periodic sample, window {a.window}, seconds wall (CPU, all threads), best of {a.repeat}\n")
    print(f"| output | pixels | 1 thread | {cores} threads |")
    print("|---|---|---|---|")
    for side in (int(s) for s in a.sizes.split(",")):
        times = [_best_of_with_cpu(a.repeat, lambda t=t: synthesize(sample, (side, side), window=a.window,
                                                                      periodic=True, threads=t)) for t in (1, cores)]
        cells = " | ".join(f"{wall:.2f} ({cpu:.2f})" for wall, cpu in times)
        print(f"| {side}x{side} | {side * side} | {cells} |")
    image = np.random.default_rng(2).random((2048, 2048, 4), dtype=np.float32)
    print(f"\nresampling a 2048x2048 RGBA float image, {cores} threads, milliseconds\n")
    print("| filter | to 512x512 | to 4096x4096 |")
    print("|---|---|---|")
    for f in RESAMPLE_FILTERS:
        down = _best_of(a.repeat, lambda: resample(image, (512, 512), filter=f))
        up = _best_of(a.repeat, lambda: resample(image, (4096, 4096), filter=f))
        print(f"| {f} | {down * 1e3:.0f} | {up * 1e3:.0f} |")


if __name__ == "__main__":
    main()
