"""Scenes: an ordered list of draws (a mesh, a model matrix, a colour and fixed-function state)."""
from __future__ import annotations

from typing import Any, Iterator, List, Optional, Tuple

from . import _checks, _core
from .camera import Camera
from .mesh import Mesh

__all__ = ["Draw", "Scene"]

BLEND_MODES = {"replace": _core.BlendMode.replace, "add": _core.BlendMode.add, "over": _core.BlendMode.over}
INTERPOLATIONS = {
    "perspective": _core.Interpolation.perspective,
    "screen": _core.Interpolation.screen,
    "flat": _core.Interpolation.flat,
}
CULL_MODES = {"none": _core.CullMode.none, "back": _core.CullMode.back, "front": _core.CullMode.front}


class Draw:
    """One draw of a :class:`Scene` (made by :meth:`Scene.add`; read-only).

    Attributes:
        mesh: the :class:`Mesh` drawn.
        model: 4×4 float64 model matrix (world = model @ [x, y, z, 1]).
        color: linear premultiplied RGBA multiplied with the vertex colours.
        depth_test, depth_write: whether samples are depth tested / store their depth.
        blend: ``"replace"``, ``"add"`` or ``"over"`` (premultiplied Porter–Duff over).
        interpolation: ``"perspective"``, ``"screen"`` (affine) or ``"flat"`` (first vertex).
        cull: ``"none"``, ``"back"`` or ``"front"`` (front faces are counter-clockwise on screen).
    """

    __slots__ = ("_mesh", "_draw")

    def __init__(self, mesh: Mesh, draw: _core.Draw) -> None:
        self._mesh = mesh
        self._draw = draw

    mesh = property(lambda self: self._mesh, doc="The mesh drawn.")
    model = property(lambda self: self._draw.model, doc="4×4 float64 model matrix (a copy).")
    color = property(lambda self: self._draw.color, doc="Constant colour, linear premultiplied RGBA.")
    depth_test = property(lambda self: self._draw.depth_test, doc="Whether samples are depth tested.")
    depth_write = property(lambda self: self._draw.depth_write, doc="Whether passing samples store depth.")
    blend = property(lambda self: self._draw.blend.name, doc="'replace', 'add' or 'over'.")
    interpolation = property(lambda self: self._draw.interpolation.name, doc="'perspective', 'screen' or 'flat'.")
    cull = property(lambda self: self._draw.cull.name, doc="'none', 'back' or 'front'.")

    def __repr__(self) -> str:
        return (f"Draw({self._mesh!r}, color={self.color}, depth_test={self.depth_test}, "
                f"depth_write={self.depth_write}, blend={self.blend!r}, interpolation={self.interpolation!r}, "
                f"cull={self.cull!r})")


class Scene:
    """An ordered list of draws, rendered in the order they were added.

    Attributes:
        draws: the :class:`Draw` objects, in submission order.
        clear_color: the background :func:`mipraster.render` uses when it is not given one
            (linear premultiplied RGBA), or None for transparent black.
    """

    def __init__(self) -> None:
        self.draws: List[Draw] = []
        self.clear_color: Optional[Tuple[float, float, float, float]] = None

    def add(self, mesh: Mesh, model: Any = None, color: Any = (1.0, 1.0, 1.0, 1.0), depth_test: bool = True,
            depth_write: bool = True, blend: str = "replace", interpolation: str = "perspective",
            cull: str = "none") -> Draw:
        """Appends a draw of ``mesh`` and returns it.

        Args:
            mesh: a :class:`Mesh`.
            model: 4×4 model matrix (object → world, column vectors), default identity.
            color: 3 (alpha 1) or 4 components, linear premultiplied; multiplies the vertex colours.
            depth_test: test samples against the depth buffer (the camera's depth convention decides
                GREATER or LESS).
            depth_write: store the depth of samples that pass.
            blend: ``"replace"``, ``"add"`` or ``"over"``.
            interpolation: ``"perspective"``, ``"screen"`` or ``"flat"``.
            cull: ``"none"``, ``"back"`` or ``"front"``.

        Raises:
            TypeError: ``mesh`` is not a Mesh, a flag is not a bool, an option is not a string.
            ValueError: a wrong matrix or colour shape, a non-finite entry, an unknown option name
                (the message lists the accepted names).
        """
        if not isinstance(mesh, Mesh):
            raise TypeError(f"mesh: expected a mipraster.Mesh, got {type(mesh).__name__}")
        m = None if model is None else _checks.matrix(model, "model", 4, 4)
        draw = _core.Draw(
            mesh._mesh,
            m,
            _checks.rgba(color, "color"),
            depth_test=_checks.flag(depth_test, "depth_test"),
            depth_write=_checks.flag(depth_write, "depth_write"),
            blend=_checks.choice(blend, "blend", BLEND_MODES),
            interpolation=_checks.choice(interpolation, "interpolation", INTERPOLATIONS),
            cull=_checks.choice(cull, "cull", CULL_MODES),
        )
        item = Draw(mesh, draw)
        self.draws.append(item)
        return item

    @classmethod
    def demo(cls) -> Tuple["Scene", Camera]:
        """The built-in demo: a lit, vertex-coloured cube on a checkered plane running to the horizon.

        Returns ``(scene, camera)``; the scene's ``clear_color`` is the sky colour. This is the scene
        the ``mipraster render`` command draws (it uses 4 samples per pixel, MSAA).
        """
        demo = _core.make_demo_scene(1.0)
        scene = cls()
        meshes = {}
        for d in demo.draws:
            core_mesh = d.mesh
            mesh = meshes.setdefault(id(core_mesh), Mesh._from_core(core_mesh))
            scene.draws.append(Draw(mesh, d))
        scene.clear_color = demo.clear_color
        return scene, Camera._demo()

    def __len__(self) -> int:
        return len(self.draws)

    def __iter__(self) -> Iterator[Draw]:
        return iter(self.draws)

    def __repr__(self) -> str:
        triangles = sum(d.mesh.triangle_count for d in self.draws)
        return f"Scene(draws={len(self.draws)}, triangles={triangles}, clear_color={self.clear_color})"


def _core_draws(scene: Scene) -> List[_core.Draw]:
    out = []
    for i, d in enumerate(scene.draws):
        if not isinstance(d, Draw):
            raise TypeError(f"scene.draws[{i}]: expected a mipraster.Draw (made by Scene.add), got {type(d).__name__}")
        out.append(d._draw)
    return out
