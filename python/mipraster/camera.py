"""Cameras: look-at perspective, orthographic, raw matrices and OpenCV calibrations.

A :class:`Camera` describes a view independently of the image size; ``build(width, height)``
makes the C++ camera for one render (the aspect ratio and, for OpenCV cameras, the pixel grid
come from the render size).

Conventions (the library's): right-handed world; the camera looks down −z with +y up; pixel
(i, j) covers [i, i+1) × [j, j+1) with its centre at (i + ½, j + ½); row 0 is the top row.
Cameras built here use reverse-Z depth (near → 1, far or infinity → 0, test GREATER), except
:meth:`Camera.from_matrices`, which takes OpenGL-style matrices (depth test LESS).
"""
from __future__ import annotations

import functools
import math
from typing import Any, Callable, Dict, Tuple

import numpy as np

from . import _checks, _core

__all__ = ["Camera"]

_CONVENTIONS = {"reverse_z": _core.DepthConvention.reverse_z, "opengl": _core.DepthConvention.opengl}

# OpenCV's camera looks down +z with y down; the library's looks down −z with y up.
_OPENCV_TO_VIEW = np.diag([1.0, -1.0, -1.0, 1.0])


def _size(width: Any, height: Any) -> Tuple[int, int]:
    w, h = _checks.integer(width, "width"), _checks.integer(height, "height")
    for name, v in (("width", w), ("height", h)):
        if not 1 <= v <= _core.MAX_DIMENSION:
            raise ValueError(f"{name}: expected 1 to {_core.MAX_DIMENSION} pixels, got {v}")
    return w, h


def _fmt(v: Any) -> str:
    if isinstance(v, np.ndarray):
        return "(" + ", ".join(f"{x:g}" for x in v.tolist()) + ")"
    return f"{v:g}" if isinstance(v, float) else repr(v)


