"""Texture-filter benchmark: mipraster's filters side by side with OpenImageIO's TextureSystem.

Runs the C++ benchmark ``mipraster_bench_texture`` (``cpp/apps/bench_texture.cpp``, CMake target
of the same name) and, with ``--anchor``, the OpenImageIO anchor
``anchor_oiio_texture.py`` (+ ``.cpp``) of the shared benchmark folder, then prints one Markdown
table per footprint: error against the exact box-filtered footprint average and single-thread
lookups per second, for the comparable modes of the two libraries. Both measure the same
textures (1024² checker with 10-texel squares, zone plate 0.5 + 0.5·sin(π r²/1024)), the same
footprints (mag_0.25px, iso_8x8, aniso_8to1_45deg, aniso_8to1_axis), the same accuracy centres,
the same ground truth (64×64 midpoint box average of the bilinear level-0 texture over the
footprint parallelogram) and the same coherent lookup pattern (2²⁰ lookups per pass, a warm-up
pass first, one thread pinned with ``taskset``).

Usage (this module needs only the standard library; it builds nothing)::

    cmake -S . -B /tmp/bench_build -G Ninja && ninja -C /tmp/bench_build mipraster_bench_texture
    python -m mipraster.bench_texture --exe /tmp/bench_build/mipraster_bench_texture --anchor --out DIR
    python python/mipraster/bench_texture.py ...      # the same, straight from a source tree

(``python -m mipraster.bench_texture`` needs an installed package that includes this module, i.e.
``pip install .`` after it was added; the file itself imports only the standard library, so
running it by path from a checkout always works.)

Options: ``--out DIR`` (results: JSON and Markdown, default ``./bench_texture_results``),
``--anchor`` (also run the OpenImageIO anchor), ``--quick`` (short run), ``--repeat N`` (run
both N times, interleaved, and take the median lookups/s of each entry: the machines are shared
and noisy), ``--cpu N`` (the CPU ``taskset`` pins the benchmark to; the anchor pins itself to 0).

Where things are found:

* the benchmark executable: ``--exe PATH``, else ``$MIPRASTER_BENCH_TEXTURE``, else
  ``mipraster_bench_texture`` on ``PATH`` or next to the ``mipraster`` CLI, else a build tree of
  the source checkout this file lives in (``build/*/mipraster_bench_texture``, which
  ``pip install .`` leaves behind, or ``build/mipraster_bench_texture``) or
  ``/tmp/bench_build/mipraster_bench_texture``, the most recently built of those. It is not
  installed with the wheel. The path used is printed; pass ``--exe`` to be sure which build runs.
* the anchor script: ``--anchor-script PATH``, else ``$MIPRASTER_OIIO_ANCHOR``, else
  ``../shared/bench/anchor_oiio_texture.py`` relative to the source checkout (or to the current
  directory), else ``/work/shared/bench/anchor_oiio_texture.py``.
* the anchor's interpreter: ``--anchor-python`` (default ``/usr/bin/python3``), which needs
  OpenImageIO's Python module and numpy: ``apt-get install -y python3-openimageio python3-numpy``
  on Debian (plus ``libopenimageio-dev`` and ``g++`` for the anchor's C++ part).

Comparable modes (OpenImageIO ↔ mipraster) are listed in :data:`COMPARABLE`; OpenImageIO reads
a 1-channel float texture, mipraster an RGBA float one (the same values in R, G, B).
``trilinear_batch`` and ``anisotropic_batch`` are the trilinear and anisotropic samplers through
``BatchSampler`` (sixteen lookups per call), compared with the same OpenImageIO modes.

Goals checked: anisotropic (one lookup at a time or batched) or EWA with an error (MAE, both
textures) at or below OpenImageIO's ``aniso16_bilinear`` and at least 10× its lookups/s;
trilinear (one at a time or batched) at least 2× OpenImageIO's trilinear lookups/s. Each filter
that may meet a goal gets its own rows, and a "met by" row names the filters that met it on
every footprint. Speeds compare the best timed pass of each library (the anchor's statistic,
best of 2), medians over ``--repeat`` runs.
"""
from __future__ import annotations

import argparse
import glob
import json
import os
import shutil
import statistics
import subprocess
import sys
from pathlib import Path
from typing import Any

EXE_NAME = "mipraster_bench_texture"
ANCHOR_NAME = "anchor_oiio_texture.py"
DEFAULT_ANCHOR_PYTHON = "/usr/bin/python3"

