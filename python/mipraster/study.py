"""Error against run time: render study scenes with every quality knob and measure both.

``python -m mipraster.study`` (or ``mipraster study``, which hands its arguments here, or
:func:`study` from Python) renders the scenes of :mod:`mipraster.study_scenes` (and any scene
files given) with a sweep of samples per pixel, sample patterns, SSAA / MSAA, texture filters,
anisotropy and LOD bias, plus adaptive renders (``render(..., target_error=e)``). For each
configuration it records the median wall time of ``repeats`` renders with one thread and with all
threads, and the error against the scene's reference (RMSE, mean and max absolute error over linear
R, G, B). For every configuration it also records the renderer's own error estimate
(``estimate_error=True``: the halves map calibrated by a sparse reference, see
:mod:`mipraster.error_probe`), its standard error, its cost and its ratio to the true RMSE. Where moderngl can
open an EGL context on Mesa's llvmpipe, llvmpipe's 1x / MSAA 4x / SSAA 4x renders of the same
scenes join as comparison points; where it cannot, the study says why and goes on.

Writes ``study.csv``, ``study.md`` (a Markdown table, the estimate calibration and the adaptive
savings) and ``study.png`` (error against time per scene, log-log, Pareto frontier marked, every
point labelled; needs matplotlib, else the study says so and writes the rest).
"""
from __future__ import annotations

import argparse
import csv
import math
import os
import statistics
import sys
import time
from dataclasses import dataclass, field, replace
from typing import Any, Dict, List, Optional, Sequence

import numpy as np

from .reference import image_error
from .render import render
from .study_scenes import SCENES, StudyScene, from_file, with_filter

__all__ = ["Knobs", "StudyRow", "default_sweep", "tiny_sweep", "study", "main"]


@dataclass(frozen=True)
class Knobs:
    """One configuration of the quality knobs (None filter / aniso / bias: the scene's own)."""

    spp: int = 1
    pattern: str = "auto"
    aa: str = "ssaa"
    filter: Optional[str] = None
    max_anisotropy: Optional[float] = None
    lod_bias: Optional[float] = None
    target_error: Optional[float] = None  # adaptive: a relative target, × the 4-spp estimate

    @property
    def label(self) -> str:
        parts = [f"{self.spp}x"]
        if self.pattern != "auto":
            parts.append(self.pattern)
        if self.aa != "ssaa":
            parts.append(self.aa)
        if self.filter is not None:
            parts.append(self.filter + (f"{self.max_anisotropy:g}" if self.max_anisotropy is not None else ""))
        if self.lod_bias:
            parts.append(f"bias{self.lod_bias:+g}")
        if self.target_error is not None:
            parts = [f"adaptive {self.spp}x..64x", f"target {self.target_error:g}x est4"]
        return " ".join(parts)


@dataclass
class StudyRow:
    """One measured point."""

    scene: str
    label: str
    renderer: str  # "mipraster", "mipraster adaptive" or "llvmpipe"
    spp: int
    pattern: str
    aa: str
    filter: str
    max_anisotropy: float
    lod_bias: float
    ms_one_thread: float
    ms_all_threads: float
    threads: int
    rmse: float
    mean_abs: float
    max_abs: float
    reference_residual: float
    estimate: float = float("nan")
    estimate_ratio: float = float("nan")
    estimate_stderr: float = float("nan")  # the probe's standard error
    estimate_ms: float = float("nan")  # the probe's cost (all threads), next to ms_all_threads
    estimate_bound: bool = False  # the estimate is an upper bound (the probe could not resolve the error)
    target_error: float = float("nan")
    mean_spp: float = float("nan")
    notes: str = ""


FIELDS = list(StudyRow.__dataclass_fields__)


