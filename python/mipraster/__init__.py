"""mipraster: a CPU software rasterizer (C++17) driven from numpy.

Build a scene from numpy arrays, pick a camera and render::

    import numpy as np
    import mipraster as mr

    mesh = mr.Mesh(positions=[[-1, 0, 0], [1, 0, 0], [0, 1.5, 0]], triangles=[[0, 1, 2]],
                   colors=[[1, 0, 0], [0, 1, 0], [0, 0, 1]])        # linear RGB(A)
    scene = mr.Scene()
    scene.add(mesh, cull="none")
    camera = mr.Camera.look_at(eye=(0, 0.5, 3), target=(0, 0.5, 0), fov_y=45)
    result = mr.render(scene, camera, 640, 360, spp=4, aa="msaa")
    result.color          # (360, 640, 4) float32, linear premultiplied RGBA
    result.save("triangle.png")                                    # sRGB 8-bit

Textures: give the mesh uvs and the draw a :class:`Texture` and a :class:`Sampler`::

    quad = mr.Mesh([[-1, 0, 0], [1, 0, 0], [1, 2, 0], [-1, 2, 0]], [[0, 1, 2], [0, 2, 3]],
                   uvs=[[0, 1], [1, 1], [1, 0], [0, 0]])           # (0, 0) = top-left texel
    checker = (np.indices((64, 64)).sum(0) // 8 % 2 * 255).astype(np.uint8)   # sRGB8 grey
    scene.add(quad, texture=mr.Texture(checker), sampler=mr.Sampler("anisotropic"))

Conventions: right-handed world, the camera looks down −z with +y up; arrays are (H, W, C) with
row 0 at the top; pixel (i, j) covers [i, i+1) × [j, j+1), its centre is (i + ½, j + ½); colour
is linear premultiplied RGBA; the library's cameras use reverse-Z depth.

The scene layer (:class:`Mesh`, :class:`Camera`, :class:`Texture`, :class:`Sampler`,
:class:`Material`, :class:`Scene`, :func:`render`) and the primitive
layer (:func:`rasterize`, :func:`interpolate`, :func:`resolve`: bring your own clip-space
positions) are Python over the C++ module ``mipraster._core``, which depends on nothing but the C++ standard library.
Image files (:func:`read_image`, :func:`write_image`, :meth:`RenderResult.save`) use
``mipraster._image`` (OpenImageIO), imported on first use only, so ``import mipraster`` is fast.
:func:`load_scene` reads OBJ and glTF scene files (geometry, colours, uvs, normals, base-colour
textures with their samplers, cameras) through the same module.

:func:`stress` runs the numerical stress suite and returns one :class:`StressRow` per
case (also ``mipraster stress`` on the command line).
:func:`resample` resizes an image with a reconstruction filter (box, tent, Mitchell–Netravali,
Catmull–Rom, Lanczos-3; widened when shrinking, in linear colour) and :func:`synthesize` grows a new
texture from a sample (Efros & Leung), ready to use as a :class:`Texture`.
:func:`render` can estimate its own error (``estimate_error=True``: ``result.error_map``,
``result.error_estimate``, measured on a sparse reference by :mod:`mipraster.error_probe`) and spend
samples adaptively, pixel by pixel (``target_error=e``, :mod:`mipraster.adaptive`). The error-against-time
study is :func:`mipraster.study.study` (``python -m mipraster.study``, ``mipraster study``); its
ground truths are in :mod:`mipraster.reference` and its scenes in :mod:`mipraster.study_scenes`.

:func:`compare` compares two images value by value with thresholds (OpenImageIO ``idiff`` style) and
returns a :class:`CompareReport`; :mod:`mipraster.testing` (imported explicitly) builds golden-image
tests on it.
"""
from ._build_info import X86_LEVEL as _X86_LEVEL
from ._cpu import check_cpu as _check_cpu

_check_cpu(_X86_LEVEL)  # before the compiled modules load: see _cpu.py

from ._core import (  # noqa: E402
    MemoryLimitError,
    kept_buffer_bytes,
    memory_limit,
    release_kept_buffers,
    set_memory_limit,
)
from .camera import Camera
from .compare import CompareReport, compare
from .image import linear_to_srgb, linear_to_srgb8, read_image, srgb_to_linear, to_srgb8, write_image
from .mesh import Mesh
from .primitives import Raster, interpolate, rasterize, resolve
from .render import RenderResult, render
from .resample import resample
from .scene import Draw, Material, Scene
from .scene_file import load_scene
from .stress import StressRow, format_stress_report, stress
from .synthesis import synthesize
from .texture import Sampler, Texture, clear_texture_cache, set_texture_cache_budget, texture_cache_stats

__version__ = "0.1.0"

__all__ = [
    "Camera",
    "CompareReport",
    "Draw",
    "Material",
    "MemoryLimitError",
    "Mesh",
    "Raster",
    "RenderResult",
    "Sampler",
    "Scene",
    "StressRow",
    "Texture",
    "clear_texture_cache",
    "compare",
    "format_stress_report",
    "linear_to_srgb",
    "linear_to_srgb8",
    "load_scene",
    "interpolate",
    "kept_buffer_bytes",
    "memory_limit",
    "rasterize",
    "read_image",
    "release_kept_buffers",
    "render",
    "resample",
    "resolve",
    "set_memory_limit",
    "set_texture_cache_budget",
    "srgb_to_linear",
    "stress",
    "synthesize",
    "texture_cache_stats",
    "to_srgb8",
    "write_image",
]