FOOTPRINTS = ("mag_0.25px", "iso_8x8", "aniso_8to1_45deg", "aniso_8to1_axis")
TEXTURES = ("checker", "zoneplate")

#: (mipraster filter, OpenImageIO TextureSystem mode) pairs compared side by side.
COMPARABLE = (
    ("nearest", "closest_nomip"),
    ("bilinear", "bilinear_nomip"),
    ("trilinear", "trilinear"),
    ("trilinear_batch", "trilinear"),
    ("anisotropic", "aniso16_bilinear"),
    ("anisotropic_batch", "aniso16_bilinear"),
    ("ewa", "aniso16_bilinear"),
    ("sat", "aniso16_bilinear"),
)

#: Goals: (mipraster filters, any of which may meet it, OIIO mode, speed ratio, error must not exceed OIIO's).
GOALS = (
    ("anisotropic, anisotropic_batch or ewa: error <= OIIO aniso16_bilinear and >= 10x its lookups/s",
     ("anisotropic", "anisotropic_batch", "ewa"), "aniso16_bilinear", 10.0, True),
    ("trilinear or trilinear_batch: >= 2x OIIO trilinear lookups/s", ("trilinear", "trilinear_batch"), "trilinear", 2.0, False),
)


# ---- locating things ----------------------------------------------------------------------------

def _source_roots() -> list[Path]:
    """Source checkouts to look in: the one holding this file, then the current directory."""
    roots = []
    here = Path(__file__).resolve().parents[2]
    for cand in (here, Path.cwd()):
        if (cand / "CMakeLists.txt").is_file() and (cand / "cpp").is_dir() and cand not in roots:
            roots.append(cand)
    return roots


def find_exe(explicit: str | None) -> Path:
    tried = []
    if explicit:
        p = Path(explicit)
        if p.is_file() and os.access(p, os.X_OK):
            return p
        raise SystemExit(f"bench_texture: --exe {explicit}: not an executable file")
    env = os.environ.get("MIPRASTER_BENCH_TEXTURE")
    if env:
        if Path(env).is_file():
            return Path(env)
        tried.append(f"$MIPRASTER_BENCH_TEXTURE={env}")
    on_path = shutil.which(EXE_NAME)
    if on_path:
        return Path(on_path)
    tried.append(f"{EXE_NAME} on PATH")
    cands = []
    cli = shutil.which("mipraster")
    if cli:
        cands.append(Path(cli).resolve().parent / EXE_NAME)
    for root in _source_roots():
        cands += [Path(p) for p in sorted(glob.glob(str(root / "build" / "*" / EXE_NAME)))]
        cands.append(root / "build" / EXE_NAME)
    cands.append(Path("/tmp/bench_build") / EXE_NAME)
    found = [c for c in cands if c.is_file() and os.access(c, os.X_OK)]
    if found:
        return max(found, key=lambda c: c.stat().st_mtime)  # the most recently built one
    tried += [str(c) for c in cands]
    raise SystemExit("bench_texture: cannot find the benchmark executable; build it with\n"
                     "  cmake -S <repo> -B /tmp/bench_build -G Ninja && ninja -C /tmp/bench_build "
                     f"{EXE_NAME}\nand/or pass --exe PATH. Tried: " + ", ".join(tried))


def find_anchor(explicit: str | None) -> Path:
    if explicit:
        p = Path(explicit)
        if not p.is_file():
            raise SystemExit(f"bench_texture: --anchor-script {explicit}: no such file")
        return p
    env = os.environ.get("MIPRASTER_OIIO_ANCHOR")
    if env:
        if not Path(env).is_file():
            raise SystemExit(f"bench_texture: $MIPRASTER_OIIO_ANCHOR={env}: no such file")
        return Path(env)
    cands = [root.parent / "shared" / "bench" / ANCHOR_NAME for root in _source_roots()]
    cands += [Path.cwd().parent / "shared" / "bench" / ANCHOR_NAME, Path("/work/shared/bench") / ANCHOR_NAME]
    for c in cands:
        if c.is_file():
            return c
    raise SystemExit("bench_texture: cannot find " + ANCHOR_NAME + " (tried " + ", ".join(map(str, cands)) +
                     "); pass --anchor-script PATH or set $MIPRASTER_OIIO_ANCHOR")


def source_revision() -> str | None:
    """`git describe --always --dirty` of the source checkout, if there is one."""
    for root in _source_roots():
        try:
            r = subprocess.run(["git", "-C", str(root), "describe", "--always", "--dirty"],
                               capture_output=True, text=True, timeout=10)
        except (OSError, subprocess.SubprocessError):
            return None
        if r.returncode == 0:
            return r.stdout.strip()
    return None


