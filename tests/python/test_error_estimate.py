"""The per-render error estimate (render(..., estimate_error=True): the halves map and the sparse
reference probe) and adaptive quality (render(..., target_error=e)), checked against exact
references (mipraster.reference)."""
import math

import numpy as np
import pytest

import mipraster as mr
from mipraster import _core
from mipraster.adaptive import MAX_PASSES, plan_refinement, uniform_samples
from mipraster.error_probe import ProbeReference, default_pixel_count, guide, measure_error
from mipraster.render import _core_draws
from mipraster.reference import exact_coverage, image_error
from mipraster.study_scenes import checker_plane, shapes, star, with_filter, zone_plate


def test_halves_and_adaptive_need_two_samples():
    s = star(32, 32)
    with pytest.raises(ValueError, match="spp >= 2"):
        mr.render(s.scene, s.camera, 32, 32, spp=1, estimate_error=True, probe_pixels=0)
    with pytest.raises(ValueError, match="spp >= 2"):
        mr.render(s.scene, s.camera, 32, 32, spp=1, target_error=0.01)
    # The probe alone works at one sample per pixel: an estimate, no map.
    r = mr.render(s.scene, s.camera, 32, 32, spp=1, estimate_error=True)
    assert r.error_map is None and r.error_estimate > 0 and r.error_probe.halves_rmse is None


def test_no_estimate_unless_asked():
    s = star(32, 32)
    r = mr.render(s.scene, s.camera, 32, 32, spp=4)
    assert r.error_map is None and r.error_estimate is None and r.pixel_spp is None and r.error_probe is None


def test_flat_image_estimates_zero():
    quad = mr.Mesh([[-5, -5, 0], [5, -5, 0], [5, 5, 0], [-5, 5, 0]], [[0, 1, 2], [0, 2, 3]])
    scene = mr.Scene()
    scene.add(quad, color=(0.3, 0.6, 0.9), depth_test=False)
    r = mr.render(scene, mr.Camera.orthographic((0, 0, 1), (0, 0, 0)), 40, 30, spp=8, estimate_error=True)
    assert r.error_map.shape == (30, 40)
    assert r.error_estimate < 1e-6  # the reference's 64 samples may round differently in the last bit
    assert np.all(r.error_map == 0.0)
    # The reference is exact too: a point estimate, and no extra passes.
    assert not r.error_probe.upper_bound and "error_estimate=" in repr(r)
    assert r.error_probe.reference_spp == 2 * _core.PROBE_REFERENCE_SPP


def test_estimate_is_half_the_disagreement_of_the_halves():
    s = star(48, 40)
    r = mr.render(s.scene, s.camera, 48, 40, spp=16, pattern="stratified", keep_samples=True, estimate_error=True,
                  probe_pixels=0)
    halves = np.array(_core.interleaved_halves(_core.PatternKind.stratified, 16, 0), dtype=bool)
    a = r.samples[:, :, ~halves, :3].astype(np.float64).mean(axis=2)
    b = r.samples[:, :, halves, :3].astype(np.float64).mean(axis=2)
    expected = np.sqrt(np.mean(((a - b) / 2) ** 2, axis=2))
    np.testing.assert_allclose(r.error_map, expected, atol=1e-6)
    assert r.error_estimate == pytest.approx(math.sqrt(np.mean(expected ** 2)), rel=1e-5)
    assert "error_estimate=" in repr(r)


@pytest.mark.parametrize("make, spp, pattern", [(star, 16, "stratified"), (star, 8, "auto"),
                                                (checker_plane, 16, "stratified")])
def test_halves_calibration(make, spp, pattern):
    # The halves estimate alone (probe_pixels=0) against the true RMSE (exact / brute-force
    # reference): within a factor of 2 where the error is sampling error: edges, and a texture read
    # at level 0 (bilinear, no mip levels: each sample is a point of the footprint integral).
    s = make(64, 48)
    ref, residual, _ = s.reference(1.0)
    scene = with_filter(s.scene, "bilinear")
    r = mr.render(scene, s.camera, s.width, s.height, spp=spp, pattern=pattern, estimate_error=True, probe_pixels=0)
    true = image_error(r.color, ref)["rmse"]
    assert residual < 0.25 * true  # the reference is good enough to judge
    assert 0.5 <= r.error_estimate / true <= 2.0, (r.error_estimate, true)


