"""What leaving out unneeded work saves: each omission's time and memory with and without it.

For each omission of DESIGN.md §3 ("leave out what a scene does not need") a small scene where it
applies is rendered two ways: as the pipeline renders it (the omission at work) and in a way that
forces the work (what it would cost without), at one thread. Where nothing can force the work, the
row says so and gives no number rather than an invented one.

Each variant runs in its own Python process (pinned to CPU 0 when ``taskset`` exists) so that its
memory is its own: ``memory`` is the growth of the process's peak resident set during the timed
frames over its peak after building the scene (``getrusage`` on Linux, which includes every
allocation the renderer and the texture cache make). Time is the median of repeated frames after a
warm-up frame; anything a frame needs that is not the omission (a fresh texture for the lazy-mip
row) is built outside the timed part. Where the two variants should draw the same image, the
images are compared: ``exact`` (bit-identical) or ``close`` (within ``CLOSE_TOLERANCE``, where
one variant computes the same value by another route, e.g. 1/w = 1 divided out).
"""
from __future__ import annotations

import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import asdict, dataclass, field
from typing import Any, Callable, Dict, List, Optional

import numpy as np

SIZE = (1280, 720)
QUICK_SIZE = (160, 90)
GRID_TRIANGLES = 20_000  # about: growth.grid_mesh rounds to whole rows and columns
OFFSCREEN_TRIANGLES = 200_000
CLOSE_TOLERANCE = 1e-5  # largest |difference| of a linear colour value for 'close'


@dataclass
class Variant:
    """One way of rendering a row's scene: ``setup()`` (untimed) returns the render's arguments;
    ``force(state)`` (timed, optional) does extra work before the render."""

    label: str
    setup: Callable[[int, int], Dict[str, Any]]
    force: Optional[Callable[[Dict[str, Any]], None]] = None


@dataclass
class Omission:
    """A row of the table: the omission, where it applies, and its two variants (None: the work
    cannot be forced)."""

    name: str
    scene: str
    with_it: Variant
    without: Optional[Variant]
    same_image: str  # "exact", "close" or "" (not compared)
    note: str = ""


@dataclass
class Row:
    """A measured row."""

    name: str
    scene: str
    with_label: str
    without_label: str
    with_ms: Optional[float] = None
    without_ms: Optional[float] = None
    with_memory: Optional[int] = None  # bytes
    without_memory: Optional[int] = None
    image_check: str = ""  # "identical", "max |diff| 3e-08", or "" when not compared
    note: str = ""
    samples: Dict[str, List[float]] = field(default_factory=dict)


# ---- scenes --------------------------------------------------------------------------------------

def _ndc_camera() -> Any:
    import mipraster as mr

    return mr.Camera.from_matrices(np.eye(4), np.eye(4), depth_convention="opengl")


def _grid(width: int, height: int, n: int = GRID_TRIANGLES) -> tuple:
    from .growth import grid_mesh

    return grid_mesh(n, width / height)


def _white_texture() -> Any:
    import mipraster as mr

    return mr.Texture(np.full((1, 1, 4), 255, np.uint8), srgb=False, name="white 1x1")


def colour_grid(textured_with: Optional[str] = None, depth_test: bool = True, colors: str = "vertex",
                offscreen: int = 0) -> Callable[[int, int], Dict[str, Any]]:
    """Setup of the vertex-coloured NDC grid: optionally with uvs and a 1×1 white texture read
    through the named filter (texture × colour = colour), without depth test, with constant colour
    as vertex colours (``colors='white-vertex'``) or none (``'none'``: the draw colour), and with
    `offscreen` extra triangles to the right of the screen (x in NDC 3…5)."""
    def setup(width: int, height: int) -> Dict[str, Any]:
        import mipraster as mr

        positions, tris, vertex_colors = _grid(width, height)
        scene = mr.Scene()
        kwargs: Dict[str, Any] = {"depth_test": depth_test}
        if colors == "none":
            vertex_colors, kwargs["color"] = None, (0.8, 0.6, 0.4, 1.0)
        elif colors == "white-vertex":
            vertex_colors = np.tile(np.float32([0.8, 0.6, 0.4, 1.0]), (len(positions), 1))
        uvs = positions[:, :2] * 0.5 + 0.5 if textured_with else None
        if textured_with:
            kwargs["texture"], kwargs["sampler"] = _white_texture(), mr.Sampler(filter=textured_with)
        scene.add(mr.Mesh(positions, tris, colors=vertex_colors, uvs=uvs), **kwargs)
        if offscreen:
            p, t, c = _grid(width, height, offscreen)
            p = p.copy()
            p[:, 0] += 4.0
            scene.add(mr.Mesh(p, t, colors=c), depth_test=depth_test)
        return {"scene": scene, "camera": _ndc_camera()}
    return setup


