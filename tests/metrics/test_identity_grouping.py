"""The identity figures computed by grouping (one sort per table) equal those of the
former per-target masks (the code before issue 31 item 4, kept here as the reference)
on scenes of many aircraft with id swaps, false tracks, coasting rows, garbled codes and
shared addresses."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from mhtrack.attributes import PlotAttributes
from mhtrack.metrics import evaluate
from mhtrack.metrics import identity as identity_module
from mhtrack.records import PlotTable, TrackTable, TruthTable


# --- the former code path (mhtrack/metrics/identity.py before the change) --------------
def _mode(v):
    v = v[v >= 0]
    if not v.size:
        return -1
    values, counts = np.unique(v, return_counts=True)
    return int(values[np.argmax(counts)])


def _former_target_identities(plots):
    a, origin = plots.attrs, plots.origin
    if a is None or origin is None:
        return {}
    out = {}
    for tid in np.unique(origin[origin >= 0]).tolist():
        mine = origin == tid
        out[int(tid)] = (_mode(a.mode_3a[mine & (a.mode_3a_g == 0)]), _mode(a.address[mine]))
    return out


def _former_default_interval(truth, plots):
    if plots is not None and plots.origin is not None and (plots.origin >= 0).any():
        o, t = np.asarray(plots.origin), np.asarray(plots.time, float)
        steps = np.concatenate([np.diff(np.sort(t[o == k]))
                                for k in np.unique(o[o >= 0]).tolist()])
    else:
        steps = np.diff(np.unique(np.asarray(truth.time, float)))
    steps = steps[steps > 0]
    return float(np.median(steps)) if steps.size else float("nan")


def _former_p_update(tracks, truth, dom, T):
    if not (np.isfinite(T) and T > 0) or not len(truth):
        return float("nan")
    target = np.array([dom.get(int(k), -1) for k in tracks.track_id.tolist()], np.int64)
    upd = np.asarray(tracks.plot) >= 0
    total = updated = 0
    for tid in np.unique(truth.target_id).tolist():
        t = np.asarray(truth.time, float)[truth.target_id == tid]
        t0, t1 = float(t.min()), float(t.max())
        n = max(1, int(np.ceil((t1 - t0) / T)))
        tu = np.asarray(tracks.time, float)[upd & (target == tid)]
        tu = tu[(tu >= t0) & (tu <= t1)]
        j = np.minimum(np.floor((tu - t0) / T).astype(np.int64), n - 1)
        total, updated = total + n, updated + len(np.unique(j))
    return updated / total


def _former_extra_kinds(aligned, truth, matching, limit):
    n = len(aligned)
    if not n:
        return {"multiple_track_rate": float("nan"), "false_track_rate": float("nan")}
    matched = {(int(s), int(k)) for s, k in zip(matching.scan.tolist(),
                                                 matching.track_id.tolist(), strict=True)}
    target_of = {(int(s), int(t)): int(k) for s, t, k in zip(
        matching.scan.tolist(), matching.target_id.tolist(), matching.track_id.tolist(),
        strict=True)}
    ts, tt = np.asarray(truth.scan), np.asarray(truth.target_id)
    multiple = false = 0
    for i, (s, k) in enumerate(zip(aligned.scan.tolist(), aligned.track_id.tolist(),
                                   strict=True)):
        if (int(s), int(k)) in matched:
            continue
        here = np.flatnonzero(ts == s)
        d = np.hypot(truth.x[here] - aligned.x[i], truth.y[here] - aligned.y[i])
        if not here.size or d.min() > limit:
            false += 1
            continue
        other = target_of.get((int(s), int(tt[here[np.argmin(d)]])))
        multiple += other is not None and other != int(k)
    return {"multiple_track_rate": multiple / n, "false_track_rate": false / n}


def _former_ids_per_aircraft(matching):
    tgt, trk = np.asarray(matching.target_id), np.asarray(matching.track_id)
    n_ids = [len(np.unique(trk[tgt == t])) for t in np.unique(tgt).tolist()]
    return float(np.mean(n_ids)) if n_ids else float("nan")


# --- a scene ------------------------------------------------------------------------------
def _scene(seed: int, n_targets: int = 150, n_scans: int = 25):
    """Targets born and dying at random scans (ids not contiguous), one plot per target
    and scan with P_D 0.85 (each target's code, garbled — one bit off — 10 %; address
    absent 30 %; two targets sharing an address; every 11th without code), clutter;
    tracks following the targets 60 m off, every 7th target's with a new id halfway,
    coasting when missed, 5 % of the rows with the plot before theirs (another target's
    or clutter), plus false tracks."""
    rng = np.random.default_rng(seed)
    ids = rng.choice(np.arange(1, 10 * n_targets), n_targets, replace=False)
    birth = rng.integers(0, n_scans // 2, n_targets)
    death = np.minimum(n_scans - 1, birth + rng.integers(2, n_scans, n_targets))
    x0, y0 = rng.uniform(-2e5, 2e5, (2, n_targets))
    v = rng.uniform(-250, 250, (2, n_targets))
    T = 10.0
    truth_rows, plot_rows, track_rows = [], [], []
    for k in range(n_scans):
        for i in np.flatnonzero((birth <= k) & (k <= death)):
            x, y = x0[i] + v[0, i] * k * T, y0[i] + v[1, i] * k * T
            truth_rows.append((k, k * T, ids[i], x, y))
            track_id = ids[i] + (100_000 if k > (birth[i] + death[i]) // 2 and i % 7 == 0
                                 else 0)  # a new id halfway for every 7th target
            if rng.random() < 0.85:
                t = k * T + rng.uniform(0, 4)  # within the scan
                garbled = int(rng.random() < 0.1)
                code = (int(ids[i]) * 37 % 4096) ^ garbled if i % 11 else -1
                address = -1 if rng.random() < 0.3 else (0xABCDE if i < 2 else 0x100 + i)
                plot_rows.append((k, t, ids[i], x, y, code, garbled, address))
                used = len(plot_rows) - 1 - int(rng.random() < 0.05)  # 5 %: the plot before
                track_rows.append((k, k * T, track_id, x + 60.0, y, used))
            else:
                track_rows.append((k, k * T, track_id, x + 60.0, y, -1))
        for _ in range(rng.poisson(3)):
            plot_rows.append((k, k * T + rng.uniform(0, 4), -1, *rng.uniform(-2e5, 2e5, 2),
                              -1, 0, -1))
        track_rows.append((k, k * T, 900_000 + k % 3, *rng.uniform(-2e5, 2e5, 2), -1))
    tr, pl, tk = (np.array(r, dtype=object) for r in (truth_rows, plot_rows, track_rows))
    truth = TruthTable(scan=tr[:, 0].astype(np.int64), time=tr[:, 1].astype(float),
                       target_id=tr[:, 2].astype(np.int64), x=tr[:, 3].astype(float),
                       y=tr[:, 4].astype(float), vx=np.zeros(len(tr)), vy=np.zeros(len(tr)))
    plots = PlotTable(
        scan=pl[:, 0].astype(np.int64), time=pl[:, 1].astype(float),
        sensor=np.zeros(len(pl), np.int64), x=pl[:, 3].astype(float),
        y=pl[:, 4].astype(float), origin=pl[:, 2].astype(np.int64),
        attrs=PlotAttributes.from_columns({
            "mode_3a": pl[:, 5].astype(np.int64), "mode_3a_g": pl[:, 6].astype(np.int64),
            "address": pl[:, 7].astype(np.int64)}))
    order = np.lexsort((tk[:, 2].astype(np.int64), tk[:, 0].astype(np.int64)))
    tk = tk[order]
    tracks = TrackTable(scan=tk[:, 0].astype(np.int64), time=tk[:, 1].astype(float),
                        track_id=tk[:, 2].astype(np.int64), x=tk[:, 3].astype(float),
                        y=tk[:, 4].astype(float), vx=np.zeros(len(tk)), vy=np.zeros(len(tk)),
                        plot=tk[:, 5].astype(np.int64))
    return tracks, truth, plots


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_grouped_figures_equal_the_former_masks(seed, monkeypatch):
    tracks, truth, plots = _scene(seed)
    new = evaluate(tracks, truth, plots=plots, identity=True)
    for name, former in (("target_identities", _former_target_identities),
                         ("_default_interval", _former_default_interval),
                         ("_p_update", _former_p_update),
                         ("_extra_kinds", _former_extra_kinds)):
        monkeypatch.setattr(identity_module, name, former)
    old = evaluate(tracks, truth, plots=plots, identity=True)
    a, b = dataclasses.asdict(new.identity), dataclasses.asdict(old.identity)
    b["ids_per_aircraft"] = _former_ids_per_aircraft(old.clear_mot.matching)
    assert a == b  # exactly: the same numbers in the same order
    # the scene exercises every figure: not NaN, not trivial
    i = new.identity
    assert i.ids_per_aircraft > 1.0 and 0.0 < i.wrong_code_rate < 1.0 and i.n_code_rows > 0
    assert 0.5 < i.p_update < 1.0 and i.update_interval > 0
    assert i.false_track_rate > 0 and i.dubious_track_rate >= 0


def test_target_identities_ties_keep_the_smaller_value():
    """Per target the most frequent code and address, ties to the smaller, garbled codes
    and absent values not counted (hand-worked), as the former per-target masks said."""
    rows = [(4, 0o5, 0, 9), (4, 0o3, 0, 9), (4, 0o5, 0, 7), (4, 0o3, 0, 7), (4, 0o3, 1, -1),
            (2, 0o7, 1, -1), (2, -1, 0, 8), (-1, 0o1, 0, 1)]
    plots = PlotTable(
        scan=np.zeros(8, np.int64), time=np.zeros(8), sensor=np.zeros(8, np.int64),
        x=np.zeros(8), y=np.zeros(8), origin=np.array([r[0] for r in rows]),
        attrs=PlotAttributes.from_columns({
            "mode_3a": np.array([r[1] for r in rows]),
            "mode_3a_g": np.array([r[2] for r in rows]),
            "address": np.array([r[3] for r in rows])}))
    # target 4: codes 5, 3, 5, 3 (the garbled 3 not counted) -> 3; addresses 9, 9, 7, 7
    # -> 7; target 2: its only code garbled -> none, address 8
    want = {4: (0o3, 7), 2: (-1, 8)}
    assert identity_module.target_identities(plots) == want
    assert _former_target_identities(plots) == want
