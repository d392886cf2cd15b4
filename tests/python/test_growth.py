"""The cost-growth study (mipraster.growth): its fits recover known laws from synthetic timings, its
procedural scenes are what they claim, and a tiny run writes its table, JSON and plot (timings are
never asserted)."""
import json

import numpy as np
import pytest

import mipraster as mr
from mipraster import growth

N = np.array([1e3, 1e4, 1e5, 1e6, 1e7])


def test_fit_recovers_a_linear_law():
    f = growth.fit(N, 2.0 + 3e-6 * N)
    assert f["a"] == pytest.approx(2.0, rel=1e-9) and f["b"] == pytest.approx(3e-6, rel=1e-9)
    assert abs(f["c2"]) < 1e-15 and abs(f["superlinear_share"]) < 1e-9
    assert f["exponent"] == pytest.approx(1.0, abs=1e-5)
    assert f["marginal"] == pytest.approx([3e-6] * 4, rel=1e-9)  # a linear law's marginal cost is b


def test_fit_recovers_an_n_log_n_term():
    f = growth.fit(N, 1.0 + 1e-6 * N + 2e-7 * N * np.log2(N))
    assert f["a2"] == pytest.approx(1.0, rel=1e-6) and f["b2"] == pytest.approx(1e-6, rel=1e-6)
    assert f["c2"] == pytest.approx(2e-7, rel=1e-6)
    top = 2e-7 * 1e7 * np.log2(1e7)
    assert f["superlinear_share"] == pytest.approx(top / (1.0 + 1e-6 * 1e7 + top), rel=1e-6)


@pytest.mark.parametrize("p", [0.5, 1.0, 1.5, 2.0])
@pytest.mark.parametrize("a", [0.0, 3.0])
def test_fit_recovers_a_power_law_exponent(p, a):
    assert growth.fit(N, a + 4e-4 * N ** p)["exponent"] == pytest.approx(p, abs=1e-5)


def test_marginal_costs_grow_for_a_quadratic_law():
    f = growth.fit([1, 2, 4, 8], [1, 4, 16, 64])  # marginal 3, 6, 12: each step twice the last
    assert f["marginal"] == pytest.approx([3, 6, 12])


def test_fit_needs_three_points():
    with pytest.raises(ValueError, match="at least 3 points, got 2"):
        growth.fit([1, 2], [1, 2])


@pytest.mark.parametrize("n", [1000, 12345])
def test_grid_has_about_n_triangles_and_covers_the_screen(n):
    scene, camera, triangles = growth.make_scene("grid", n, 64, 36)
    assert 0.9 * n <= triangles <= n
    img = mr.render(scene, camera, 64, 36, clear_color=(0, 0, 0, 0)).color
    assert np.all(img[..., 3] == 1.0)  # no pixel keeps the transparent clear colour


def test_random_triangles_have_the_stated_edge_in_pixels():
    w, h = 200, 100
    positions, tris, _ = growth.random_mesh(500, w, h)
    assert tris.shape == (500, 3)
    px = (positions[:, :2].astype(np.float64) + 1) / 2 * [w, h]
    corners = px[tris]
    edges = np.linalg.norm(corners - np.roll(corners, 1, axis=1), axis=-1)
    np.testing.assert_allclose(edges, growth.RANDOM_EDGE_PX, rtol=1e-4)


def test_unknown_scene_kind_is_named():
    with pytest.raises(ValueError, match="kind: expected 'grid' or 'random', got 'cube'"):
        growth.make_scene("cube", 10, 8, 8)


def test_tiny_run_writes_table_json_and_plot(tmp_path, monkeypatch):
    monkeypatch.setattr(growth, "QUICK_TRIANGLE_COUNTS", [100, 200, 400])
    monkeypatch.setattr(growth, "TRIANGLE_SIZE", (32, 18))
    monkeypatch.setattr(growth, "QUICK_SAMPLE_SWEEP_WIDTHS", [16, 32, 48])
    monkeypatch.setattr(growth, "SAMPLE_SWEEP_TRIANGLES", 200)
    report = growth.run(str(tmp_path), quick=True)
    series = {p["series"] for p in report["points"]}
    assert series == {"triangles:grid", "triangles:random", "samples:grid 1 spp", "samples:grid 4 spp",
                      "samples:grid all"}
    assert set(report["fits"]) == series
    assert all(p["median_ms"] > 0 for p in report["points"])
    assert json.loads((tmp_path / "growth.json").read_text())["fits"].keys() == report["fits"].keys()
    assert "| triangles:grid | 32×18×1 |" in (tmp_path / "growth.md").read_text()
    png = (tmp_path / "cost_growth.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
