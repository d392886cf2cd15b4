"""The anisotropic-cost table (mipraster.aniso_cost): every sampler of the sweep is measured on the
plane, the anisotropic ones really filter differently from trilinear, and the files hold the rows
printed (timings are never asserted)."""
import json
import math

from mipraster import aniso_cost, bench


def test_every_anisotropy_is_measured_against_trilinear(tmp_path):
    rows = aniso_cost.run(str(tmp_path), quick=True)
    assert [r.max_anisotropy for r in rows] == list(aniso_cost.ANISOTROPIES)
    assert rows[0].filter == "trilinear" and rows[0].ratio == 1.0 and rows[0].mean_abs_difference == 0.0
    for r in rows:
        assert len(r.frames_ms) == 3 and all(t > 0 and math.isfinite(t) for t in r.frames_ms)
        assert math.isclose(r.ratio, r.median_ms / rows[0].median_ms)
    # Every anisotropic sampler reads more than trilinear's footprint towards the horizon: its
    # image differs (zero would mean the variant rendered with trilinear after all).
    assert all(r.filter == "anisotropic" and r.mean_abs_difference > 1e-3 for r in rows[1:])

    saved = json.loads((tmp_path / "aniso_cost.json").read_text())
    assert (saved["width"], saved["height"]) == aniso_cost.QUICK_SIZE
    assert [r["median_ms"] for r in saved["rows"]] == [r.median_ms for r in rows]
    table = (tmp_path / "aniso_cost.md").read_text()
    assert "anisotropic 16×" in table and f"{rows[-1].ratio:.2f}×" in table


def test_the_bench_command_runs_it(tmp_path, capsys):
    assert bench.main(["--aniso-cost", "--quick", "--out", str(tmp_path)]) == 0
    assert "Target: 16× anisotropic at most 2× trilinear" in capsys.readouterr().out
    assert (tmp_path / "aniso_cost.json").exists()
