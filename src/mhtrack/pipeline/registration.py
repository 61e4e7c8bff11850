"""Online registration of a run's radars (``track --estimate-bias``, ``docs/registration.md``).

Each frame's plots of an estimated radar are corrected with the current bias estimate
before the tracker sees them (measured ``(r_m, θ_m)`` recovered exactly from the plot's
position by :func:`~mhtrack.models.geodesy.local_to_polar`, corrected by
:meth:`~mhtrack.models.registration.RadarBias.correct`, placed again with its covariance
by :func:`~mhtrack.models.geodesy.polar_to_local`). After the step, every confirmed
track updated by a plot of one sensor is paired with the last plot another sensor gave
that track within :attr:`Registration.max_dt` seconds; the pair's difference, the times
bridged by the track's velocity, updates the estimator
(:class:`~mhtrack.models.registration.BiasEstimator`). A radar's estimate corrects all
its plots once it has settled (:data:`APPLY_SIGMA`); before that, only the plots where
the correction is already known better than the plot itself (:data:`APPLY_POS_SIGMA`:
where the first pairs were, the correction's σ is small even while the components trade
against each other elsewhere). Each pair updates the estimator in the cluster of its
track (the cluster-robust σ).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from mhtrack.models.geodesy import local_to_polar, polar_to_local
from mhtrack.models.radars import SensorSet
from mhtrack.models.registration import BiasEstimator, RadarBias, correction_jacobian
from mhtrack.records import Scan, TrackTable

#: Longest time between the two plots of a pair (s, ours): a 4 s radar gives every plot
#: of the others a partner; the velocity bridges at most this.
MAX_PAIR_DT = 5.0
#: σ of the track velocity (m/s) and of an unmodelled acceleration (m/s²) bridging the
#: two plots' times (ours): ``C += (dt² σ_v² + (σ_a dt²/2)²) I``.
SIGMA_V, SIGMA_A = 5.0, 2.0
#: Interval of :attr:`Registration.history` snapshots (s of plot time).
SNAPSHOT_S = 10.0
#: A radar's estimate corrects its plots once every σ is below these (range offset m,
#: gain, azimuth °; ours): the first few pairs, under the wide prior, can swing the
#: estimate by 0.4° (opensky-radars seed 3, first 20 s), and plots moved by such a swing
#: break tracks. Until then its plots go to the tracker as measured.
APPLY_SIGMA = (20.0, 2e-4, 0.02)
#: Before that, a plot is corrected where the correction is known: the σ of the
#: correction's position (:meth:`Registration._position_sigma`) below this fraction of
#: the plot's own σ (the larger axis of its covariance; ours).
APPLY_POS_SIGMA = 1.0


@dataclass
class _Plot:
    """A sensor's last plot on a track: time, measured range/azimuth (estimated radars)
    or position and covariance (references)."""

    t: float
    sensor: int
    r: float = np.nan
    b: float = np.nan
    z: np.ndarray | None = None
    R: np.ndarray | None = None


def estimable(sensors: SensorSet, reference: int | None = None
              ) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """``(estimated, references)`` among ``sensors``: ADS-B and Cartesian sensors are
    references; of the polar radars with a site, ``reference`` (default: ADS-B if any,
    else the lowest id) is one too and the others are estimated."""
    polar = sorted(s.id for s in sensors.sensors if s.kind == "polar" and s.has_site)
    others = tuple(s.id for s in sensors.sensors if s.kind != "polar")
    if reference is not None and reference not in sensors.ids:
        raise ValueError(f"bias reference {reference}: no such sensor (sensors: "
                         f"{', '.join(str(i) for i in sensors.ids)})")
    if reference is None and not any(sensors.sensor(i).kind == "adsb" for i in others):
        reference = polar[0] if polar else None
    ref = tuple(i for i in polar if i == reference)
    return tuple(i for i in polar if i != reference), others + ref


class Registration:
    """Bias correction and estimation over a run (module docstring)."""

    def __init__(self, sensors: SensorSet, *, reference: int | None = None,
                 prior: Mapping[int, RadarBias] | None = None,
                 max_dt: float = MAX_PAIR_DT) -> None:
        self.sensors = sensors
        self.frame = sensors.frame()
        estimated, self.references = estimable(sensors, reference)
        self.estimator = BiasEstimator(estimated, prior=prior)
        self.max_dt = float(max_dt)
        self._site = {i: sensors.site_latlon(i) for i in estimated}
        self._last: dict[int, dict[int, _Plot]] = {}
        self._raw: dict[int, tuple[float, float]] = {}
        #: Radar id → plot time from which its estimate corrects its plots (None: from
        #: the start, a prior already within :data:`APPLY_SIGMA`).
        self.settled: dict[int, float | None] = {}
        for sid in estimated:
            self._settle(sid, None)
        self.pairs = 0
        #: ``(t, {id: RadarBias})`` every :data:`SNAPSHOT_S` seconds of plot time (the
        #: estimate's history: convergence, ``docs/registration.md``).
        self.history: list[tuple[float, dict[int, RadarBias]]] = []

    def applied(self, sid: int) -> RadarBias:
        """The bias that corrects radar ``sid``'s plots for the tracker: the estimate once
        its σ are all below :data:`APPLY_SIGMA` (and from then on), else none."""
        self._settle(sid, None)
        return self.estimator.bias(sid, model=True) if sid in self.settled else RadarBias()

    def _settle(self, sid: int, t: float | None) -> None:
        """Mark radar ``sid`` settled (at time ``t``) once its σ are below the bounds."""
        if sid not in self.settled and all(
                s < a for s, a in zip(self.estimator.bias(sid, model=True).sigma, APPLY_SIGMA,
                                      strict=True)):
            self.settled[sid] = t

    def _position_sigma(self, sid: int, H: np.ndarray) -> np.ndarray:
        """σ (m, the larger axis) of the correction's position at each plot of radar
        ``sid`` (``H`` (n, 2, 3)): ``√λmax(H P_ii Hᵀ)``, ``P_ii`` the model covariance of
        its bias."""
        k = self.estimator._slot[sid]
        S = H @ self.estimator.P[k:k + 3, k:k + 3] @ np.swapaxes(H, 1, 2)
        return np.sqrt(np.linalg.eigvalsh(S)[:, -1])

    def _place(self, sid: int, r: np.ndarray, b: np.ndarray, bias: RadarBias | None = None
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Measured ``(r, b)`` of radar ``sid`` corrected by ``bias`` (default: the
        current estimate): ``z`` (n, 2), ``R`` (n, 2, 2) and the correction Jacobian
        ``H`` (n, 2, 3)."""
        s = self.sensors.sensor(sid)
        bias = self.estimator.bias(sid, model=True) if bias is None else bias
        rc, bc = bias.correct(r, b)
        z, R = polar_to_local(self.frame, *self._site[sid], rc, bc, s.sigma_range,
                              s.sigma_bearing_deg)
        return z.reshape(-1, 2), R.reshape(-1, 2, 2), correction_jacobian(rc, bc,
                                                                           bias.range_gain)

    def correct(self, scan: Scan) -> Scan:
        """``scan`` with the plots of estimated radars corrected (their measured range and
        azimuth kept for :meth:`learn`)."""
        self._raw = {}
        if len(scan) == 0:
            return scan
        z = np.array(scan.z, float)
        R = None if scan.R is None else np.array(scan.R, float)
        for sid in np.unique(scan.sensor).tolist():
            if not self.estimator.estimates(sid):
                continue
            idx = np.flatnonzero(scan.sensor == sid)
            r, b = local_to_polar(self.frame, *self._site[sid], z[idx, 0], z[idx, 1])
            r, b = np.atleast_1d(r), np.atleast_1d(b)
            zc, Rc, _ = self._place(sid, r, b, self.applied(sid))
            if sid not in self.settled and APPLY_POS_SIGMA > 0:
                ze, Re, He = self._place(sid, r, b)
                own = np.sqrt(np.linalg.eigvalsh(Re)[:, -1])
                known = self._position_sigma(sid, He) < APPLY_POS_SIGMA * own
                zc[known], Rc[known] = ze[known], Re[known]
            z[idx] = zc
            if R is None:
                R = np.zeros((len(scan), 2, 2))
            R[idx] = Rc
            self._raw.update({int(scan.rows[i]): (float(ri), float(bi))
                              for i, ri, bi in zip(idx, r, b, strict=True)})
        return dataclasses.replace(scan, z=z, R=R)

    def learn(self, scan: Scan, online: TrackTable) -> int:
        """Pair each confirmed track's plot at this frame (``scan`` as corrected by
        :meth:`correct`) with other sensors' recent plots on that track and update the
        estimator; returns the number of pairs used."""
        where = {int(r): i for i, r in enumerate(scan.rows.tolist())}
        times = scan.plot_times()
        pairs = []
        for k in np.flatnonzero(online.plot >= 0).tolist():
            i = where.get(int(online.plot[k]))
            if i is None:
                continue
            sid, t = int(scan.sensor[i]), float(times[i])
            if self.estimator.estimates(sid):
                r, b = self._raw[int(scan.rows[i])]
                new = _Plot(t, sid, r=r, b=b)
            else:
                new = _Plot(t, sid, z=np.array(scan.z[i], float),
                            R=None if scan.R is None else np.array(scan.R[i], float))
            last = self._last.setdefault(int(online.track_id[k]), {})
            v = np.array((online.vx[k], online.vy[k]), float)
            for other in last.values():
                if other.sensor != sid and abs(t - other.t) <= self.max_dt:
                    pairs.append((new, other, v, int(online.track_id[k])))
            last[sid] = new
        used = self._update(pairs)
        if len(times):
            now = float(times.max())
            for sid in self.estimator.ids:
                self._settle(sid, now)
            self.estimator.close_clusters(now)
            if not self.history or now >= self.history[-1][0] + SNAPSHOT_S:
                self.history.append((now, self.biases()))
        if len(self._last) > 4096:  # forget tracks with no recent plot
            now = float(times.max()) if len(times) else 0.0
            self._last = {tid: d for tid, d in self._last.items()
                          if max(p.t for p in d.values()) >= now - self.max_dt}
        return used

    def _state(self, p: _Plot) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Position, covariance and correction Jacobian of a stored plot now."""
        if p.z is not None:
            R = np.zeros((2, 2)) if p.R is None else p.R
            return p.z, R, np.zeros((2, 3))
        z, R, H = self._place(p.sensor, np.array([p.r]), np.array([p.b]))
        return z[0], R[0], H[0]

    def _update(self, pairs: list[tuple[_Plot, _Plot, np.ndarray, int]]) -> int:
        used = 0
        for new, other, v, tid in pairs:
            zi, Ri, Hi = self._state(new)
            zj, Rj, Hj = self._state(other)
            dt = new.t - other.t
            y = zi - zj - v * dt
            C = Ri + Rj + np.eye(2) * (dt**2 * SIGMA_V**2 + (SIGMA_A * dt**2 / 2) ** 2)
            used += self.estimator.update(new.sensor, Hi, other.sensor, Hj, y, C, new.t,
                                          cluster=tid)
        self.pairs += used
        return used

    def _since(self, sid: int) -> str:
        if sid not in self.settled:
            return "never applied: σ above the bounds"
        t = self.settled[sid]
        return "applied from the start" if t is None else f"applied from t = {t:.0f} s"

    def biases(self) -> dict[int, RadarBias]:
        """The estimated radars' current biases."""
        return self.estimator.biases()

    def describe(self) -> list[str]:
        """One line per estimated radar: its bias ± σ and the pairs it was in."""
        refs = ", ".join(str(i) for i in self.references) or "none"
        lines = [f"registration bias (reference sensors: {refs}; {self.pairs} plot pairs "
                 f"used, {self.estimator.rejected} gated out):"]
        for sid, b in self.biases().items():
            s = b.sigma
            lines.append(f"  radar {sid}: range offset {b.range_offset:+.1f} ± {s[0]:.1f} m, "
                         f"gain {b.range_gain:.5f} ± {s[1]:.5f}, azimuth "
                         f"{b.azimuth_deg:+.4f} ± {s[2]:.4f}° "
                         f"({self.estimator.used[sid]} pairs; {self._since(sid)})")
        return lines