@pytest.mark.parametrize("make, spp, aa, filt", [
    (star, 1, "ssaa", None), (star, 4, "ssaa", None), (shapes, 2, "ssaa", None),
    (checker_plane, 4, "msaa", "trilinear"), (checker_plane, 1, "ssaa", "trilinear"),
    (zone_plate, 4, "msaa", "trilinear"), (zone_plate, 1, "ssaa", None)])
def test_probe_calibration(make, spp, aa, filt):
    # The full estimate (halves map calibrated by the sparse reference) where the halves alone see
    # little or nothing: one sample per pixel, MSAA's one shade per pixel, a mip-mapped filter's
    # blur. Against the exact / brute-force reference: within a factor of 2.
    s = make(64, 48)
    ref, residual, _ = s.reference(1.0)
    scene = with_filter(s.scene, filt) if filt else s.scene
    r = mr.render(scene, s.camera, s.width, s.height, spp=spp, aa=aa, estimate_error=True)
    true = image_error(r.color, ref)["rmse"]
    assert residual < 0.25 * true
    assert 0.5 <= r.error_estimate / true <= 2.0, (r.error_estimate, true, r.error_probe)
    assert r.error_probe.pixels == default_pixel_count(64, 48, spp)
    assert not r.error_probe.upper_bound  # errors well above the reference's own are resolved
    assert 0 < r.error_probe.stderr < r.error_estimate
    if r.error_map is not None and r.error_probe.halves_rmse > 0:  # the map is scaled to the estimate
        assert math.sqrt(np.mean(r.error_map.astype(np.float64) ** 2)) == pytest.approx(r.error_estimate, rel=1e-5)


def test_probe_is_unbiased():
    # The mean of the probe's MSE over many seeds (each a new stratified pattern for the render and
    # a new choice of pixels) against the mean of the true MSE, with the exact-coverage reference.
    s = star(48, 40)
    ref, _, _ = s.reference(1.0)
    est, true = [], []
    for seed in range(12):
        r = mr.render(s.scene, s.camera, 48, 40, spp=4, pattern="stratified", seed=seed, estimate_error=True,
                      probe_pixels=64)
        est.append(r.error_estimate ** 2)
        true.append(image_error(r.color, ref)["rmse"] ** 2)
    assert np.mean(est) == pytest.approx(np.mean(true), rel=0.25), (np.mean(est), np.mean(true))


def test_probe_finds_an_error_held_by_few_pixels_at_one_spp():
    # The checker plane at 1 spp with anisotropy 4: its error sits in the distance, in about 1 % of
    # the pixels (the pixels whose footprint is longer than 4 probes reach); with one sample per
    # pixel there is no halves map, and the colour-step guide points at the near checks instead.
    # The default draw (at least kProbeMinPixels) measures it within a factor of 2 for every seed;
    # the old minimum of 64 draws missed by more than 2x for some.
    s = checker_plane(128, 96)
    ref, residual, _ = s.reference(1.0)
    scene = with_filter(s.scene, None, 4.0)
    r = mr.render(scene, s.camera, 128, 96, spp=1)
    true = image_error(r.color, ref)["rmse"]
    assert residual < 0.25 * true
    ratios = [mr.render(scene, s.camera, 128, 96, spp=1, seed=seed, estimate_error=True).error_estimate / true
              for seed in range(10)]
    assert all(0.5 <= x <= 2.0 for x in ratios), ratios


