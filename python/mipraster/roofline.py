"""Roofline of a frame: the least time its framebuffer writes and texture lookups need on this machine.

Two machine limits come from ``mipraster_bench_roofline`` (``cpp/apps/bench_roofline.cpp``): the
framebuffer-write bandwidth (streaming RGBA float + depth float stores over a 1080p frame) and
mipraster's trilinear lookup throughput (``BatchSampler``, as renders look textures up) at a
coherent pattern, each for 1 and 2 threads.
A frame's work is counted from its render statistics:

* bytes written: every sample is cleared once and written again each time a fragment passes
  (``samples_passed``, overdraw included), at 16 bytes of RGBA float plus 4 of depth when the
  scene tests depth; above one sample per pixel the resolve writes the RGBA float image once more;
* texture lookups: one per shader invocation of a textured scene (``shader_invocations``: per
  sample under SSAA, per pixel and triangle under MSAA); an anisotropic lookup is counted as
  one trilinear lookup, so its bound is loose.

The bound is ``max(bytes / bandwidth, lookups / lookup rate)`` (either resource alone forces at
least that long), with the best pass of each limit (the fastest footprint for the lookups); the
fraction of the roofline a frame reaches is ``bound / measured`` (1 would be at the limit).
"""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from dataclasses import dataclass
from typing import Any, Dict, Optional

EXE_NAME = "mipraster_bench_roofline"
COLOR_BYTES = 16  # RGBA float per sample (and per resolved pixel)
DEPTH_BYTES = 4   # float depth per sample


@dataclass
class MachineLimits:
    """Framebuffer-write bytes/s and trilinear lookups/s, by thread count."""

    bandwidth: Dict[int, float]
    lookups: Dict[int, float]
    source: str = ""

    @classmethod
    def from_json(cls, report: Dict[str, Any], source: str = "") -> "MachineLimits":
        """From the JSON ``mipraster_bench_roofline`` writes: best pass of each figure; for the
        lookups, the best over the footprints."""
        bandwidth = {int(t): v["best"] * 1e9 for t, v in report["framebuffer_write"]["threads"].items()}
        lookups: Dict[int, float] = {}
        for footprint in report["trilinear"]["footprints"]:
            for t, v in footprint["threads"].items():
                lookups[int(t)] = max(lookups.get(int(t), 0.0), v["best"])
        return cls(bandwidth, lookups, source)

    def for_threads(self, threads: int) -> tuple:
        """(bytes/s, lookups/s) for `threads`; beyond the measured counts, the largest one's."""
        t = min(threads, max(self.bandwidth))
        return self.bandwidth[t], self.lookups[min(threads, max(self.lookups))]


@dataclass
class FrameWork:
    """What one frame must write and look up."""

    bytes_written: int
    lookups: int


def frame_work(width: int, height: int, spp: int, depth_test: bool, samples_passed: int,
               shader_invocations: int, textured: bool) -> FrameWork:
    """The work of one frame (see the module docstring for what is counted)."""
    per_sample = COLOR_BYTES + (DEPTH_BYTES if depth_test else 0)
    samples = width * height * spp
    written = (samples + samples_passed) * per_sample
    if spp > 1:
        written += width * height * COLOR_BYTES  # the resolved image
    return FrameWork(written, shader_invocations if textured else 0)


def bound_seconds(work: FrameWork, bytes_per_s: float, lookups_per_s: float) -> Dict[str, float]:
    """The write time, the lookup time and their maximum (the bound), in seconds."""
    write_s = work.bytes_written / bytes_per_s
    lookup_s = work.lookups / lookups_per_s
    return {"write_s": write_s, "lookup_s": lookup_s, "bound_s": max(write_s, lookup_s)}


def find_exe(explicit: Optional[str] = None) -> str:
    """``mipraster_bench_roofline``: `explicit`, else ``$MIPRASTER_BENCH_ROOFLINE``, else on PATH,
    else next to the ``mipraster`` command."""
    candidates = [explicit, os.environ.get("MIPRASTER_BENCH_ROOFLINE"), shutil.which(EXE_NAME)]
    cli = shutil.which("mipraster")
    if cli:
        candidates.append(os.path.join(os.path.dirname(os.path.realpath(cli)), EXE_NAME))
    for c in candidates:
        if c and os.path.isfile(c) and os.access(c, os.X_OK):
            return c
        if c and c == explicit:
            raise FileNotFoundError(f"--roofline {explicit!r}: not an executable or a JSON file")
    raise FileNotFoundError(f"{EXE_NAME} was not found: build it (ninja {EXE_NAME}) and pass --roofline PATH "
                            "or set MIPRASTER_BENCH_ROOFLINE")


def measure_limits(source: Optional[str], out_dir: str, quick: bool) -> MachineLimits:
    """Machine limits from `source`: a JSON file ``mipraster_bench_roofline`` wrote, or the
    executable (run pinned to CPUs 0 and 1 when ``taskset`` exists), or None to find it."""
    if source and source.endswith(".json"):
        if not os.path.isfile(source):
            raise FileNotFoundError(f"--roofline {source!r}: no such JSON file")
        with open(source) as f:
            return MachineLimits.from_json(json.load(f), source)
    exe = find_exe(source)
    out = os.path.join(out_dir, "roofline_limits.json")
    cmd = [exe, out] + (["--quick"] if quick else [])
    if shutil.which("taskset"):
        cmd = ["taskset", "-c", "0,1"] + cmd
    print("roofline: " + " ".join(cmd), file=sys.stderr)
    done = subprocess.run(cmd, stdout=subprocess.PIPE, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{exe} failed with status {done.returncode}")
    print(done.stdout, file=sys.stderr)
    with open(out) as f:
        return MachineLimits.from_json(json.load(f), exe)


def markdown(rows: list, limits: MachineLimits) -> str:
    """The roofline table: one row per case dict with scene, mode, threads, MB written, M lookups,
    write/lookup/bound ms, measured ms and the fraction reached."""
    lines = ["| scene | mode | threads | MB written | M lookups | write ms | lookup ms | measured ms | "
             "fraction of roofline |", "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['scene']} | {r['mode']} | {r['threads']} | {r['bytes_written'] / 1e6:,.1f} | "
                     f"{r['lookups'] / 1e6:,.2f} | {r['write_s'] * 1e3:,.2f} | {r['lookup_s'] * 1e3:,.2f} | "
                     f"{r['measured_ms']:,.2f} | {r['fraction']:.3f} |")
    limit_text = "; ".join(f"{t} thread{'s' if t > 1 else ''}: {limits.bandwidth[t] / 1e9:.1f} GB/s, "
                           f"{limits.lookups[t] / 1e6:.1f} M trilinear lookups/s" for t in sorted(limits.bandwidth))
    return "\n".join(lines) + f"\n\nMachine limits ({limits.source}): {limit_text}.\n"
