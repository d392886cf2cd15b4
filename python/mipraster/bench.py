"""Frame-time benchmark: mipraster side by side with Mesa's llvmpipe on the shared benchmark scenes.

Renders every scene of the shared ``scenes.py`` (numpy scenes in OpenGL conventions: clip space
with NDC z in [-1, 1], depth LESS, no culling, no blending, no sRGB, trilinear or anisotropic
filtering with repeat wrap) with mipraster for 1x, MSAA 4x and SSAA 4x at 1 and 2 threads, and,
in the same run when moderngl and an EGL llvmpipe context are available, with llvmpipe through
the shared ``anchor_llvmpipe.py``. Prints one Markdown row per scene × mode × threads: median ms
per frame of each renderer, their ratio, and the PSNR between the two images; writes it all to
``OUT/bench.json`` and ``OUT/bench.md``.

Usage::

    python -m mipraster.bench [--scenes plane cube ...] [--modes 1x msaa4 ssaa4] [--threads 1 2]
                              [--no-anchor] [--quick] [--out DIR] [--bench-dir DIR] [--roofline [PATH]]
    python -m mipraster.bench --growth [--quick] [--out DIR]       # cost growth (growth.py)
    python -m mipraster.bench --omissions [--quick] [--out DIR]    # what omissions save (omissions.py)
    python -m mipraster.bench --aniso-cost [--quick] [--out DIR]   # anisotropic vs trilinear (aniso_cost.py)

``--roofline`` adds each case's roofline (roofline.py): the least time its framebuffer writes and
texture lookups need at the machine's measured limits, and the fraction of it the frame reaches.
``--growth``, ``--omissions`` and ``--aniso-cost`` run their study instead of the scene matrix.

A frame is what llvmpipe's is: clear, draw, resolve, and the image in a numpy array (mipraster
renders straight into one). Scene construction (meshes, textures) is outside the timed frame, as
llvmpipe's uploads are; mip levels are built lazily in the first (warm-up) frame. Each case runs
at least ``--min-frames`` frames and ``--min-time`` seconds after warm-up (at most
``--max-frames``) and reports the median; slow cases (> 2 s a frame) stop after 3 frames.
Timing is never a pass/fail test.

Where the scenes are found: ``--bench-dir``, else ``$MIPRASTER_BENCH_DIR``, else
``../shared/bench`` next to the source checkout or the current directory, else
``/work/shared/bench``.
"""
from __future__ import annotations

import argparse
import contextlib
import importlib.util
import json
import math
import os
import statistics
import subprocess
import sys
import time
from dataclasses import asdict, dataclass
from typing import Any, Dict, Iterator, List, Optional, Sequence

import numpy as np

from . import roofline

MODES = {"1x": (1, "ssaa"), "msaa4": (4, "msaa"), "ssaa4": (4, "ssaa")}  # name -> (spp, aa)
SLOW_FRAME_S = 2.0  # frames slower than this: 3 timed frames are enough


@dataclass
class Case:
    """One timed configuration and its result."""

    scene: str
    mode: str
    threads: int
    width: int
    height: int
    triangles: int
    median_ms: float
    min_ms: float
    frames: int
    llvmpipe_ms: Optional[float] = None
    ratio: Optional[float] = None  # mipraster / llvmpipe: below 1 is faster
    psnr_db: Optional[float] = None  # mipraster's 8-bit image against llvmpipe's
    # --roofline (see roofline.py): the frame's work, its lower bound and the fraction reached
    bytes_written: Optional[int] = None
    lookups: Optional[int] = None
    write_ms: Optional[float] = None   # bytes_written at the measured write bandwidth
    lookup_ms: Optional[float] = None  # lookups at the measured trilinear rate
    bound_ms: Optional[float] = None   # the larger of the two
    roofline_fraction: Optional[float] = None  # bound / median: 1 would be at the machine's limit


