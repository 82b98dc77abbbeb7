"""simulate: the experiment's table rows."""

from __future__ import annotations

from typing import Any
import pytest

import gaze_lidar as gl


def test_rows_for_each_cell_and_reproducible() -> None:
    rows = gl.simulate(model="argus", trials=3, seed=1, variants=["baseline", "range"], fog_pct=[0, 50])
    assert [(r["variant"], r["fog_pct"]) for r in rows] == [
        ("baseline", 0),
        ("baseline", 50),
        ("range", 0),
        ("range", 50),
    ]
    for r in rows:
        assert r["model"] == "argus" and r["trials"] == 3
        assert 0 <= r["detected"] <= 3
        assert r["density_median_pts_per_deg"] > 0
    assert gl.simulate(model="argus", trials=3, seed=1, variants=["baseline", "range"], fog_pct=[0, 50]) == rows
    # In argus fog the range-controlled LiDAR detects the right-hand car earlier.
    by = {(r["variant"], r["fog_pct"]): r for r in rows}
    assert by[("range", 50)]["tta_median_s"] > by[("baseline", 50)]["tta_median_s"]


def test_both_models_and_options() -> None:
    rows = gl.simulate(model=["argus", "physical"], trials=1, seed=2, variants=["joint"], fog_pct=[25], detect="1/1")
    assert sorted(r["model"] for r in rows) == ["argus", "physical"]


def test_optimizer_toml_runs_the_closed_forms_on_its_sensor() -> None:
    """With optimizer_toml the closed-form variants run on the configuration's
    sensor (as the CLI's --optimizer-config), not on the paper preset."""
    toml = 'bins = 72\n[lidar]\npreset = "vls128"\n[objective]\nmode = "range"\n'
    common: dict[str, Any] = {"model": "physical", "trials": 2, "seed": 3, "fog_pct": [0]}
    rows = gl.simulate(variants=["range", "optimized"], optimizer_toml=toml, **common)
    closed = [r for r in rows if r["variant"] == "range"]
    assert closed == list(gl.simulate(variants=["range"], preset="vls128", **common))
    assert closed != list(gl.simulate(variants=["range"], **common))


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"trials": 0}, "trials"),
        ({"seed": -1}, "seed"),
        ({"model": "lambertian"}, "model"),
        ({"fog_pct": [10]}, "fog_pct"),
        ({"variants": ["fast"]}, "variants"),
        ({"detect": "3/2"}, "detect"),
        ({"colour": "red"}, "colour"),
        ({"scenario_toml": "speed_kmh = -5"}, "speed_kmh"),
    ],
)
def test_bad_options_name_the_field(kwargs: dict[str, Any], field: str) -> None:
    with pytest.raises(ValueError, match=field):
        gl.simulate(**kwargs)
