"""Triangle meshes from numpy arrays."""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

from . import _checks, _core

__all__ = ["Mesh"]


class Mesh:
    """Indexed triangles: vertex positions, triangle indices and optional per-vertex colours,
    texture coordinates and normals.

    Args:
        positions: ``(N, 3)`` vertex positions, any float or integer dtype (stored as float32).
        triangles: ``(T, 3)`` vertex indices, any integer dtype, each in ``0 <= i < N``
            (stored as uint32).
        colors: optional ``(N, 3)`` or ``(N, 4)`` vertex colours, linear and premultiplied RGBA
            (alpha 1 when 3 channels are given), stored as float32. Integer arrays (e.g. a list
            like ``[[1, 0, 0], ...]``) are accepted when every value is 0 or 1; 8-bit sRGB codes
            are refused (convert them with ``mipraster.srgb_to_linear(rgb8 / 255)``).
        uvs: optional ``(N, 2)`` texture coordinates, any real dtype (stored as float32); (0, 0) is
            the top-left corner of the texture image, v grows downwards (glTF convention).
        normals: optional ``(N, 3)`` vertex normals (stored as float32; carried, not yet used
            for shading).

    Lists, non-contiguous and Fortran-order arrays are accepted; the data are checked, converted
    and copied once into the C++ mesh. The arrays read back as read-only views of
    that copy.

    Raises:
        TypeError: an array of bool, complex, string or object dtype, or float triangles.
        ValueError: a wrong shape, a NaN or infinite value (naming its row and column), or an
            index that is negative or not below the vertex count (naming the triangle and corner),
            or an integer colour other than 0 or 1.
    """

    __slots__ = ("_mesh",)

    def __init__(self, positions: Any, triangles: Any, colors: Optional[Any] = None, uvs: Optional[Any] = None,
                 normals: Optional[Any] = None) -> None:
        pos = _checks.empty_rows(_checks.real_array(positions, "positions"), 3)
        _checks.check_shape(pos, "positions", (None, 3))
        _checks.check_finite(pos, "positions")
        pos32 = _checks.to_float32(pos, "positions")
        n = pos32.shape[0]

        tri = _checks.integer_array(
            triangles, "triangles", hint="; convert vertex indices with .astype(np.uint32)")
        tri = _checks.empty_rows(tri, 3)
        _checks.check_shape(tri, "triangles", (None, 3), letters=("T",))
        if tri.size:
            _check_indices(tri, n)
        tri32 = np.ascontiguousarray(tri, dtype=np.uint32)

        col32 = None
        if colors is not None:
            col = _checks.empty_rows(_checks.real_array(colors, "colors"), 4)
            _checks.check_shape(col, "colors", (n, 3), (n, 4))
            _checks.check_finite(col, "colors")
            _check_integer_colors(col)
            if col.shape[1] == 3:
                col = np.concatenate([col, np.ones((n, 1), dtype=col.dtype)], axis=1)
            col32 = _checks.to_float32(col, "colors")

        uv32 = None if uvs is None else _per_vertex(uvs, "uvs", n, 2)
        nrm32 = None if normals is None else _per_vertex(normals, "normals", n, 3)
        self._mesh = _core.Mesh(pos32, tri32, col32, uv32, nrm32)

    @classmethod
    def from_trimesh(cls, mesh: Any, colors: bool = True) -> "Mesh":
        """A Mesh from a ``trimesh.Trimesh`` (or any object with ``.vertices`` and ``.faces``).

        Takes the vertex positions, the faces and ``mesh.vertex_normals``; texture coordinates
        from ``mesh.visual.uv`` when the visual has them (a ``TextureVisuals``), with v flipped
        (``v' = 1 − v``: trimesh and OBJ have v growing upwards from the image's bottom row,
        mipraster's (0, 0) is its top-left corner); and, when ``colors`` is true and the visual is
        a ``ColorVisuals`` holding vertex or face colours (``visual.kind`` ``"vertex"`` or
        ``"face"``), ``visual.vertex_colors`` — 8-bit sRGB RGBA with straight alpha (floats are
        taken as sRGB in [0, 1]) — decoded to linear premultiplied RGBA with
        :func:`mipraster.srgb_to_linear`. Face colours are averaged onto the vertices by trimesh;
        call ``mesh.unmerge_vertices()`` first to keep them exact. Textures and materials are not
        converted. A ``trimesh.Scene`` is flattened into one mesh (``Scene.to_geometry()``).

        Duck-typed objects need ``vertices`` and ``faces``; ``vertex_normals`` and ``visual``
        (with ``uv`` and/or ``kind`` + ``vertex_colors``) are optional. trimesh itself is only
        imported for other objects (to recognize a Scene), never by ``import mipraster``.

        Raises:
            ImportError: ``mesh`` has no ``vertices`` and ``faces`` and trimesh is not installed.
            TypeError: ``mesh`` is neither a mesh nor a Scene.
            ValueError / TypeError: as :class:`Mesh` for the arrays (e.g. NaN positions, naming
                the array).
        """
        want_colors = _checks.flag(colors, "colors")
        if not (hasattr(mesh, "vertices") and hasattr(mesh, "faces")):
            try:
                import trimesh
            except ImportError:
                raise ImportError(
                    f"Mesh.from_trimesh: got a {type(mesh).__name__}, not an object with .vertices and .faces; "
                    "reading trimesh objects needs the trimesh package: pip install trimesh"
                ) from None
            if not isinstance(mesh, trimesh.Scene):
                raise TypeError(f"mesh: expected a trimesh.Trimesh, a trimesh.Scene or an object with .vertices and "
                                f".faces, got {type(mesh).__name__}")
            mesh = mesh.to_geometry() if hasattr(mesh, "to_geometry") else mesh.dump(concatenate=True)

        positions = np.asarray(mesh.vertices)
        normals = getattr(mesh, "vertex_normals", None)
        visual = getattr(mesh, "visual", None)
        uvs = getattr(visual, "uv", None)
        if uvs is not None:
            uvs = _checks.real_array(uvs, "uvs").astype(np.float64)
            _checks.check_shape(uvs, "uvs", (None, 2))
            uvs = np.stack([uvs[:, 0], 1.0 - uvs[:, 1]], axis=1)
        col = None
        if want_colors and getattr(visual, "kind", None) in ("vertex", "face"):
            rgba = getattr(visual, "vertex_colors", None)
            if rgba is not None:
                col = _srgb8_to_linear_premultiplied(rgba)
        return cls(positions, mesh.faces, colors=col, uvs=uvs, normals=normals)

    @classmethod
    def _from_core(cls, mesh: _core.Mesh) -> "Mesh":
        """Wraps an existing C++ mesh (e.g. the demo's) without copying or re-checking it."""
        self = cls.__new__(cls)
        self._mesh = mesh
        return self

    @property
    def positions(self) -> np.ndarray:
        """``(N, 3)`` float32 vertex positions (read-only view)."""
        return self._mesh.positions

    @property
    def triangles(self) -> np.ndarray:
        """``(T, 3)`` uint32 vertex indices (read-only view)."""
        return self._mesh.triangles

    @property
    def colors(self) -> Optional[np.ndarray]:
        """``(N, 4)`` float32 linear premultiplied RGBA (read-only view), or None."""
        return self._mesh.colors

    @property
    def uvs(self) -> Optional[np.ndarray]:
        """``(N, 2)`` float32 texture coordinates (read-only view), or None."""
        return self._mesh.uvs

    @property
    def normals(self) -> Optional[np.ndarray]:
        """``(N, 3)`` float32 vertex normals (read-only view), or None."""
        return self._mesh.normals

    @property
    def vertex_count(self) -> int:
        """Number of vertices N."""
        return self._mesh.vertex_count

    @property
    def triangle_count(self) -> int:
        """Number of triangles T."""
        return self._mesh.triangle_count

    def __repr__(self) -> str:
        extras = "".join(f", {name}" for name in ("colors", "uvs", "normals") if getattr(self._mesh, name) is not None)
        return f"Mesh(vertices={self.vertex_count}, triangles={self.triangle_count}{extras})"