def find_bench_dir(explicit: Optional[str] = None) -> str:
    """The folder holding ``scenes.py`` and ``anchor_llvmpipe.py``."""
    if explicit:
        if os.path.isfile(os.path.join(explicit, "scenes.py")):
            return os.path.abspath(explicit)
        raise FileNotFoundError(f"--bench-dir {explicit!r}: no scenes.py there")
    here = os.path.dirname(os.path.abspath(__file__))
    candidates = [os.environ.get("MIPRASTER_BENCH_DIR"),
                  os.path.join(here, "..", "..", "..", "shared", "bench"),
                  os.path.join(os.getcwd(), "..", "shared", "bench"), "/work/shared/bench"]
    for c in candidates:
        if c and os.path.isfile(os.path.join(c, "scenes.py")):
            return os.path.abspath(c)
    raise FileNotFoundError("the shared benchmark scenes (scenes.py) were not found: pass --bench-dir DIR "
                            "or set MIPRASTER_BENCH_DIR")


def load_scenes_module(bench_dir: str) -> Any:
    """Imports the shared ``scenes.py`` from ``bench_dir``."""
    spec = importlib.util.spec_from_file_location("mipraster_bench_scenes", os.path.join(bench_dir, "scenes.py"))
    if spec is None or spec.loader is None:
        raise ImportError(f"cannot load scenes.py from {bench_dir}")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up while the file executes
    spec.loader.exec_module(module)
    return module


def to_mipraster(bench_scene: Any) -> tuple:
    """(Scene, Camera) for a shared benchmark scene, in its conventions: the scene's mvp as an
    OpenGL-convention projection (depth LESS), its uint8 texture as linear data (no sRGB), and
    ``texture × vertex colour`` shading."""
    import mipraster as mr

    mesh = mr.Mesh(bench_scene.positions, bench_scene.indices.astype(np.int64), colors=bench_scene.colors,
                   uvs=bench_scene.uv if bench_scene.texture is not None else None)
    scene = mr.Scene()
    texture = sampler = None
    if bench_scene.texture is not None:
        texture = mr.Texture(bench_scene.texture, srgb=False, name=bench_scene.name)
        aniso = bench_scene.max_anisotropy > 1.0
        sampler = mr.Sampler(filter="anisotropic" if aniso else bench_scene.filter,
                             max_anisotropy=max(1.0, float(bench_scene.max_anisotropy)), wrap=bench_scene.wrap)
    scene.add(mesh, depth_test=bench_scene.depth_test, texture=texture, sampler=sampler)
    camera = mr.Camera.from_matrices(np.eye(4), bench_scene.mvp.astype(np.float64), depth_convention="opengl")
    return scene, camera


def time_frames(frame, min_frames: int, min_time: float, max_frames: int) -> List[float]:
    """Seconds per frame of `frame()` after one warm-up frame."""
    frame()
    times: List[float] = []
    start = time.perf_counter()
    while len(times) < max_frames:
        t0 = time.perf_counter()
        frame()
        times.append(time.perf_counter() - t0)
        enough = len(times) >= min_frames and time.perf_counter() - start >= min_time
        if enough or (len(times) >= 3 and statistics.median(times) > SLOW_FRAME_S):
            break
    return times


@contextlib.contextmanager
def pinned_to_one_cpu() -> Iterator[None]:
    """Runs the block on one CPU (the first this process may use) where the OS allows it."""
    if not hasattr(os, "sched_setaffinity"):
        yield
        return
    allowed = os.sched_getaffinity(0)
    os.sched_setaffinity(0, {min(allowed)})
    try:
        yield
    finally:
        os.sched_setaffinity(0, allowed)


def psnr(a: np.ndarray, b: np.ndarray) -> float:
    """PSNR in dB between two 8-bit RGB images (inf when identical)."""
    mse = float(np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2))
    return math.inf if mse == 0.0 else 10.0 * math.log10(255.0 ** 2 / mse)


def to_rgb8_linear(rgba: np.ndarray) -> np.ndarray:
    """The benchmark's 8-bit output: linear values scaled to 0..255, no sRGB (as the GL anchor)."""
    return np.clip(np.rint(rgba[..., :3] * 255.0), 0, 255).astype(np.uint8)


