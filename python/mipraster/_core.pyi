"""mipraster's C++ core: meshes, cameras, draws, the renderer and image comparison (no file I/O; see mipraster._image)."""
from typing import Any, ClassVar, Dict, List, NoReturn, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

_ArrayLike = npt.ArrayLike
_Float32Array = npt.NDArray[np.float32]
_Float64Array = npt.NDArray[np.float64]
_RGBA = Tuple[float, float, float, float]

INFINITE_FAR: float
MAX_DIMENSION: int
MAX_SAMPLES: int
MAX_THREADS: int
SUBPIXEL_ONE: int
TILE_SIZE: int

class _Enum:
    @property
    def name(self) -> str: ...
    @property
    def value(self) -> int: ...
    __members__: ClassVar[Dict[str, Any]]
    def __init__(self, value: int) -> None: ...
    def __int__(self) -> int: ...
    def __index__(self) -> int: ...
    def __eq__(self, other: object) -> bool: ...
    def __hash__(self) -> int: ...

class DepthConvention(_Enum):
    reverse_z: ClassVar[DepthConvention]
    opengl: ClassVar[DepthConvention]

class BlendMode(_Enum):
    replace: ClassVar[BlendMode]
    add: ClassVar[BlendMode]
    over: ClassVar[BlendMode]

class Interpolation(_Enum):
    flat: ClassVar[Interpolation]
    screen: ClassVar[Interpolation]
    perspective: ClassVar[Interpolation]

class CullMode(_Enum):
    none: ClassVar[CullMode]
    back: ClassVar[CullMode]
    front: ClassVar[CullMode]

class AntiAliasing(_Enum):
    ssaa: ClassVar[AntiAliasing]
    msaa: ClassVar[AntiAliasing]

class PatternKind(_Enum):
    automatic: ClassVar[PatternKind]
    center: ClassVar[PatternKind]
    grid: ClassVar[PatternKind]
    rotated: ClassVar[PatternKind]
    stratified: ClassVar[PatternKind]

# --- camera matrices: (4, 4) float64, clip = projection @ view @ [x, y, z, 1] -------------------

def look_at(eye: _ArrayLike, target: _ArrayLike, up: _ArrayLike) -> _Float64Array: ...
def frustum(
    left: float, right: float, bottom: float, top: float, near: float, far: float = ...,
    depth_convention: DepthConvention = ...,
) -> _Float64Array: ...
def perspective(
    fovy: float, aspect: float, near: float, far: float = ..., depth_convention: DepthConvention = ...
) -> _Float64Array: ...
def orthographic(
    left: float, right: float, bottom: float, top: float, near: float, far: float,
    depth_convention: DepthConvention = ...,
) -> _Float64Array: ...

class Camera:
    def __init__(
        self, view: _ArrayLike, projection: _ArrayLike, depth_convention: DepthConvention = ...
    ) -> None: ...
    @staticmethod
    def look_at_perspective(
        eye: _ArrayLike, target: _ArrayLike, up: _ArrayLike, fovy: float, aspect: float, near: float
    ) -> Camera: ...
    @staticmethod
    def from_matrices(
        view: _ArrayLike, projection: _ArrayLike, depth_convention: DepthConvention = ...
    ) -> Camera: ...
    @property
    def view(self) -> _Float64Array: ...
    @property
    def projection(self) -> _Float64Array: ...
    @property
    def depth_convention(self) -> DepthConvention: ...

class Mesh:
    def __init__(
        self,
        positions: _ArrayLike,
        triangles: _ArrayLike,
        colors: Optional[_ArrayLike] = None,
        uvs: Optional[_ArrayLike] = None,
        normals: Optional[_ArrayLike] = None,
    ) -> None: ...
    @property
    def positions(self) -> _Float32Array: ...
    @property
    def triangles(self) -> npt.NDArray[np.uint32]: ...
    @property
    def colors(self) -> Optional[_Float32Array]: ...
    @property
    def uvs(self) -> Optional[_Float32Array]: ...
    @property
    def normals(self) -> Optional[_Float32Array]: ...
    @property
    def vertex_count(self) -> int: ...
    @property
    def triangle_count(self) -> int: ...
    def has_colors(self) -> bool: ...
    def has_uvs(self) -> bool: ...
    def validate(self, name: str = "mesh") -> None: ...

