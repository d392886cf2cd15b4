"""The roofline arithmetic of mipraster.roofline (hand-computed cases) and mipraster.bench --roofline
end to end on the stand-in scenes with a hand-written limits file (timings are never asserted)."""
import json

import pytest

from mipraster import bench, roofline

from test_bench import bench_dir  # noqa: F401  (the stand-in scenes.py fixture)

def _passes(best):
    return {"best": best, "median": best / 2}


LIMITS = {"framebuffer_write": {"threads": {"1": _passes(10.0), "2": _passes(16.0)}},
          "trilinear": {"footprints": [
              {"texels_per_pixel": 0.5, "threads": {"1": _passes(2e7), "2": _passes(3e7)}},
              {"texels_per_pixel": 1.5, "threads": {"1": _passes(1e7), "2": _passes(4e7)}}]}}


def test_frame_work_counts_clear_passed_samples_and_resolve():
    # 4×2 pixels × 4 samples = 32 cleared + 40 passed, 20 bytes each (RGBA float + depth), plus the
    # resolved 8 pixels × 16 bytes: 72 · 20 + 128 = 1568 bytes; 10 textured invocations.
    work = roofline.frame_work(4, 2, 4, True, 40, 10, True)
    assert (work.bytes_written, work.lookups) == (1568, 10)
    # One sample, no depth, untextured: (8 + 8) · 16 bytes, no resolve, no lookups.
    work = roofline.frame_work(4, 2, 1, False, 8, 8, False)
    assert (work.bytes_written, work.lookups) == (256, 0)


def test_bound_is_the_slower_resource():
    bound = roofline.bound_seconds(roofline.FrameWork(1568, 10), 1568.0, 5.0)
    assert bound == {"write_s": 1.0, "lookup_s": 2.0, "bound_s": 2.0}
    assert roofline.bound_seconds(roofline.FrameWork(3000, 0), 1000.0, 5.0)["bound_s"] == 3.0


def test_limits_take_the_best_pass_and_the_fastest_footprint():
    limits = roofline.MachineLimits.from_json(LIMITS)
    assert limits.bandwidth == {1: 10e9, 2: 16e9}
    assert limits.lookups == {1: 2e7, 2: 4e7}
    assert limits.for_threads(2) == (16e9, 4e7)
    assert limits.for_threads(8) == (16e9, 4e7)  # beyond the measured counts: the largest


def test_bench_roofline_from_a_limits_file(bench_dir, tmp_path):  # noqa: F811
    limits_path = tmp_path / "limits.json"
    limits_path.write_text(json.dumps(LIMITS))
    out = tmp_path / "out"
    assert bench.main(["--bench-dir", str(bench_dir), "--scenes", "depth", "textured", "--modes", "1x", "msaa4",
                       "--threads", "1", "--quick", "--no-anchor", "--roofline", str(limits_path),
                       "--out", str(out)]) == 0
    report = json.loads((out / "bench.json").read_text())
    assert report["roofline_limits"]["bandwidth"] == {"1": 10e9, "2": 16e9}
    for c in report["cases"]:
        spp = 4 if c["mode"] == "msaa4" else 1
        pixels = c["width"] * c["height"]
        # Every sample is cleared and at least the covered ones written once more.
        assert c["bytes_written"] >= 2 * pixels * spp * 16
        assert (c["lookups"] > 0) == (c["scene"] == "textured")
        assert c["bound_ms"] == pytest.approx(max(c["write_ms"], c["lookup_ms"]))
        assert c["write_ms"] == pytest.approx(c["bytes_written"] / 10e9 * 1e3)
        assert c["roofline_fraction"] == pytest.approx(c["bound_ms"] / c["median_ms"])
    # The textured quad covers its 8×8 pixels once: 64 invocations at 1x; under MSAA one per pixel
    # and triangle, so the 8 pixels its diagonal crosses (samples of both triangles) shade twice.
    lookups = {c["mode"]: c["lookups"] for c in report["cases"] if c["scene"] == "textured"}
    assert lookups == {"1x": 64, "msaa4": 72}
    assert "fraction of roofline" in (out / "bench.md").read_text()


@pytest.mark.parametrize("argv, message", [
    (["--roofline", "absent.json"], "--roofline 'absent.json': no such JSON file"),
    (["--roofline", "/no/such/exe"], "--roofline '/no/such/exe': not an executable"),
    (["--min-frames", "0"], "--min-frames: 0"),
    (["--min-time", "nan"], "--min-time: nan"),
])
def test_bad_options_are_named(bench_dir, tmp_path, capsys, argv, message):  # noqa: F811
    with pytest.raises(SystemExit) as e:
        bench.main(["--bench-dir", str(bench_dir), "--no-anchor", "--out", str(tmp_path), *argv])
    assert e.value.code == 2 and message in capsys.readouterr().err