def run_anchor(bench_dir: str, out_dir: str, scenes: Sequence[str], modes: Sequence[str],
               threads: Sequence[int], quick: bool) -> Optional[dict]:
    """Runs llvmpipe through ``anchor_llvmpipe.py``; None (with the reason printed) when it cannot."""
    try:
        import moderngl  # noqa: F401
    except ImportError as e:
        print(f"llvmpipe anchor skipped: moderngl does not import ({e}); `pip install moderngl` and the "
              "Debian packages libegl1 libgl1-mesa-dri give it", file=sys.stderr)
        return None
    os.makedirs(out_dir, exist_ok=True)
    cmd = [sys.executable, os.path.join(bench_dir, "anchor_llvmpipe.py"), "--out", out_dir, "--scenes", *scenes,
           "--modes", *modes, "--threads", *map(str, threads), "--wait-quiet", "0"]
    if quick:
        cmd += ["--min-frames", "3", "--min-time", "0.2", "--max-frames", "5", "--warmup", "1"]
    print("llvmpipe: " + " ".join(cmd), file=sys.stderr)
    done = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        print(f"llvmpipe anchor failed (exit {done.returncode}); going on without it:\n{done.stderr[-2000:]}",
              file=sys.stderr)
        return None
    with open(os.path.join(out_dir, "results.json")) as f:
        return json.load(f)


def anchor_image(out_dir: str, scene: str, mode: str) -> Optional[np.ndarray]:
    path = os.path.join(out_dir, f"{scene}_{mode}.png")
    if not os.path.isfile(path):
        return None
    from PIL import Image

    return np.asarray(Image.open(path).convert("RGB"))


def geometric_mean(values: Sequence[float]) -> float:
    return math.exp(sum(math.log(v) for v in values) / len(values))


def markdown(cases: Sequence[Case], anchor_note: str) -> str:
    rows = ["| scene | size | triangles | mode | threads | mipraster ms | llvmpipe ms | ratio | PSNR dB |",
            "|---|---|---|---|---|---|---|---|---|"]
    fmt = lambda v, f: "–" if v is None else format(v, f)  # noqa: E731
    for c in cases:
        rows.append(f"| {c.scene} | {c.width}×{c.height} | {c.triangles:,} | {c.mode} | {c.threads} | "
                    f"{c.median_ms:,.2f} | {fmt(c.llvmpipe_ms, ',.2f')} | {fmt(c.ratio, '.2f')} | "
                    f"{fmt(c.psnr_db, '.1f')} |")
    ratios = [c.ratio for c in cases if c.ratio]
    lines = ["\n".join(rows), ""]
    if ratios:
        lines.append(f"Geometric mean of the ratios: {geometric_mean(ratios):.3f} (mipraster / llvmpipe, "
                     f"{len(ratios)} cases; worst {max(ratios):.2f}, best {min(ratios):.2f}).")
    scaling = thread_scaling(cases)
    if scaling:
        lines.append("2-thread speed-up (1-thread ms / 2-thread ms): "
                     + ", ".join(f"{k} {v:.2f}×" for k, v in scaling.items()) + ".")
    lines.append(anchor_note)
    return "\n".join(lines) + "\n"


def thread_scaling(cases: Sequence[Case]) -> Dict[str, float]:
    by_key = {(c.scene, c.mode, c.threads): c.median_ms for c in cases}
    return {f"{s}/{m}": by_key[(s, m, 1)] / by_key[(s, m, 2)]
            for (s, m, t) in by_key if t == 1 and (s, m, 2) in by_key}


