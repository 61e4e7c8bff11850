"""Registration bias of radars: range offset, range gain and azimuth offset per radar,
estimated online from targets that several sensors see (``docs/registration.md``).

**Bias model** (the range/azimuth offset model of radar registration: Fischer, Muehe &
Cameron, MIT Lincoln Laboratory, 1980; Dana, "Registration: a prerequisite for multiple
sensor tracking", in Bar-Shalom (ed.), *Multitarget-Multisensor Tracking: Advanced
Applications*, 1990; Okello & Ristic, IEEE TAES 39(3), 2003, add the range gain). Radar
``i`` reports a target at geodesic range ``r`` and azimuth ``θ`` as::

    r_m = g_i r + Δr_i + n_r,        θ_m = θ + Δθ_i + n_θ

so a plot is corrected by ``r = (r_m − Δr_i) / g_i``, ``θ = θ_m − Δθ_i``
(:meth:`RadarBias.correct`). The state of radar ``i`` is ``b_i = (Δr_i, ε_i = g_i − 1,
Δθ_i)`` (m, 1, radians).

**Measurement** (linearised least squares on common-target plot differences, as in the
references above). Two plots of one target, ``p_i`` by radar ``i`` at ``t_i`` and
``p_j`` by radar ``j`` at ``t_j``, each corrected with the current estimates ``b̂`` and
placed in the local frame, give, with the target's velocity ``v`` bridging the times::

    y = p_i(b̂_i) − p_j(b̂_j) − v (t_i − t_j) ≈ H_i (b̂_i − b_i) − H_j (b̂_j − b_j) + e

with ``H = ∂p/∂b̂`` of the correction (:func:`correction_jacobian`: ``−u_r / g``,
``−u_r r / g``, ``−r u_θ`` for ``u_r``, ``u_θ`` the unit vectors along range and
azimuth) and ``e ~ N(0, C)``, ``C = R_i + R_j +`` the velocity's share. Each ``y``
updates the stacked state by one Kalman step of a static state (recursive least
squares; Bar-Shalom, Li & Kirubarajan 2001, §5.2, the "information" of each pair adding
``Gᵀ C⁻¹ G``). A pair whose normalised innovation exceeds the χ² gate (2 degrees of
freedom) is not used (a wrong association).

**Honest uncertainty.** The pairs of one aircraft are not independent: one plot enters
several pairs, and the track velocity that bridges their times has an error correlated
from scan to scan. The Kalman ``P`` treats every pair as independent and is optimistic
(errors of 3.5 σ on opensky-radars). The σ reported is therefore the cluster-robust
("sandwich") covariance of the least-squares estimate with one cluster per aircraft
track (Liang & Zeger, Biometrika 73, 1986; White, Econometrica 48, 1980)::

    P_r = P (P0⁻¹ + Σ_g s_g s_gᵀ) P,    s_g = Σ_{k ∈ g} G_kᵀ C_k⁻¹ r_k(b̂)

with ``r_k(b̂) = y_k − G_k b̂_k + G_k b̂`` the pair's residual at the current estimate
(linearised). Errors shared within an aircraft's pairs count once per aircraft, not once
per pair; with independent pairs and the right ``C``, ``E[P_r] = P``.

**Gauge.** Differences only see the biases relative to each other: the biases of the
*reference* sensors are held at zero (ADS-B, Cartesian sensors and one chosen radar), so
the estimates are those of every other radar against them.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.stats import chi2

#: Prior σ of each bias component (ours, wider than the biases of civil radars, 100–200 m
#: and 0.1–0.2°, issue 29): range offset (m), gain − 1, azimuth offset (degrees).
PRIOR_SIGMA = (500.0, 0.01, 0.5)
#: The χ² gate on a pair's normalised innovation (2 degrees of freedom, P = 0.999).
GATE_P = 0.999
#: The cluster-robust covariance (:meth:`BiasEstimator.covariance`) is reported once this
#: many clusters (aircraft tracks) gave pairs (ours: the sandwich is biased low and noisy
#: with few clusters; until then the model covariance ``P``).
MIN_CLUSTERS = 20
#: A cluster with no pair for this long (s of plot time) is closed: its score is fixed at
#: the estimate then (ours; bounds the memory of a long run).
CLUSTER_CLOSE_S = 60.0


@dataclass(frozen=True)
class RadarBias:
    """One radar's registration bias: ``range_offset`` (m), ``range_gain`` (1: none),
    ``azimuth_deg`` (degrees clockwise); ``sigma`` their standard deviations when
    estimated (same units, gain σ as σ of ``g``)."""

    range_offset: float = 0.0
    range_gain: float = 1.0
    azimuth_deg: float = 0.0
    sigma: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def correct(self, range_m: np.ndarray, bearing_deg: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
        """Measured → corrected: ``r = (r_m − Δr) / g``, ``θ = θ_m − Δθ`` (mod 360)."""
        r = (np.asarray(range_m, float) - self.range_offset) / self.range_gain
        return np.abs(r), np.mod(np.asarray(bearing_deg, float) - self.azimuth_deg, 360.0)

    def as_dict(self) -> dict[str, Any]:
        """``range_offset``, ``range_gain``, ``azimuth_deg`` and their ``sigma_*``."""
        return {"range_offset": self.range_offset, "range_gain": self.range_gain,
                "azimuth_deg": self.azimuth_deg, "sigma_range_offset": self.sigma[0],
                "sigma_range_gain": self.sigma[1], "sigma_azimuth_deg": self.sigma[2]}


def correction_jacobian(range_m: np.ndarray, bearing_deg: np.ndarray,
                        gain: float | np.ndarray = 1.0) -> np.ndarray:
    """``H = ∂p/∂(Δr, ε, Δθ)`` (n, 2, 3) of the corrected position ``p = s + r u(θ)``,
    ``u = (sin θ, cos θ)`` (east, north; ``θ`` clockwise from north), at the corrected
    range ``r`` and azimuth ``θ``: ``∂r/∂Δr = −1/g``, ``∂r/∂ε = −r/g``, ``∂θ/∂Δθ = −1``
    (radians), ``∂p/∂r = u``, ``∂p/∂θ = r (cos θ, −sin θ)``. Flat-plane directions: the
    residual itself is computed on the ellipsoid, so this only sets the step."""
    r = np.asarray(range_m, float)
    th = np.radians(np.asarray(bearing_deg, float))
    ur = np.stack((np.sin(th), np.cos(th)), axis=-1)
    ut = np.stack((np.cos(th), -np.sin(th)), axis=-1)
    g = np.asarray(gain, float)
    return np.stack((-ur / g[..., None] if g.ndim else -ur / g,
                     -ur * (r / g)[..., None], -ut * r[..., None]), axis=-1)


class BiasEstimator:
    """Kalman (recursive least-squares) estimate of the biases of ``estimated`` radars
    against the reference sensors (module docstring). ``prior``: an earlier run's
    estimates (``{id: RadarBias}``, their σ as prior σ; none: zero bias with
    :data:`PRIOR_SIGMA`); ``process_sigma``: random-walk σ per second of the three
    components (default none: static biases)."""

    def __init__(self, estimated: Sequence[int], *,
                 prior: Mapping[int, RadarBias] | None = None,
                 process_sigma: tuple[float, float, float] = (0.0, 0.0, 0.0),
                 gate_p: float = GATE_P) -> None:
        self.ids = tuple(int(i) for i in estimated)
        if len(set(self.ids)) != len(self.ids):
            raise ValueError(f"estimated radars repeated: {self.ids}")
        self._slot = {sid: 3 * k for k, sid in enumerate(self.ids)}
        n = 3 * len(self.ids)
        self.b = np.zeros(n)
        sig = np.tile([PRIOR_SIGMA[0], PRIOR_SIGMA[1], np.radians(PRIOR_SIGMA[2])],
                      len(self.ids))
        for sid, pb in (prior or {}).items():
            if sid in self._slot:
                k = self._slot[sid]
                self.b[k:k + 3] = (pb.range_offset, pb.range_gain - 1.0,
                                   np.radians(pb.azimuth_deg))
                if all(s > 0 for s in pb.sigma):
                    sig[k:k + 3] = (pb.sigma[0], pb.sigma[1], np.radians(pb.sigma[2]))
        self.P = np.diag(sig**2)
        #: Prior information ``P0⁻¹`` and the sandwich's meat of closed clusters.
        self.P0_inv = np.diag(1.0 / sig**2)
        self.meat = np.zeros((n, n))
        #: Open clusters: key → [Σ GᵀC⁻¹(y − G b̂_k), Σ GᵀC⁻¹G, last time].
        self.clusters: dict[int, list[Any]] = {}
        self.n_clusters = 0
        self._q = np.tile([process_sigma[0], process_sigma[1], np.radians(process_sigma[2])],
                          len(self.ids)) ** 2
        self.gate = float(chi2.ppf(gate_p, 2))
        self.t: float | None = None
        self.used = dict.fromkeys(self.ids, 0)
        self.rejected = 0

    def estimates(self, sid: int) -> bool:
        """Radar ``sid``'s bias is estimated (not a reference)."""
        return sid in self._slot

    def covariance(self) -> np.ndarray:
        """The reported covariance: the cluster-robust ``P_r`` (module docstring) once
        :data:`MIN_CLUSTERS` clusters gave pairs, else the model's ``P``."""
        if self.n_clusters < MIN_CLUSTERS:
            return self.P
        meat = self.meat + self.P0_inv
        for alpha, A, _ in self.clusters.values():
            sg = alpha + A @ self.b
            meat = meat + np.outer(sg, sg)
        Pr = self.P @ meat @ self.P
        return (Pr + Pr.T) / 2

    def close_clusters(self, t: float) -> None:
        """Close the clusters with no pair since ``t −`` :data:`CLUSTER_CLOSE_S`: their
        scores at the current estimate go into the meat."""
        for key in [k for k, c in self.clusters.items() if c[2] < t - CLUSTER_CLOSE_S]:
            alpha, A, _ = self.clusters.pop(key)
            sg = alpha + A @ self.b
            self.meat += np.outer(sg, sg)

    def bias(self, sid: int, *, model: bool = False) -> RadarBias:
        """The current estimate of radar ``sid`` (zero for a reference sensor), its σ from
        :meth:`covariance` (``model``: from the model's ``P``)."""
        k = self._slot.get(sid)
        if k is None:
            return RadarBias()
        return self._bias_at(k, self.P if model else self.covariance())

    def biases(self) -> dict[int, RadarBias]:
        """Every estimated radar's :meth:`bias` (the covariance computed once)."""
        cov = self.covariance()
        return {sid: self._bias_at(self._slot[sid], cov) for sid in self.ids}

    def _bias_at(self, k: int, cov: np.ndarray) -> RadarBias:
        """The estimate in slots ``k … k+2`` of the state, its σ from ``cov``."""
        s = np.sqrt(np.diag(cov)[k:k + 3])
        return RadarBias(float(self.b[k]), float(1.0 + self.b[k + 1]),
                         float(np.degrees(self.b[k + 2])),
                         (float(s[0]), float(s[1]), float(np.degrees(s[2]))))

    def _advance(self, t: float) -> None:
        """Random walk of the biases up to time ``t`` (nothing with no process noise)."""
        if self.t is not None and t > self.t and self._q.any():
            self.P[np.diag_indices_from(self.P)] += self._q * (t - self.t)
        self.t = t if self.t is None else max(self.t, t)

    def update(self, sid_i: int, H_i: np.ndarray, sid_j: int, H_j: np.ndarray,
               y: np.ndarray, C: np.ndarray, t: float | None = None,
               cluster: int | None = None) -> bool:
        """One pair's difference ``y`` (2,) with its noise ``C`` (2, 2) and the radars'
        correction Jacobians ``H_i``, ``H_j`` (2, 3) (module docstring); ``cluster``: the
        aircraft (track) whose errors it shares (none: a cluster of its own). Returns
        whether it passed the gate and was used."""
        if t is not None:
            self._advance(float(t))
        G = np.zeros((2, len(self.b)))
        for sid, H, sign in ((sid_i, H_i, 1.0), (sid_j, H_j, -1.0)):
            k = self._slot.get(sid)
            if k is not None:
                G[:, k:k + 3] += sign * H
        if not G.any():
            return False
        # y ≈ G (b̂ − b) + e: the innovation of δ = b − b̂ (prior 0) is y, its matrix −G
        S = G @ self.P @ G.T + C
        Si = np.linalg.inv(S)
        if float(y @ Si @ y) > self.gate:
            self.rejected += 1
            return False
        Ci = np.linalg.inv(C)
        score = (G.T @ Ci @ (y - G @ self.b), G.T @ Ci @ G)
        key = -1 - self.n_clusters if cluster is None else int(cluster)
        c = self.clusters.get(key)
        if c is None:
            self.clusters[key] = [*score, -np.inf if self.t is None else self.t]
            self.n_clusters += 1
        else:
            c[0] = c[0] + score[0]
            c[1] = c[1] + score[1]
            c[2] = -np.inf if self.t is None else self.t
        K = -self.P @ G.T @ Si
        self.b += K @ y
        IKH = np.eye(len(self.b)) + K @ G
        self.P = IKH @ self.P @ IKH.T + K @ C @ K.T  # Joseph form: P stays symmetric ≥ 0
        for sid in (sid_i, sid_j):
            if sid in self.used:
                self.used[sid] += 1
        return True

    def update_many(self, pairs: Iterable[tuple[int, np.ndarray, int, np.ndarray,
                                                np.ndarray, np.ndarray, float | None]]
                    ) -> int:
        """:meth:`update` with each pair in turn; the number used."""
        return sum(self.update(*p) for p in pairs)