def default_sweep(textured: bool) -> List[Knobs]:
    """Samples per pixel 1..64, patterns and MSAA at 4 and 16, adaptive at two targets; on
    textured scenes also every texture filter, anisotropy 4 and 16, LOD bias ±1, and SSAA 16 with
    bilinear level-0 lookups or trilinear (each sample at its own footprint)."""
    sweep = [Knobs(spp) for spp in (1, 2, 4, 8, 16, 32, 64)]
    sweep += [Knobs(4, "grid"), Knobs(4, "stratified"), Knobs(16, "stratified"), Knobs(4, aa="msaa"),
              Knobs(16, aa="msaa")]
    if textured:
        for f in ("nearest", "bilinear", "trilinear", "ewa", "sat"):
            sweep.append(Knobs(1, filter=f))
        sweep += [Knobs(1, filter="anisotropic", max_anisotropy=4.0), Knobs(4, filter="trilinear"),
                  Knobs(16, "stratified", filter="bilinear"), Knobs(16, filter="trilinear"),
                  Knobs(1, filter="trilinear", lod_bias=-1.0), Knobs(1, filter="trilinear", lod_bias=1.0),
                  Knobs(16, aa="msaa", filter="trilinear")]
    sweep += [Knobs(4, target_error=0.5), Knobs(4, target_error=0.25)]
    return sweep


def tiny_sweep(textured: bool) -> List[Knobs]:
    """A few configurations for a quick end-to-end run (CI)."""
    sweep = [Knobs(1), Knobs(4), Knobs(16), Knobs(4, aa="msaa")]
    if textured:
        sweep.append(Knobs(1, filter="trilinear"))
    sweep.append(Knobs(4, target_error=0.5))
    return sweep


UNIFORM_FAMILY = (2, 4, 8, 16, 32, 64)  # what adaptive renders are compared with (same patterns, SSAA)


def _uniform_time_for_error(rows: List[StudyRow], scene: str, error: float) -> Optional[float]:
    """Time (one thread) uniform SSAA needs for ``error``: log-log interpolation between the
    bracketing uniform renders (auto pattern, the scene's filter); None when 64 spp does not reach it."""
    pts = sorted((r.spp, r.ms_one_thread, r.rmse) for r in rows
                 if r.scene == scene and r.renderer == "mipraster" and r.label == f"{r.spp}x" and r.spp in UNIFORM_FAMILY)
    for (s0, t0, e0), (s1, t1, e1) in zip(pts, pts[1:]):
        if e0 >= error >= e1 and e0 > 0 and e1 > 0:
            if e0 == e1:
                return t1
            w = (math.log(e0) - math.log(error)) / (math.log(e0) - math.log(e1))
            return math.exp(math.log(t0) + w * (math.log(t1) - math.log(t0)))
    if pts and error >= pts[0][2]:
        return pts[0][1]
    return None