def add_roofline(case: Case, limits: roofline.MachineLimits, spp: int, bench_scene: Any,
                 stats: Dict[str, Any]) -> None:
    """Fills the case's roofline fields from the frame's render statistics."""
    work = roofline.frame_work(case.width, case.height, spp, bool(bench_scene.depth_test),
                               int(stats["samples_passed"]), int(stats["shader_invocations"]),
                               bench_scene.texture is not None)
    bound = roofline.bound_seconds(work, *limits.for_threads(case.threads))
    case.bytes_written, case.lookups = work.bytes_written, work.lookups
    case.write_ms, case.lookup_ms, case.bound_ms = (bound[k] * 1e3 for k in ("write_s", "lookup_s", "bound_s"))
    case.roofline_fraction = case.bound_ms / case.median_ms


def roofline_row(case: Case) -> Dict[str, Any]:
    """A row of roofline.markdown for a case that has its roofline."""
    assert case.write_ms is not None and case.lookup_ms is not None, "add_roofline first"
    return {"scene": case.scene, "mode": case.mode, "threads": case.threads, "bytes_written": case.bytes_written,
            "lookups": case.lookups, "write_s": case.write_ms / 1e3, "lookup_s": case.lookup_ms / 1e3,
            "measured_ms": case.median_ms, "fraction": case.roofline_fraction}


