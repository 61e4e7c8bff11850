"""``Pipeline.run(keep_stats=False)`` (what ``mhtrack track`` does) keeps no per-step
statistics, and its summary gives the printout of the run that keeps them all."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from mhtrack.io import write_plots
from mhtrack.io.sensors import write_sensors
from mhtrack.pipeline import Pipeline, TrackOptions, caps_acted
from mhtrack.scenario import preset, simulate
from mhtrack.scenario.overrides import apply_overrides


def test_summary_equals_the_kept_statistics(tmp_path):
    sc = apply_overrides(preset("opensky-radars"), scans=3)
    write_plots(simulate(sc, seed=1).plots, tmp_path / "plots.csv")
    write_sensors(sc.sensor_set(), tmp_path / "sensors.toml")
    kept = Pipeline.open(str(tmp_path / "plots.csv"), TrackOptions()).run()
    lean = Pipeline.open(str(tmp_path / "plots.csv"), TrackOptions()).run(keep_stats=False)
    assert lean.stats == () and len(kept.stats) > 10
    assert lean.summary is not None and lean.summary.n == len(kept.stats)
    assert lean.caps == caps_acted(kept.stats) == kept.caps
    assert lean.n_tracks == kept.n_tracks
    # the printout, timing aside
    assert lean.describe().split(" ms/scan")[0].rsplit(",", 1)[0] == \
        kept.describe().split(" ms/scan")[0].rsplit(",", 1)[0]
    assert lean.t_avg > 0


@given(st.lists(st.lists(st.integers(0, 5000), max_size=30), max_size=30))
def test_id_bitmap_counts_as_a_set(batches: list[list[int]]) -> None:
    """The run's count of distinct track ids (a bitmap: flat memory over days) equals
    the size of a Python set of the same ids, batch after batch."""
    import numpy as np

    from mhtrack.pipeline.run import IdSet

    ids, ref = IdSet(), set()
    for b in batches:
        ids.update(np.array(b, np.int64))
        ref.update(b)
        assert len(ids) == len(ref)