class Draw:
    def __init__(
        self,
        mesh: Mesh,
        model: Optional[_ArrayLike] = None,
        color: _ArrayLike = ...,
        depth_test: bool = True,
        depth_write: bool = True,
        blend: BlendMode = ...,
        interpolation: Interpolation = ...,
        cull: CullMode = ...,
        texture: Optional[Texture] = None,
        sampler: Optional[Sampler] = None,
        alpha_cutoff: Optional[float] = None,
    ) -> None: ...
    @property
    def mesh(self) -> Mesh: ...
    @property
    def model(self) -> _Float64Array: ...
    @property
    def color(self) -> _RGBA: ...
    @property
    def depth_test(self) -> bool: ...
    @property
    def depth_write(self) -> bool: ...
    @property
    def blend(self) -> BlendMode: ...
    @property
    def interpolation(self) -> Interpolation: ...
    @property
    def cull(self) -> CullMode: ...
    @property
    def alpha_cutoff(self) -> Optional[float]: ...
    @property
    def texture(self) -> Optional[Texture]: ...
    @property
    def sampler(self) -> Sampler: ...

class DemoScene:
    @property
    def meshes(self) -> List[Mesh]: ...
    @property
    def draws(self) -> List[Draw]: ...
    @property
    def camera(self) -> Camera: ...
    @property
    def clear_color(self) -> _RGBA: ...

def make_demo_scene(aspect: float) -> DemoScene: ...

# --- rendering ---------------------------------------------------------------------------------

def parse_pattern_kind(name: str) -> PatternKind: ...
def parse_anti_aliasing(name: str) -> AntiAliasing: ...

class RenderSettings:
    width: int
    height: int
    samples: int
    pattern: PatternKind
    pattern_seed: int
    anti_aliasing: AntiAliasing
    threads: int
    keep_samples: bool
    depth_output: bool
    deferred_shading: bool
    batched_lookups: bool
    derivatives: str
    debug_view: str
    resolve_filter: str
    estimate_error: bool
    @property
    def tile_mask(self) -> List[int]: ...
    @tile_mask.setter
    def tile_mask(self, value: Sequence[int]) -> None: ...
    @property
    def pixels(self) -> List[int]:
        """[] = every pixel; else the indices y * width + x of the only pixels to render (one transform
        and setup; each row of listed pixels in a tile is one span); the others keep the clear colour."""
    @pixels.setter
    def pixels(self, value: Sequence[int]) -> None: ...
    def __init__(self) -> None: ...
    @property
    def clear_color(self) -> _RGBA: ...
    @clear_color.setter
    def clear_color(self, value: _ArrayLike) -> None: ...

class RasterizeSettings:
    width: int
    height: int
    samples: int
    pattern: PatternKind
    pattern_seed: int
    threads: int
    depth_convention: DepthConvention
    cull: CullMode
    def __init__(self) -> None: ...

def sample_pattern(kind: PatternKind, samples: int, seed: int = 0) -> _Float64Array: ...
def interleaved_halves(kind: PatternKind, samples: int, seed: int = 0) -> List[int]: ...
def validate_framebuffer_size(width: int, height: int, samples: int, with_depth: bool) -> None: ...
def render(draws: Sequence[Draw], camera: Camera, settings: RenderSettings) -> Dict[str, Any]:
    """Keys: color (H, W, 4) float32; depth (H, W) float32 or None; samples (H, W, S, 4) float32 or
    None; sample_depth (H, W, S) float32 or None; error_map (H, W) float32 or None; error_estimate
    float or None; pattern (S, 2) float64; pattern_kind str; stats dict."""
def rasterize(pos_clip: _ArrayLike, triangles: _ArrayLike, settings: RasterizeSettings) -> Dict[str, Any]:
    """Keys: triangle_id (H, W, S) int32; barycentrics (H, W, S, 2) float32; depth (H, W, S) float32;
    pattern (S, 2) float64; pattern_kind str; stats dict."""

# --- error probe (mipraster/pipeline/error_probe.hpp) ------------------------------------------

PROBE_REFERENCE_SPP: int
PROBE_MAX_PASSES: int

class ErrorProbe:
    """What the sparse reference measured (see mipraster.error_probe)."""
    @property
    def rmse(self) -> float:
        """Estimated RMSE (linear R, G, B); an upper bound when upper_bound."""
    @property
    def stderr(self) -> float: ...
    @property
    def upper_bound(self) -> bool:
        """True when the error was too small to resolve: the image's RMSE is at most rmse."""
    @property
    def pixels(self) -> int: ...
    @property
    def distinct_pixels(self) -> int: ...
    @property
    def reference_spp(self) -> int: ...
    @property
    def rendered_passes(self) -> int:
        """Reference passes this probe rendered (0: all reused from a ProbeReference)."""
    @property
    def reference_rmse(self) -> float: ...
    @property
    def halves_rmse(self) -> Optional[float]: ...
    @property
    def ms(self) -> float: ...

