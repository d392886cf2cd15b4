"""The fuzz harness (tests/fuzz): its seed inputs are accepted, hostile inputs are refused with the
documented exceptions, and a short atheris run of every target finds nothing."""
import os
import shutil
import struct
import subprocess
import sys
import zlib
from pathlib import Path

import pytest

FUZZ_DIR = Path(__file__).resolve().parents[1] / "fuzz"
sys.path.insert(0, str(FUZZ_DIR))
import fuzz_targets  # noqa: E402

CORPUS = FUZZ_DIR / "corpus"
# Seconds of fuzzing per target in the test suite (libFuzzer's -max_total_time); the long runs
# (10^6 inputs per target) are `python tests/fuzz/run_fuzz.py TARGET -runs=1000000 DIR`.
SHORT_RUN_SECONDS = int(os.environ.get("MIPRASTER_FUZZ_SECONDS", "20"))


@pytest.fixture(autouse=True)
def default_memory_limit():
    """The targets lower the process-wide memory limit; the other tests expect the default."""
    yield
    import mipraster

    mipraster.set_memory_limit(0)


@pytest.mark.parametrize("target", sorted(fuzz_targets.TARGETS))
def test_every_seed_is_accepted(target):
    seeds = sorted((CORPUS / target).iterdir())
    assert seeds, f"no seeds for {target}"
    for seed in seeds:
        assert fuzz_targets.TARGETS[target](seed.read_bytes()), seed.name


def _png(width, height, body=b""):
    chunk = lambda kind, data: struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))  # noqa: E731
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)) + body


def _ext(extension, extensions):
    return bytes([extensions.index(extension)])


HOSTILE_IMAGES = {
    "empty png": _ext(".png", fuzz_targets.IMAGE_EXTENSIONS),
    "png header claiming 10^9 x 10^9": _ext(".png", fuzz_targets.IMAGE_EXTENSIONS) + _png(10**9, 10**9),
    "png cut inside its data": _ext(".png", fuzz_targets.IMAGE_EXTENSIONS) + (CORPUS / "image" / "checker.png").read_bytes()[1:50],
    "ppm claiming 100000 x 100000": _ext(".ppm", fuzz_targets.IMAGE_EXTENSIONS) + b"P6 100000 100000 255\n\x00\x00\x00",
    "exr of random bytes": _ext(".exr", fuzz_targets.IMAGE_EXTENSIONS) + b"v/1\x01" + bytes(range(256)) * 4,
    "hdr with a negative size": _ext(".hdr", fuzz_targets.IMAGE_EXTENSIONS) + b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y -5 +X 4\n",
}

GLB = (CORPUS / "scene" / "triangle.glb").read_bytes()[1:]
HOSTILE_SCENES = {
    "obj face with index 10^12": _ext(".obj", fuzz_targets.SCENE_EXTENSIONS) + b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 1000000000000\n",
    "obj face with index 0 and -9": _ext(".obj", fuzz_targets.SCENE_EXTENSIONS) + b"v 0 0 0\nf 0 -9 1\n",
    "obj with nan vertex": _ext(".obj", fuzz_targets.SCENE_EXTENSIONS) + b"v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
    "gltf that is not json": _ext(".gltf", fuzz_targets.SCENE_EXTENSIONS) + b"{\"asset\": ",
    "gltf accessor past its buffer": _ext(".gltf", fuzz_targets.SCENE_EXTENSIONS) + (CORPUS / "scene" / "triangle.gltf").read_bytes()[1:].replace(b'"count":3,"type":"VEC3"', b'"count":3000000,"type":"VEC3"'),
    "glb truncated": _ext(".glb", fuzz_targets.SCENE_EXTENSIONS) + GLB[:40],
    "glb claiming a 4 GiB chunk": _ext(".glb", fuzz_targets.SCENE_EXTENSIONS) + GLB[:12] + struct.pack("<I", 0xFFFFFFF0) + GLB[16:],
}


@pytest.mark.parametrize("name", sorted(HOSTILE_IMAGES))
def test_hostile_images_are_refused(name):
    assert fuzz_targets.image(HOSTILE_IMAGES[name]) is False


@pytest.mark.parametrize("name", sorted(HOSTILE_SCENES))
def test_hostile_scenes_are_refused(name):
    assert fuzz_targets.scene(HOSTILE_SCENES[name]) is False


def test_render_target_refuses_out_of_range_indices():
    # 3 vertices, 1 triangle whose indices stay raw (the "keep them valid" byte is 0): 7, 8, 9
    data = bytes([3, 1]) + bytes(36) + struct.pack("<3i", 7, 8, 9) + bytes([0])
    assert fuzz_targets.render(data) is False


@pytest.mark.parametrize("target", sorted(fuzz_targets.TARGETS))
def test_short_fuzz_run_finds_nothing(target, tmp_path):
    import atheris  # noqa: F401  (installed by `bash .ci/dev test`: a missing one fails, never skips)

    corpus = tmp_path / target
    shutil.copytree(CORPUS / target, corpus)
    run = subprocess.run([sys.executable, str(FUZZ_DIR / "run_fuzz.py"), target, f"-max_total_time={SHORT_RUN_SECONDS}",
                          "-timeout=20", "-rss_limit_mb=4096", f"-artifact_prefix={tmp_path}/", str(corpus)],
                         capture_output=True, text=True, timeout=SHORT_RUN_SECONDS + 120)
    assert run.returncode == 0, run.stderr[-4000:]
    assert "Done" in run.stderr
