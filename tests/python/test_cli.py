"""The installed `mipraster` command: the demo render, its options, and its error messages."""
import os
import shutil
import subprocess
import sysconfig

import numpy as np
import pytest
from PIL import Image

import mipraster as mr


def _find_exe():
    if os.environ.get("MIPRASTER_EXE"):  # e.g. the sanitized build of .ci/sanitize
        return os.environ["MIPRASTER_EXE"]
    for d in (sysconfig.get_path("scripts"), sysconfig.get_path("scripts", f"{os.name}_user")):
        p = os.path.join(d, "mipraster")
        if os.access(p, os.X_OK):
            return p
    p = shutil.which("mipraster")
    assert p, "the mipraster executable is not installed (run `pip install .`)"
    return p


EXE = _find_exe()


def run(*args):
    return subprocess.run([EXE, *args], capture_output=True, text=True, timeout=300)


def render_png(tmp_path, name, *args):
    out = tmp_path / name
    r = run("render", "-o", str(out), *args)
    assert r.returncode == 0, r.stderr
    assert str(out) in r.stdout
    return np.asarray(Image.open(out))


def test_demo_renders_png_of_requested_size(tmp_path):
    img = render_png(tmp_path, "demo.png", "--size", "96x64")
    assert img.shape == (64, 96, 4)
    assert img.dtype == np.uint8
    assert (img[..., 3] == 255).all()  # sky and ground cover every pixel


def test_supersampling_converges_towards_a_many_sample_reference(tmp_path):
    # 16 spp SSAA is much closer to a 64 spp reference than 1 spp (edges, texture detail near the
    # horizon), and the mean brightness does not drift.
    size = ("--size", "160x90", "--aa", "ssaa")
    one = render_png(tmp_path, "s1.png", *size, "--spp", "1").astype(np.float64)
    many = render_png(tmp_path, "s16.png", *size, "--spp", "16").astype(np.float64)
    ref = render_png(tmp_path, "s64.png", *size, "--spp", "64").astype(np.float64)
    rmse = lambda im: np.sqrt(np.mean((im - ref) ** 2))
    assert rmse(many) < 0.5 * rmse(one)
    assert abs(one.mean() - many.mean()) < 3.0


def test_texture_flags_change_the_filtering(tmp_path):
    size = ("--size", "160x90", "--spp", "1")
    nearest = render_png(tmp_path, "n.png", *size, "--filter", "nearest").astype(np.float64)
    aniso = render_png(tmp_path, "a.png", *size, "--filter", "anisotropic", "--max-aniso", "16").astype(np.float64)
    ref = render_png(tmp_path, "r.png", "--size", "160x90", "--spp", "64", "--aa", "ssaa").astype(np.float64)
    rmse = lambda im: np.sqrt(np.mean((im - ref) ** 2))
    assert rmse(aniso) < rmse(nearest)  # nearest aliases towards the horizon
    levels = render_png(tmp_path, "m.png", *size, "--debug-view", "mip-level")
    assert len(np.unique(levels[45:, :, :3].reshape(-1, 3), axis=0)) > 8  # the ground shows several levels
    biased = render_png(tmp_path, "b.png", *size, "--filter", "trilinear", "--lod-bias", "2", "--wrap", "clamp,repeat")
    plain = render_png(tmp_path, "p.png", *size, "--filter", "trilinear")
    assert not np.array_equal(biased, plain)


def test_thread_count_does_not_change_the_image(tmp_path):
    a = render_png(tmp_path, "t1.png", "--size", "128x72", "--threads", "1", "--spp", "4")
    b = render_png(tmp_path, "t2.png", "--size", "128x72", "--threads", "2", "--spp", "4")
    assert np.array_equal(a, b)


def test_exr_output_is_openexr(tmp_path):
    out = tmp_path / "demo.exr"
    r = run("render", "-o", str(out), "--size", "32x32")
    assert r.returncode == 0, r.stderr
    assert out.read_bytes()[:4] == bytes([0x76, 0x2F, 0x31, 0x01])  # OpenEXR magic number