def _per_vertex(values: Any, name: str, n: int, columns: int) -> np.ndarray:
    """A checked ``(n, columns)`` float32 copy of an optional per-vertex array."""
    a = _checks.empty_rows(_checks.real_array(values, name), columns)
    _checks.check_shape(a, name, (n, columns))
    _checks.check_finite(a, name)
    return _checks.to_float32(a, name)


def _srgb8_to_linear_premultiplied(rgba: Any) -> np.ndarray:
    """``(N, 3)`` / ``(N, 4)`` sRGB colours with straight alpha — integer codes 0…255 or floats in
    [0, 1] — as ``(N, 4)`` float64 linear premultiplied RGBA."""
    a = _checks.empty_rows(_checks.real_array(rgba, "vertex_colors"), 4)
    _checks.check_shape(a, "vertex_colors", (None, 3), (None, 4))
    _checks.check_finite(a, "vertex_colors")
    if a.dtype.kind in "iu" and a.size and (a.min() < 0 or a.max() > 255):
        r, c = (int(i) for i in np.argwhere((a < 0) | (a > 255))[0])
        raise ValueError(f"vertex_colors[{r}, {c}] = {int(a[r, c])}: expected 8-bit codes 0 to 255")
    a = a.astype(np.float64) / 255.0 if a.dtype.kind in "iu" else a.astype(np.float64)
    alpha = a[:, 3:4] if a.shape[1] == 4 else np.ones((a.shape[0], 1))
    linear = np.asarray(_core.srgb_to_linear(np.ascontiguousarray(a[:, :3])), dtype=np.float64)
    return np.concatenate([linear * alpha, alpha], axis=1)


def _check_indices(tri: np.ndarray, n: int) -> None:
    """ValueError naming the first negative or out-of-range index (triangle row and corner)."""
    bad = (tri >= n) if tri.dtype.kind == "u" else ((tri < 0) | (tri >= n))
    if not bad.any():
        return
    t, k = (int(i) for i in np.argwhere(bad)[0])
    value = int(tri[t, k])
    where = f"triangles[{t}, {k}] (triangle {t}, corner {k}) = {value}"
    if value < 0:
        raise ValueError(f"{where} is negative; indices must satisfy 0 <= index < {n} (the vertex count)")
    raise ValueError(f"{where} is out of range; indices must satisfy 0 <= index < {n} (the vertex count)")


def _check_integer_colors(col: np.ndarray) -> None:
    """Integer colours are linear values: only 0 and 1 make sense (255 is an 8-bit code)."""
    if col.dtype.kind not in "iu" or col.size == 0:
        return
    bad = (col != 0) & (col != 1)
    if bad.any():
        r, c = (int(i) for i in np.argwhere(bad)[0])
        raise ValueError(
            f"colors[{r}, {c}] (row {r}, column {c}) = {int(col[r, c])}: integer colours are taken as linear "
            "values and must be 0 or 1; pass floats, or for 8-bit sRGB codes mipraster.srgb_to_linear(rgb8 / 255)"
        )
