"""Rendering a scene: :func:`render` and its :class:`RenderResult`."""
from __future__ import annotations

import os
from typing import Any, Dict, List, Optional, Union

import numpy as np

from . import _checks, _core
from .camera import Camera
from .resample import RESAMPLE_FILTERS
from .scene import Scene, _core_draws

__all__ = ["render", "RenderResult"]

ANTI_ALIASING = {"ssaa": _core.AntiAliasing.ssaa, "msaa": _core.AntiAliasing.msaa}
DERIVATIVES = {"analytic": "analytic", "quad": "quad"}
DEBUG_VIEWS = {"none": "none", "mip-level": "mip-level", "uv": "uv"}
PATTERNS = {
    "auto": _core.PatternKind.automatic,
    "center": _core.PatternKind.center,
    "grid": _core.PatternKind.grid,
    "rotated": _core.PatternKind.rotated,
    "stratified": _core.PatternKind.stratified,
}

_INT32_MIN, _INT32_MAX = -(2**31), 2**31 - 1


class RenderResult:
    """The output of :func:`render`.

    Attributes:
        color: ``(H, W, 4)`` float32, linear premultiplied RGBA after the resolve. The array owns
            the renderer's buffer (no copy was made) and is writable.
        samples: ``(H, W, S, 4)`` float32 supersamples when the render kept them, else None.
        sample_depth: ``(H, W, S)`` float32 window depth of every sample when the render kept the
            samples and a draw tests depth, else None. Reverse-Z cameras: 1 at near, 0 at far/cleared;
            OpenGL-style matrices: z_ndc / 2 + ½, 1 cleared.
        depth: ``(H, W)`` float32 view-space depth (distance along the viewing axis, −z in view
            space) of each pixel's nearest sample, +inf where nothing was drawn; None when no draw
            tests depth or the render was asked for no depth (``depth=False``).
        pattern: ``(S, 2)`` float64 sample offsets from the pixel's top-left corner, in pixels
            (multiples of 1/256).
        pattern_kind: the pattern used (``"center"``, ``"grid"``, ``"rotated"`` or ``"stratified"``).
        error_map: ``(H, W)`` float32 per-pixel error estimate (root mean square over R, G, B of the
            linear colour) when the render was asked for one (``estimate_error=True`` or
            ``target_error``) with 2 or more samples per pixel, else None. It comes from the
            disagreement of two interleaved halves of each pixel's samples, scaled so that its
            root mean square is :attr:`error_estimate` (see :func:`render`).
        error_estimate: the estimated RMSE of the whole image (linear R, G, B), or None. When
            ``error_probe.upper_bound`` is True it is an upper bound: the error was too small for
            the probe to resolve, and the image's RMSE is at most this.
        error_probe: the :class:`mipraster.error_probe.ErrorProbe` (the sparse reference's
            measurement, its standard error, whether it is an upper bound, and its cost), or None.
        pixel_spp: ``(H, W)`` int array of the samples each pixel got, for an adaptive render
            (``target_error``), else None.
        adaptive: the passes of an adaptive render after the first, a list of
            :class:`mipraster.adaptive.AdaptivePass` (each ``"refine"`` or ``"uniform"``, with the
            cost model's prediction for both plans and the measured time), else None.
        stats: dict of the renderer's counters (``triangles_in``, ``triangles_clipped``,
            ``triangles_outside``, ``triangles_between_samples``: in the view, but with no sample
            position inside its bounding box (left out before binning), ``triangles_backface``,
            ``triangles_degenerate``, ``triangles_nonfinite``, ``triangles_rasterized``, ``samples_covered``,
            ``samples_passed``: of those, the ones that passed the depth test and any alpha test (as an
            OpenGL occlusion query counts), ``shader_invocations``, ``depth_blocks_rejected``, ``tiles_deferred``: tiles
            whose visible samples were shaded after a pre-pass, ``tiles_empty``: tiles no triangle
            reached, written from the clear values alone, ``threads``) and times in milliseconds
            (``transform_ms``, ``setup_ms``, ``raster_ms``, ``total_ms``).
    """

    __slots__ = ("color", "depth", "samples", "sample_depth", "pattern", "pattern_kind", "stats", "error_map",
                 "error_estimate", "error_probe", "pixel_spp", "adaptive")

    def __init__(self, raw: Dict[str, Any]) -> None:
        self.color: np.ndarray = raw["color"]
        self.depth: Optional[np.ndarray] = raw["depth"]
        self.samples: Optional[np.ndarray] = raw["samples"]
        self.sample_depth: Optional[np.ndarray] = raw["sample_depth"]
        self.pattern: np.ndarray = raw["pattern"]
        self.pattern_kind: str = raw["pattern_kind"]
        self.stats: Dict[str, Union[int, float]] = raw["stats"]
        self.error_map: Optional[np.ndarray] = raw.get("error_map")
        estimate = raw.get("error_estimate")
        self.error_estimate: Optional[float] = None if estimate is None else float(estimate)
        self.error_probe: Optional[_core.ErrorProbe] = raw.get("error_probe")
        self.pixel_spp: Optional[np.ndarray] = raw.get("pixel_spp")
        self.adaptive: Optional[List[Any]] = raw.get("adaptive")

    @property
    def width(self) -> int:
        """Image width in pixels."""
        return int(self.color.shape[1])

    @property
    def height(self) -> int:
        """Image height in pixels."""
        return int(self.color.shape[0])

    @property
    def spp(self) -> int:
        """Samples per pixel."""
        return int(self.pattern.shape[0])

    def to_srgb8(self) -> np.ndarray:
        """``(H, W, 4)`` uint8: straight-alpha sRGB colour, alpha linear (as a PNG stores it)."""
        return _core.to_srgb8(self.color)

    def save(self, path: Union[str, os.PathLike], bits: int = 8) -> None:
        """Writes :attr:`color`: ``.png`` as sRGB (straight alpha) with ``bits`` 8 or 16 per
        channel, ``.exr`` as linear float.

        Raises ValueError for another extension or bit depth and OSError (with ``.filename``) when
        the file cannot be written.
        """
        from .image import write_image

        write_image(path, self.color, bits=bits)

    def __repr__(self) -> str:
        return (f"RenderResult({self.width}x{self.height}, spp={self.spp} {self.pattern_kind}, "
                f"samples={'kept' if self.samples is not None else 'None'}, "
                + (f"error_estimate{'<=' if self.error_probe is not None and self.error_probe.upper_bound else '='}"
                   f"{self.error_estimate:.4g}, " if self.error_estimate is not None else "")
                + f"total_ms={self.stats['total_ms']:.3f})")