@pytest.mark.parametrize(
    "args, words",
    [
        (["--size", "0x10"], ["width", "0"]),
        (["--size", "100000x100000"], ["width", "100000"]),
        (["--size", "32768x32768", "--spp", "64"], ["a render of 32768x32768 pixels", "needs", "the memory limit is 16.0 GiB"]),
        (["--memory-limit", "1M"], ["needs", "the memory limit is 1.00 MiB", "--memory-limit"]),
        (["--memory-limit", "lots"], ["--memory-limit", "lots"]),
        (["--memory-limit", "0"], ["--memory-limit", "'0'"]),
        (["--spp", "65"], ["samples", "65"]),
        (["--spp", "8", "--pattern", "rotated"], ["rotated", "4", "8"]),
        (["--aa", "fxaa"], ["fxaa", "ssaa", "msaa"]),
        (["--pattern", "poisson"], ["poisson"]),
        (["--threads", "-1"], ["threads"]),
        (["--size", "12"], ["WxH"]),
        (["--bogus"], ["--bogus"]),
        (["--filter", "cubic"], ["cubic", "trilinear"]),
        (["--max-aniso", "0.5"], ["--max-aniso"]),
        (["--wrap", "tile"], ["tile", "repeat"]),
        (["--debug-view", "lod"], ["lod", "mip-level"]),
        (["--derivatives", "numeric"], ["numeric", "quad"]),
        (["--lod-bias", "x"], ["--lod-bias"]),
        (["--lod-bias", "-1e300"], ["--lod-bias", "-1e300", "beyond float's range"]),  # (was called "not finite")
        (["--seed", "-1"], ["--seed", "from 0 to 18446744073709551615", "'-1'"]),  # (was taken as 2^64 - 1)
        (["--seed", "18446744073709551616"], ["--seed", "'18446744073709551616'"]),
        (["--bits", "12"], ["--bits", "8 or 16", "'12'"]),
        # An integer out of range was called "expected an integer": say so and give the range.
        (["--probe-pixels", "99999999999"], ["--probe-pixels: 99999999999 is out of range",
                                             "from 0 to 1073741824"]),
        (["--probe-pixels", "-1"], ["--probe-pixels: -1 is out of range", "from 0 to 1073741824"]),
        (["--spp", "-99999999999999999999999"], ["--spp: -99999999999999999999999 is out of range",
                                                 "from -1073741824 to 1073741824"]),
        (["--camera", "-1"], ["--camera: -1 is out of range", "from 0"]),
        (["--threads", "4x"], ["--threads: expected an integer, got '4x'"]),
        (["--size", "99999999999x10"], ["--size width: 99999999999 is out of range"]),
    ],
)
def test_bad_options_exit_2_naming_the_input(tmp_path, args, words):
    r = run("render", "-o", str(tmp_path / "x.png"), *args)
    assert r.returncode == 2
    for w in words:
        assert w in r.stderr
    assert not (tmp_path / "x.png").exists()


def test_bits_16_writes_the_8_bit_image_in_finer_steps(tmp_path):
    # The demo at 16 bits per channel: the 8-bit file's image within half an 8-bit step (both
    # read back through read_image's sRGB decoding), in a file with 16-bit channels.
    for bits in ("8", "16"):
        r = run("render", "-o", str(tmp_path / f"demo{bits}.png"), "--size", "48x32", "--spp", "1", "--bits", bits)
        assert r.returncode == 0, r.stderr
    with open(tmp_path / "demo16.png", "rb") as f:
        assert f.read(25)[24] == 16  # IHDR bit depth
    fine, coarse = mr.read_image(tmp_path / "demo16.png"), mr.read_image(tmp_path / "demo8.png")
    assert np.abs(mr.linear_to_srgb(fine) - mr.linear_to_srgb(coarse)).max() <= 0.5 / 255 + 2 / 65535
    r = run("render", "-o", str(tmp_path / "x.exr"), "--bits", "16")
    assert r.returncode == 2 and "--bits 16" in r.stderr and "x.exr" in r.stderr
    assert not (tmp_path / "x.exr").exists()


