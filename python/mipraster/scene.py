"""Scenes: an ordered list of draws (a mesh, a model matrix, a material and fixed-function state)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Iterator, List, Optional, Tuple, Union

import numpy as np

from . import _checks, _core
from .camera import Camera
from .mesh import Mesh
from .texture import Sampler, Texture, _sampler

__all__ = ["Draw", "Material", "Scene"]

BLEND_MODES = {"replace": _core.BlendMode.replace, "add": _core.BlendMode.add, "over": _core.BlendMode.over}
INTERPOLATIONS = {
    "perspective": _core.Interpolation.perspective,
    "screen": _core.Interpolation.screen,
    "flat": _core.Interpolation.flat,
}
CULL_MODES = {"none": _core.CullMode.none, "back": _core.CullMode.back, "front": _core.CullMode.front}


@dataclass(frozen=True)
class Material:
    """What a surface looks like: fragment colour = ``color`` × vertex colour × ``texture``.

    Attributes:
        color: constant linear premultiplied RGBA (3 components: alpha 1).
        texture: optional base-colour :class:`Texture` (the mesh needs uvs).
        sampler: how the texture is filtered and wrapped: a :class:`Sampler`, a filter name
            (``"trilinear"``, ``"anisotropic"``, ...) or None for the default (trilinear, repeat).
    """

    color: Any = (1.0, 1.0, 1.0, 1.0)
    texture: Optional[Texture] = None
    sampler: Union[Sampler, str, None] = None


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
        alpha_cutoff: the alpha test's cutoff in [0, 1] (glTF ``alphaMode: MASK``), or None: no test.
        texture: the base-colour :class:`Texture`, or None.
        sampler: the :class:`Sampler` of the texture.
    """

    __slots__ = ("_mesh", "_draw")

    def __init__(self, mesh: Mesh, draw: _core.Draw) -> None:
        self._mesh = mesh
        self._draw = draw

    @property
    def mesh(self) -> Mesh:
        """The mesh drawn."""
        return self._mesh

    @property
    def model(self) -> np.ndarray:
        """4×4 float64 model matrix (a copy)."""
        return self._draw.model

    @property
    def color(self) -> Tuple[float, float, float, float]:
        """Constant colour, linear premultiplied RGBA."""
        return self._draw.color

    @property
    def depth_test(self) -> bool:
        """Whether samples are depth tested."""
        return self._draw.depth_test

    @property
    def depth_write(self) -> bool:
        """Whether passing samples store depth."""
        return self._draw.depth_write

    @property
    def blend(self) -> str:
        """'replace', 'add' or 'over'."""
        return self._draw.blend.name

    @property
    def interpolation(self) -> str:
        """'perspective', 'screen' or 'flat'."""
        return self._draw.interpolation.name

    @property
    def cull(self) -> str:
        """'none', 'back' or 'front'."""
        return self._draw.cull.name

    @property
    def alpha_cutoff(self) -> Optional[float]:
        """The alpha test's cutoff (fragments with a lower alpha are discarded), or None: no test."""
        return self._draw.alpha_cutoff

    @property
    def texture(self) -> Optional[Texture]:
        """The base-colour texture, or None."""
        t = self._draw.texture
        return None if t is None else Texture._from_core(t)

    @property
    def sampler(self) -> Sampler:
        """The texture's sampler."""
        return Sampler._from_core(self._draw.sampler)

    def __repr__(self) -> str:
        return (f"Draw({self._mesh!r}, color={self.color}, depth_test={self.depth_test}, "
                f"depth_write={self.depth_write}, blend={self.blend!r}, interpolation={self.interpolation!r}, "
                f"cull={self.cull!r}, alpha_cutoff={self.alpha_cutoff!r})")


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
            cull: str = "none", texture: Optional[Texture] = None, sampler: Union[Sampler, str, None] = None,
            material: Optional[Material] = None, alpha_cutoff: Optional[float] = None) -> Draw:
        """Appends a draw of ``mesh`` and returns it.

        Args:
            mesh: a :class:`Mesh`.
            model: 4×4 model matrix (object → world, column vectors), default identity.
            color: 3 (alpha 1) or 4 components, linear premultiplied; multiplies the vertex colours.
            texture: a base-colour :class:`Texture` multiplied in (the mesh needs uvs); uvs are
                interpolated like colours (``interpolation``).
            sampler: the texture's :class:`Sampler` or a filter name; default trilinear, repeat.
            material: a :class:`Material` giving color, texture and sampler at once (then those
                three arguments must be left at their defaults).
            depth_test: test samples against the depth buffer (the camera's depth convention decides
                GREATER or LESS).
            depth_write: store the depth of samples that pass.
            blend: ``"replace"``, ``"add"`` or ``"over"``.
            interpolation: ``"perspective"``, ``"screen"`` or ``"flat"``.
            cull: ``"none"``, ``"back"`` or ``"front"``.
            alpha_cutoff: alpha testing (glTF ``alphaMode: MASK``), a number in [0, 1]; None (the
                default): off. A fragment whose shaded alpha (color × vertex colour × texture,
                premultiplied) is below it is discarded: it writes neither colour nor depth. One at
                or above it is written opaque: rgb divided by its alpha, alpha 1 (then ``blend``
                applies). Such a draw is shaded before its depth is written, sample by sample, and
                the tiles it reaches are not deferred (about 1.1× the draw's time at one sample,
                1.7× under MSAA).

        Raises:
            TypeError: ``mesh`` is not a Mesh, a flag is not a bool, an option is not a string,
                ``alpha_cutoff`` is not a number or None.
            ValueError: a wrong matrix or colour shape, a non-finite entry, an unknown option name
                (the message lists the accepted names), an ``alpha_cutoff`` outside [0, 1] or NaN.
        """
        if not isinstance(mesh, Mesh):
            raise TypeError(f"mesh: expected a mipraster.Mesh, got {type(mesh).__name__}")
        if material is not None:
            if not isinstance(material, Material):
                raise TypeError(f"material: expected a mipraster.Material, got {type(material).__name__}")
            if texture is not None or sampler is not None or tuple(color) != (1.0, 1.0, 1.0, 1.0):
                raise ValueError("material: give either material or color/texture/sampler, not both")
            color, texture, sampler = material.color, material.texture, material.sampler
        if texture is not None and not isinstance(texture, Texture):
            raise TypeError(f"texture: expected a mipraster.Texture, got {type(texture).__name__}")
        if texture is not None and mesh.uvs is None:
            raise ValueError("texture: the mesh has no uvs; give Mesh(..., uvs=...) to texture it")
        core_sampler = _sampler(sampler)._sampler
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
            texture=None if texture is None else texture._texture,
            sampler=core_sampler,
            alpha_cutoff=_checks.unit_or_none(alpha_cutoff, "alpha_cutoff"),
        )
        item = Draw(mesh, draw)
        self.draws.append(item)
        return item

    @classmethod
    def demo(cls) -> Tuple["Scene", Camera]:
        """The built-in demo: a lit, textured cube on a textured checker plane running to the horizon.

        Returns ``(scene, camera)``; the scene's ``clear_color`` is the sky colour. This is the scene
        the ``mipraster render`` command draws (it uses 4 samples per pixel, MSAA).
        """
        demo = _core.make_demo_scene(1.0)
        scene = cls()
        meshes: dict[int, Mesh] = {}
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