def _pin(cmd: list[str], cpu: int | None) -> list[str]:
    if cpu is not None and shutil.which("taskset"):
        return ["taskset", "-c", str(cpu)] + cmd
    return cmd


# ---- running ------------------------------------------------------------------------------------

def run_mipraster(exe: Path, out_json: Path, quick: bool, n_acc: int | None, cpu: int | None,
                  extra: list[str]) -> dict:
    cmd = [str(exe), str(out_json)] + (["--quick"] if quick else [])
    if n_acc is not None:
        cmd += ["--n-acc", str(n_acc)]
    cmd += extra
    cmd = _pin(cmd, cpu)
    print("$ " + " ".join(cmd), file=sys.stderr, flush=True)
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, text=True)
    if proc.returncode != 0:
        raise SystemExit(f"bench_texture: {exe} failed with status {proc.returncode}")
    (out_json.parent / (out_json.stem + ".md")).write_text(proc.stdout)
    with open(out_json) as f:
        return json.load(f)


def check_anchor_python(python: str) -> None:
    probe = subprocess.run([python, "-c", "import OpenImageIO, numpy"], capture_output=True, text=True)
    if probe.returncode != 0:
        raise SystemExit(f"bench_texture: {python} cannot import OpenImageIO and numpy, which the anchor needs:\n"
                         f"{probe.stderr.strip()}\nOn Debian: apt-get install -y python3-openimageio python3-numpy "
                         "libopenimageio-dev g++ (or pass --anchor-python)")


def run_anchor(python: str, script: Path, out_dir: Path, quick: bool, n_acc: int | None, tag: str) -> dict:
    cmd = [python, str(script), "--out", str(out_dir), "--tag", tag]
    if quick:
        cmd += ["--n-timing", str(1 << 16)]
    if n_acc is not None or quick:
        cmd += ["--n-acc", str(n_acc if n_acc is not None else 1000)]
    print("$ " + " ".join(cmd), file=sys.stderr, flush=True)
    proc = subprocess.run(cmd, stdout=subprocess.DEVNULL)
    if proc.returncode != 0:
        raise SystemExit(f"bench_texture: the anchor {script} failed with status {proc.returncode}")
    with open(out_dir / f"anchor_oiio_texture{tag}.json") as f:
        return json.load(f)


# ---- collecting ---------------------------------------------------------------------------------

def mip_errors(res: dict) -> dict:
    return {(r["texture"], r["footprint"], r["filter"]): r for r in res["accuracy"]}


def mip_speeds(res: dict) -> dict:
    return {(r["footprint"], r["filter"]): r["lookups_per_s"] for r in res["timing"]}


def oiio_errors(res: dict) -> dict:
    return {(r["texture"], r["footprint"], r["mode"]): r for r in res["accuracy"]}


def oiio_speeds(res: dict) -> dict:
    return {(r["footprint"], r["mode"]): r["lookups_per_s"] for r in res["timing"]
            if r["texture"] == "zoneplate_f32" and r["pattern"] == "coherent" and r["api"] == "handle"
            and r["nchannels"] == 1}


def median_speeds(runs: list[dict]) -> dict:
    keys = set().union(*runs)
    return {k: statistics.median(r[k] for r in runs if k in r) for k in keys}


def crosscheck(mip: dict, anchor_out: Path, tag: str) -> dict | None:
    """Same accuracy centres and ground truth as the anchor? (zone plate, aniso_8to1_45deg, 16 points)"""
    path = anchor_out / f"anchor_oiio_texture{tag}.json.crosscheck.txt"
    ours = mip.get("crosscheck_zoneplate_aniso_8to1_45deg_s_t_gt")
    if not path.is_file() or not ours:
        return None
    rows = [list(map(float, line.split())) for line in path.read_text().splitlines() if line.strip()]
    n = min(len(rows), len(ours))
    return {
        "points": n,
        "max_abs_centre_diff": max(max(abs(rows[k][0] - ours[k][0]), abs(rows[k][1] - ours[k][1])) for k in range(n)),
        "max_abs_ground_truth_diff": max(abs(rows[k][6] - ours[k][2]) for k in range(n)),
    }


# ---- reporting ----------------------------------------------------------------------------------

def _f(v, spec):
    return "—" if v is None else format(v, spec)


