"""mipraster.bench_texture's side-by-side table and goals on hand-made results (nothing is run or
timed): the batched filters (trilinear_batch, anisotropic_batch: BatchSampler) are compared with the
same OpenImageIO modes as their one-at-a-time twins, and the goals table names the variant that met
each goal."""
from mipraster import bench_texture as bt

OIIO_SPEED = {"trilinear": 1e6, "aniso16_bilinear": 1e5}
OIIO_MAE = {"trilinear": 0.02, "aniso16_bilinear": 0.02}


def _results(speed: dict, mae: dict):
    """mipraster and OpenImageIO results as the two benchmarks write them: every footprint and texture
    gets the filter's (mode's) speed and error."""
    mip = {"accuracy": [{"texture": t, "footprint": fp, "filter": f, "mae": e, "rmse": e}
                        for f, e in mae.items() for t in bt.TEXTURES for fp in bt.FOOTPRINTS],
           "timing": [{"footprint": fp, "filter": f, "lookups_per_s": v} for f, v in speed.items() for fp in bt.FOOTPRINTS]}
    oiio = {"accuracy": [{"texture": t, "footprint": fp, "mode": m, "mae": e, "rmse": e}
                         for m, e in OIIO_MAE.items() for t in bt.TEXTURES for fp in bt.FOOTPRINTS],
            "timing": [{"texture": "zoneplate_f32", "pattern": "coherent", "api": "handle", "nchannels": 1,
                        "footprint": fp, "mode": m, "lookups_per_s": v}
                       for m, v in OIIO_SPEED.items() for fp in bt.FOOTPRINTS]}
    return bt.side_by_side(bt.mip_errors(mip), bt.mip_speeds(mip), bt.oiio_errors(oiio), bt.oiio_speeds(oiio))


def _met_by(goal_rows, prefix):
    [row] = [r for r in goal_rows if "met_by" in r and r["goal"].startswith(prefix)]
    return row["met_by"]


def test_batched_filters_are_compared_with_the_same_oiio_modes():
    table, rows = _results({"trilinear_batch": 3e6, "anisotropic_batch": 2e6}, {"trilinear_batch": 0.01,
                                                                              "anisotropic_batch": 0.01})
    pairs = {(r["mipraster"], r["oiio"]) for r in rows}
    assert ("trilinear_batch", "trilinear") in pairs and ("anisotropic_batch", "aniso16_bilinear") in pairs
    r = next(r for r in rows if r["mipraster"] == "trilinear_batch" and r["footprint"] == "iso_8x8")
    assert r["speed_ratio"] == 3.0
    assert "| trilinear_batch | trilinear |" in table


def test_goal_met_only_by_the_batched_variant_names_it():
    # Trilinear one at a time 1.5x OpenImageIO, batched 2.5x: the goal is met by trilinear_batch only.
    _, rows = _results({"trilinear": 1.5e6, "trilinear_batch": 2.5e6}, {"trilinear": 0.03, "trilinear_batch": 0.03})
    md, goal_rows = bt.goals(rows)
    assert _met_by(goal_rows, "trilinear") == ["trilinear_batch"]
    assert "| **met by** | | | | **trilinear_batch** |" in md
    assert _met_by(goal_rows, "anisotropic") == []  # no anisotropic row measured


def test_batched_variant_faster_but_less_accurate_does_not_meet_the_error_goal():
    # anisotropic_batch is 20x OpenImageIO but its error is above OpenImageIO's; anisotropic is 12x
    # at a lower error: only anisotropic meets the goal.
    _, rows = _results({"anisotropic": 1.2e6, "anisotropic_batch": 2e6, "trilinear": 2e6},
                       {"anisotropic": 0.01, "anisotropic_batch": 0.05, "trilinear": 0.03})
    md, goal_rows = bt.goals(rows)
    assert _met_by(goal_rows, "anisotropic") == ["anisotropic"]
    assert _met_by(goal_rows, "trilinear") == ["trilinear"]
    per_filter = {r["filter"]: r["met"] for r in goal_rows if r.get("footprint") == "all"}
    assert per_filter["anisotropic"] and not per_filter["anisotropic_batch"] and not per_filter["ewa"]


def test_results_without_batched_rows_still_report():
    # Results from a benchmark run without the batched filters (an older binary, or --filters).
    table, rows = _results({"trilinear": 3e6}, {"trilinear": 0.03})
    md, goal_rows = bt.goals(rows)
    assert _met_by(goal_rows, "trilinear") == ["trilinear"]
    assert "| trilinear_batch | trilinear |" in table  # listed, with dashes for what was not measured
