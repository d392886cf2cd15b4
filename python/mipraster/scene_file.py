"""Scene files: OBJ (+ MTL) and glTF 2.0 (.gltf, .glb) loaded into a :class:`Scene` and cameras.

The files are read by ``mipraster._image`` (the module that holds the file formats, imported on
first use); this module turns what it returns into :class:`Mesh`, :class:`Scene` and
:class:`Camera` objects. What loads: triangle geometry (glTF triangles, strips and fans; dense
and sparse accessors), vertex colours (linear), material colours (OBJ ``Kd``, glTF
``baseColorFactor``, both linear), texture coordinates (OBJ ``vt`` with v flipped to the glTF
convention; glTF ``KHR_texture_transform`` applied) and normals, base colour textures (OBJ
``map_Kd``, glTF ``baseColorTexture``; sRGB) with their samplers, glTF node transforms, alpha
blending and testing (``alphaMode: BLEND`` and ``MASK``), back-face culling of single-sided glTF materials, and glTF
cameras. A texture that cannot be read is replaced by a magenta/black checker, with a warning.
"""
from __future__ import annotations

import errno
import math
import os
import warnings
from typing import Any, Dict, List, Tuple

from . import _core
from .camera import Camera
from .image import PathLike, _image_module, _path
from .mesh import Mesh
from .scene import Scene
from .texture import Sampler, Texture

__all__ = ["load_scene"]


def _camera_from_file(named: Any) -> Camera:
    """A :class:`Camera` whose projection is built from the file's parameters for each image aspect."""
    view = named.view

    def build(width: int, height: int) -> _core.Camera:
        return _core.Camera(view, named.projection_matrix(width / height), _core.DepthConvention.reverse_z)

    if named.projection == "perspective":
        params = dict(name=named.name, fov_y=math.degrees(named.yfov), aspect_ratio=named.aspect_ratio,
                      near=named.znear, far=named.zfar)
    else:
        params = dict(name=named.name, xmag=named.xmag, ymag=named.ymag, near=named.znear, far=named.zfar)
    return Camera(f"scene_file_{named.projection}", params, build, "reverse_z")


def _sampler_from_file(fields: Dict[str, Any]) -> Sampler:
    """A :class:`Sampler` equal to the C++ loader's (an isotropic footprint: the trilinear preset with
    the file's texel and mip filters and wrap modes)."""
    preset = "trilinear" if fields["footprint"] == "isotropic" else fields["footprint"]
    return Sampler(filter=preset, mag_filter=fields["mag_filter"], min_filter=fields["min_filter"],
                   mip_filter=fields["mip_filter"], wrap=tuple(fields["wrap"]))


def load_scene(path: PathLike) -> Tuple[Scene, List[Camera]]:
    """Loads a scene file into ``(scene, cameras)``.

    Args:
        path: ``.obj`` (with the MTL files it names, looked up next to it), ``.gltf`` (with its
            ``.bin`` buffers or data-URI buffers) or ``.glb``; the extension picks the reader.

    Returns:
        A :class:`Scene` with one draw per OBJ material or per glTF node primitive (model matrix =
        the node's world matrix; colour = the material's linear base colour, premultiplied for
        ``BLEND`` and ``MASK`` materials; ``BLEND`` materials blend ``"over"``, ``MASK`` materials are
        alpha-tested with their ``alphaCutoff``, default 0.5, as ``draw.alpha_cutoff``; single-sided
        glTF materials cull back faces),
        and the file's cameras in node order as :class:`Camera` objects (OBJ has none). A
        perspective camera uses the file's aspect ratio if it gives one, else the render's;
        reverse-Z depth, infinite far plane when the file gives no ``zfar``. The scene's
        ``clear_color`` is left None (transparent black). Meshes carry the file's uvs (glTF: the
        ``TEXCOORD_n`` the base colour texture reads, ``TEXCOORD_0`` without one, with its
        ``KHR_texture_transform`` applied; OBJ ``vt`` with v flipped, OBJ vertices split where a
        position has several texture coordinates or normals) and normals. A draw whose material
        has a base colour texture (glTF ``baseColorTexture``, OBJ ``map_Kd``, both decoded from
        sRGB; the texture's alpha is ignored unless the material blends or masks) gets it as
        ``draw.texture``, with ``draw.sampler`` from the glTF sampler (wrap and filter enums;
        undefined filters are trilinear) or the default sampler (OBJ; ``-clamp on`` clamps). A
        texture file that is missing or unreadable does not stop the load: the draw gets an 8×8
        magenta/black checker named ``"error texture"`` and a :class:`UserWarning` names the
        material and the file.

    Warns:
        UserWarning: one per loader warning (skipped primitives, unsupported features, textures
            that could not be loaded), each naming the file.

    Raises:
        FileNotFoundError: there is no such file.
        OSError: the file (or a buffer it names) cannot be read, or it is truncated or corrupt;
            the message names the file and the problem, ``.filename`` is set.
        ValueError: an unsupported extension (the message lists .obj, .gltf, .glb) or invalid
            geometry (e.g. an index out of range, naming the file and the element).
    """
    p = _path(path)
    if not os.path.exists(p):
        raise FileNotFoundError(errno.ENOENT, os.strerror(errno.ENOENT), p)
    data = _image_module().load_scene(p)
    meshes = [Mesh(positions, triangles, colors, uvs=uvs, normals=normals)
              for positions, triangles, colors, uvs, normals in data["meshes"]]
    textures = [Texture(texels, premultiplied=True, name=name) for name, texels in data["textures"]]
    scene = Scene()
    for d in data["draws"]:
        texture = None if d["texture"] is None else textures[d["texture"]]
        sampler = None if texture is None else _sampler_from_file(d["sampler"])
        scene.add(meshes[d["mesh"]], model=d["model"], color=d["color"], blend=d["blend"], cull=d["cull"],
                  texture=texture, sampler=sampler, alpha_cutoff=d["alpha_cutoff"])
    for message in data["warnings"]:
        warnings.warn(message, UserWarning, stacklevel=2)
    cameras = [_camera_from_file(c) for c in data["cameras"]]
    return scene, cameras