def side_by_side(mip_err, mip_speed, oi_err, oi_speed) -> tuple[str, list[dict]]:
    rows = []
    for fp in FOOTPRINTS:
        for mf, om in COMPARABLE:
            row: dict[str, Any] = {"footprint": fp, "mipraster": mf, "oiio": om}
            for tex in TEXTURES:
                me, oe = mip_err.get((tex, fp, mf)), (oi_err or {}).get((tex, fp, om))
                row[f"{tex}_mae_mipraster"] = me["mae"] if me else None
                row[f"{tex}_mae_oiio"] = oe["mae"] if oe else None
                row[f"{tex}_rmse_mipraster"] = me["rmse"] if me else None
                row[f"{tex}_rmse_oiio"] = oe["rmse"] if oe else None
            ms, os_ = mip_speed.get((fp, mf)), (oi_speed or {}).get((fp, om))
            row["mlookups_mipraster"] = ms / 1e6 if ms else None
            row["mlookups_oiio"] = os_ / 1e6 if os_ else None
            row["speed_ratio"] = ms / os_ if ms and os_ else None
            rows.append(row)
    lines = []
    for fp in FOOTPRINTS:
        lines.append(f"\n### {fp}\n")
        lines.append("| mipraster | OIIO | checker MAE mip / OIIO | zoneplate MAE mip / OIIO | "
                     "checker RMSE mip / OIIO | zoneplate RMSE mip / OIIO | M lookups/s mip / OIIO | speed ratio |")
        lines.append("|---|---|---|---|---|---|---|---|")
        for r in rows:
            if r["footprint"] != fp:
                continue
            cells = [r["mipraster"], r["oiio"]]
            for metric in ("mae", "rmse"):
                for tex in TEXTURES:
                    cells.append(_f(r[f"{tex}_{metric}_mipraster"], ".4f") + " / " + _f(r[f"{tex}_{metric}_oiio"], ".4f"))
            cells.append(_f(r["mlookups_mipraster"], ".2f") + " / " + _f(r["mlookups_oiio"], ".2f"))
            cells.append(_f(r["speed_ratio"], ".1f") + ("×" if r["speed_ratio"] is not None else ""))
            lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines), rows