def _checker(size: int) -> np.ndarray:
    tex = np.full((size, size, 4), 255, np.uint8)
    cells = (np.arange(size) // 16)
    tex[((cells[:, None] + cells[None, :]) % 2) == 1, :3] = (40, 90, 200)
    return tex


def ortho_textured(interpolation: str) -> Callable[[int, int], Dict[str, Any]]:
    """Setup of a textured, vertex-coloured grid seen by an orthographic camera, uvs and colours
    interpolated with `interpolation`."""
    def setup(width: int, height: int) -> Dict[str, Any]:
        import mipraster as mr

        positions, tris, colors = _grid(width, height)
        positions = positions * np.float32([width / height, 1.0, 1.0])
        uvs = positions[:, :2] * 0.5 + 0.5
        scene = mr.Scene()
        scene.add(mr.Mesh(positions, tris, colors=colors, uvs=uvs), interpolation=interpolation,
                  texture=mr.Texture(_checker(256), srgb=False, name="checker"), sampler="trilinear")
        return {"scene": scene, "camera": mr.Camera.orthographic((0, 0, 1), (0, 0, 0), height=2.0, near=0.5, far=2.0)}
    return setup


def magnified_quad(width: int, height: int) -> Dict[str, Any]:
    """A full-screen quad showing a quarter of a fresh 1024² checker (magnified: level 0 only)."""
    import mipraster as mr

    positions = np.float32([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]])
    uvs = np.float32([[0, 0.5], [0.5, 0.5], [0.5, 0], [0, 0]])
    texture = mr.Texture(_checker(1024), srgb=False, name="checker 1024")
    scene = mr.Scene()
    scene.add(mr.Mesh(positions, np.array([[0, 1, 2], [0, 2, 3]]), uvs=uvs), texture=texture, sampler="trilinear")
    return {"scene": scene, "camera": _ndc_camera(), "texture": texture}


def build_all_levels(state: Dict[str, Any]) -> None:
    """Builds every mip level of the state's texture (level k builds the levels above it too)."""
    texture = state["texture"]
    texture.level(texture.level_count - 1)


def with_options(setup: Callable[[int, int], Dict[str, Any]], **options: Any) -> Callable[[int, int], Dict[str, Any]]:
    """`setup` with extra mr.render options."""
    def wrapped(width: int, height: int) -> Dict[str, Any]:
        return {**setup(width, height), **options}
    return wrapped


