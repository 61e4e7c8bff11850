"""Registration bias on ``opensky-radars`` (issue 29, deliverable 4): per bias draw, the
unbiased run, the biased run without estimation and with it (``--estimate-bias``), side
by side — OSPA (c = 500 m, p = 2), coverage and ids per aircraft from ``mhtrack
evaluate`` — and the estimates after 600 s and at the end against the true biases.

Draw 1 is the issue's example (+200 m and −0.12° on radar 1, +0.08° and gain 1.002 on
radar 2, radar 3 unbiased); draws 2… are random (range offset U(−250, 250) m, gain
1 + U(−0.002, 0.002), azimuth U(−0.15, 0.15)°) on two radars, the third unbiased and the
reference, cycling 3, 1, 2. Draw ``k`` simulates with seed ``k``. Each run is the CLI's
(``mhtrack simulate … --bias``, ``mhtrack track … [--estimate-bias --bias-reference
REF]``, ``mhtrack evaluate … --json``); the estimate at 600 s is read from the run's
:attr:`~mhtrack.pipeline.registration.Registration.history` (the same pipeline, in
process). Each estimate's error is also given in its reported σ, and the fraction of
them within 2σ and 3σ over all draws (the coverage of the cluster-robust σ), and beside
it the Cramér–Rao bound of an estimate from the radar's target plots up to that time if
the targets' paths were known exactly (:func:`known_path_bound`: no estimator of the bias
from those plots has a smaller σ; the real one must also estimate the paths from the
reference's plots, so its σ is larger). Run:
``PYTHONPATH=src python benchmarks/bench_registration.py [--quick] [draws...]``
(``--quick``: without the unbiased run with estimation).
"""

from __future__ import annotations

import contextlib
import io
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

from mhtrack.cli.main import cli
from mhtrack.pipeline import TrackOptions
from mhtrack.pipeline.run import Pipeline
from mhtrack.sinks.files import TracksFileSink

AT_S = 600.0
#: Scale of each component below which "within 20 %" is taken of the scale (a true bias
#: of 0 has no 20 %): 100 m, gain 0.001, 0.05°; the relative errors are printed beside.
SCALE = (100.0, 0.001, 0.05)


def draw(k: int) -> tuple[int, dict[int, tuple[float, float, float]]]:
    """(reference radar, {radar: (range offset m, gain, azimuth °)}) of draw ``k``."""
    if k == 1:
        return 3, {1: (200.0, 1.0, -0.12), 2: (0.0, 1.002, 0.08), 3: (0.0, 1.0, 0.0)}
    rng = np.random.default_rng(1000 + k)
    ref = (3, 1, 2)[(k - 1) % 3]
    out = {ref: (0.0, 1.0, 0.0)}
    for sid in sorted({1, 2, 3} - {ref}):
        out[sid] = (round(float(rng.uniform(-250, 250)), 1),
                    round(1 + float(rng.uniform(-0.002, 0.002)), 5),
                    round(float(rng.uniform(-0.15, 0.15)), 3))
    return ref, out


def _cli(args: list[str]) -> str:
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        cli.main(args, standalone_mode=False)
    return buf.getvalue()


def _evaluate(tracks: Path, truth: Path) -> tuple[float, float, float]:
    d = json.loads(_cli(["evaluate", str(tracks), str(truth), "--json"]))
    return d["ospa_mean"], d["coverage"], d["n_track_ids"] / d["n_targets"]


def _estimated(d: Path, ref: int, out: Path) -> list:  # type: ignore[type-arg]
    opts = TrackOptions(estimate_bias=True, bias_reference=ref)
    pipe = Pipeline.open(d / "plots.csv", opts, sensors_file=str(d / "sensors.toml"))
    pipe.run([TracksFileSink(out, frame=pipe.frame, output=pipe.output)], keep_stats=False)
    assert pipe.registration is not None
    print("   ", pipe.registration.describe()[1:])
    return pipe.registration.history


