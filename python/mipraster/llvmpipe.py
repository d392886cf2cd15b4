"""Comparison renders with Mesa's llvmpipe (OpenGL on the CPU) through moderngl on headless EGL.

The study's scenes are drawn as OpenGL draws of the same clip-space triangles (projection · view ·
model applied here in double precision), vertex colours × draw colour × texture (RGBA32F, mip-mapped
by GL, trilinear with 16× anisotropy, the sampler's wrap), into an RGBA32F target: ``1x``, ``msaa4``
(a 4-sample target resolved by a blit) or ``ssaa4`` (twice the size each way, 2×2 box average). One
timed frame = clear + draws + resolve + finish + read back into numpy, the median of ``repeats``
frames after one warm-up. llvmpipe reads LP_NUM_THREADS when the driver loads, so each thread count
runs in its own process (``python -m mipraster.llvmpipe``).
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from typing import Any, Optional, Tuple, cast

import numpy as np

__all__ = ["unavailable_reason", "render_timed"]

_PROBE = "import moderngl; ctx = moderngl.create_standalone_context(backend='egl'); print(ctx.info['GL_RENDERER'])"


def unavailable_reason() -> Optional[str]:
    """None when moderngl can open an EGL context on llvmpipe here, else why not."""
    try:
        import moderngl  # noqa: F401
    except ImportError:
        return "moderngl is not installed (pip install moderngl; Debian: libegl1 libgl1-mesa-dri)"
    try:
        out = subprocess.run([sys.executable, "-c", _PROBE], capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired) as e:
        return f"cannot start the EGL probe: {e}"
    if out.returncode != 0:
        lines = (out.stderr or out.stdout).strip().splitlines()
        return f"no EGL context: {lines[-1] if lines else 'unknown error'}"
    if "llvmpipe" not in out.stdout:
        return f"the EGL context is not llvmpipe but {out.stdout.strip()!r}"
    return None


def _export(s: Any, path: str) -> None:
    """The study scene's draws as arrays in an .npz (clip-space positions per triangle corner)."""
    core = s.camera.build(s.width, s.height)
    vp = np.asarray(core.projection) @ np.asarray(core.view)
    arrays: dict[str, Any] = {"size": np.array([s.width, s.height]),
                              "clear": np.asarray(s.clear_color, dtype=np.float32),
                              "reverse_z": np.array([s.camera.depth_convention == "reverse_z"])}
    for i, d in enumerate(s.scene.draws):
        tri = np.asarray(d.mesh.triangles).reshape(-1)
        pos = np.asarray(d.mesh.positions, dtype=np.float64)[tri]
        clip = np.c_[pos, np.ones(len(pos))] @ (vp @ np.asarray(d.model)).T
        colors = d.mesh.colors
        col = np.ones((len(tri), 4)) if colors is None else np.asarray(colors, dtype=np.float64)[tri]
        if col.shape[1] == 3:
            col = np.c_[col, np.ones(len(col))]
        col = col * np.asarray(d.color)
        arrays[f"clip{i}"] = clip.astype(np.float32)
        arrays[f"color{i}"] = col.astype(np.float32)
        arrays[f"depth{i}"] = np.array([d.depth_test])
        if d.texture is not None:
            uvs = np.asarray(d.mesh.uvs, dtype=np.float32)[tri]
            arrays[f"uv{i}"] = uvs
            arrays[f"texels{i}"] = np.ascontiguousarray(d.texture.level(0), dtype=np.float32)
            arrays[f"wrap{i}"] = np.array([w == "repeat" for w in d.sampler.wrap])
    np.savez(path, draws=np.array([len(s.scene.draws)]), **arrays)


def render_timed(s: Any, mode: str, threads: int = 0, repeats: int = 5) -> Tuple[np.ndarray, float]:
    """Renders study scene ``s`` with llvmpipe in ``mode`` (``1x``, ``msaa4``, ``ssaa4``) on
    ``threads`` threads (0 = llvmpipe's default, every core). Returns ((H, W, 4) linear float image,
    median ms per frame). Raises RuntimeError when the child process fails."""
    if mode not in ("1x", "msaa4", "ssaa4"):
        raise ValueError(f"mode: expected 1x, msaa4 or ssaa4, got {mode!r}")
    with tempfile.TemporaryDirectory() as tmp:
        scene_path, out_path = os.path.join(tmp, "scene.npz"), os.path.join(tmp, "out.npy")
        _export(s, scene_path)
        env = dict(os.environ)
        if threads:
            env["LP_NUM_THREADS"] = str(threads)  # 1 thread: llvmpipe's own count is 1 too
        else:
            env.pop("LP_NUM_THREADS", None)
        out = subprocess.run([sys.executable, "-m", "mipraster.llvmpipe", scene_path, mode, str(repeats), out_path],
                             capture_output=True, text=True, env=env, timeout=600)
        if out.returncode != 0:
            raise RuntimeError(f"llvmpipe render failed: {out.stderr.strip().splitlines()[-1:]}")
        return np.load(out_path), float(json.loads(out.stdout.strip().splitlines()[-1])["ms"])