def test_any_seed_below_2_to_the_64(tmp_path):
    # --seed takes what render(seed=...) takes: any integer below 2^64 (-1 was taken as 2^64 - 1).
    def stratified(name, seed):
        out = tmp_path / name
        r = run("render", "-o", str(out), "--size", "24x16", "--spp", "4", "--pattern", "stratified", "--seed", seed)
        assert r.returncode == 0, r.stderr
        return mr.read_image(out)

    largest = stratified("a.exr", str(2**64 - 1))
    assert np.array_equal(stratified("b.exr", str(2**64 - 1)), largest)
    assert not np.array_equal(stratified("c.exr", "0"), largest)


def test_missing_output_and_unknown_command():
    r = run("render")
    assert r.returncode == 2 and "-o" in r.stderr
    r = run("paint")
    assert r.returncode == 2 and "paint" in r.stderr


def test_unwritable_output_reports_the_path(tmp_path):
    bad = tmp_path / "no" / "such" / "dir" / "x.png"
    r = run("render", "-o", str(bad), "--size", "8x8")
    assert r.returncode == 1
    assert str(bad) in r.stderr


def test_unsupported_extension_is_refused(tmp_path):
    r = run("render", "-o", str(tmp_path / "x.bmpx"), "--size", "8x8")
    assert r.returncode != 0 and "x.bmpx" in r.stderr


def test_stats_json_reports_the_counts_to_stdout_or_a_file(tmp_path):
    import json

    r = run("render", "-o", str(tmp_path / "a.png"), "--size", "64x36", "--stats-json", "-", "--quiet")
    assert r.returncode == 0, r.stderr
    stats = json.loads(r.stdout)  # --quiet: the JSON is the only output
    assert stats["triangles_in"] == 14  # the demo: the ground quad + 6 cube faces, 2 triangles each
    assert stats["samples_covered"] > 0 and stats["total_ms"] > 0
    out = tmp_path / "stats.json"
    r = run("render", "-o", str(tmp_path / "b.png"), "--size", "64x36", "--stats-json", str(out))
    assert r.returncode == 0, r.stderr
    assert json.loads(out.read_text())["triangles_in"] == 14


def test_quiet_prints_nothing(tmp_path):
    r = run("render", "-o", str(tmp_path / "q.png"), "--size", "32x32", "--quiet")
    assert r.returncode == 0 and r.stdout == "" and r.stderr == ""
    assert (tmp_path / "q.png").exists()


def test_look_at_and_fov_move_the_camera(tmp_path):
    base = render_png(tmp_path, "base.png", "--size", "96x54")
    # The demo's own eye, target and field of view reproduce the default image exactly.
    same = render_png(tmp_path, "same.png", "--size", "96x54", "--look-at", "5.5,4,5.5,0,0.8,0", "--fov",
                      str(0.9 * 180 / np.pi))
    assert np.array_equal(base, same)
    moved = render_png(tmp_path, "moved.png", "--size", "96x54", "--look-at", "0,1.5,6,0,1,0")
    narrow = render_png(tmp_path, "narrow.png", "--size", "96x54", "--fov", "20")
    assert not np.array_equal(base, moved) and not np.array_equal(base, narrow)


@pytest.mark.parametrize(
    "args, words",
    [
        (["--look-at", "1,2,3"], ["--look-at", "6"]),
        (["--look-at", "1,2,3,4,5,x"], ["--look-at", "x"]),
        (["--look-at", "1,2,3,1,2,3"], ["eye", "target"]),
        (["--fov", "0"], ["--fov"]),
        (["--fov", "nan"], ["--fov", "nan"]),
    ],
)
def test_bad_camera_options_exit_2_naming_them(tmp_path, args, words):
    r = run("render", "-o", str(tmp_path / "x.png"), *args)
    assert r.returncode == 2
    for w in words:
        assert w in r.stderr