def known_path_bound(d: Path, sid: int, until: float, near_s: float = 15.0
                     ) -> tuple[float, float, float]:
    """σ (m, gain, degrees) of the Cramér–Rao bound on radar ``sid``'s bias from its
    target plots up to ``until`` whose target another sensor saw within ``near_s``
    seconds (those a pair can use), the paths known: each plot measures
    ``(r_m, θ_m) = (g r + Δr, θ + Δθ)`` with noise ``diag(σ_r², σ_θ²)``, so its Fisher
    information is ``Jᵀ diag(σ_r⁻², σ_θ⁻²) J``, ``J = [[1, r, 0], [0, 0, 1]]``; the bound
    is the diagonal of the inverse of their sum (Van Trees 1968, §2.4)."""
    import tomllib
    sensor = next(s for s in tomllib.loads((d / "sensors.toml").read_text())["sensors"]
                  if s["id"] == sid)
    a = np.genfromtxt(d / "plots.csv", delimiter=",", names=True)
    a = a[(a["origin"] >= 0) & (a["time"] <= until)]
    mine, other = a[a["sensor"] == sid], a[a["sensor"] != sid]
    keep = np.zeros(len(mine), bool)
    for target in np.unique(mine["origin"]):
        seen = np.sort(other["time"][other["origin"] == target])
        m = np.flatnonzero(mine["origin"] == target)
        if seen.size:
            k = np.clip(np.searchsorted(seen, mine["time"][m]), 1, max(seen.size - 1, 1))
            gap = np.minimum(np.abs(seen[np.minimum(k, seen.size - 1)] - mine["time"][m]),
                             np.abs(seen[k - 1] - mine["time"][m]))
            keep[m] = gap <= near_s
    r = mine["range"][keep]
    sr, sb = sensor["sigma_range"], np.radians(sensor["sigma_bearing_deg"])
    info = np.array([[r.size / sr**2, r.sum() / sr**2, 0.0],
                     [r.sum() / sr**2, (r**2).sum() / sr**2, 0.0],
                     [0.0, 0.0, r.size / sb**2]])
    s = np.sqrt(np.diag(np.linalg.inv(info)))
    return float(s[0]), float(s[1]), float(np.degrees(s[2]))


def _within(est: tuple[float, float, float], true: tuple[float, float, float]) -> bool:
    errs = (est[0] - true[0], est[1] - true[1], est[2] - true[2])
    tv = (true[0], true[1] - 1.0, true[2])
    return all(abs(e) <= 0.2 * max(abs(t), s) for e, t, s in zip(errs, tv, SCALE, strict=True))


def _in_bound(true: tuple[float, float, float], crb: tuple[float, float, float]) -> str:
    """Each component's 20 % of its true value in the bound's σ ("-" for a true 0)."""
    tv = (true[0], true[1] - 1.0, true[2])
    return "/".join(f"{0.2 * abs(v) / c:.1f}" if v else "-" for v, c in zip(tv, crb, strict=True))


def _relative(est: tuple[float, float, float], true: tuple[float, float, float]) -> str:
    """Each component's error in % of its true value ("-" for a true 0)."""
    tv = (true[0], true[1] - 1.0, true[2])
    ev = (est[0], est[1] - 1.0, est[2])
    return "/".join(f"{100 * (e - t) / abs(t):+.0f} %" if t else "-"
                    for e, t in zip(ev, tv, strict=True))


def _z(b: object, true: tuple[float, float, float]) -> list[float]:
    """Each component's error in reported σ."""
    e = (b.range_offset - true[0], b.range_gain - true[1], b.azimuth_deg - true[2])  # type: ignore[attr-defined]
    return [float(x / s) if s > 0 else float("nan")
            for x, s in zip(e, b.sigma, strict=True)]  # type: ignore[attr-defined]