def _measure_scene(s: StudyScene, sweep: Sequence[Knobs], repeats: int, threads: int, ref: np.ndarray,
                   residual: float, log) -> List[StudyRow]:
    rows: List[StudyRow] = []
    runs = []
    estimate4 = None
    for k in sweep:
        scene = with_filter(s.scene, k.filter, k.max_anisotropy, k.lod_bias) if (k.filter or k.max_anisotropy or
                                                                                  k.lod_bias) else s.scene
        target = None
        if k.target_error is not None:
            if estimate4 is None:
                estimate4 = render(s.scene, s.camera, s.width, s.height, spp=4, estimate_error=True).error_estimate
                assert estimate4 is not None  # estimate_error=True at 4 spp always estimates
            target = max(k.target_error * estimate4, 1e-6)
        kwargs: Dict[str, Any] = dict(spp=k.spp, aa=k.aa, pattern=k.pattern, depth=False, target_error=target)

        def run(n_threads: int, scene=scene, kwargs=kwargs):  # bound now: runs are timed after the loop
            return render(scene, s.camera, s.width, s.height, threads=n_threads, **kwargs)

        result = run(0)
        err = image_error(result.color, ref)
        runs.append(run)
        draws = [d for d in scene.draws if d.texture is not None]
        sampler = draws[0].sampler if draws else None
        row = StudyRow(scene=s.name, label=k.label, renderer="mipraster adaptive" if target else "mipraster",
                       spp=k.spp, pattern=result.pattern_kind, aa=k.aa,
                       filter=sampler.filter if sampler else "-",
                       max_anisotropy=sampler.max_anisotropy if sampler else float("nan"),
                       lod_bias=sampler.lod_bias if sampler else float("nan"), ms_one_thread=math.nan,
                       ms_all_threads=math.nan,
                       threads=int(result.stats["threads"]) if threads == 0 else threads,
                       reference_residual=residual, **err)
        if target is not None:
            row.target_error = target
            row.mean_spp = float(result.pixel_spp.mean())
            row.estimate = math.nan if result.error_estimate is None else result.error_estimate
            if result.error_probe is not None:
                row.estimate_stderr = result.error_probe.stderr
                row.estimate_bound = result.error_probe.upper_bound
            row.notes = "passes: " + ", ".join(
                f"{p.kind} {p.pixels} px at {p.samples}x (model {p.predicted_ms:.3g} ms against "
                f"{p.alternative_ms:.3g} ms)" for p in result.adaptive) if result.adaptive else "no pass after the first"
        else:
            probed = render(scene, s.camera, s.width, s.height, estimate_error=True, **kwargs)
            row.estimate = math.nan if probed.error_estimate is None else probed.error_estimate
            if probed.error_probe is not None:
                row.estimate_stderr, row.estimate_ms = probed.error_probe.stderr, probed.error_probe.ms
                row.estimate_bound = probed.error_probe.upper_bound
        if not math.isnan(row.estimate) and row.rmse > 0:
            row.estimate_ratio = row.estimate / row.rmse
        rows.append(row)
    # Timing in rounds over all configurations, so that a burst of load elsewhere on the machine
    # spreads over all of them instead of landing on one.
    times: List[Dict[int, List[float]]] = [{1: [], threads: []} for _ in runs]
    for _ in range(repeats):
        for i, run in enumerate(runs):
            for n in (1, threads):
                t0 = time.perf_counter()
                run(n)
                times[i][n].append((time.perf_counter() - t0) * 1000.0)
    for row, t in zip(rows, times):
        row.ms_one_thread, row.ms_all_threads = statistics.median(t[1]), statistics.median(t[threads])
        log(f"  {row.label:36s} {row.ms_one_thread:8.2f} ms x1 {row.ms_all_threads:8.2f} ms xN  rmse {row.rmse:.4g}"
            + (f"  est/true {row.estimate_ratio:.2f}" if not math.isnan(row.estimate_ratio) else "")
            + (" (upper bound)" if row.estimate_bound else ""))
    for row in rows:
        if row.renderer == "mipraster adaptive":
            uniform = _uniform_time_for_error(rows, s.name, row.rmse)
            if uniform is None:
                row.notes += "; uniform SSAA up to 64x does not reach this error"
            else:
                row.notes += (f"; uniform SSAA needs {uniform:.2f} ms (one thread) for this error: "
                              f"{100 * (1 - row.ms_one_thread / uniform):.0f}% saved")
    return rows


def _llvmpipe_rows(s: StudyScene, ref: np.ndarray, residual: float, repeats: int, log) -> List[StudyRow]:
    from . import llvmpipe

    rows = []
    for mode in ("1x", "msaa4", "ssaa4"):
        times = {}
        for n in (1, 0):
            image, ms = llvmpipe.render_timed(s, mode, threads=n, repeats=repeats)
            times[n] = ms
        err = image_error(image, ref)
        rows.append(StudyRow(scene=s.name, label=f"llvmpipe {mode}", renderer="llvmpipe",
                             spp=1 if mode == "1x" else 4, pattern="-", aa=mode, filter="gl trilinear+aniso16"
                             if s.textured else "-", max_anisotropy=16.0 if s.textured else float("nan"),
                             lod_bias=0.0, ms_one_thread=times[1], ms_all_threads=times[0],
                             threads=os.cpu_count() or 1, reference_residual=residual, **err))
        log(f"  {'llvmpipe ' + mode:32s} {times[1]:8.2f} ms x1 {times[0]:8.2f} ms xN  rmse {err['rmse']:.4g}")
    return rows


def pareto(points: Sequence[tuple]) -> List[int]:
    """Indices of the (time, error) points no other point beats in both, sorted by time."""
    order = sorted(range(len(points)), key=lambda i: (points[i][0], points[i][1]))
    best, front = math.inf, []
    for i in order:
        if points[i][1] < best:
            front.append(i)
            best = points[i][1]
    return front


def write_csv(rows: Sequence[StudyRow], path: str) -> None:
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=FIELDS)
        w.writeheader()
        for r in rows:
            w.writerow({k: getattr(r, k) for k in FIELDS})