def _int_in(value: Any, name: str, lo: int, hi: int, expected: str) -> int:
    v = _checks.integer(value, name)
    if not lo <= v <= hi:  # outside what C++ takes at all: say what C++ would say
        raise ValueError(f"{name}: expected {expected}, got {v}")
    return v


def render(scene: Scene, camera: Camera, width: int, height: int, spp: int = 1, aa: str = "ssaa",
           pattern: str = "auto", seed: int = 0, threads: int = 0, clear_color: Any = None,
           keep_samples: bool = False, depth: bool = True, derivatives: str = "analytic",
           debug_view: str = "none", resolve_filter: str = "box", estimate_error: bool = False,
           target_error: Optional[float] = None, probe_pixels: Optional[int] = None,
           deferred_shading: bool = True, batched_lookups: bool = True) -> RenderResult:
    """Renders ``scene`` through ``camera`` into a ``width`` × ``height`` image.

    Args:
        scene: the :class:`Scene` (draws are rendered in order).
        camera: a :class:`Camera` (built for this size) or a ``mipraster._core.Camera``.
        width, height: image size in pixels, 1…32768 each.
        spp: samples per pixel, 1…64.
        aa: ``"ssaa"`` shades every sample; ``"msaa"`` shades once per pixel per triangle.
        pattern: ``"auto"`` (center for 1 sample, rotated for 4, grid otherwise), ``"center"``,
            ``"grid"``, ``"rotated"`` (4 samples) or ``"stratified"`` (seeded jittered grid).
        seed: seed of the stratified pattern, 0 ≤ seed < 2**64.
        threads: worker threads, 0 = all cores. The image does not depend on it.
        clear_color: background, linear premultiplied RGBA (3 components: alpha 1); None uses
            ``scene.clear_color``, or transparent black when the scene has none.
        keep_samples: also return every sample (and its depth) in ``samples`` / ``sample_depth``.
        depth: return each pixel's view-space depth in ``depth`` (cheap; needs a projection whose
            z and w rows depend on view-space z only, as every perspective and orthographic one does).
        derivatives: uv derivatives of textured draws: ``"analytic"`` (the chain rule from the
            triangle's planes, exact per sample) or ``"quad"`` (differences across the 2×2 pixel
            quad, as GPUs do).
        debug_view: ``"none"``, ``"mip-level"`` (textured draws show a colour per mip level,
            blended for fractional levels) or ``"uv"`` (textured draws show fract(u), fract(v)).
        resolve_filter: how samples become pixels: ``"box"`` (the mean of the pixel's own samples) or
            a wider reconstruction filter of :func:`mipraster.resample` (``"tent"``, ``"mitchell"``,
            ``"catmull-rom"``, ``"lanczos3"``; radius in pixels) that weighs the samples of the
            pixels around it too: for a grid pattern, the same as resampling the image of the
            samples to the output size with that filter. One sample per pixel runs no resolve.
        estimate_error: also estimate the render's error without a reference, in two parts. The
            halves map says where: each pixel's samples are split into two interleaved halves A
            and B (a checkerboard over the pattern's strata) and the full resolve's error is
            estimated as |A − B|·√(nA·nB)/n; it sees sampling error (edges, texture detail between
            samples), not error that every sample shares (a blurring texture filter, MSAA's one
            shade per pixel), and needs ``spp >= 2``. The probe says how much: ``probe_pixels``
            pixels, chosen at random (half of them where edges or the map are large), are
            rendered again at reference quality (2 or more passes of 64 stratified samples, SSAA,
            textures read at level 0 with bilinear) and their squared differences (less the
            reference's own error) give an unbiased estimate of the image's mean squared error,
            for any scene and any ``spp`` (see :mod:`mipraster.error_probe`); where the error is
            too small to resolve against the reference's own, the reference gets more passes,
            and if that is not enough the estimate is an upper bound (``error_probe.upper_bound``).
            ``error_estimate`` is the probe's RMSE, ``error_map`` the halves map scaled to it,
            ``error_probe`` the probe's details (standard error, cost in ms). The command line's
            ``--stats`` and ``--error-map`` run the same probe and report the same numbers.
        target_error: adaptive quality: render at ``spp`` (at least 2) with the estimate, then
            give more samples (up to 64) to the pixels whose estimated error needs them, in one
            extra pass of just those pixels: the fewest samples that bring the image's estimated
            RMSE to ``target_error`` (an RMSE in linear colour) with error ∝ 1/√spp; repeated
            (at most 4 passes) while the estimate misses the target and some pixel with error
            has fewer than 64; each round's error is a probe of the new image with the first
            probe's draws and reference passes (no reference pixel rendered again). While every pixel
            has the same count, a cost model from measured per-sample times weighs that pass
            against a uniform render of every pixel at the samples predicted to meet the target,
            and the cheaper one is rendered (see :mod:`mipraster.adaptive`).
            ``stats['total_ms']`` is the time of all passes and probes; ``pixel_spp`` shows where
            samples went, ``adaptive`` which plan each pass took. Needs the box resolve.
        probe_pixels: pixels the probe renders again (``estimate_error`` / ``target_error``):
            None = W·H·spp/(256·K) within [512, 4096] with K reference passes (2, or 4 at 64 spp):
            a quarter of the render's samples; 0 = no probe (the raw halves estimate; needs
            ``spp >= 2``).
        deferred_shading: where a tile's triangles overlap 1.25 or more deep (without a texture,
            deeper the smaller its triangles; under MSAA 1.5 or more deep, textured draws only) and
            each of them replaces what lies beneath without an alpha test, find each sample's
            visible triangle first and shade it once (MSAA: once per pixel and visible triangle)
            (``stats["tiles_deferred"]`` counts those tiles). The image is the same bit for bit;
            False shades every sample that passes its depth test, for comparison.
        batched_lookups: textured draws whose sampler is bilinear or trilinear (isotropic, or
            anisotropic where a footprint needs one probe) with repeat or clamp wrapping look
            their texture up sixteen samples at a time in float. Each lookup is within
            (4e-6 + 2^-22 × the texture's longer side in texels) × its largest texel value of the
            double-precision reference: 2.5e-4 for 1024 texels, and nearer 1e-7 in practice for
            power-of-two sizes. False uses the reference for every sample, for comparison.

    Returns:
        A :class:`RenderResult`.

    Raises:
        TypeError: a wrong kind of argument.
        ValueError: an unknown option name, a size, sample count or thread count out of range (the
            C++ message), or a pattern that does not fit the sample count.

    The GIL is released while the C++ renderer runs.
    """
    if not isinstance(scene, Scene):
        raise TypeError(f"scene: expected a mipraster.Scene, got {type(scene).__name__}")
    if not isinstance(camera, (Camera, _core.Camera)):
        raise TypeError(f"camera: expected a mipraster.Camera, got {type(camera).__name__}")
    w = _int_in(width, "width", _INT32_MIN, _INT32_MAX, f"1 to {_core.MAX_DIMENSION} pixels")
    h = _int_in(height, "height", _INT32_MIN, _INT32_MAX, f"1 to {_core.MAX_DIMENSION} pixels")
    samples = _int_in(spp, "spp", _INT32_MIN, _INT32_MAX, f"1 to {_core.MAX_SAMPLES}")
    n_threads = _int_in(threads, "threads", _INT32_MIN, _INT32_MAX, f"0 (all cores) to {_core.MAX_THREADS}")
    pattern_seed = _int_in(seed, "seed", 0, 2**64 - 1, "0 <= seed < 2**64")
    anti_aliasing = _checks.choice(aa, "aa", ANTI_ALIASING)
    pattern_kind = _checks.choice(pattern, "pattern", PATTERNS)
    keep = _checks.flag(keep_samples, "keep_samples")
    depth_output = _checks.flag(depth, "depth")
    deferred = _checks.flag(deferred_shading, "deferred_shading")
    batched = _checks.flag(batched_lookups, "batched_lookups")
    derivative_mode = _checks.choice(derivatives, "derivatives", DERIVATIVES)
    debug = _checks.choice(debug_view, "debug_view", DEBUG_VIEWS)
    resolve = _checks.choice(resolve_filter, "resolve_filter", {f: f for f in RESAMPLE_FILTERS})
    estimate = _checks.flag(estimate_error, "estimate_error")
    if probe_pixels is None:
        n_probe = None
    else:
        n_probe = _int_in(probe_pixels, "probe_pixels", 0, 2**31 - 1, "0 (no probe) or a number of pixels")
    if target_error is not None and samples == 1:
        raise ValueError("target_error: adaptive quality needs the halves map of each pixel's samples; give spp >= 2")
    if estimate and samples == 1 and n_probe == 0:
        raise ValueError("estimate_error: without a probe (probe_pixels=0) the error estimate compares two halves "
                         "of each pixel's samples; give spp >= 2")
    if clear_color is None:
        clear_color = scene.clear_color if scene.clear_color is not None else (0.0, 0.0, 0.0, 0.0)
    clear = _checks.rgba(clear_color, "clear_color")
    draws = _core_draws(scene)

    # The size first (the C++ message, before the camera divides by it), then the camera.
    _core.validate_framebuffer_size(w, h, samples, any(d.depth_test for d in draws))
    core_camera = camera.build(w, h) if isinstance(camera, Camera) else camera

    settings = _core.RenderSettings()
    settings.width, settings.height, settings.samples = w, h, samples
    settings.anti_aliasing, settings.pattern, settings.pattern_seed = anti_aliasing, pattern_kind, pattern_seed
    settings.threads, settings.clear_color, settings.keep_samples = n_threads, clear, keep
    settings.depth_output, settings.deferred_shading = depth_output, deferred
    settings.batched_lookups = batched
    settings.derivatives, settings.debug_view = derivative_mode, debug
    settings.resolve_filter = resolve
    settings.estimate_error = (estimate or target_error is not None) and samples >= 2
    if n_probe is None:
        from .error_probe import default_pixel_count

        n_probe = default_pixel_count(w, h, samples)
    if target_error is not None:
        from .adaptive import render_adaptive_settings

        return render_adaptive_settings(draws, core_camera, settings, target_error, n_probe)
    raw = _core.render(draws, core_camera, settings)
    if estimate and n_probe > 0:
        _calibrate(raw, draws, core_camera, settings, n_probe)
    return RenderResult(raw)


def _calibrate(raw: Dict[str, Any], draws: Any, core_camera: Any, settings: Any, n_probe: int) -> None:
    """Measures the error of the core render ``raw`` with a probe of ``n_probe`` pixels (see
    :mod:`mipraster.error_probe`) and puts it into ``raw``: ``error_estimate`` becomes the probe's
    RMSE and ``error_map`` (when there is one and it is not zero everywhere) the halves map scaled
    to it."""
    from .error_probe import measure_error

    probe = measure_error(draws, core_camera, settings, raw["color"], raw.get("error_map"), n_probe,
                          seed=settings.pattern_seed)
    raw["error_probe"], raw["error_estimate"] = probe, probe.rmse
    if raw.get("error_map") is not None and probe.halves_rmse:
        raw["error_map"] = (raw["error_map"] * np.float32(probe.rmse / probe.halves_rmse)).astype(np.float32)
