"""What leaving out unneeded work saves: each omission's time and memory with and without it.

For each omission of DESIGN.md §3 ("leave out what a scene does not need") a small scene where it
applies is rendered two ways: as the pipeline renders it (the omission at work) and in a way that
forces the work (what it would cost without), at one thread on one CPU. Where nothing can force
the work, the row says so and gives no number rather than an invented one.

Time is the median of repeated frames, the two variants alternating frame by frame (so both see
the same background load) after a warm-up frame of each; anything a frame needs that is not the
omission (a fresh texture for the lazy-mip row) is built outside the timed part. Memory is the
growth of the resident set during one frame over the resident set before it (Linux: the peak is
reset through /proc/self/clear_refs, and freed heap memory returned with malloc_trim first). It
counts everything the frame allocates: the Python layer's copy of the meshes, the output image,
tile buffers, kept samples, texture levels. Where the two variants should draw the same image,
the images are compared: ``exact`` (bit-identical) or ``close`` (within ``CLOSE_TOLERANCE``,
where one variant computes the same value by another route, e.g. 1/w = 1 divided out).
"""
from __future__ import annotations

import ctypes
import gc
import json
import os
import statistics
import sys
import time
from dataclasses import asdict, dataclass, field
from typing import Any, Callable, Dict, List, Optional

import numpy as np

from .bench import pinned_to_one_cpu

SIZE = (1280, 720)
QUICK_SIZE = (160, 90)
GRID_TRIANGLES = 20_000  # about: growth.grid_mesh rounds to whole rows and columns
OFFSCREEN_TRIANGLES = 200_000
STACKED_QUADS = 8
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
    forced: bool = True  # False: `without` is a comparison, not the omitted work forced back in


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
    forced: bool = True
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
            vertex_colors = np.tile(np.array([0.8, 0.6, 0.4, 1.0], np.float32), (len(positions), 1))
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


def ortho_textured(force_division: bool) -> Callable[[int, int], Dict[str, Any]]:
    """Setup of a textured, vertex-coloured grid seen by an orthographic camera, uvs and colours
    perspective-correct. Every clip w is 1, so the pipeline interpolates affinely; with
    `force_division` the projection's w row gets a 1e-9·x term, so w differs between vertices
    (by 1e-9: the same image) and every sample takes the division again."""
    def setup(width: int, height: int) -> Dict[str, Any]:
        import mipraster as mr

        positions, tris, colors = _grid(width, height)
        positions = positions * np.array([width / height, 1.0, 1.0], np.float32)
        uvs = positions[:, :2] * 0.5 + 0.5
        scene = mr.Scene()
        scene.add(mr.Mesh(positions, tris, colors=colors, uvs=uvs), interpolation="perspective",
                  texture=mr.Texture(_checker(256), srgb=False, name="checker"), sampler="trilinear")
        camera = mr.Camera.orthographic((0, 0, 1), (0, 0, 0), height=2.0, near=0.5, far=2.0)
        if force_division:
            view, projection = camera.matrices(width, height)
            projection = projection.copy()
            projection[3, 0] = 1e-9
            camera = mr.Camera.from_matrices(view, projection, depth_convention=camera.depth_convention)
        return {"scene": scene, "camera": camera}
    return setup


def magnified_quad(width: int, height: int) -> Dict[str, Any]:
    """A full-screen quad showing a quarter of a fresh 1024² checker (magnified: level 0 only)."""
    import mipraster as mr

    positions = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32)
    uvs = np.array([[0, 0.5], [0.5, 0.5], [0.5, 0], [0, 0]], np.float32)
    texture = mr.Texture(_checker(1024), srgb=False, name="checker 1024")
    scene = mr.Scene()
    scene.add(mr.Mesh(positions, np.array([[0, 1, 2], [0, 2, 3]]), uvs=uvs), texture=texture, sampler="trilinear")
    return {"scene": scene, "camera": _ndc_camera(), "texture": texture}


def stacked_quads(width: int, height: int) -> Dict[str, Any]:
    """STACKED_QUADS full-screen textured quads (trilinear, minified checker), depth-tested, drawn
    in an order where every second one is nearer than all before it: each pixel passes the depth
    test STACKED_QUADS / 2 + 1 times, and only the nearest quad stays visible."""
    import mipraster as mr

    half = STACKED_QUADS // 2  # layers far to near: half + 1 … n − 1 interleaved with half − 1 … 0
    order = [i for pair in zip(range(STACKED_QUADS - 1, half - 1, -1), range(half - 1, -1, -1)) for i in pair]
    positions, uvs, tris = [], [], []
    for k, layer in enumerate(order):
        z = -0.9 + 1.8 * layer / STACKED_QUADS  # OpenGL NDC: smaller z is nearer
        positions += [[-1, -1, z], [1, -1, z], [1, 1, z], [-1, 1, z]]
        uvs += [[0, 4], [4, 4], [4, 0], [0, 0]]
        tris += [[4 * k, 4 * k + 1, 4 * k + 2], [4 * k, 4 * k + 2, 4 * k + 3]]
    scene = mr.Scene()
    scene.add(mr.Mesh(np.array(positions, np.float32), np.array(tris), uvs=np.array(uvs, np.float32)),
              texture=mr.Texture(_checker(256), srgb=False, name="checker 256"), sampler="trilinear")
    return {"scene": scene, "camera": _ndc_camera()}


