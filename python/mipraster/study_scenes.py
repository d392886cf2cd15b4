"""The scenes of the error-against-time study, each with the ground truth it is measured against.

- ``star``: a fan of thin triangles (a star) with two thin bars across it, flat colours, seen
  through an orthographic camera that maps world (x, −y) to pixel (x, y): edge aliasing. Its
  reference is the exact coverage (:func:`mipraster.reference.exact_coverage`).
- ``shapes``: five large flat-coloured triangles, overlapping, same camera and reference: wide flat
  regions and a few long edges (where per-pixel adaptive sampling can pay).
- ``checker_plane``: a checker-textured floor running to the horizon: texture minification and
  anisotropy, edge aliasing along the horizon. Reference: :func:`mipraster.reference.plane_reference`.
- ``zone_plate``: a zone plate cos(π r²/w) texture (its frequency rises to the Nyquist limit of the
  texture at the rim) on a tilted square: the notes' aliasing example. Same reference.
- a scene file: its first camera (else one that frames it); reference
  :func:`mipraster.reference.converged_reference`.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Callable, Optional, Tuple

import numpy as np

from .camera import Camera
from .mesh import Mesh
from .reference import PerspectiveView, TexturedPlane, converged_reference, exact_coverage, plane_reference
from .scene import Scene
from .texture import Sampler, Texture

__all__ = ["StudyScene", "star", "shapes", "checker_plane", "zone_plate", "from_file", "with_filter", "SCENES"]


@dataclass
class StudyScene:
    """A scene of the study: what to render and how to get its reference.

    ``reference(quality)`` returns ``(image, residual, kind)``: the (H, W, ≥3) linear reference,
    the estimated RMSE of the reference itself (0 for exact ones) and a word on how it was made;
    ``quality`` (1 = the study's default) scales its integration effort.
    """

    name: str
    scene: Scene
    camera: Camera
    width: int
    height: int
    clear_color: Tuple[float, float, float, float]
    reference: Callable[[float], Tuple[np.ndarray, float, str]]

    @property
    def textured(self) -> bool:
        return any(d.texture is not None for d in self.scene.draws)


def with_filter(scene: Scene, filter: Optional[str] = None, max_anisotropy: Optional[float] = None,
                lod_bias: Optional[float] = None) -> Scene:
    """A copy of ``scene`` whose textured draws use another filter / max anisotropy / LOD bias
    (None keeps each draw's own); wrap modes are kept."""
    out = Scene()
    out.clear_color = scene.clear_color
    for d in scene.draws:
        texture, sampler = d.texture, None
        if texture is not None:
            old = d.sampler
            sampler = Sampler(filter or old.filter, max_anisotropy=old.max_anisotropy if max_anisotropy is None
                              else max_anisotropy, wrap=old.wrap, border_color=old.border_color,
                              lod_bias=old.lod_bias if lod_bias is None else lod_bias)
        out.add(d.mesh, model=d.model, color=d.color, depth_test=d.depth_test, depth_write=d.depth_write,
                blend=d.blend, interpolation=d.interpolation, cull=d.cull, texture=texture, sampler=sampler,
                alpha_cutoff=d.alpha_cutoff)
    return out


def _pixel_camera(width: int, height: int) -> Camera:
    # World (x, −y, 0) lands on pixel (x, y): an orthographic view exactly as tall as the image.
    return Camera.orthographic(eye=(width / 2, -height / 2, 1.0), target=(width / 2, -height / 2, 0.0),
                               height=float(height), near=0.0, far=2.0)


def _flat_scene(name: str, tri_xy: np.ndarray, colours: np.ndarray, width: int, height: int) -> StudyScene:
    """Flat-coloured triangles given in pixel coordinates (``tri_xy`` (T, 3, 2), ``colours`` (T, 3)
    linear RGB), drawn in order over a dark background through :func:`_pixel_camera`; reference:
    their exact coverage."""
    positions = np.concatenate([tri_xy[..., 0:1], -tri_xy[..., 1:2], np.zeros(tri_xy.shape[:2] + (1,))], axis=2)
    mesh = Mesh(positions.reshape(-1, 3), np.arange(3 * len(tri_xy)).reshape(-1, 3),
                colors=np.repeat(colours, 3, axis=0))
    scene = Scene()
    scene.add(mesh, depth_test=False, interpolation="flat")
    clear = (0.02, 0.02, 0.05, 1.0)
    scene.clear_color = clear

    def reference(quality: float = 1.0) -> Tuple[np.ndarray, float, str]:
        return exact_coverage(tri_xy, colours, width, height, clear[:3]), 0.0, "exact coverage"

    return StudyScene(name, scene, _pixel_camera(width, height), width, height, clear, reference)


def star(width: int = 160, height: int = 120, spikes: int = 24) -> StudyScene:
    """Thin triangles from the centre (a star) and two thin bars drawn over it, flat colours."""
    cx, cy, radius = width / 2, height / 2, 0.47 * min(width, height)
    half_angle = math.pi / spikes * 0.3
    tris, cols = [], []
    for k in range(spikes):
        a = 2 * math.pi * k / spikes + 0.1
        tris.append([(cx, cy), (cx + radius * math.cos(a - half_angle), cy + radius * math.sin(a - half_angle)),
                     (cx + radius * math.cos(a + half_angle), cy + radius * math.sin(a + half_angle))])
        cols.append((1.0, 0.85, 0.2) if k % 2 == 0 else (0.2, 0.6, 1.0))
    for angle, colour in ((0.23, (0.9, 0.15, 0.1)), (1.9, (0.1, 0.8, 0.3))):
        dx, dy = math.cos(angle), math.sin(angle)
        nx, ny = -dy * 0.6, dx * 0.6  # bars 1.2 px wide
        length = 0.45 * min(width, height)
        p = [(cx - dx * length + nx, cy - dy * length + ny), (cx + dx * length + nx, cy + dy * length + ny),
             (cx + dx * length - nx, cy + dy * length - ny), (cx - dx * length - nx, cy - dy * length - ny)]
        tris += [[p[0], p[1], p[2]], [p[0], p[2], p[3]]]
        cols += [colour, colour]
    return _flat_scene("star", np.array(tris, dtype=np.float64), np.array(cols, dtype=np.float64), width, height)


def shapes(width: int = 160, height: int = 120) -> StudyScene:
    """A few large flat-coloured triangles, some overlapping, over a background: wide flat regions
    that one sample per pixel renders exactly and a few long edges that need many (where per-pixel
    adaptive sampling can save time)."""
    corners = [  # in fractions of the image, drawn in this order
        [(0.08, 0.12), (0.55, 0.05), (0.30, 0.62)],
        [(0.60, 0.18), (0.96, 0.47), (0.50, 0.90)],
        [(0.05, 0.72), (0.47, 0.55), (0.33, 0.96)],
        [(0.22, 0.30), (0.83, 0.37), (0.44, 0.52)],
        [(0.70, 0.60), (0.93, 0.93), (0.62, 0.97)],
    ]
    colours = np.array([(0.9, 0.3, 0.1), (0.1, 0.5, 0.9), (0.2, 0.8, 0.3), (0.95, 0.85, 0.2), (0.8, 0.2, 0.7)])
    return _flat_scene("shapes", np.array(corners, dtype=np.float64) * [width, height], colours, width, height)


def _plane_scene(name: str, plane: TexturedPlane, view: PerspectiveView, sampler: Sampler, width: int, height: int,
                 clear: Tuple[float, float, float, float]) -> StudyScene:
    o, ea, eb = (np.asarray(v, dtype=np.float64) for v in (plane.origin, plane.edge_a, plane.edge_b))
    uv0, ua, ub = (np.asarray(v, dtype=np.float64) for v in (plane.uv_origin, plane.uv_a, plane.uv_b))
    mesh = Mesh(np.array([o, o + ea, o + ea + eb, o + eb]), np.array([[0, 1, 2], [0, 2, 3]]),
                uvs=np.array([uv0, uv0 + ua, uv0 + ua + ub, uv0 + ub]))
    scene = Scene()
    scene.add(mesh, texture=Texture(plane.texels.astype(np.float32), name=name), sampler=sampler,
              depth_test=False)
    scene.clear_color = clear
    camera = Camera.look_at(eye=view.eye, target=view.target, up=view.up, fov_y=view.fov_y)

    def reference(quality: float = 1.0) -> Tuple[np.ndarray, float, str]:
        n = max(2, int(round(16 * quality)))
        image, residual = plane_reference(plane, view, width, height, clear[:3], n=n)
        return image, residual, f"ray-cast footprint integral, 2x{n}x{n} points/pixel, bilinear level 0"

    return StudyScene(name, scene, camera, width, height, clear, reference)


def checker_plane(width: int = 160, height: int = 120) -> StudyScene:
    """A checker floor (64×64 texels, 8×8 checks of 8 texels, repeated) running to the horizon."""
    checks = (np.indices((64, 64)).sum(axis=0) // 8) % 2
    texels = np.where(checks[..., None] == 1, 0.8, 0.05) * np.ones(4)
    texels[..., 3] = 1.0
    plane = TexturedPlane(origin=(-100.0, 0.0, 4.0), edge_a=(200.0, 0.0, 0.0), edge_b=(0.0, 0.0, -204.0),
                          uv_origin=(0.0, 0.0), uv_a=(25.0, 0.0), uv_b=(0.0, 25.5), texels=texels, wrap="repeat")
    view = PerspectiveView(eye=(0.0, 1.5, 3.0), target=(0.0, 0.7, -3.0), fov_y=50.0)
    return _plane_scene("checker_plane", plane, view, Sampler("anisotropic", max_anisotropy=16), width, height,
                        (0.3, 0.5, 0.8, 1.0))


def zone_plate(width: int = 160, height: int = 120, size: int = 256) -> StudyScene:
    """A zone plate ½ + ½·cos(π r²/size) texture (r in texels from the centre) on a tilted square."""
    ys, xs = np.mgrid[0:size, 0:size] + 0.5 - size / 2
    value = 0.5 + 0.5 * np.cos(math.pi * (xs * xs + ys * ys) / size)
    texels = np.ones((size, size, 4))
    texels[..., :3] = value[..., None]
    plane = TexturedPlane(origin=(-2.0, 0.0, 1.0), edge_a=(4.0, 0.0, 0.0), edge_b=(0.0, 0.0, -4.0),
                          uv_origin=(0.0, 1.0), uv_a=(1.0, 0.0), uv_b=(0.0, -1.0), texels=texels, wrap="clamp")
    view = PerspectiveView(eye=(0.0, 2.2, 2.6), target=(0.0, 0.0, -1.0), fov_y=45.0)
    return _plane_scene("zone_plate", plane, view, Sampler("anisotropic", max_anisotropy=16, wrap="clamp"), width,
                        height, (0.0, 0.0, 0.0, 1.0))


def from_file(path: str, width: int = 160, height: int = 120) -> StudyScene:
    """A scene file (OBJ / glTF) with its first camera, else one that frames it (a look-at at the
    bounding box); reference: :func:`converged_reference`."""
    from .scene_file import load_scene

    scene, cameras = load_scene(path)
    if cameras:
        camera = cameras[0]
    else:
        points = np.zeros((1, 3))
        if scene.draws:
            points = np.concatenate([(np.c_[np.asarray(d.mesh.positions, dtype=np.float64),
                                             np.ones(len(d.mesh.positions))] @ np.asarray(d.model).T)[:, :3]
                                     for d in scene.draws])
        lo, hi = points.min(axis=0), points.max(axis=0)
        centre, extent = (lo + hi) / 2, float(np.linalg.norm(hi - lo)) or 1.0
        camera = Camera.look_at(eye=centre + np.array([0.0, 0.3, 1.2]) * extent, target=centre, fov_y=50.0)
    r, g, b, a = scene.clear_color if scene.clear_color is not None else (0.5, 0.5, 0.5, 1.0)
    clear = (r, g, b, a)
    name = os.path.splitext(os.path.basename(path))[0]

    def reference(quality: float = 1.0) -> Tuple[np.ndarray, float, str]:
        upscale = max(1, int(round(4 * quality)))
        image, residual = converged_reference(scene, camera, width, height, clear_color=clear, upscale=upscale)
        return image, residual, f"mipraster {upscale}x{upscale} larger at 64 stratified spp, bilinear level 0"

    return StudyScene(name, scene, camera, width, height, clear, reference)


SCENES = {"star": star, "shapes": shapes, "checker_plane": checker_plane, "zone_plate": zone_plate}