def goals(rows: list[dict]) -> tuple[str, list[dict]]:
    out, lines = [], ["\n### goals\n", "| goal | filter | footprint | MAE checker / zoneplate (OIIO) | speed ratio | met |",
                      "|---|---|---|---|---|---|"]
    by = {(r["footprint"], r["mipraster"], r["oiio"]): r for r in rows}
    for text, filters, om, need_ratio, need_err in GOALS:
        met_by = []
        for mf in filters:
            all_met = True
            for fp in FOOTPRINTS:
                r = by.get((fp, mf, om))
                if r is None or r["speed_ratio"] is None:
                    all_met = False
                    continue
                err_ok = True
                if need_err:
                    for tex in TEXTURES:
                        m, o = r[f"{tex}_mae_mipraster"], r[f"{tex}_mae_oiio"]
                        err_ok = err_ok and m is not None and o is not None and m <= o
                met = err_ok and r["speed_ratio"] >= need_ratio
                all_met = all_met and met
                errs = " / ".join(_f(r[f"{t}_mae_mipraster"], ".4f") for t in TEXTURES) + " (" + \
                    " / ".join(_f(r[f"{t}_mae_oiio"], ".4f") for t in TEXTURES) + ")"
                lines.append(f"| {text} | {mf} | {fp} | {errs} | {r['speed_ratio']:.2f}× (need {need_ratio:g}×) | "
                             f"{'yes' if met else 'no'} |")
                out.append({"goal": text, "filter": mf, "footprint": fp, "error_ok": err_ok,
                            "speed_ratio": r["speed_ratio"], "met": met})
            lines.append(f"| {text} | **{mf}** | **all footprints** | | | **{'yes' if all_met else 'no'}** |")
            out.append({"goal": text, "filter": mf, "footprint": "all", "met": all_met})
            if all_met:
                met_by.append(mf)
        # Which variant met it (a batched filter and its one-at-a-time twin are told apart).
        lines.append(f"| {text} | **met by** | | | | **{', '.join(met_by) if met_by else 'none'}** |")
        out.append({"goal": text, "met_by": met_by, "met": bool(met_by)})
    return "\n".join(lines), out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m mipraster.bench_texture",
                                 description="mipraster texture filters vs OpenImageIO's TextureSystem: "
                                             "error and single-thread lookups/s (see the module docstring).")
    ap.add_argument("--out", default="bench_texture_results", help="results folder [./bench_texture_results]")
    ap.add_argument("--exe", help=f"the {EXE_NAME} executable (default: see the module docstring)")
    ap.add_argument("--anchor", action="store_true", help="also run the OpenImageIO anchor and compare")
    ap.add_argument("--anchor-script", help=f"path of {ANCHOR_NAME} (default: $MIPRASTER_OIIO_ANCHOR, "
                                            "else ../shared/bench next to the source checkout)")
    ap.add_argument("--anchor-python", default=DEFAULT_ANCHOR_PYTHON,
                    help="interpreter with OpenImageIO's Python module [/usr/bin/python3]")
    ap.add_argument("--quick", action="store_true", help="short run (65536 timing lookups, 1000 footprints)")
    ap.add_argument("--repeat", type=int, default=1, help="runs of each benchmark; median lookups/s [1]")
    ap.add_argument("--cpu", type=int, default=0, help="CPU to pin the mipraster benchmark to with taskset [0]")
    a = ap.parse_args(argv)
    if a.repeat < 1:
        ap.error("--repeat must be >= 1")

    exe = find_exe(a.exe)
    anchor = find_anchor(a.anchor_script) if a.anchor else None
    if anchor:
        check_anchor_python(a.anchor_python)
    out = Path(a.out)
    (out / "oiio").mkdir(parents=True, exist_ok=True)

    mip_runs, oiio_runs = [], []
    mip_first = oiio_first = None
    for i in range(a.repeat):
        # Accuracy is deterministic: the repeats only re-time (with few accuracy footprints).
        n_acc = None if i == 0 else 100
        res = run_mipraster(exe, out / f"mipraster_run{i}.json", a.quick, n_acc, a.cpu, [])
        mip_first = mip_first or res
        mip_runs.append(mip_speeds(res))
        if anchor:
            ores = run_anchor(a.anchor_python, anchor, out / "oiio", a.quick, n_acc, f"_run{i}")
            oiio_first = oiio_first or ores
            oiio_runs.append(oiio_speeds(ores))

    assert mip_first is not None  # (--repeat >= 1)
    mip_speed = median_speeds(mip_runs)
    oi_speed = median_speeds(oiio_runs) if oiio_runs else None
    revision = source_revision()
    header = (f"mipraster {exe}{f' (source {revision})' if revision else ''} vs OpenImageIO {oiio_first['oiio_version'] if oiio_first else '(not run: --anchor)'}; "
              f"{mip_first['n_timing']} lookups per pass, best pass, median of {a.repeat} run(s); "
              f"{mip_first['n_accuracy']} accuracy footprints per texture; error vs the 64x64 box average of the "
              "bilinear level-0 texture over the footprint")
    table_md, rows = side_by_side(mip_errors(mip_first), mip_speed,
                                  oiio_errors(oiio_first) if oiio_first else None, oi_speed)
    md = [header, table_md]
    summary = {"exe": str(exe), "source_revision": revision, "repeat": a.repeat, "quick": a.quick, "comparable": COMPARABLE, "rows": rows,
               "mipraster_speed_runs": [{f"{k[0]}/{k[1]}": v for k, v in r.items()} for r in mip_runs],
               "oiio_speed_runs": [{f"{k[0]}/{k[1]}": v for k, v in r.items()} for r in oiio_runs]}
    if oiio_first and oi_speed is not None:  # (both or neither: the anchor ran)
        goals_md, goal_rows = goals(rows)
        md.append(goals_md)
        summary["goals"] = goal_rows
        ck = crosscheck(mip_first, out / "oiio", "_run0")
        summary["crosscheck"] = ck
        if ck:
            md.append(f"\ncrosscheck vs the anchor (zone plate, aniso_8to1_45deg, {ck['points']} points): "
                      f"max |centre diff| {ck['max_abs_centre_diff']:.3g}, "
                      f"max |ground truth diff| {ck['max_abs_ground_truth_diff']:.3g}")
        spread = {k: (min(r[k] for r in oiio_runs), max(r[k] for r in oiio_runs)) for k in oi_speed}
        summary["oiio_speed_min_max"] = {f"{k[0]}/{k[1]}": v for k, v in spread.items()}
    text = "\n".join(md) + "\n"
    (out / "side_by_side.md").write_text(text)
    with open(out / "side_by_side.json", "w") as f:
        json.dump(summary, f, indent=1)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