class ProbeReference:
    """A probe's draws and their reference passes, kept for later probes of the same scene."""
    def __init__(self) -> None: ...
    @property
    def draws(self) -> int: ...
    @property
    def distinct_pixels(self) -> int: ...
    @property
    def passes(self) -> int: ...
    @property
    def empty(self) -> bool: ...

def measure_error(draws: Sequence[Draw], camera: Camera, settings: RenderSettings, color: _ArrayLike,
                  halves_map: Optional[_ArrayLike], pixels: int, seed: int = 0,
                  guide: Optional[_ArrayLike] = None, reuse: Optional[ProbeReference] = None) -> ErrorProbe: ...
def error_guide(color: _ArrayLike, halves_map: Optional[_ArrayLike] = None) -> npt.NDArray[np.float32]: ...
def probe_reference_passes(spp: int) -> int: ...
def default_probe_pixels(width: int, height: int, spp: int) -> int: ...

# --- colour ------------------------------------------------------------------------------------

def to_srgb8(image: _ArrayLike) -> npt.NDArray[np.uint8]: ...
def srgb_to_linear(encoded: Union[float, _ArrayLike]) -> Any: ...
def linear_to_srgb(linear: Union[float, _ArrayLike]) -> Any: ...
def linear_to_srgb8(linear: Union[float, _ArrayLike]) -> Any: ...

# --- image comparison --------------------------------------------------------------------------

class CompareSettings:
    fail_threshold: float
    fail_fraction: float
    hard_fail_threshold: float
    def __init__(
        self, fail_threshold: float = ..., fail_fraction: float = 0.0, hard_fail_threshold: float = 1.0
    ) -> None: ...
    def validate(self) -> None: ...

class CompareReport:
    @property
    def passed(self) -> bool: ...
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @property
    def channels(self) -> int: ...
    @property
    def values_compared(self) -> int: ...
    @property
    def max_abs_error(self) -> float: ...
    @property
    def mean_abs_error(self) -> float: ...
    @property
    def rmse(self) -> float: ...
    @property
    def psnr(self) -> float: ...
    @property
    def failing_values(self) -> int: ...
    @property
    def failing_fraction(self) -> float: ...
    @property
    def hard_failing_values(self) -> int: ...
    @property
    def nan_values(self) -> int: ...
    @property
    def worst_x(self) -> int: ...
    @property
    def worst_y(self) -> int: ...
    @property
    def worst_channel(self) -> int: ...
    @property
    def worst_actual(self) -> float: ...
    @property
    def worst_expected(self) -> float: ...
    @property
    def settings(self) -> CompareSettings: ...
    def __bool__(self) -> NoReturn:
        """Raises TypeError: use ``passed``."""

def compare_images(actual: _ArrayLike, expected: _ArrayLike, settings: CompareSettings = ...) -> CompareReport: ...

# --- textures ----------------------------------------------------------------------------------

MAX_TEXTURE_DIMENSION: int
MAX_TEXTURE_BYTES: int

class WrapMode(_Enum):
    repeat: ClassVar[WrapMode]
    clamp: ClassVar[WrapMode]
    mirror: ClassVar[WrapMode]
    border: ClassVar[WrapMode]

class TexelFilter(_Enum):
    nearest: ClassVar[TexelFilter]
    linear: ClassVar[TexelFilter]

class MipFilter(_Enum):
    none: ClassVar[MipFilter]
    nearest: ClassVar[MipFilter]
    linear: ClassVar[MipFilter]

class FootprintFilter(_Enum):
    isotropic: ClassVar[FootprintFilter]
    anisotropic: ClassVar[FootprintFilter]
    ewa: ClassVar[FootprintFilter]
    sat: ClassVar[FootprintFilter]

class Sampler:
    mag_filter: TexelFilter
    min_filter: TexelFilter
    mip_filter: MipFilter
    footprint: FootprintFilter
    max_anisotropy: float
    wrap_u: WrapMode
    wrap_v: WrapMode
    lod_bias: float
    min_lod: float
    max_lod: float
    def __init__(self) -> None: ...
    @staticmethod
    def from_filter_name(name: str) -> Sampler: ...
    @property
    def border_color(self) -> _RGBA: ...
    @border_color.setter
    def border_color(self, value: _ArrayLike) -> None: ...
    def needs_derivatives(self) -> bool: ...
    def uses_mip_levels(self) -> bool: ...
    def validate(self) -> None: ...