def build_all_levels(state: Dict[str, Any]) -> None:
    """Builds every mip level of the state's texture (level k builds the levels above it too)."""
    texture = state["texture"]
    texture.level(texture.level_count - 1)


def with_no_op_draw(setup: Callable[[int, int], Dict[str, Any]]) -> Callable[[int, int], Dict[str, Any]]:
    """`setup` plus one triangle off the screen drawn blending add without a depth test: nothing on
    screen changes, but not every draw writes depth where it writes colour, so each tile's colour is
    cleared before drawing again."""
    def wrapped(width: int, height: int) -> Dict[str, Any]:
        import mipraster as mr

        state = setup(width, height)
        triangle = np.array([[3.0, 0.0, 0.5], [4.0, 0.0, 0.5], [3.0, 1.0, 0.5]], np.float32)
        state["scene"].add(mr.Mesh(triangle, np.array([[0, 1, 2]], np.uint32)), depth_test=False, depth_write=False,
                           blend="add")
        return state
    return wrapped


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
             Variant("automatic: every clip w is 1, so perspective-correct is interpolated affinely",
                     ortho_textured(force_division=False)),
             Variant("w = 1 + 1e-9·x (the division per sample)", ortho_textured(force_division=True)), "close"),
    Omission("no resolve at 1 sample", "colour grid, 1 sample",
             Variant("tiles copy their samples into the image", colour_grid()),
             Variant("keep_samples: whole-frame sample buffer + resolve pass (+ samples returned)",
                     with_options(colour_grid(), keep_samples=True)), "exact"),
    Omission("no depth buffer when nothing tests depth", "colour grid (no overlaps)",
             Variant("depth_test=False", colour_grid(depth_test=False)),
             Variant("depth_test=True (never rejects)", colour_grid()), "exact",
             "the depth buffer is tile-local (one per worker), so the memory it saves is small"),
    Omission("no depth buffer when nothing tests depth (textured, MSAA 4x)",
             "colour grid with a 1×1 white texture (trilinear), MSAA 4x",
             Variant("depth_test=False", with_options(colour_grid("trilinear", depth_test=False), spp=4, aa="msaa")),
             Variant("depth_test=True (never rejects)", with_options(colour_grid("trilinear"), spp=4, aa="msaa")),
             "exact"),
    Omission("no colour clear before drawing where every sample is drawn", "colour grid, MSAA 4x",
             Variant("every draw tests and writes depth and replaces colour: the samples still at the clear "
                     "depth count as the clear colour in the resolve", with_options(colour_grid(), spp=4, aa="msaa")),
             Variant("+ one off-screen triangle blending add: each tile's colour cleared before drawing",
                     with_options(with_no_op_draw(colour_grid()), spp=4, aa="msaa")), "exact"),
    Omission("lazily built mip levels", "full-screen quad magnifying a fresh 1024² texture",
             Variant("lazy: level 0 only", magnified_quad),
             Variant("every level built first (timed)", magnified_quad, build_all_levels), "exact"),
    Omission("culled off-screen triangles", f"colour grid + ~{OFFSCREEN_TRIANGLES:,} triangles off screen",
             Variant(f"~{OFFSCREEN_TRIANGLES:,} off-screen triangles, culled",
                     colour_grid(offscreen=OFFSCREEN_TRIANGLES)),
             Variant("them removed from the input (comparison)", colour_grid()), "exact",
             "no switch turns culling off: the comparison is the same frame without the off-screen triangles, "
             "so the difference is what rejecting them costs, not what culling saves", forced=False),
    Omission("shading hidden samples (deferred shading)", f"{STACKED_QUADS} stacked full-screen textured quads",
             Variant("visibility pre-pass, then one shade per visible sample", stacked_quads),
             Variant("deferred_shading=False: every sample that passes the depth test is shaded",
                     with_options(stacked_quads, deferred_shading=False)), "exact"),
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


def _status_bytes(key: str) -> int:
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith(key + ":"):
                return int(line.split()[1]) * 1024  # kB
    raise KeyError(key)