def test_adaptive_probes_measure_the_first_probes_draws():
    # Every probe of an adaptive render measures the first probe's draws against the reference
    # passes already rendered: the final estimate is exactly a fresh probe of the final image with
    # the first pass's guide and the same seed (the same draws, the same passes).
    scene, camera, _ = _corner_triangle(96, 64)
    clear = (0.0, 0.0, 0.0, 1.0)
    first = mr.render(scene, camera, 96, 64, spp=4, estimate_error=True, probe_pixels=0, clear_color=clear)
    base = mr.render(scene, camera, 96, 64, spp=4, estimate_error=True, clear_color=clear)
    r = mr.render(scene, camera, 96, 64, spp=4, target_error=base.error_estimate / 3, clear_color=clear)
    assert len(r.adaptive) >= 1 and r.pixel_spp.max() > 4
    settings = _core.RenderSettings()
    settings.width, settings.height, settings.samples, settings.clear_color = 96, 64, 4, clear
    fresh = measure_error(_core_draws(scene), camera.build(96, 64), settings, r.color, None,
                          default_pixel_count(96, 64, 4), seed=0, guide_map=guide(first.color, first.error_map))
    assert fresh.reference_spp == r.error_probe.reference_spp
    assert r.error_probe.rendered_passes == 0  # every reference pass came from the first probe
    assert r.error_estimate == fresh.rmse and r.error_probe.stderr == fresh.stderr, (r.error_probe, fresh)
    # The first probe's draws, kept: the same pixels as the plain render's probe (same seed, guide).
    assert r.error_probe.distinct_pixels == base.error_probe.distinct_pixels
    # A ProbeReference starts empty and is filled by the first probe given it.
    kept = ProbeReference()
    assert kept.empty and kept.passes == 0
    measure_error(_core_draws(scene), camera.build(96, 64), settings, first.color, first.error_map, 128, seed=0,
                  reuse=kept)
    assert not kept.empty and kept.draws == 128 and kept.passes >= 2 and "ProbeReference" in repr(kept)
    with pytest.raises(ValueError, match="reuse"):
        small = _core.RenderSettings()
        small.width, small.height, small.samples = 32, 32, 4
        measure_error(_core_draws(scene), camera.build(32, 32), small, np.zeros((32, 32, 4), np.float32), None, 64,
                      reuse=kept)


def test_probe_is_deterministic_for_any_thread_count():
    s = zone_plate(40, 30)
    a = mr.render(s.scene, s.camera, 40, 30, spp=4, estimate_error=True, threads=1)
    b = mr.render(s.scene, s.camera, 40, 30, spp=4, estimate_error=True, threads=2)
    assert a.error_estimate == b.error_estimate and a.error_probe.stderr == b.error_probe.stderr
    np.testing.assert_array_equal(a.error_map, b.error_map)
    c = mr.render(s.scene, s.camera, 40, 30, spp=4, estimate_error=True, threads=2, seed=1)
    assert c.error_estimate != a.error_estimate  # another seed, another choice of pixels


def _corner_triangle(width, height):
    # One triangle in the top-left tile (pixel coordinates, as the study's star): every other pixel
    # is flat background with no error.
    tri = np.array([[(3.0, 4.0), (27.0, 9.0), (9.0, 26.0)]])
    mesh = mr.Mesh(np.c_[tri[0], np.zeros(3)] * [1, -1, 1], [[0, 1, 2]], colors=np.ones((3, 3)))
    scene = mr.Scene()
    scene.add(mesh, depth_test=False)
    camera = mr.Camera.orthographic(eye=(width / 2, -height / 2, 1.0), target=(width / 2, -height / 2, 0.0),
                                    height=float(height), near=0.0, far=2.0)
    return scene, camera, exact_coverage(tri, np.ones((1, 3)), width, height, (0.0, 0.0, 0.0))


def _partly_covered(ref):
    return (ref[..., 0] > 0) & (ref[..., 0] < 1)


def _dilate(mask, steps):
    out = mask.copy()
    for _ in range(steps):
        grown = np.pad(out, 1)
        h, w = mask.shape
        out = np.any([grown[dy:dy + h, dx:dx + w] for dy in range(3) for dx in range(3)], axis=0)
    return out