def _fmt(v: float, digits: int = 3) -> str:
    return "–" if isinstance(v, float) and math.isnan(v) else f"{v:.{digits}g}"


def _estimate_text(r: StudyRow) -> str:
    """The estimate as the table prints it: "x ± se", or "≤ x" for an upper bound."""
    if r.estimate_bound:
        return f"≤ {_fmt(r.estimate)}"
    return f"{_fmt(r.estimate)} ± {_fmt(r.estimate_stderr, 2)}"


def markdown(rows: Sequence[StudyRow], notes: Sequence[str]) -> str:
    """The study as Markdown: a table per scene, then the estimate calibration and adaptive savings."""
    out = ["# Error against run time", ""] + [f"- {n}" for n in notes] + [""]
    for scene in dict.fromkeys(r.scene for r in rows):
        rs = [r for r in rows if r.scene == scene]
        front = set(pareto([(r.ms_one_thread, r.rmse) for r in rs]))
        out += [f"## {scene}", "", f"Reference residual (its own estimated RMSE): {_fmt(rs[0].reference_residual)}", "",
                "| configuration | filter | ms (1 thread) | ms (all) | RMSE | mean abs | max abs | estimate | est/true | Pareto (1 thread) |",
                "|---|---|---:|---:|---:|---:|---:|---:|---:|:-:|"]
        for i, r in enumerate(rs):
            label = r.label + (f" (mean {r.mean_spp:.1f} spp)" if not math.isnan(r.mean_spp) else "")
            out.append(f"| {label} | {r.filter} | {r.ms_one_thread:.2f} | {r.ms_all_threads:.2f} | {r.rmse:.4g} | "
                       f"{r.mean_abs:.4g} | {r.max_abs:.3g} | {_estimate_text(r)} | "
                       f"{_fmt(r.estimate_ratio, 2)} | "
                       f"{'●' if i in front else ''} |")
        out.append("")
    ratios = [r for r in rows if not math.isnan(r.estimate_ratio) and r.renderer == "mipraster"
              and not r.estimate_bound]
    bounds = [r for r in rows if r.estimate_bound and r.renderer == "mipraster" and not math.isnan(r.estimate)]
    if ratios:
        inside = [r for r in ratios if 0.5 <= r.estimate_ratio <= 2.0]
        # Where the reference's own error is more than half the measured one, the measured RMSE is
        # mostly the reference's: it cannot judge an estimate of the render's error.
        judged = [r for r in ratios if r.reference_residual <= 0.5 * r.rmse]
        judged_inside = [r for r in judged if r in inside]
        worst = max(ratios, key=lambda r: abs(math.log(r.estimate_ratio)) if r.estimate_ratio > 0 else math.inf)
        costs = [r.estimate_ms / r.ms_all_threads for r in ratios + bounds
                 if not math.isnan(r.estimate_ms) and r.ms_all_threads > 0]
        out += ["## Error estimate calibration", "",
                f"estimate / true RMSE within a factor of 2 on {len(inside)} of {len(ratios)} configurations "
                f"(median ratio {statistics.median(r.estimate_ratio for r in ratios):.2f}, range "
                f"{min(r.estimate_ratio for r in ratios):.2f}–{max(r.estimate_ratio for r in ratios):.2f}, worst "
                f"{worst.scene} {worst.label}: {worst.estimate_ratio:.2f}); on {len(judged_inside)} of the "
                f"{len(judged)} whose reference's own error is at most half the measured RMSE (the others' "
                f"measured RMSE is mostly the reference's).", ""]
        if bounds:
            held = [r for r in bounds if r.rmse <= r.estimate]
            out += [f"Upper bounds (the probe could not resolve the error even with more reference passes, "
                    f"and says the RMSE is at most the figure): {len(bounds)} configuration(s), not counted "
                    f"above; the bound holds (true RMSE ≤ bound) on {len(held)} of them: "
                    + "; ".join(f"{r.scene} {r.label}: true {r.rmse:.2g} ≤ {r.estimate:.2g}"
                                if r in held else f"{r.scene} {r.label}: true {r.rmse:.2g} > {r.estimate:.2g} (FAILS)"
                                for r in bounds) + ".", ""]
        if costs:
            out += [f"The probe costs {statistics.median(costs):.2f}× the render's time (median; "
                    f"{min(costs):.2f}–{max(costs):.2f}×, all threads).", ""]
        misses = [r for r in ratios if r not in inside]
        if misses:
            out.append("Outside the factor of 2:")
            out += [f"- {r.scene} {r.label} ({r.filter}): {r.estimate_ratio:.2f}"
                    + (" (reference residual {:.2g} of RMSE {:.2g})".format(r.reference_residual, r.rmse)
                       if r not in judged else "") for r in misses]
            out.append("")
    adaptive = [r for r in rows if r.renderer == "mipraster adaptive"]
    if adaptive:
        out += ["## Adaptive quality", ""]
        out += [f"- {r.scene} {r.label}: target {r.target_error:.3g}, estimate {_estimate_text(r)}, true RMSE "
                f"{r.rmse:.4g}, {r.ms_one_thread:.2f} ms (one thread), mean {r.mean_spp:.1f} spp; {r.notes}" for r in adaptive]
        out.append("")
    return "\n".join(out)