OMISSIONS = [
    Omission("no derivatives for untextured draws", f"{GRID_TRIANGLES:,}-triangle colour grid",
             Variant("untextured", colour_grid()),
             Variant("1×1 white texture, trilinear (uv, derivatives, λ, lookup)", colour_grid("trilinear")),
             "exact"),
    Omission("no derivatives when λ does not matter", "the same grid with a 1×1 white texture",
             Variant("bilinear (no derivatives)", colour_grid("bilinear")),
             Variant("trilinear (derivatives and λ)", colour_grid("trilinear")), "exact"),
    Omission("no perspective division for orthographic cameras", "textured colour grid, orthographic camera",
             Variant("interpolation='screen' (by hand)", ortho_textured("screen")),
             Variant("interpolation='perspective' (the default)", ortho_textured("perspective")), "close",
             "not automatic: the kernel follows the draw's interpolation, not the camera; with w = 1 both give "
             "the same values"),
    Omission("no resolve at 1 sample", "colour grid, 1 sample",
             Variant("tile writes straight into the image", colour_grid()),
             Variant("keep_samples: whole-frame sample buffer + resolve pass (+ samples returned)",
                     with_options(colour_grid(), keep_samples=True)), "exact"),
    Omission("no depth buffer when nothing tests depth", "colour grid (no overlaps)",
             Variant("depth_test=False", colour_grid(depth_test=False)),
             Variant("depth_test=True (never rejects)", colour_grid()), "exact",
             "the depth buffer is tile-local (one per worker), so the memory it saves is small"),
    Omission("lazily built mip levels", "full-screen quad magnifying a fresh 1024² texture",
             Variant("lazy: level 0 only", magnified_quad),
             Variant("every level built first (timed)", magnified_quad, build_all_levels), "exact"),
    Omission("culled off-screen triangles", f"colour grid + ~{OFFSCREEN_TRIANGLES:,} triangles off screen",
             Variant(f"~{OFFSCREEN_TRIANGLES:,} off-screen triangles, culled",
                     colour_grid(offscreen=OFFSCREEN_TRIANGLES)),
             Variant("them removed from the input (comparison)", colour_grid()), "exact",
             "no switch turns culling off: the comparison is the same frame without the off-screen triangles, "
             "so the difference is what rejecting them costs, not what culling saves"),
    Omission("specialization: constant colour", "colour grid with one colour",
             Variant("no vertex colours (constant-colour kernel)", colour_grid(colors="none")),
             Variant("the colour as vertex colours (interpolating kernel)", colour_grid(colors="white-vertex")),
             "close"),
    Omission("specialization vs a generic path", "any", Variant("specialized kernels", colour_grid()), None, "",
             "not measured: there is no generic (unspecialized) kernel; every draw runs an instance "
             "specialized on depth, blend, shading, samples and texturing (the rows above measure single features)"),
]


# ---- measuring ----------------------------------------------------------------------------------

def render_variant(variant: Variant, width: int, height: int, state: Optional[Dict[str, Any]] = None) -> Any:
    """One frame of `variant` (its forced work included); returns the RenderResult."""
    import mipraster as mr

    state = variant.setup(width, height) if state is None else state
    if variant.force is not None:
        variant.force(state)
    options = {k: v for k, v in state.items() if k not in ("scene", "camera", "texture")}
    return mr.render(state["scene"], state["camera"], width, height, threads=1, depth=False, **options)


def _peak_rss_bytes() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024  # kilobytes on Linux


def measure_variant(variant: Variant, width: int, height: int, frames: int) -> Dict[str, Any]:
    """Median ms of `frames` frames after a warm-up, and the peak-RSS growth over the setup's."""
    state = variant.setup(width, height)
    before = _peak_rss_bytes()
    image = render_variant(variant, width, height, state).color
    times = []
    for _ in range(frames):
        state.clear()  # drop the last frame's state before building the next one
        state = variant.setup(width, height)
        t0 = time.perf_counter()
        render_variant(variant, width, height, state)
        times.append(time.perf_counter() - t0)
    return {"median_ms": statistics.median(times) * 1e3, "times_ms": [t * 1e3 for t in times],
            "memory": _peak_rss_bytes() - before, "image": image}


def compare_images(kind: str, a: np.ndarray, b: np.ndarray) -> str:
    """'identical', or the largest difference; raises AssertionError when `kind` promises more."""
    diff = float(np.max(np.abs(a.astype(np.float64) - b.astype(np.float64)))) if a.shape == b.shape else np.inf
    if kind == "exact" and diff != 0.0:
        raise AssertionError(f"images differ (max |diff| {diff:.3g}) where they should be identical")
    if kind == "close" and not diff <= CLOSE_TOLERANCE:
        raise AssertionError(f"images differ by {diff:.3g} > {CLOSE_TOLERANCE:g}")
    return "identical" if diff == 0.0 else f"max |diff| {diff:.2g}"