def main(argv: Optional[Sequence[str]] = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m mipraster.bench", description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", nargs="+", help="scene names of scenes.py (default: its DEFAULT_BENCH list)")
    ap.add_argument("--modes", nargs="+", default=list(MODES), choices=list(MODES))
    ap.add_argument("--threads", nargs="+", type=int, default=[1, 2])
    ap.add_argument("--min-frames", type=int, default=10)
    ap.add_argument("--min-time", type=float, default=1.0, help="seconds of timed frames per case, at least")
    ap.add_argument("--max-frames", type=int, default=60)
    ap.add_argument("--quick", action="store_true", help="3 frames per case, 0.2 s (a smoke run)")
    ap.add_argument("--no-anchor", action="store_true", help="do not run llvmpipe")
    ap.add_argument("--bench-dir", help="folder with scenes.py and anchor_llvmpipe.py")
    ap.add_argument("--out", default="bench_results", help="output folder [bench_results]")
    ap.add_argument("--roofline", nargs="?", const="", metavar="PATH",
                    help="add each case's roofline; PATH: the mipraster_bench_roofline executable or a JSON "
                         "it wrote (default: $MIPRASTER_BENCH_ROOFLINE, PATH, next to the mipraster command)")
    ap.add_argument("--growth", action="store_true", help="run the cost-growth study instead (growth.py)")
    ap.add_argument("--omissions", action="store_true", help="run the omission table instead (omissions.py)")
    ap.add_argument("--aniso-cost", action="store_true",
                    help="time anisotropic filtering against trilinear on the 1080p plane instead (aniso_cost.py)")
    args = ap.parse_args(argv)
    for t in args.threads:
        if t < 1:
            ap.error(f"--threads: {t} is not a thread count (>= 1)")
    for name in ("min_frames", "max_frames"):
        if getattr(args, name) < 1:
            ap.error(f"--{name.replace('_', '-')}: {getattr(args, name)} is not a frame count (>= 1)")
    if not (args.min_time >= 0 and math.isfinite(args.min_time)):
        ap.error(f"--min-time: {args.min_time} is not a finite number of seconds (>= 0)")
    if args.quick:
        args.min_frames, args.min_time, args.max_frames = 3, 0.2, 5
    if args.growth or args.omissions or args.aniso_cost:
        from . import aniso_cost, growth, omissions

        os.makedirs(args.out, exist_ok=True)
        if args.growth:
            growth.run(args.out, quick=args.quick)
        if args.omissions:
            omissions.run(args.out, quick=args.quick)
        if args.aniso_cost:
            aniso_cost.run(args.out, quick=args.quick, bench_dir=args.bench_dir)
        return 0

    import mipraster as mr

    bench_dir = find_bench_dir(args.bench_dir)
    scenes_module = load_scenes_module(bench_dir)
    names = args.scenes or list(scenes_module.DEFAULT_BENCH)
    unknown = [n for n in names if n not in scenes_module.SCENE_NAMES]
    if unknown:
        ap.error(f"--scenes: unknown {unknown}; scenes.py has {scenes_module.SCENE_NAMES}")
    os.makedirs(args.out, exist_ok=True)

    limits = None
    if args.roofline is not None:
        try:
            limits = roofline.measure_limits(args.roofline or None, args.out, args.quick)
        except (FileNotFoundError, RuntimeError) as e:
            ap.error(str(e))
    cases: List[Case] = []
    images: Dict[tuple, np.ndarray] = {}
    anchor_dir = os.path.join(args.out, "llvmpipe")
    # llvmpipe runs right after each scene's mipraster cases, not after every scene's: the shared
    # machine's speed drifts over minutes, and a ratio is fairest between neighbouring measurements.
    anchor_runs: Dict[tuple, dict] = {}
    gl_renderer: Optional[str] = None
    anchor_failed = False
    for name in names:
        bench_scene = scenes_module.make_scene(name)
        scene, camera = to_mipraster(bench_scene)
        w, h = bench_scene.width, bench_scene.height
        for mode in args.modes:
            spp, aa = MODES[mode]
            for threads in args.threads:
                result: Dict[str, Any] = {}

                def frame() -> None:
                    rendered = mr.render(scene, camera, w, h, spp=spp, aa=aa, threads=threads,
                                         clear_color=bench_scene.clear_color, depth=False)
                    result["image"], result["stats"] = rendered.color, rendered.stats

                times = time_frames(frame, args.min_frames, args.min_time, args.max_frames)
                case = Case(name, mode, threads, w, h, bench_scene.n_triangles, statistics.median(times) * 1e3,
                            min(times) * 1e3, len(times))
                if limits is not None:
                    add_roofline(case, limits, spp, bench_scene, result["stats"])
                cases.append(case)
                images[(name, mode)] = to_rgb8_linear(result["image"])
                print(f"mipraster {name:18s} {mode:6s} {threads}T {case.median_ms:10.2f} ms "
                      f"({case.frames} frames)", file=sys.stderr)
        if args.no_anchor or anchor_failed:
            continue
        anchor = run_anchor(bench_dir, os.path.join(anchor_dir, name), [name], args.modes, args.threads, args.quick)
        if anchor is None:
            anchor_failed = True  # (not available: the reason is printed once)
            continue
        gl: Dict[str, Any] = next(iter(anchor.get("gl_info", {}).values()), {})
        gl_renderer = gl_renderer or gl.get("GL_RENDERER", "?")
        anchor_runs.update({(r["scene"], r["mode"], r["threads"]): r for r in anchor["runs"]})

    if not anchor_runs:
        note = "llvmpipe was not run (" + ("--no-anchor" if args.no_anchor else "not available, see above") + ")."
    else:
        note = f"llvmpipe: {gl_renderer}, measured in the same run, right after each scene's mipraster cases."
        for c in cases:
            r = anchor_runs.get((c.scene, c.mode, c.threads))
            if r is None:
                continue
            c.llvmpipe_ms = r["median_s"] * 1e3
            c.ratio = c.median_ms / c.llvmpipe_ms
            other = anchor_image(os.path.join(anchor_dir, c.scene), c.scene, c.mode)
            if other is not None and other.shape == images[(c.scene, c.mode)].shape:
                c.psnr_db = psnr(images[(c.scene, c.mode)], other)

    table = markdown(cases, note)
    if limits is not None:
        table += "\n" + roofline.markdown([roofline_row(c) for c in cases], limits)
    print(table)
    with open(os.path.join(args.out, "bench.md"), "w") as f:
        f.write(table)
    with open(os.path.join(args.out, "bench.json"), "w") as f:
        json.dump({"bench_dir": bench_dir, "cases": [asdict(c) for c in cases],
                   "thread_scaling": thread_scaling(cases), "anchor": note,
                   "roofline_limits": None if limits is None else asdict(limits)}, f, indent=1,
                  default=lambda v: None)
    return 0


if __name__ == "__main__":
    sys.exit(main())