def render_memory(variant: Variant, width: int, height: int) -> Optional[int]:
    """Growth of the resident set during one frame (its peak over the resident set before it), or
    None where Linux's /proc and glibc's malloc_trim are not available. Freed heap memory and the
    buffers renders keep for the next render are first returned to the system, so the frame cannot
    hide its allocations in memory freed or kept before it."""
    import mipraster as mr

    try:
        libc = ctypes.CDLL("libc.so.6")
        state = variant.setup(width, height)
        gc.collect()
        mr.release_kept_buffers()
        libc.malloc_trim(0)
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")  # resets VmHWM, the peak resident set, to the current one
        before = _status_bytes("VmRSS")
        render_variant(variant, width, height, state)
        return _status_bytes("VmHWM") - before
    except (OSError, KeyError, AttributeError):
        return None


def time_pair(a: Variant, b: Variant, width: int, height: int, frames: int) -> tuple:
    """Frame times in ms of a and b, alternating frame by frame after a warm-up frame of each, so
    that both see the same background load; each frame's state is built untimed. Also returns
    the last image of each."""
    times: Dict[int, List[float]] = {0: [], 1: []}
    images = [render_variant(v, width, height).color for v in (a, b)]  # warm-up
    for _ in range(frames):
        for i, v in enumerate((a, b)):
            state = v.setup(width, height)
            t0 = time.perf_counter()
            render_variant(v, width, height, state)
            times[i].append((time.perf_counter() - t0) * 1e3)
            del state
    return times[0], times[1], images


def compare_images(kind: str, a: np.ndarray, b: np.ndarray) -> str:
    """'identical', or the largest difference; raises AssertionError when `kind` promises more."""
    diff = float(np.max(np.abs(a.astype(np.float64) - b.astype(np.float64)))) if a.shape == b.shape else np.inf
    if kind == "exact" and diff != 0.0:
        raise AssertionError(f"images differ (max |diff| {diff:.3g}) where they should be identical")
    if kind == "close" and not diff <= CLOSE_TOLERANCE:
        raise AssertionError(f"images differ by {diff:.3g} > {CLOSE_TOLERANCE:g}")
    return "identical" if diff == 0.0 else f"max |diff| {diff:.2g}"


def measure(width: int, height: int, frames: int) -> List[Row]:
    """Every row of OMISSIONS at one thread, pinned to one CPU."""
    rows = []
    with pinned_to_one_cpu():
        for om in OMISSIONS:
            row = Row(om.name, om.scene, om.with_it.label, om.without.label if om.without else "–", note=om.note,
                      forced=om.forced)
            if om.without is not None:
                a, b, images = time_pair(om.with_it, om.without, width, height, frames)
                row.with_ms, row.without_ms = statistics.median(a), statistics.median(b)
                row.samples = {"with_ms": a, "without_ms": b}
                row.with_memory = render_memory(om.with_it, width, height)
                row.without_memory = render_memory(om.without, width, height)
                if om.same_image:
                    row.image_check = compare_images(om.same_image, *images)
            print(f"omission {row.name}: {row.with_ms} / {row.without_ms} ms", file=sys.stderr)
            rows.append(row)
    return rows


def markdown(rows: List[Row], width: int, height: int) -> str:
    """The omission table."""
    mib = lambda v: "–" if v is None else f"{v / 2**20:,.1f}"  # noqa: E731
    ms = lambda v: "–" if v is None else f"{v:,.2f}"  # noqa: E731
    lines = [f"Omissions at {width}×{height}, 1 thread (median ms; memory = resident-set growth during a frame, MiB):",
             "", "| omission | scene | with it | ms | MiB | without (forced work) | ms | MiB | saves | same image |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r.with_ms is None or r.without_ms is None:
            saves = "–"
        elif not r.forced:
            saves = f"n/a (costs {r.with_ms / r.without_ms - 1:+.0%})"
        else:
            saves = f"{1 - r.with_ms / r.without_ms:+.0%}"
        lines.append(f"| {r.name} | {r.scene} | {r.with_label} | {ms(r.with_ms)} | {mib(r.with_memory)} | "
                     f"{r.without_label} | {ms(r.without_ms)} | {mib(r.without_memory)} | {saves} | "
                     f"{r.image_check or '–'} |")
    notes = [f"- {r.name}: {r.note}" for r in rows if r.note]
    return "\n".join(lines + [""] + notes) + "\n"


def run(out_dir: str, quick: bool = False) -> List[Row]:
    """Measures the table; prints and writes omissions.md and omissions.json to out_dir."""
    width, height = QUICK_SIZE if quick else SIZE
    rows = measure(width, height, 3 if quick else 15)
    table = markdown(rows, width, height)
    print(table)
    with open(os.path.join(out_dir, "omissions.md"), "w") as f:
        f.write(table)
    with open(os.path.join(out_dir, "omissions.json"), "w") as f:
        json.dump({"width": width, "height": height, "rows": [asdict(r) for r in rows]}, f, indent=1)
    return rows