def _child(index: int, which: str, width: int, height: int, frames: int, image_path: str) -> None:
    row = OMISSIONS[index]
    result = measure_variant(row.with_it if which == "with" else row.without, width, height, frames)
    np.save(image_path, result.pop("image"))
    print(json.dumps(result))


def _run_child(index: int, which: str, width: int, height: int, frames: int, tmp: str) -> Dict[str, Any]:
    image_path = os.path.join(tmp, f"{index}_{which}.npy")
    cmd = [sys.executable, "-m", "mipraster.omissions", "--child", str(index), which, str(width), str(height),
           str(frames), image_path]
    if shutil.which("taskset"):
        cmd = ["taskset", "-c", "0"] + cmd
    done = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"omission {OMISSIONS[index].name!r} ({which}) failed:\n{done.stderr[-2000:]}")
    result = json.loads(done.stdout.strip().splitlines()[-1])
    result["image"] = np.load(image_path)
    return result


def measure(width: int, height: int, frames: int) -> List[Row]:
    """Every row of OMISSIONS, each variant in its own process."""
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for i, om in enumerate(OMISSIONS):
            row = Row(om.name, om.scene, om.with_it.label, om.without.label if om.without else "–", note=om.note)
            if om.without is not None:
                a = _run_child(i, "with", width, height, frames, tmp)
                b = _run_child(i, "without", width, height, frames, tmp)
                row.with_ms, row.without_ms = a["median_ms"], b["median_ms"]
                row.with_memory, row.without_memory = a["memory"], b["memory"]
                row.samples = {"with_ms": a["times_ms"], "without_ms": b["times_ms"]}
                if om.same_image:
                    row.image_check = compare_images(om.same_image, a["image"], b["image"])
            print(f"omission {row.name}: {row.with_ms} / {row.without_ms} ms", file=sys.stderr)
            rows.append(row)
    return rows


def markdown(rows: List[Row], width: int, height: int) -> str:
    """The omission table."""
    mib = lambda v: "–" if v is None else f"{v / 2**20:,.1f}"  # noqa: E731
    ms = lambda v: "–" if v is None else f"{v:,.2f}"  # noqa: E731
    lines = [f"Omissions at {width}×{height}, 1 thread (median ms; memory = peak-RSS growth while rendering, MiB):",
             "", "| omission | scene | with it | ms | MiB | without (forced work) | ms | MiB | saves | same image |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        saves = "–" if r.with_ms is None or r.without_ms is None else f"{1 - r.with_ms / r.without_ms:+.0%}"
        lines.append(f"| {r.name} | {r.scene} | {r.with_label} | {ms(r.with_ms)} | {mib(r.with_memory)} | "
                     f"{r.without_label} | {ms(r.without_ms)} | {mib(r.without_memory)} | {saves} | "
                     f"{r.image_check or '–'} |")
    notes = [f"- {r.name}: {r.note}" for r in rows if r.note]
    return "\n".join(lines + [""] + notes) + "\n"


def run(out_dir: str, quick: bool = False) -> List[Row]:
    """Measures the table; prints and writes omissions.md and omissions.json to out_dir."""
    width, height = QUICK_SIZE if quick else SIZE
    rows = measure(width, height, 3 if quick else 9)
    table = markdown(rows, width, height)
    print(table)
    with open(os.path.join(out_dir, "omissions.md"), "w") as f:
        f.write(table)
    with open(os.path.join(out_dir, "omissions.json"), "w") as f:
        json.dump({"width": width, "height": height, "rows": [asdict(r) for r in rows]}, f, indent=1)
    return rows


if __name__ == "__main__":
    if len(sys.argv) == 8 and sys.argv[1] == "--child":
        _child(int(sys.argv[2]), sys.argv[3], int(sys.argv[4]), int(sys.argv[5]), int(sys.argv[6]), sys.argv[7])
    else:
        sys.exit("usage: python -m mipraster.omissions --child INDEX with|without WIDTH HEIGHT FRAMES IMAGE.npy "
                 "(internal; run `python -m mipraster.bench --omissions`)")
