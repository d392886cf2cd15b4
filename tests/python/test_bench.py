"""The llvmpipe frame-time benchmark (mipraster.bench): its scene conversion, image comparison and
report, run end to end on a small stand-in for the shared scenes.py (timings are never asserted)."""
import json
import math
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import mipraster as mr
from mipraster import bench

# A stand-in for the shared scenes.py with its interface (Scene fields, SCENE_NAMES, DEFAULT_BENCH,
# make_scene): two overlapping triangles in OpenGL clip space, the red one nearer
# (NDC z −0.5) drawn after the green one (z +0.5), so depth LESS must keep red; and a textured quad.
FAKE_SCENES = textwrap.dedent('''
    from dataclasses import dataclass, field
    import numpy as np

    @dataclass
    class Scene:
        name: str
        width: int
        height: int
        positions: np.ndarray
        indices: np.ndarray
        uv: np.ndarray
        colors: np.ndarray
        mvp: np.ndarray
        texture: object
        depth_test: bool = True
        filter: str = "trilinear"
        max_anisotropy: float = 1.0
        wrap: str = "repeat"
        clear_color: tuple = (0.0, 0.0, 0.0, 1.0)
        description: str = ""
        meta: dict = field(default_factory=dict)

        @property
        def n_triangles(self):
            return int(self.indices.shape[0])

    def depth():
        pos = np.array([[-1, -1, 0.5], [1.5, -1, 0.5], [-1, 1.5, 0.5],
                        [-1, -1, -0.5], [1.5, -1, -0.5], [-1, 1.5, -0.5]], np.float32)
        col = np.array([[0, 1, 0, 1]] * 3 + [[1, 0, 0, 1]] * 3, np.float32)
        # the far (green) triangle last: LESS keeps the near red one wherever both cover
        idx = np.array([[3, 4, 5], [0, 1, 2]], np.uint32)
        return Scene("depth", 16, 8, pos, idx, np.zeros((6, 2), np.float32), col, np.eye(4, dtype=np.float32),
                     None, clear_color=(0.0, 0.0, 1.0, 1.0))

    def textured():
        pos = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32)
        uv = np.array([[0, 1], [1, 1], [1, 0], [0, 0]], np.float32)
        tex = np.zeros((4, 4, 4), np.uint8)
        tex[..., 0] = 100  # linear data: 100/255 everywhere, no sRGB decoding
        tex[..., 3] = 255
        col = np.ones((4, 4), np.float32)
        col[:, 1] = 0.5
        idx = np.array([[0, 1, 2], [0, 2, 3]], np.uint32)
        return Scene("textured", 8, 8, pos, idx, uv, col, np.eye(4, dtype=np.float32), tex)

    _FACTORIES = {"depth": depth, "textured": textured}
    SCENE_NAMES = list(_FACTORIES)
    DEFAULT_BENCH = ["depth"]

    def make_scene(name):
        return _FACTORIES[name]()
''')


@pytest.fixture
def bench_dir(tmp_path):
    (tmp_path / "scenes.py").write_text(FAKE_SCENES)
    return tmp_path


def test_conversion_keeps_opengl_depth_less(bench_dir):
    scenes = bench.load_scenes_module(str(bench_dir))
    s = scenes.make_scene("depth")
    scene, camera = bench.to_mipraster(s)
    img = mr.render(scene, camera, s.width, s.height, clear_color=s.clear_color).color
    # Pixel centres inside the triangle x + y < 0.5 (NDC) are red; the rest keep the clear colour.
    ys, xs = np.mgrid[0:s.height, 0:s.width]
    ndc_x = (xs + 0.5) / s.width * 2 - 1
    ndc_y = 1 - (ys + 0.5) / s.height * 2
    inside = ndc_x + ndc_y < 0.5
    assert inside.any() and (~inside).any()
    assert np.array_equal(img[inside], np.tile([1, 0, 0, 1], (inside.sum(), 1)).astype(np.float32))
    assert np.array_equal(img[~inside], np.tile([0, 0, 1, 1], ((~inside).sum(), 1)).astype(np.float32))


def test_conversion_reads_texture_as_linear_data_times_vertex_colour(bench_dir):
    scenes = bench.load_scenes_module(str(bench_dir))
    s = scenes.make_scene("textured")
    scene, camera = bench.to_mipraster(s)
    img = mr.render(scene, camera, s.width, s.height).color
    np.testing.assert_allclose(img[..., 0], 100 / 255, rtol=1e-6)
    assert np.all(img[..., 1] == 0) and np.all(img[..., 3] == 1)
    assert np.array_equal(bench.to_rgb8_linear(img)[..., 0], np.full((8, 8), 100, np.uint8))


def test_psnr_closed_form():
    a = np.zeros((10, 10, 3), np.uint8)
    b = a.copy()
    assert bench.psnr(a, b) == math.inf
    b[0, 0, 0] = 10  # MSE = 100 / 300
    assert bench.psnr(a, b) == pytest.approx(10 * math.log10(255 ** 2 * 3))


def test_geometric_mean_and_thread_scaling():
    assert bench.geometric_mean([0.25, 4.0]) == pytest.approx(1.0)
    cases = [bench.Case("a", "1x", 1, 1, 1, 1, 30.0, 30.0, 3), bench.Case("a", "1x", 2, 1, 1, 1, 15.0, 15.0, 3),
             bench.Case("b", "1x", 1, 1, 1, 1, 5.0, 5.0, 3)]
    assert bench.thread_scaling(cases) == {"a/1x": pytest.approx(2.0)}


def test_end_to_end_without_anchor(bench_dir, tmp_path):
    out = tmp_path / "out"
    code = bench.main(["--bench-dir", str(bench_dir), "--scenes", "depth", "textured", "--modes", "1x", "msaa4",
                       "--threads", "1", "2", "--quick", "--no-anchor", "--out", str(out)])
    assert code == 0
    report = json.loads((out / "bench.json").read_text())
    keys = {(c["scene"], c["mode"], c["threads"]) for c in report["cases"]}
    assert keys == {(s, m, t) for s in ("depth", "textured") for m in ("1x", "msaa4") for t in (1, 2)}
    assert all(c["median_ms"] > 0 and c["frames"] >= 3 and c["llvmpipe_ms"] is None for c in report["cases"])
    table = (out / "bench.md").read_text()
    assert "| depth | 16×8 | 2 | msaa4 | 2 |" in table and "llvmpipe was not run (--no-anchor)" in table


@pytest.mark.parametrize("argv, message", [
    (["--scenes", "nope"], "unknown ['nope']"),
    (["--threads", "0"], "--threads: 0"),
])
def test_bad_arguments_are_named(bench_dir, tmp_path, argv, message):
    done = subprocess.run([sys.executable, "-m", "mipraster.bench", "--bench-dir", str(bench_dir), "--no-anchor",
                           "--out", str(tmp_path / "o"), *argv], capture_output=True, text=True)
    assert done.returncode == 2 and message in done.stderr


def test_missing_bench_dir_is_named(tmp_path):
    with pytest.raises(FileNotFoundError, match="no scenes.py"):
        bench.find_bench_dir(str(tmp_path / "absent"))


@pytest.mark.skipif(not hasattr(os, "sched_setaffinity"), reason="no CPU affinity on this OS")
def test_pinned_to_one_cpu_restores_the_affinity():
    before = os.sched_getaffinity(0)
    with bench.pinned_to_one_cpu():
        assert os.sched_getaffinity(0) == {min(before)}
    assert os.sched_getaffinity(0) == before