_VS = """
#version 330
in vec4 in_clip; in vec4 in_col; in vec2 in_uv;
out vec4 v_col; out vec2 v_uv;
void main() { v_col = in_col; v_uv = in_uv; gl_Position = in_clip; }
"""
_FS = """
#version 330
uniform sampler2D tex; uniform bool textured;
in vec4 v_col; in vec2 v_uv;
out vec4 f_col;
void main() { f_col = textured ? texture(tex, v_uv) * v_col : v_col; }
"""


def _child(scene_path: str, mode: str, repeats: int, out_path: str) -> None:
    import statistics
    import time

    import moderngl

    data = np.load(scene_path)
    w, h = (int(v) for v in data["size"])
    scale = 2 if mode == "ssaa4" else 1
    # moderngl's stub types the **settings values as Dict[str, Any]; backend takes a str
    ctx = moderngl.create_standalone_context(backend="egl")  # type: ignore[arg-type]
    prog = ctx.program(vertex_shader=_VS, fragment_shader=_FS)
    draws = []
    for i in range(int(data["draws"][0])):
        clip, col = data[f"clip{i}"], data[f"color{i}"]
        textured = f"uv{i}" in data
        uv = data[f"uv{i}"] if textured else np.zeros((len(clip), 2), dtype=np.float32)
        vbo = ctx.buffer(np.concatenate([clip, col, uv], axis=1).astype(np.float32).tobytes())
        vao = ctx.vertex_array(prog, [(vbo, "4f 4f 2f", "in_clip", "in_col", "in_uv")])
        tex = None
        if textured:
            texels = data[f"texels{i}"]
            tex = ctx.texture((texels.shape[1], texels.shape[0]), 4, texels.tobytes(), dtype="f4")
            tex.build_mipmaps()
            tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
            tex.anisotropy = 16.0
            tex.repeat_x, tex.repeat_y = (bool(v) for v in data[f"wrap{i}"])
        draws.append((vao, tex, bool(data[f"depth{i}"][0])))
    size = (w * scale, h * scale)
    samples = 4 if mode == "msaa4" else 0
    fbo = ctx.framebuffer(ctx.renderbuffer(size, 4, samples=samples, dtype="f4"),
                          ctx.depth_renderbuffer(size, samples=samples))
    resolved = ctx.framebuffer(ctx.renderbuffer(size, 4, dtype="f4")) if samples else fbo
    reverse = bool(data["reverse_z"][0])
    clear = data["clear"]

    def frame() -> np.ndarray:
        fbo.use()
        red, green, blue, alpha = (float(c) for c in clear)
        ctx.clear(red, green, blue, alpha, depth=0.0 if reverse else 1.0)
        for vao, tex, depth_test in draws:
            if depth_test:
                ctx.enable(moderngl.DEPTH_TEST)
                ctx.depth_func = ">" if reverse else "<"
            else:
                ctx.disable(moderngl.DEPTH_TEST)
            cast(moderngl.Uniform, prog["textured"]).value = tex is not None
            if tex is not None:
                tex.use(0)
            vao.render(moderngl.TRIANGLES)
        if samples:
            ctx.copy_framebuffer(resolved, fbo)
        ctx.finish()
        img = np.frombuffer(resolved.read(components=4, dtype="f4"), dtype=np.float32).reshape(size[1], size[0], 4)
        if scale > 1:
            img = img.reshape(h, scale, w, scale, 4).mean(axis=(1, 3))
        return img[::-1]

    image = frame()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        image = frame()
        times.append((time.perf_counter() - t0) * 1000.0)
    np.save(out_path, np.ascontiguousarray(image))
    print(json.dumps({"ms": statistics.median(times), "renderer": ctx.info["GL_RENDERER"]}))


if __name__ == "__main__":
    _child(sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4])