def plot(rows: Sequence[StudyRow], path: str, dpi: int = 80, time: str = "one") -> Optional[str]:
    """Error against time, log-log, one panel per scene; returns None or why it could not.

    ``time`` is ``"one"`` (the one-thread median, steadier on a shared machine) or ``"all"``."""
    if time not in ("one", "all"):
        raise ValueError(f"time: expected 'one' or 'all', got {time!r}")
    attr = "ms_one_thread" if time == "one" else "ms_all_threads"
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return "matplotlib is not installed (pip install matplotlib): no plot; the CSV and Markdown are written"
    scenes = list(dict.fromkeys(r.scene for r in rows))
    fig, axes = plt.subplots(1, len(scenes), figsize=(5.2 * len(scenes), 4.6), squeeze=False)
    styles = {"mipraster": ("o", "tab:blue"), "mipraster adaptive": ("*", "tab:green"), "llvmpipe": ("s", "tab:red")}
    for ax, scene in zip(axes[0], scenes):
        rs = [r for r in rows if r.scene == scene and r.rmse > 0]
        for kind, (marker, colour) in styles.items():
            pts = [r for r in rs if r.renderer == kind]
            if pts:
                ax.scatter([getattr(r, attr) for r in pts], [r.rmse for r in pts], marker=marker, color=colour,
                           s=60 if marker == "*" else 22, label=kind, zorder=3)
        front = pareto([(getattr(r, attr), r.rmse) for r in rs])
        ax.step([getattr(rs[i], attr) for i in front], [rs[i].rmse for i in front], where="post", color="black",
                lw=1, alpha=0.6, label="Pareto frontier", zorder=2)
        for r in rs:
            ax.annotate(r.label, (getattr(r, attr), r.rmse), fontsize=5.5, xytext=(3, 2), textcoords="offset points")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(f"{scene} (residual of reference {rs[0].reference_residual:.1e})" if rs else scene, fontsize=9)
        ax.set_xlabel(f"ms per frame (median, {'one thread' if time == 'one' else 'all threads'})", fontsize=8)
        ax.set_ylabel("RMSE vs reference (linear RGB)", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(True, which="both", alpha=0.2)
        ax.legend(fontsize=6, loc="upper right")
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return None


def study(out_dir: str, scenes: Sequence[str] = tuple(SCENES), scene_files: Sequence[str] = (), width: int = 160,
          height: int = 120, repeats: int = 3, threads: int = 0, tiny: bool = False, llvmpipe: bool = True,
          make_plot: bool = True, reference_quality: float = 1.0, log=print) -> List[StudyRow]:
    """Runs the study and writes ``study.csv``, ``study.md`` and (with matplotlib) ``study.png`` into
    ``out_dir``; returns the rows. ``threads`` is the "all threads" count (0 = every core).

    Raises ValueError for an unknown scene name or a size / repeat count out of range, and
    FileNotFoundError for a missing scene file (before anything is rendered).
    """
    for name in scenes:
        if name not in SCENES:
            raise ValueError(f"scenes: unknown scene {name!r}; expected some of {', '.join(SCENES)}")
    for path in scene_files:
        if not os.path.isfile(path):
            raise FileNotFoundError(f"scene file {path!r} does not exist")
    if not (1 <= width <= 4096 and 1 <= height <= 4096):
        raise ValueError(f"size: expected 1..4096 pixels each, got {width}x{height}")
    if repeats < 1:
        raise ValueError(f"repeats: expected at least 1, got {repeats}")
    os.makedirs(out_dir, exist_ok=True)
    notes = [f"image size {width}x{height}; times are the median of {repeats} renders (wall clock, "
             f"one thread and {'all cores' if threads == 0 else f'{threads} threads'}); errors over linear R, G, B"]
    study_scenes: List[StudyScene] = [SCENES[n](width, height) for n in scenes]
    study_scenes += [from_file(p, width, height) for p in scene_files]
    lp_reason = None
    if llvmpipe:
        from . import llvmpipe as lp

        lp_reason = lp.unavailable_reason()
        if lp_reason:
            notes.append(f"llvmpipe points left out: {lp_reason}")
            log(f"llvmpipe: {lp_reason}; going on without it")
    else:
        notes.append("llvmpipe points left out (not asked for)")
    rows: List[StudyRow] = []
    for s in study_scenes:
        log(f"{s.name}:")
        sweep = tiny_sweep(s.textured) if tiny else default_sweep(s.textured)
        t0 = time.perf_counter()
        ref, residual, kind = s.reference(reference_quality)  # once: llvmpipe's points use it too
        log(f"  reference: {kind}; its own estimated RMSE {residual:.2e} ({time.perf_counter() - t0:.1f} s)")
        scene_rows = _measure_scene(s, sweep, repeats, threads, ref, residual, log)
        if llvmpipe and not lp_reason:
            try:
                scene_rows += _llvmpipe_rows(s, ref, residual, repeats, log)
            except Exception as e:  # a driver failure must not lose the measurements made so far
                notes.append(f"llvmpipe failed on {s.name}: {e}")
                log(f"  llvmpipe failed: {e}")
        rows += scene_rows
    write_csv(rows, os.path.join(out_dir, "study.csv"))
    if make_plot:
        why = plot(rows, os.path.join(out_dir, "study.png"))
        if why:
            notes.append(why)
            log(why)
    with open(os.path.join(out_dir, "study.md"), "w") as f:
        f.write(markdown(rows, notes))
    log(f"wrote {os.path.join(out_dir, 'study.csv')}, study.md" + ("" if not make_plot else ", study.png"))
    return rows


def main(argv: Optional[Sequence[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="mipraster study", description=__doc__.split("\n\n")[0])
    parser.add_argument("scene_files", nargs="*", help="scene files (.obj, .gltf, .glb) to study too")
    parser.add_argument("-o", "--out", default="study", help="output folder [study]")
    parser.add_argument("--scenes", default=",".join(SCENES),
                        help=f"built-in scenes, comma-separated, or 'none' [{','.join(SCENES)}]")
    parser.add_argument("--size", default="160x120", help="image size WxH [160x120]")
    parser.add_argument("--repeats", type=int, default=3, help="renders per timing (median) [3]")
    parser.add_argument("--threads", type=int, default=0, help="the 'all threads' count, 0 = every core [0]")
    parser.add_argument("--tiny", action="store_true", help="a few configurations only (a quick end-to-end check)")
    parser.add_argument("--reference-quality", type=float, default=1.0,
                        help="scales the references' integration effort (1 = 2x16x16 points per pixel) [1]")
    parser.add_argument("--no-llvmpipe", action="store_true", help="leave out the llvmpipe comparison points")
    parser.add_argument("--no-plot", action="store_true", help="write no PNG")
    args = parser.parse_args(argv)
    try:
        w, h = (int(v) for v in args.size.lower().split("x"))
    except ValueError:
        parser.error(f"--size: expected WxH, e.g. 160x120, got {args.size!r}")
    names = [] if args.scenes == "none" else [n for n in args.scenes.split(",") if n]
    try:
        study(args.out, names, args.scene_files, w, h, args.repeats, args.threads, args.tiny,
              llvmpipe=not args.no_llvmpipe, make_plot=not args.no_plot, reference_quality=args.reference_quality)
    except (ValueError, FileNotFoundError) as e:
        print(f"mipraster study: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