def main(draws: list[int], quick: bool = False) -> None:
    """``quick``: without the unbiased run with estimation."""
    zs: list[float] = []
    for k in draws:
        ref, biases = draw(k)
        flags = [a for sid, (r, g, az) in sorted(biases.items()) if sid != ref
                 for a in ("--bias", f"{sid}:range={r},gain={g},azimuth={az}")]
        print(f"draw {k} (seed {k}, reference radar {ref}): {' '.join(flags)}")
        with tempfile.TemporaryDirectory() as tmp:
            t = Path(tmp)
            for name, extra in (("clean", []), ("biased", flags)):
                _cli(["simulate", "opensky-radars", "--seed", str(k), "--no-attributes",
                      "--out", str(t / name), *extra])
            rows = []
            for label, data, est in (("unbiased", "clean", False),
                                     ("unbiased, estimated", "clean", True),
                                     ("biased", "biased", False),
                                     ("biased, estimated", "biased", True)):
                if quick and label == "unbiased, estimated":
                    rows.append((label, np.nan, np.nan, np.nan, None))
                    continue
                d, out = t / data, t / f"{label.replace(', ', '_')}.csv"
                if est:
                    hist = _estimated(d, ref, out)
                else:
                    _cli(["track", str(d / "plots.csv"), "--sensors", str(d / "sensors.toml"),
                          "--out", str(out)])
                    hist = None
                rows.append((label, *_evaluate(out, d / "truth.csv"), hist))
            base_ospa, base_ids = rows[0][1], rows[0][3]
            for label, ospa, cov, ids, _ in rows:
                print(f"  {label:20s} OSPA {ospa:7.1f} m ({100 * (ospa / base_ospa - 1):+5.1f} %)"
                      f"  coverage {cov:.4f}  ids/aircraft {ids:.3f} "
                      f"({100 * (ids / base_ids - 1):+5.1f} %)")
            for label, hist in (("unbiased", rows[1][4]), ("biased", rows[3][4])):
                if hist is None:
                    continue
                t_at, at = next(((tt, b) for tt, b in hist if tt >= AT_S), hist[-1])
                t_end, end = hist[-1]
                for sid in sorted(end):
                    true = (0.0, 1.0, 0.0) if label == "unbiased" else biases[sid]
                    for when, b, until in ((f"{AT_S:.0f} s", at[sid], t_at),
                                           ("end", end[sid], t_end)):
                        crb = known_path_bound(t / ("clean", "biased")[label == "biased"],
                                               sid, until)
                        print(f"  {label:8s} known-path bound radar {sid} at {when:6s}: σ range "
                              f"{crb[0]:.1f} m, gain {crb[1]:.5f}, azimuth {crb[2]:.4f}°; "
                              f"20 % of the true bias in bound σ "
                              f"{_in_bound(true, crb)}")
                        e = (b.range_offset, b.range_gain, b.azimuth_deg)
                        z = _z(b, true)
                        if label == "biased":
                            zs.extend(z)
                        print(f"  {label:8s} radar {sid} at {when:6s}: range "
                              f"{e[0]:+7.1f} ± {b.sigma[0]:4.1f} m (true {true[0]:+.1f}), gain "
                              f"{e[1]:.5f} ± {b.sigma[1]:.5f} (true {true[1]:.5f}), azimuth "
                              f"{e[2]:+.4f} ± {b.sigma[2]:.4f}° (true {true[2]:+.3f})"
                              f"  relative errors {_relative(e, true)}"
                              f"  within 20 %: {'yes' if _within(e, true) else 'NO'}"
                              f"  error/σ {'/'.join(f'{x:+.1f}' for x in z)}")
    z = np.abs(np.array(zs))
    print(f"biased runs, every component at {AT_S:.0f} s and at the end: {np.mean(z < 2):.0%} "
          f"within 2σ, {np.mean(z < 3):.0%} within 3σ, mean (error/σ)² {np.mean(z**2):.2f} "
          f"({len(z)} components)")


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--quick"]
    main([int(s) for s in args] or [1, 2, 3], quick="--quick" in sys.argv)
