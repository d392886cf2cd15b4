"""The bits of a few renders of the demo scene, against tests/golden/fingerprints.txt.

tests/cpp/test_fingerprints.cpp checks the same file in the CTest build, which .ci/dev compiles for
the x86-64 baseline; this package is compiled for the machine (x86-64-v3 where it has AVX2). Both
reproducing the file means the two instruction sets give the same bits (DESIGN.md §2.8).
``--update-goldens`` rewrites the file from this build (the test then compares with what it wrote).
"""
from pathlib import Path

import numpy as np

import mipraster as mr
from mipraster import _build_info

FILE = Path(__file__).resolve().parents[1] / "golden" / "fingerprints.txt"
MODES = {"1x": (1, "ssaa"), "msaa4": (4, "msaa"), "ssaa4": (4, "ssaa")}
W, H = 128, 96


def fingerprint(image: np.ndarray) -> str:
    """Σ word_i · (2i + 1) mod 2⁶⁴ over the image's 32-bit words (as the C++ test computes it)."""
    words = np.ascontiguousarray(image, dtype=np.float32).view(np.uint32).ravel().astype(np.uint64)
    factors = np.arange(words.size, dtype=np.uint64) * np.uint64(2) + np.uint64(1)
    return f"{int(np.sum(words * factors, dtype=np.uint64)):016x}"


def recorded() -> dict:
    lines = [line.split() for line in FILE.read_text().splitlines() if line and not line.startswith("#")]
    return {name: value for name, value in lines}


def render_demo(mode: str) -> np.ndarray:
    scene, camera = mr.Scene.demo()
    spp, aa = MODES[mode]
    return mr.render(scene, camera, W, H, spp=spp, aa=aa, threads=2, depth=False).color


def test_fingerprint_changes_with_any_one_word():
    image = np.linspace(0, 1, 64 * 4, dtype=np.float32).reshape(8, 8, 4)
    base = fingerprint(image)
    for index in [(0, 0, 0), (3, 5, 2), (7, 7, 3)]:
        changed = image.copy()
        changed[index] = np.nextafter(changed[index], np.float32(2))  # one bit of one word
        assert fingerprint(changed) != base
    swapped = image.copy()
    swapped[0, 0], swapped[0, 1] = image[0, 1], image[0, 0]  # same words, other places
    assert fingerprint(swapped) != base


def test_demo_renders_reproduce_the_recorded_bits(update_goldens):
    actual = {f"demo_{mode}": fingerprint(render_demo(mode)) for mode in MODES}
    if update_goldens:
        FILE.write_text(
            "# Fingerprints of the demo scene at 128x96, two threads (tests/python/test_fingerprints.py and\n"
            "# tests/cpp/test_fingerprints.cpp). Rewritten by pytest --update-goldens.\n"
            + "".join(f"{name} {value}\n" for name, value in actual.items()))
    assert actual == recorded(), f"this build compiled for x86-64 level {_build_info.X86_LEVEL!r}"
