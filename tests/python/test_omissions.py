"""The omission table (mipraster.omissions): every omission of issue 7 has a row, and where the two
variants should draw the same image they do (timings are never asserted)."""
import json

import numpy as np
import pytest

from mipraster import bench, growth, omissions

ISSUE_OMISSIONS = ["no derivatives for untextured draws", "no perspective division for orthographic cameras",
                   "no resolve at 1 sample", "no depth buffer when nothing tests depth", "lazily built mip levels",
                   "culled off-screen triangles", "specialization vs a generic path"]


def test_every_omission_of_the_issue_has_a_row():
    names = [o.name for o in omissions.OMISSIONS]
    assert all(n in names for n in ISSUE_OMISSIONS)
    # A row without a way to force the work says why instead of giving a number.
    assert all(o.note for o in omissions.OMISSIONS if o.without is None)


@pytest.mark.parametrize("om", [o for o in omissions.OMISSIONS if o.same_image], ids=lambda o: o.name)
def test_with_and_without_draw_the_same_image(om):
    a = omissions.render_variant(om.with_it, 48, 27).color
    b = omissions.render_variant(om.without, 48, 27).color
    assert np.all(a[..., 3] == 1.0)  # drawn everywhere: not the transparent clear colour
    omissions.compare_images(om.same_image, a, b)


def test_forcing_all_levels_builds_them_and_lazy_does_not():
    om = next(o for o in omissions.OMISSIONS if o.name == "lazily built mip levels")
    w, h = omissions.SIZE  # the table's size: 512 texels over more than 512 pixels each way
    lazy = om.with_it.setup(w, h)
    omissions.render_variant(om.with_it, w, h, lazy)
    assert lazy["texture"].built_levels == 0  # magnified: level 0 only
    forced = om.without.setup(w, h)
    omissions.render_variant(om.without, w, h, forced)
    assert forced["texture"].built_levels == forced["texture"].level_count - 1


def test_offscreen_triangles_are_culled_not_drawn():
    om = next(o for o in omissions.OMISSIONS if o.name == "culled off-screen triangles")
    stats = omissions.render_variant(om.with_it, 48, 27).stats
    offscreen = len(growth.grid_mesh(omissions.OFFSCREEN_TRIANGLES, 48 / 27)[1])
    onscreen = len(growth.grid_mesh(omissions.GRID_TRIANGLES, 48 / 27)[1])
    assert stats["triangles_in"] == onscreen + offscreen and stats["triangles_outside"] == offscreen


def test_compare_images_kinds():
    a = np.zeros((2, 2, 4), np.float32)
    b = a.copy()
    assert omissions.compare_images("exact", a, b) == "identical"
    b[0, 0, 0] = 1e-6
    assert omissions.compare_images("close", a, b) == "max |diff| 1e-06"
    with pytest.raises(AssertionError, match="should be identical"):
        omissions.compare_images("exact", a, b)
    b[0, 0, 0] = 1e-3
    with pytest.raises(AssertionError, match="0.001 > 1e-05"):
        omissions.compare_images("close", a, b)


def test_bench_omissions_end_to_end(tmp_path, monkeypatch):
    monkeypatch.setattr(omissions, "QUICK_SIZE", (32, 18))
    assert bench.main(["--omissions", "--quick", "--out", str(tmp_path)]) == 0
    rows = json.loads((tmp_path / "omissions.json").read_text())["rows"]
    assert [r["name"] for r in rows] == [o.name for o in omissions.OMISSIONS]
    for r, o in zip(rows, omissions.OMISSIONS):
        measured = o.without is not None
        assert (r["with_ms"] is not None and r["without_ms"] is not None) == measured
        assert (r["image_check"] != "") == bool(o.same_image)
    table = (tmp_path / "omissions.md").read_text()
    assert "| specialization vs a generic path | any |" in table and "not measured" in table


def test_memory_sees_the_kept_sample_buffer():
    om = next(o for o in omissions.OMISSIONS if o.name == "no resolve at 1 sample")
    w, h = 1280, 720  # (large enough that a megabyte of other allocations cannot hide the buffer)
    with_it, without = (omissions.render_memory(v, w, h) for v in (om.with_it, om.without))
    if with_it is None:
        pytest.skip("no /proc/self/clear_refs or malloc_trim here")
    # The image itself (RGBA float) is in both; keeping the samples adds at least their colour.
    assert with_it >= w * h * 16 and without - with_it >= w * h * 16
