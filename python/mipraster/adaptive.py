"""Adaptive quality: more samples only for the pixels whose estimated error needs them, or for
every pixel when that is cheaper.

A first pass renders the image at the requested samples per pixel S₀ with the halves map on, and
the probe (:mod:`mipraster.error_probe`) measures the image's error E. The per-pixel estimate is the
probe's guide (the halves map squared and spread over 3×3 neighbourhoods, plus the squared colour
step to the neighbours: error the halves miss at few samples) scaled so that its root mean square
is E. With error ∝ 1/√S, raising pixel i from s_i to S samples lowers its squared error e_i² by e_i²·(1 − s_i/S). For
each candidate count S (S₀·2^k, up to 64) the pixels with the largest gains are taken until the
image's predicted mean squared error meets the target T²; the candidate with the fewest new samples
(pixels × S) wins, and only those pixels are rendered again, in one pass of the C++ renderer
(``RenderSettings.pixels``: one transform and setup, each row of chosen pixels in a tile one span).
Their colour and halves replace the first pass's, and the probe measures the new image: with the
first probe's draws and reference passes (a :class:`mipraster.error_probe.ProbeReference`), so a
later probe renders no reference pixel again and costs only its arithmetic (and any passes it
adds). Each probe is still unbiased for the image it measures given that image; what links them
is that the image after a pass depends on the first probe's draws through one number, the
measured RMSE that scales the plan.

Each round also prices the plain alternative while every pixel still has the same count s: a
uniform render of the whole image at the fewest samples S_u (s·2^k, up to 64) whose predicted error
E·√(s/S_u) meets the target. A cost model from measured per-sample times decides: the uniform
plan costs W·H·S_u samples at the first pass's measured time per sample, the refinement its new
samples at the time per sample of listed pixels (``LISTED_SAMPLE_COST`` × that until a refinement
pass has measured its own). The cheaper plan is rendered; each pass is reported
(:class:`AdaptivePass` in ``RenderResult.adaptive``) with its kind, both predicted costs and its
measured time, so a render that chose uniform supersampling says so. The rounds
go on (at most ``MAX_PASSES`` passes after the first) while the measured error misses the target and
some pixel with estimated error has fewer than 64 samples. The error reported is always the probe's
measurement of the returned image (an upper bound where the probe could not resolve it; a bound
at or below the target meets it). Pixels with no estimated error nearby (flat colour) are never
rendered again.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from typing import Any, List, Optional, Tuple

import numpy as np

from . import _checks, _core

__all__ = ["AdaptivePass", "plan_refinement", "uniform_samples", "render_adaptive_settings", "MAX_PASSES",
           "LISTED_SAMPLE_COST"]

MAX_PASSES = 4  # refinement passes after the first; each repeats the scene's setup once
# A sample of a listed (sparse) pixel costs 1.7-3x one of a whole-tile render (each row span repeats
# the edge setup of every triangle in its tile; measured on the study scenes, README "Error against
# run time"): the cost model's prior until a refinement pass has measured it.
LISTED_SAMPLE_COST = 2.0


@dataclass(frozen=True)
class AdaptivePass:
    """One pass of an adaptive render after the first.

    Attributes:
        kind: ``"refine"`` (only the listed pixels again) or ``"uniform"`` (every pixel again).
        samples: the samples per pixel of the pass.
        pixels: the pixels it rendered.
        predicted_ms: the cost model's time of this plan.
        alternative_ms: the cost model's time of the other plan (inf when there was none: a
            uniform render once pixels differ in samples, or a refinement with no pixel to refine).
        ms: the measured time of the pass.
        error: the probe's estimate of the image after the pass.
    """

    kind: str
    samples: int
    pixels: int
    predicted_ms: float
    alternative_ms: float
    ms: float
    error: float

    def __repr__(self) -> str:
        return (f"AdaptivePass({self.kind} {self.pixels} px at {self.samples} spp: predicted {self.predicted_ms:.3g} ms "
                f"against {self.alternative_ms:.3g} ms for the other plan, took {self.ms:.3g} ms, error {self.error:.4g})")


def plan_refinement(error: np.ndarray, spp: np.ndarray, target: float, base: int) -> Optional[Tuple[np.ndarray, int]]:
    """The pixels to render again and their new sample count: ``(mask, S)`` with the fewest new
    samples that bring the root mean square of ``error`` (per pixel, with ``spp`` samples each) to
    ``target`` under error ∝ 1/√spp, or, when no candidate S reaches it, every pixel with error at
    64. None when no pixel with error can get more samples."""
    e2 = np.asarray(error, dtype=np.float64) ** 2
    need = e2.sum() - target * target * e2.size  # the squared error to remove, summed over pixels
    some = np.flatnonzero(e2 > 0)  # only pixels with error can gain
    e2_some, spp_some = e2.ravel()[some], np.asarray(spp).ravel()[some]
    candidates = sorted({base * 2 ** k for k in range(1, 7) if base * 2 ** k <= _core.MAX_SAMPLES}
                        | {_core.MAX_SAMPLES})
    # With equal sample counts every candidate ranks the pixels alike: sort once.
    uniform = np.argsort(-e2_some, kind="stable") if np.all(spp_some == spp_some[:1]) else None
    best = None
    for s in candidates:
        eligible = spp_some < s
        if not eligible.any():
            continue
        gain = np.where(eligible, e2_some * (1.0 - spp_some / s), 0.0)
        # Largest gain first; ties in pixel order.
        order = uniform if uniform is not None else np.argsort(-gain, kind="stable")
        k = int(np.searchsorted(np.cumsum(gain[order]), need * (1 - 1e-12))) + 1
        if k > int(eligible.sum()):
            continue  # this count cannot reach the target
        if best is None or k * s < best[0]:
            best = (k * s, some[order[:k]], s)
    mask = np.zeros(e2.size, dtype=bool)
    if best is not None:
        mask[best[1]] = True
        return mask.reshape(e2.shape), best[2]
    mask[some[spp_some < _core.MAX_SAMPLES]] = True
    return (mask.reshape(e2.shape), _core.MAX_SAMPLES) if mask.any() else None


def uniform_samples(error: float, spp: int, target: float) -> Optional[int]:
    """The fewest samples per pixel S (spp·2^k, k >= 1, or 64) whose predicted error error·√(spp/S)
    meets ``target`` for an image measured at ``error`` with ``spp`` samples in every pixel; 64 when
    none does; None when ``spp`` is already 64."""
    if spp >= _core.MAX_SAMPLES:
        return None
    candidates = sorted({spp * 2 ** k for k in range(1, 7) if spp * 2 ** k <= _core.MAX_SAMPLES} | {_core.MAX_SAMPLES})
    for s in candidates:
        if error * math.sqrt(spp / s) <= target:
            return s
    return _core.MAX_SAMPLES


def render_adaptive_settings(draws: List[Any], camera: Any, settings: Any, target_error: Any,
                             probe_pixels: int) -> Any:
    """Adaptive render of already checked core draws / camera / settings (``mipraster.render``
    calls this).

    Raises ValueError for a target that is not a finite number > 0, with ``keep_samples`` or with
    a resolve filter other than box.
    """
    from .error_probe import ProbeReference, guide, measure_error, rms
    from .render import RenderResult

    target = _checks.real(target_error, "target_error")
    if not (math.isfinite(target) and target > 0.0):
        raise ValueError(f"target_error: expected a finite RMSE > 0 (linear colour), got {target!r}")
    if settings.keep_samples:
        raise ValueError("target_error: cannot keep the samples of an adaptive render (pixels differ in samples)")
    if settings.resolve_filter != "box":
        raise ValueError(f"target_error: adaptive quality re-renders single pixels and needs the box resolve, "
                         f"got resolve_filter={settings.resolve_filter!r}")
    start = time.perf_counter()
    settings.estimate_error = True
    raw = _core.render(draws, camera, settings)
    color, depth = raw["color"], raw["depth"]
    halves = raw["error_map"]  # float32
    stats = dict(raw["stats"])
    base = settings.samples
    n_all = halves.size
    spp = np.full(halves.shape, base, dtype=np.int64)
    base_pattern = settings.pattern
    # The cost model: measured milliseconds per sample of a whole render and of listed pixels.
    ms_per_sample = stats["total_ms"] / (n_all * base)
    listed_ms_per_sample = LISTED_SAMPLE_COST * ms_per_sample
    passes_done: List[AdaptivePass] = []
    probe = None
    likely = None
    reference = ProbeReference()  # the first probe's draws and passes, measured against by every probe
    for passes in range(MAX_PASSES + 1):
        # The first probe draws its pixels by the first pass's guide; later probes measure the same
        # draws (``reference``). The guide is computed again only when a pass is to be planned on it.
        if likely is None:
            likely = guide(color, halves)
        if probe_pixels > 0:
            probe = measure_error(draws, camera, settings, color, halves, probe_pixels, seed=settings.pattern_seed,
                                  guide_map=likely, reuse=reference)
            measured = probe.rmse
        else:
            measured = rms(halves)
        if passes_done:
            passes_done[-1] = replace(passes_done[-1], error=measured)
        if measured <= target or passes == MAX_PASSES or not likely.any():
            break
        if passes > 0:
            likely = guide(color, halves)
        error = np.sqrt(likely * np.float32(measured * measured / likely.mean(dtype=np.float64)))  # RMS: measured
        refine = plan_refinement(error, spp, target, int(spp.min()))
        refine_ms = math.inf if refine is None else int(refine[0].sum()) * refine[1] * listed_ms_per_sample
        s_now = int(spp.flat[0])
        s_uniform = uniform_samples(measured, s_now, target) if np.all(spp == s_now) else None
        uniform_ms = math.inf if s_uniform is None else n_all * s_uniform * ms_per_sample
        if refine is None and s_uniform is None:
            break
        uniform = uniform_ms <= refine_ms
        if uniform:
            assert s_uniform is not None  # (uniform_ms is infinite without it, refine_ms then finite)
            settings.samples, chosen = s_uniform, np.flatnonzero([])
        else:
            assert refine is not None  # (refine_ms is infinite without it)
            settings.samples, chosen = refine[1], np.flatnonzero(refine[0])
        if settings.pattern == _core.PatternKind.rotated:
            settings.pattern = _core.PatternKind.grid  # the rotated pattern has 4 samples only
        settings.pixels = [] if uniform else chosen.tolist()
        again = _core.render(draws, camera, settings)
        if uniform:
            color, halves, depth = again["color"], again["error_map"], again["depth"]
            spp[...] = settings.samples
            ms_per_sample = again["stats"]["total_ms"] / (n_all * settings.samples)
        else:
            color.reshape(-1, color.shape[-1])[chosen] = again["color"].reshape(-1, color.shape[-1])[chosen]
            halves.reshape(-1)[chosen] = again["error_map"].reshape(-1)[chosen]
            if depth is not None and again["depth"] is not None:
                depth.reshape(-1)[chosen] = again["depth"].reshape(-1)[chosen]
            spp.reshape(-1)[chosen] = settings.samples
            listed_ms_per_sample = again["stats"]["total_ms"] / (chosen.size * settings.samples)
        for key, value in again["stats"].items():
            if key != "threads":
                stats[key] += value
        passes_done.append(AdaptivePass(kind="uniform" if uniform else "refine", samples=settings.samples,
                                        pixels=n_all if uniform else int(chosen.size),
                                        predicted_ms=uniform_ms if uniform else refine_ms,
                                        alternative_ms=refine_ms if uniform else uniform_ms,
                                        ms=again["stats"]["total_ms"], error=math.nan))
        settings.samples, settings.pattern, settings.pixels = base, base_pattern, []
    settings.samples, settings.pattern, settings.pixels = base, base_pattern, []
    stats["total_ms"] = (time.perf_counter() - start) * 1000.0  # every pass, every probe, the bookkeeping
    halves_rmse = rms(halves)
    raw["color"], raw["depth"], raw["stats"] = color, depth, stats
    raw["error_estimate"] = measured
    raw["error_map"] = (halves * (measured / halves_rmse if halves_rmse > 0 else 1.0)).astype(np.float32)
    raw["error_probe"] = probe
    raw["pixel_spp"] = spp
    raw["adaptive"] = passes_done
    return RenderResult(raw)