class Texture:
    @staticmethod
    def from_uint8(texels: npt.NDArray[np.uint8], srgb: bool = True, name: str = "texture") -> Texture: ...
    @staticmethod
    def from_uint16(texels: npt.NDArray[np.uint16], srgb: bool = True, name: str = "texture") -> Texture: ...
    @staticmethod
    def from_float(texels: _ArrayLike, premultiplied: bool = False, name: str = "texture") -> Texture: ...
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    @property
    def level_count(self) -> int: ...
    @property
    def name(self) -> str: ...
    @property
    def built_levels(self) -> int: ...
    @property
    def has_summed_area_table(self) -> bool: ...
    @property
    def derived_bytes(self) -> int: ...
    @property
    def identity(self) -> int: ...
    def level(self, k: int) -> _Float32Array: ...

def sample_texture(
    texture: Texture, sampler: Sampler, uv: _ArrayLike, duv_dx: _ArrayLike, duv_dy: _ArrayLike
) -> _Float32Array:
    """uv (N, 2) float32, duv_dx / duv_dy (N, 2) or (1, 2) -> (N, 4) float32 premultiplied linear RGBA."""
def texture_lod(texture: Texture, sampler: Sampler, duv_dx: _ArrayLike, duv_dy: _ArrayLike) -> _Float64Array: ...
def texture_cache_stats() -> Dict[str, int]:
    """Keys: budget_bytes, derived_bytes, levels_built, tables_built, evictions, keyed_textures."""
def set_texture_cache_budget(budget_bytes: int) -> None: ...
def clear_texture_cache() -> None: ...

# memory.cpp: the process-wide memory limit
DEFAULT_MEMORY_LIMIT: int

class MemoryLimitError(ValueError, MemoryError):
    """Work refused because its estimated memory exceeds memory_limit()."""

def memory_limit() -> int:
    """The process-wide memory limit in bytes."""

def set_memory_limit(bytes: int) -> None:
    """Sets the process-wide memory limit in bytes; 0 restores the default."""

def kept_buffer_bytes() -> int:
    """Bytes of large render buffers (images, clip-space vertices, set-up triangles) kept after
    renders for the next buffer of the same size, so that a loop of renders does not fault them
    in again each frame (at most 512 MiB)."""

def release_kept_buffers() -> None:
    """Frees the buffers kept_buffer_bytes() counts."""

# --- stress suite (issue 6) ---------------------------------------------------------------------

class StressRow:
    @property
    def number(self) -> int: ...
    @property
    def name(self) -> str: ...
    @property
    def tried(self) -> str: ...
    @property
    def figure(self) -> str: ...
    @property
    def bound(self) -> str: ...
    @property
    def passed(self) -> bool: ...
    @property
    def details(self) -> List[str]: ...
    def to_json(self) -> str: ...

def run_stress_suite(size: str = "fast") -> List[StressRow]: ...
def format_stress_report(rows: Sequence[StressRow], with_details: bool = False) -> str: ...
def stress_rows_to_json(rows: Sequence[StressRow]) -> str: ...

# --- resampling (bindings/resample.cpp) ---------------------------------------------------------

MAX_RESAMPLE_DIMENSION: int
RECONSTRUCTION_FILTERS: str

def resample(image: _ArrayLike, width: int, height: int, filter: str, threads: int = 0) -> npt.NDArray[np.float32]: ...
def resample_weights(
    source_size: int, target_size: int, filter: str
) -> Tuple[npt.NDArray[np.int32], npt.NDArray[np.int32], npt.NDArray[np.float32], float]: ...
def filter_weight(filter: str, x: float) -> float: ...
def filter_radius(filter: str) -> float: ...

# --- texture synthesis (bindings/synthesis.cpp) -------------------------------------------------

MAX_SYNTHESIS_DIMENSION: int

class SynthesisSettings:
    width: int
    height: int
    window: int
    seed: int
    epsilon: float
    periodic_sample: bool
    tileable: bool
    threads: int
    def __init__(self) -> None: ...

def synthesize(sample: _ArrayLike, settings: SynthesisSettings) -> Dict[str, Any]:
    """Returns image (H, W, C) float32, source (H, W) int32, candidates, milliseconds."""