@pytest.mark.parametrize("spp, pattern", [(4, "auto"), (4, "stratified"), (2, "auto")])
def test_adaptive_refines_only_where_needed(spp, pattern):
    scene, camera, ref = _corner_triangle(96, 64)
    clear = (0.0, 0.0, 0.0, 1.0)
    base = mr.render(scene, camera, 96, 64, spp=spp, pattern=pattern, estimate_error=True, clear_color=clear)
    assert image_error(base.color, ref)["rmse"] > 0
    target = base.error_estimate / 3
    r = mr.render(scene, camera, 96, 64, spp=spp, pattern=pattern, target_error=target, clear_color=clear)
    assert r.pixel_spp.shape == (64, 96)
    near_edges = guide(base.color, base.error_map) > 0  # estimated error nearby, or a colour step
    # The image's estimate meets the target, or the pixels with error have run out of samples.
    assert r.error_estimate <= target or np.all(r.pixel_spp[near_edges] == _core.MAX_SAMPLES)
    assert r.pixel_spp.max() > spp
    # Only pixels near the triangle's edges (partly covered in the exact reference; the guide
    # reaches a pixel beyond, and each pass one more) were rendered again; the others are the
    # base render's.
    refined = r.pixel_spp > spp
    assert np.all(_dilate(_partly_covered(ref), MAX_PASSES + 1)[refined])
    assert refined.sum() < 0.2 * refined.size
    np.testing.assert_array_equal(r.color[~refined], base.color[~refined])
    # And the true error went down.
    assert image_error(r.color, ref)["rmse"] < image_error(base.color, ref)["rmse"]


def test_adaptive_unreachable_target_stops_at_64():
    scene, camera, ref = _corner_triangle(64, 32)
    base = mr.render(scene, camera, 64, 32, spp=4, estimate_error=True)
    r = mr.render(scene, camera, 64, 32, spp=4, target_error=1e-9)
    near_edges = guide(base.color, base.error_map) > 0
    assert set(np.unique(r.pixel_spp)) == {4, _core.MAX_SAMPLES}
    assert np.all(r.pixel_spp[near_edges] == _core.MAX_SAMPLES)
    assert np.all(_dilate(_partly_covered(ref), MAX_PASSES + 1)[r.pixel_spp > 4])


def test_plan_is_the_cheapest_single_pass():
    # Brute force over every subset of pixels and every sample count: the plan's new samples are
    # the fewest of any one pass whose predicted error (∝ 1/√spp) meets the target.
    rng = np.random.default_rng(5)
    for trial in range(20):
        error = rng.uniform(0, 1, 7) * (rng.uniform(0, 1, 7) > 0.2)
        spp = rng.choice([4, 8, 16], 7)
        target = math.sqrt(np.mean(error ** 2)) * rng.uniform(0.2, 0.9)
        best = None
        for s in sorted({4 * 2 ** k for k in range(1, 5)} | {64}):
            for bits in range(1, 2 ** 7):
                mask = np.array([(bits >> i) & 1 for i in range(7)], dtype=bool)
                if np.any(spp[mask] >= s) or np.any(error[mask] == 0):
                    continue
                after = np.where(mask, error * np.sqrt(spp / s), error)
                if np.mean(after ** 2) <= target ** 2 * (1 + 1e-9) and (best is None or mask.sum() * s < best):
                    best = mask.sum() * s
        plan = plan_refinement(error, spp, target, 4)
        assert plan is not None
        mask, s = plan
        if best is None:  # unreachable in one pass: every pixel with error at 64
            assert s == 64 and np.array_equal(mask, (error > 0) & (spp < 64))
        else:
            assert mask.sum() * s == best, (trial, mask, s, best)