def test_compare_passes_identical_images_and_fails_different_ones(tmp_path):
    a, b = tmp_path / "a.png", tmp_path / "b.png"
    assert run("render", "-o", str(a), "--size", "64x36", "--quiet").returncode == 0
    assert run("render", "-o", str(b), "--size", "64x36", "--spp", "1", "--quiet").returncode == 0
    same = run("compare", str(a), str(a))
    assert same.returncode == 0 and same.stdout.splitlines()[1] == "PASS"
    differ = run("compare", str(a), str(b))
    assert differ.returncode == 1 and "FAIL" in differ.stdout and "PSNR" in differ.stdout
    # The antialiased and aliased demo differ only at edges: a loose enough threshold passes.
    loose = run("compare", str(a), str(b), "--fail-fraction", "0.5", "--hard-fail", "1")
    assert loose.returncode == 0, loose.stdout


@pytest.mark.parametrize(
    "extra, words",
    [
        (["missing.png"], ["missing.png"]),
        ([], ["two image paths"]),
        # The options are named (the messages said CompareSettings::fail_threshold etc.)
        (["--fail", "-1", "X"], ["--fail: expected a threshold >= 0, got '-1'"]),
        (["--hard-fail", "-0.5", "X"], ["--hard-fail: expected a threshold >= 0, got '-0.5'"]),
        (["--fail-fraction", "2", "X"], ["--fail-fraction: expected a fraction in [0, 1], got '2'"]),
        (["--bogus", "X"], ["--bogus"]),
    ],
)
def test_compare_that_cannot_compare_exits_2(tmp_path, extra, words):
    a = tmp_path / "a.png"
    assert run("render", "-o", str(a), "--size", "16x16", "--quiet").returncode == 0
    args = [str(tmp_path / w) if w.endswith(".png") else (str(a) if w == "X" else w) for w in extra]
    r = run("compare", str(a), *args)
    assert r.returncode == 2, (r.stdout, r.stderr)
    for w in words:
        assert w in r.stderr


def test_compare_refuses_images_of_different_sizes(tmp_path):
    a, b = tmp_path / "a.png", tmp_path / "b.png"
    run("render", "-o", str(a), "--size", "16x16", "--quiet")
    run("render", "-o", str(b), "--size", "16x8", "--quiet")
    r = run("compare", str(a), str(b))
    assert r.returncode == 2 and "16x16" in r.stderr and "16x8" in r.stderr


def test_help_and_version():
    r = run("--help")
    assert r.returncode == 0 and "render" in r.stdout and "--spp" in r.stdout
    r = run("--version")
    assert r.returncode == 0 and r.stdout.startswith("mipraster ")


def test_texture_options_on_an_untextured_scene_warn(tmp_path):
    obj = tmp_path / "tri.obj"
    obj.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    r = run("render", str(obj), "-o", str(tmp_path / "tri.png"), "--size", "32x32", "--filter", "ewa")
    assert r.returncode == 0, r.stderr
    assert "no textured draw" in r.stderr
    quiet = run("render", str(obj), "-o", str(tmp_path / "tri.png"), "--size", "32x32", "--filter", "ewa", "--quiet")
    assert quiet.returncode == 0 and quiet.stderr == ""


@pytest.mark.parametrize("cpu", ["Nehalem", "Haswell"])
def test_an_older_cpu_gets_a_message_not_an_illegal_instruction(cpu):
    # The command under qemu's user-mode emulation of an older CPU (Nehalem: SSE4.2, no AVX) and of
    # the first with x86-64-v3 (Haswell). A build for v3 refuses the older one by name, before any
    # of its code runs; a baseline build runs on both.
    from mipraster import _build_info

    qemu = shutil.which("qemu-x86_64")
    assert qemu, "qemu-x86_64 is not installed (Debian's qemu-user; .ci/dev test installs it)"
    r = subprocess.run([qemu, "-cpu", cpu, EXE, "--help"], capture_output=True, text=True, timeout=300)
    if _build_info.X86_LEVEL == "v3" and cpu == "Nehalem":
        assert r.returncode == 2
        assert "compiled for x86-64-v3 (AVX2), which this CPU does not have" in r.stderr
        assert "-DMIPRASTER_X86_LEVEL=baseline" in r.stderr
    else:
        assert r.returncode == 0, r.stderr
        assert "usage: mipraster" in r.stdout + r.stderr
