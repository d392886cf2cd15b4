"""Fuzz targets for mipraster's input boundaries, driven by atheris (tests/fuzz/run_fuzz.py).

Each target takes the fuzzer's bytes, feeds them to one boundary and returns True when the input
was accepted, False when it was refused with an expected error. The only acceptable outcomes
are success or the documented exceptions that name the bad input (ValueError, TypeError, OSError,
including MemoryLimitError); any other exception, a crash, a hang or a sanitizer report is a bug
the fuzzer reports with the input that caused it.

Targets:
    scene   bytes as a scene file (.obj, .gltf, .glb: the first byte picks) -> load_scene + render
    image   bytes as an image file (.png, .exr, .jpg, .tga, .hdr, .ppm: the first byte picks) -> read_image
    render  bytes decoded into a mesh, a texture, a camera and render settings -> render
"""
from __future__ import annotations

import os
import struct
import tempfile
import warnings

import numpy as np

import mipraster as mr

EXPECTED = (ValueError, TypeError, OSError)
SCENE_EXTENSIONS = (".obj", ".gltf", ".glb")
IMAGE_EXTENSIONS = (".png", ".exr", ".jpg", ".tga", ".hdr", ".ppm")
# Inputs go through a file (the loaders take paths): in memory where the system has a tmpfs.
_TMP = tempfile.mkdtemp(prefix="mipraster_fuzz_", dir="/dev/shm" if os.path.isdir("/dev/shm") else None)
# Every target renders and loads within this, so an absurd header or size is refused quickly.
FUZZ_MEMORY_LIMIT = 256 << 20
# Images up to ~400,000 pixels: larger headers are refused before decoding, which keeps the
# image target at hundreds of inputs per second instead of decoding 100 MB of garbage each.
IMAGE_MEMORY_LIMIT = 16 << 20


def _as_file(data: bytes, extensions) -> str:
    ext = extensions[data[0] % len(extensions)] if data else extensions[0]
    path = os.path.join(_TMP, "input" + ext)
    with open(path, "wb") as f:
        f.write(data[1:])
    return path


def scene(data: bytes) -> bool:
    mr.set_memory_limit(FUZZ_MEMORY_LIMIT)
    path = _as_file(data, SCENE_EXTENSIONS)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            loaded, cameras = mr.load_scene(path)
            camera = cameras[0] if cameras else mr.Camera.look_at((0, 0, 3), (0, 0, 0))
            mr.render(loaded, camera, 16, 12, spp=4, threads=1)
    except EXPECTED:
        return False
    return True


def image(data: bytes) -> bool:
    mr.set_memory_limit(IMAGE_MEMORY_LIMIT)
    path = _as_file(data, IMAGE_EXTENSIONS)
    try:
        pixels = mr.read_image(path)
        assert pixels.ndim == 3 and pixels.dtype == np.float32
    except EXPECTED:
        return False
    return True


class _Reader:
    """Reads typed values from the fuzzer's bytes; zeros once they run out."""

    def __init__(self, data: bytes) -> None:
        self.data, self.pos = data, 0

    def take(self, n: int) -> bytes:
        chunk = self.data[self.pos:self.pos + n]
        self.pos += n
        return chunk + bytes(n - len(chunk))

    def u8(self) -> int:
        return self.take(1)[0]

    def floats(self, count: int) -> np.ndarray:
        # raw float32 bits: NaN, ±inf, denormals and huge values all occur
        return np.frombuffer(self.take(4 * count), dtype=np.float32).copy()

    def i32(self, count: int) -> np.ndarray:
        return np.frombuffer(self.take(4 * count), dtype=np.int32).copy()


FILTERS = ("nearest", "bilinear", "trilinear", "anisotropic", "ewa", "sat")
WRAPS = ("repeat", "clamp", "mirror", "border")


def render(data: bytes) -> bool:
    mr.set_memory_limit(FUZZ_MEMORY_LIMIT)
    r = _Reader(data)
    n_vertices = r.u8() % 12
    n_triangles = r.u8() % 8
    positions = r.floats(3 * n_vertices).reshape(-1, 3)
    # mostly valid indices, sometimes out of range or negative
    triangles = r.i32(3 * n_triangles).reshape(-1, 3)
    if r.u8() % 4 and n_vertices:
        triangles = np.abs(triangles % n_vertices)
    uvs = r.floats(2 * n_vertices).reshape(-1, 2) if r.u8() % 2 else None
    colors = r.floats(4 * n_vertices).reshape(-1, 4) if r.u8() % 2 else None
    width, height = r.u8() % 40 - 2, r.u8() % 40 - 2
    spp = (1, 4, 16, 0, 65)[r.u8() % 5]
    aa = ("ssaa", "msaa")[r.u8() % 2]
    texture_size = (r.u8() % 9, r.u8() % 9)
    texels = r.floats(texture_size[0] * texture_size[1] * 4).reshape(texture_size[1], texture_size[0], 4)
    sampler_args = dict(filter=FILTERS[r.u8() % len(FILTERS)], wrap=WRAPS[r.u8() % len(WRAPS)],
                        max_anisotropy=float(r.floats(1)[0]), lod_bias=float(r.floats(1)[0]))
    eye, target = r.floats(3), r.floats(3)
    try:
        mesh = mr.Mesh(positions, triangles, colors=colors, uvs=uvs)
        scene = mr.Scene()
        texture = mr.Texture(texels, name="fuzz") if uvs is not None else None
        sampler = mr.Sampler(**sampler_args) if texture is not None else None
        scene.add(mesh, texture=texture, sampler=sampler, cull=("none", "back", "front")[r.u8() % 3])
        kind, threads = r.u8(), 1 + r.u8() % 2
        # Raw matrices (a projection of any scale, w of either sign) when the byte after the
        # older fields asks for them: the seeds from before them read as they did.
        if r.u8() % 2:
            view, projection = r.floats(16).reshape(4, 4), r.floats(16).reshape(4, 4)
            camera = mr.Camera.from_matrices(view, projection, ("opengl", "reverse_z")[r.u8() % 2])
        else:
            camera = mr.Camera.look_at(eye, target) if kind % 2 else mr.Camera.orthographic(eye, target)
        result = mr.render(scene, camera, width, height, spp=spp, aa=aa, threads=threads)
        assert result.color.shape == (height, width, 4)
        # Shading multiplies texel by vertex colour, and the texture premultiplies each texel's
        # colour by its alpha: only where colour × texel × alpha fits in a float is an infinite
        # result the renderer's fault (1e28 × 1e28 overflows in any float pipeline).
        largest = lambda a: float(np.abs(a).max()) if a is not None and a.size else 1.0  # noqa: E731
        if largest(colors) * max(largest(texels), 1.0) ** 2 < 1e36:
            assert np.isfinite(result.color).all(), "a render returned a non-finite colour"
    except EXPECTED:
        return False
    return True


TARGETS = {"scene": scene, "image": image, "render": render}