def test_uniform_samples_is_the_fewest_that_meet_the_target():
    rng = np.random.default_rng(7)
    for _ in range(200):
        spp = int(rng.choice([1, 2, 4, 8, 16, 32, 64]))
        error = float(rng.uniform(0.001, 0.1))
        target = error * float(rng.uniform(0.05, 1.2))
        got = uniform_samples(error, spp, target)
        if spp == 64:
            assert got is None
            continue
        meets = [s for s in range(spp + 1, 65) if (s == 64 or s % spp == 0 and (s // spp) & (s // spp - 1) == 0)
                 and error * math.sqrt(spp / s) <= target]
        assert got == (min(meets) if meets else 64), (spp, error, target, got)


@pytest.mark.parametrize("make, kind", [(zone_plate, "uniform"), (None, "refine")])
def test_adaptive_takes_the_cheaper_plan(make, kind):
    # Error everywhere (the zone plate): refining most pixels as listed pixels costs more than a
    # uniform render, so adaptive renders every pixel again and says so. Error in a few pixels
    # (one small triangle): refining them is cheaper. Each pass took the plan the cost model
    # (measured per-sample times) priced lower.
    if make is None:
        scene, camera, _ = _corner_triangle(96, 64)
    else:
        s = make(96, 64)
        scene, camera = s.scene, s.camera
    base = mr.render(scene, camera, 96, 64, spp=4, estimate_error=True)
    r = mr.render(scene, camera, 96, 64, spp=4, target_error=0.5 * base.error_estimate)
    assert r.adaptive and r.adaptive[0].kind == kind, r.adaptive
    for p in r.adaptive:
        assert p.predicted_ms <= p.alternative_ms and p.ms > 0 and not math.isnan(p.error)
        assert p.kind in repr(p)
    refined = int(np.sum(r.pixel_spp > 4))
    if kind == "uniform":
        assert r.adaptive[0].pixels == 96 * 64 and r.pixel_spp.min() >= r.adaptive[0].samples
    else:
        assert refined <= sum(p.pixels for p in r.adaptive) and refined < 0.2 * 96 * 64
    assert r.adaptive[-1].error == r.error_estimate


def test_adaptive_bad_input():
    s = star(32, 32)
    for bad in (0.0, -1.0, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="target_error"):
            mr.render(s.scene, s.camera, 32, 32, spp=4, target_error=bad)
    with pytest.raises(TypeError, match="target_error"):
        mr.render(s.scene, s.camera, 32, 32, spp=4, target_error="small")
    with pytest.raises(ValueError, match="keep the samples"):
        mr.render(s.scene, s.camera, 32, 32, spp=4, target_error=0.01, keep_samples=True)
    with pytest.raises(ValueError, match="box resolve"):
        mr.render(s.scene, s.camera, 32, 32, spp=4, target_error=0.01, resolve_filter="tent")
    with pytest.raises(ValueError, match="probe_pixels"):
        mr.render(s.scene, s.camera, 32, 32, spp=4, estimate_error=True, probe_pixels=-1)
    with pytest.raises(TypeError, match="probe_pixels"):
        mr.render(s.scene, s.camera, 32, 32, spp=4, estimate_error=True, probe_pixels="many")


def test_pixel_list_is_checked():
    s = star(40, 40)
    settings = _core.RenderSettings()
    settings.width = settings.height = 40
    settings.samples = 4
    settings.pixels = [5, 1600]
    with pytest.raises(ValueError, match=r"pixels\[1\] = 1600 is outside the 40x40 image"):
        _core.render([d._draw for d in s.scene.draws], s.camera.build(40, 40), settings)


def test_tile_mask_size_is_checked():
    s = star(40, 40)
    settings = _core.RenderSettings()
    settings.width = settings.height = 40
    settings.samples = 4
    settings.tile_mask = [1, 0, 1]
    with pytest.raises(ValueError, match="tile_mask: expected 4 flags"):
        _core.render([d._draw for d in s.scene.draws], s.camera.build(40, 40), settings)


def _cli_estimate(stdout):
    line = [l for l in stdout.splitlines() if l.startswith("error estimate")][0]
    bound = "rmse<=" in line
    value = float(line.split("rmse<=" if bound else "rmse=")[1].split(" ")[0].rstrip(","))
    return line, value, bound


@pytest.mark.parametrize("spp, aa", [(8, "msaa"), (1, "ssaa")])
def test_cli_stats_reports_the_calibrated_estimate(tmp_path, spp, aa):
    # The CLI's --stats runs the same probe as render(..., estimate_error=True) on the same demo
    # render: the same estimate (printed to 6 digits), at 1 spp too.
    from test_cli import EXE
    import subprocess

    r = subprocess.run([EXE, "render", "-o", str(tmp_path / "a.png"), "--size", "64x36", "--spp", str(spp), "--aa", aa,
                        "--stats"], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    line, value, bound = _cli_estimate(r.stdout)
    scene, camera = mr.Scene.demo()
    py = mr.render(scene, camera, 64, 36, spp=spp, aa=aa, estimate_error=True)
    assert value == pytest.approx(py.error_estimate, rel=1e-5) and bound == py.error_probe.upper_bound
    assert value > 0  # the demo has edges
    assert f"{py.error_probe.pixels} pixels rendered again at {py.error_probe.reference_spp} spp" in line
    assert ("worst pixel=" in line) == (spp >= 2)


def test_cli_stats_without_probe(tmp_path):
    # --probe-pixels 0: the raw halves estimate (needs 2 samples), as render(..., probe_pixels=0).
    from test_cli import EXE
    import subprocess

    r = subprocess.run([EXE, "render", "-o", str(tmp_path / "a.png"), "--size", "64x36", "--spp", "8", "--stats",
                        "--probe-pixels", "0"], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    line, value, _ = _cli_estimate(r.stdout)
    scene, camera = mr.Scene.demo()
    py = mr.render(scene, camera, 64, 36, spp=8, aa="msaa", estimate_error=True, probe_pixels=0)
    assert "two interleaved halves" in line and value == pytest.approx(py.error_estimate, rel=1e-5)
    r = subprocess.run([EXE, "render", "-o", str(tmp_path / "b.png"), "--size", "64x36", "--spp", "1", "--stats",
                        "--probe-pixels", "0"], capture_output=True, text=True, timeout=120)
    assert "error estimate: without a probe (--probe-pixels 0) it needs --spp 2 or more" in r.stdout
    r = subprocess.run([EXE, "render", "-o", str(tmp_path / "b.png"), "--probe-pixels", "-3"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "--probe-pixels: -3 is out of range; expected an integer from 0 to" in r.stderr


@pytest.mark.parametrize("probe_pixels", [None, 0])
def test_cli_error_map(tmp_path, probe_pixels):
    # The map the CLI writes is the one render(..., estimate_error=True) returns for the same demo:
    # the halves map scaled to the probe's estimate, or with --probe-pixels 0 the raw halves map.
    from test_cli import EXE
    import subprocess

    out = tmp_path / "err.exr"
    extra = [] if probe_pixels is None else ["--probe-pixels", str(probe_pixels)]
    r = subprocess.run([EXE, "render", "-o", str(tmp_path / "a.png"), "--size", "64x36", "--spp", "8", "--aa", "ssaa",
                        "--error-map", str(out), "--quiet", *extra], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    written = np.asarray(mr.read_image(out)).reshape(36, 64, -1)[..., 0]
    scene, camera = mr.Scene.demo()
    expected = mr.render(scene, camera, 64, 36, spp=8, aa="ssaa", estimate_error=True, probe_pixels=probe_pixels)
    np.testing.assert_allclose(written, expected.error_map, rtol=1e-6, atol=1e-9)
    assert expected.error_map.max() > 0
    if probe_pixels is None:
        assert math.sqrt(np.mean(written.astype(np.float64) ** 2)) == pytest.approx(expected.error_estimate, rel=1e-4)
    r = subprocess.run([EXE, "render", "-o", str(tmp_path / "b.png"), "--spp", "1", "--error-map", str(out)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "--error-map" in r.stderr and "--spp 2" in r.stderr