class Camera:
    """A view of the scene, turned into the C++ camera for a given image size by :meth:`build`.

    Make one with :meth:`look_at`, :meth:`orthographic`, :meth:`from_matrices` or
    :meth:`from_opencv` (the constructor is not meant to be called directly).
    """

    __slots__ = ("_kind", "_params", "_build", "_convention")

    def __init__(self, kind: str, params: Dict[str, Any], build: Callable[[int, int], _core.Camera],
                 depth_convention: str) -> None:
        self._kind = kind
        self._params = params
        self._build = build
        self._convention = depth_convention

    # --- constructors ------------------------------------------------------------------------------

    @classmethod
    def look_at(cls, eye: Any, target: Any, up: Any = (0.0, 1.0, 0.0), fov_y: float = 60.0,
                near: float = 0.01, far: float = math.inf) -> "Camera":
        """Perspective camera at ``eye`` looking at ``target``.

        Args:
            eye, target, up: 3-vectors in world space (``up`` need not be orthogonal to the view
                direction, only not parallel to it).
            fov_y: vertical field of view in degrees, in (0, 180).
            near: distance of the near plane, at least float32's smallest normal number
                (about 1.18e-38: the depth buffer holds near / distance in float32).
            far: distance of the far plane, > near; ``inf`` (the default) for an infinite far plane.

        The horizontal field of view follows from the render's aspect ratio (width / height).
        Reverse-Z depth (near → 1, far → 0).
        """
        eye_v, target_v, up_v = (_checks.vector(v, n) for v, n in ((eye, "eye"), (target, "target"), (up, "up")))
        fov = _checks.real(fov_y, "fov_y")
        if not 0.0 < fov < 180.0:
            raise ValueError(f"fov_y: expected degrees in (0, 180), got {fov:g}")
        n, f = _near_far(near, far, allow_infinite_far=True)
        view = _core.look_at(eye_v, target_v, up_v)  # ValueError if eye == target or up is parallel
        fovy = math.radians(fov)

        def build(width: int, height: int) -> _core.Camera:
            projection = _core.perspective(fovy, width / height, n, f)
            return _core.Camera(view, projection, _core.DepthConvention.reverse_z)

        params = dict(eye=eye_v, target=target_v, up=up_v, fov_y=fov, near=n, far=f)
        return cls("look_at", params, build, "reverse_z")

    @classmethod
    def orthographic(cls, eye: Any, target: Any, up: Any = (0.0, 1.0, 0.0), height: float = 2.0,
                     near: float = 0.0, far: float = 100.0) -> "Camera":
        """Orthographic camera at ``eye`` looking at ``target``.

        Args:
            eye, target, up: 3-vectors in world space.
            height: the view's vertical extent in world units (its width is height × aspect).
            near, far: the depth range in front of the eye, ``near < far``, both finite
                (``near`` may be 0 or negative).

        Reverse-Z depth (near → 1, far → 0).
        """
        eye_v, target_v, up_v = (_checks.vector(v, n) for v, n in ((eye, "eye"), (target, "target"), (up, "up")))
        extent = _checks.real(height, "height")
        if not (math.isfinite(extent) and extent > 0.0):
            raise ValueError(f"height: expected a finite view height > 0 in world units, got {extent:g}")
        n, f = _checks.real(near, "near"), _checks.real(far, "far")
        if not (math.isfinite(n) and math.isfinite(f) and f > n and math.isfinite(f - n)):
            raise ValueError(f"near, far: expected finite values with near < far and a finite far - near, got "
                             f"near={n:g}, far={f:g}")
        view = _core.look_at(eye_v, target_v, up_v)

        def build(width: int, image_height: int) -> _core.Camera:
            half_h = extent / 2.0
            half_w = half_h * width / image_height
            projection = _core.orthographic(-half_w, half_w, -half_h, half_h, n, f)
            return _core.Camera(view, projection, _core.DepthConvention.reverse_z)

        params = dict(eye=eye_v, target=target_v, up=up_v, height=extent, near=n, far=f)
        return cls("orthographic", params, build, "reverse_z")

    @classmethod
    def from_matrices(cls, view: Any, projection: Any, depth_convention: str = "opengl") -> "Camera":
        """Camera from raw 4×4 matrices in the maths convention: clip = projection @ view @ [x, y, z, 1].

        Args:
            view, projection: 4×4 arrays (row-major, column vectors; transpose matrices taken from
                a column-major API such as glm or an OpenGL uniform buffer).
            depth_convention: ``"opengl"`` (the default: near → −1, far → +1, depth test LESS)
                or ``"reverse_z"`` (near → 1, far → 0, test GREATER).

        The matrices are used as given for every image size.
        """
        v = _checks.matrix(view, "view", 4, 4)
        p = _checks.matrix(projection, "projection", 4, 4)
        convention = _checks.choice(depth_convention, "depth_convention", _CONVENTIONS)
        core = _core.Camera.from_matrices(v, p, convention)
        return cls("from_matrices", dict(depth_convention=depth_convention), lambda w, h: core, depth_convention)

    @classmethod
    def from_opencv(cls, K: Any, R: Any, t: Any, near: float = 0.01, far: float = 1000.0) -> "Camera":
        """Pinhole camera from an OpenCV calibration.

        Args:
            K: 3×3 intrinsics ``[[fx, s, cx], [0, fy, cy], [0, 0, 1]]`` in pixels of the render
                size, with OpenCV's pixel convention (pixel centres at integer coordinates).
            R: 3×3 world-to-camera rotation.
            t: world-to-camera translation, shape (3,) or (3, 1): x_cam = R @ x_world + t.
            near, far: depth range along the optical axis, ``0 < near < far`` (``far`` may be inf;
                ``near`` at least about 1.18e-38, as for :meth:`look_at`).

        OpenCV's camera looks down +z with y down; this maps it to the library's (−z, y up), and
        maps OpenCV pixel coordinates (u, v) to the library's screen position (u + ½, v + ½), so
        a point OpenCV projects to (u, v) = (i, j) lands on the centre of pixel (i, j).
        Reverse-Z depth (near → 1, far → 0).
        """
        k = _checks.matrix(K, "K", 3, 3)
        if not (k[1, 0] == 0.0 and k[2, 0] == 0.0 and k[2, 1] == 0.0 and k[2, 2] == 1.0):
            raise ValueError(f"K: expected [[fx, s, cx], [0, fy, cy], [0, 0, 1]], got {k.tolist()}")
        fx, skew, cx, fy, cy = k[0, 0], k[0, 1], k[0, 2], k[1, 1], k[1, 2]
        if not (fx > 0.0 and fy > 0.0):
            raise ValueError(f"K: expected focal lengths fx, fy > 0, got fx={fx:g}, fy={fy:g}")
        r = _checks.matrix(R, "R", 3, 3)
        error = float(np.abs(r @ r.T - np.eye(3)).max())
        if error > 1e-5 or np.linalg.det(r) < 0.0:
            raise ValueError(
                "R: expected a rotation matrix (R @ R.T = I, det R = +1); "
                f"got max |R @ R.T - I| = {error:.3g}, det R = {np.linalg.det(r):.6g}"
                + (" (use cv2.Rodrigues to turn a rotation vector into R)" if error > 0.5 else "")
            )
        tv = _checks.vector(t, "t")
        n, f = _near_far(near, far, allow_infinite_far=True)

        world_to_cv = np.eye(4)
        world_to_cv[:3, :3] = r
        world_to_cv[:3, 3] = tv
        view = _OPENCV_TO_VIEW @ world_to_cv

        def build(width: int, height: int) -> _core.Camera:
            # The frustum whose edges are the image's outer pixel edges at OpenCV u = −½ and
            # u = width − ½ (and likewise v), scaled to the near plane.
            left, right = -n * (cx + 0.5) / fx, n * (width - cx - 0.5) / fx
            top, bottom = n * (cy + 0.5) / fy, -n * (height - cy - 0.5) / fy
            projection = _core.frustum(left, right, bottom, top, n, f)
            # Skew: u gains s·y_cv/z_cv; y_cv = −y_view and z_cv = w_clip.
            projection[0, 1] = -2.0 * skew / width
            return _core.Camera(view, projection, _core.DepthConvention.reverse_z)

        params = dict(fx=float(fx), fy=float(fy), cx=float(cx), cy=float(cy), skew=float(skew), near=n, far=f)
        return cls("from_opencv", params, build, "reverse_z")

    @classmethod
    def _demo(cls) -> "Camera":
        """The built-in demo scene's camera (for :meth:`mipraster.Scene.demo`)."""

        @functools.lru_cache(maxsize=8)
        def build_for_aspect(aspect: float) -> _core.Camera:
            return _core.make_demo_scene(aspect).camera

        return cls("demo", {}, lambda w, h: build_for_aspect(w / h), "reverse_z")

    # --- use ---------------------------------------------------------------------------------------

    @property
    def depth_convention(self) -> str:
        """``"reverse_z"`` (depth test GREATER) or ``"opengl"`` (depth test LESS)."""
        return self._convention

    def build(self, width: int, height: int) -> _core.Camera:
        """The C++ camera for an image of ``width`` × ``height`` pixels."""
        w, h = _size(width, height)
        return self._build(w, h)

    def matrices(self, width: int, height: int) -> Tuple[np.ndarray, np.ndarray]:
        """``(view, projection)`` as 4×4 float64 arrays for an image of the given size."""
        core = self.build(width, height)
        return core.view, core.projection

    def project(self, points: Any, width: int, height: int) -> np.ndarray:
        """Projects world points to the screen of a ``width`` × ``height`` image.

        Returns an ``(N, 3)`` float64 array of (x, y, depth): x and y in pixels (pixel (i, j)
        has its centre at (i + ½, j + ½); y grows downwards) and the window depth the depth test
        compares (reverse-Z: z_ndc; OpenGL: z_ndc / 2 + ½). Points at or behind the camera
        plane (w ≤ 0) give NaN. Accepts a single point of shape (3,) too (returns shape (3,)).
        """
        p = _checks.real_array(points, "points")
        single = p.ndim == 1
        p = p.reshape(1, -1) if single else p
        _checks.check_shape(p, "points", (None, 3))
        view, projection = self.matrices(width, height)
        homogeneous = np.concatenate([p.astype(np.float64), np.ones((p.shape[0], 1))], axis=1)
        clip = homogeneous @ (projection @ view).T
        with np.errstate(divide="ignore", invalid="ignore"):
            ndc = clip[:, :3] / clip[:, 3:4]
        out = np.empty((p.shape[0], 3))
        out[:, 0] = (ndc[:, 0] + 1.0) * width / 2.0
        out[:, 1] = (1.0 - ndc[:, 1]) * height / 2.0
        out[:, 2] = ndc[:, 2] if self._convention == "reverse_z" else ndc[:, 2] / 2.0 + 0.5
        out[clip[:, 3] <= 0.0] = np.nan
        return out[0] if single else out

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={_fmt(v)}" for k, v in self._params.items())
        return f"Camera.{self._kind}({args})"


def _near_far(near: Any, far: Any, *, allow_infinite_far: bool) -> Tuple[float, float]:
    """A perspective camera's near and far, checked when the camera is made (its projection is
    built only for a render's size)."""
    n, f = _checks.real(near, "near"), _checks.real(far, "far")
    if not (math.isfinite(n) and n > 0.0):
        raise ValueError(f"near: expected a finite distance > 0, got {n:g}")
    if not (f > n and (math.isfinite(f) or (allow_infinite_far and f == math.inf))):
        raise ValueError(f"far: expected a distance > near ({n:g}) or inf, got {f:g}")
    # The C++ projection's own checks, e.g. a near too small for float32 depth (ValueError naming
    # near and the smallest allowed, kMinPerspectiveNear in camera.hpp): one place holds the limit.
    _core.frustum(-1.0, 1.0, -1.0, 1.0, n, f)
    return n, f
