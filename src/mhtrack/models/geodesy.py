"""WGS-84 geodesy for real radar data: the tracker's local east-north plane, and a site's
polar plots (range, bearing) converted into it with their covariances.

Every conversion goes through pyproj (PROJ ≥ 9), whose ellipsoidal geodesics are
GeographicLib's (C. F. F. Karney, "Algorithms for geodesics", *J. Geodesy* 87, 2013;
accurate to about 15 nm). Nothing here is a hand-written approximation of the ellipsoid.

**Local frame.** The azimuthal equidistant projection about the origin ``(φ0, λ0)``
(``+proj=aeqd +lat_0=φ0 +lon_0=λ0 +ellps=WGS84``; PROJ computes it with the geodesic
inverse problem from the origin). A point at geodesic distance ``s`` and azimuth ``α1``
from the origin goes to::

    x = s sin α1   (east),   y = s cos α1   (north),   metres

so distances and azimuths *from the origin* are exact. Elsewhere the plane is not
conformal: grid north differs from true north by the meridian convergence ``γ``
(about ``Δλ sin φ``: 1.9° at 200 km east of 46.8° N), and lengths across the line to the
origin are stretched by ``s / m12`` (``m12`` the reduced length; ``1 + s²/6R²``, i.e.
2.6·10⁻⁴ at 250 km).

**Jacobians by central differences through the same pyproj calls.** A velocity (east,
north at its point) and a polar plot's covariance need the derivative of the whole chain
(geodesic direct problem, then the projection), convergence *and* scale included. pyproj
exposes neither the reduced length ``m12`` nor exact projection derivatives
(``Proj.get_factors`` differentiates numerically too, and gives only ``γ`` and scales, not
the full non-conformal 2×2 matrix), so the Jacobian is taken by central differences of
the very functions that give the position::

    ∂f/∂u ≈ (f(u + δ) − f(u − δ)) / 2δ,   error ≈ δ² f''' / 6  +  ε / δ

With steps of :data:`STEP_M` = 10 m and :data:`STEP_RAD` = 10⁻⁴ rad the truncation term is
below 10⁻⁹ relative (``f''' / f' ~ 1/R²`` along the ground, ``~1`` per rad² in bearing)
and the rounding term ``ε/δ`` (``ε`` ≈ 15 nm) below 10⁻⁸ relative at 200 km; the tests
compare with GeographicLib's exact ``azi2`` and ``m12`` to 10⁻⁶.

The covariance is the linearised ``R = J diag(σr², σθ²) Jᵀ`` (``θ`` in radians); the
neglected second-order terms are ``r σθ² / 2`` in range (0.7 m at 200 km with σθ = 0.15°),
far below ``σr``.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
import pyproj

from mhtrack.models.linalg2 import inv2

#: The WGS-84 ellipsoid's geodesics (GeographicLib inside PROJ).
WGS84 = pyproj.Geod(ellps="WGS84")
#: Central-difference step along the ground (m) for Jacobians in east/north and range.
STEP_M = 10.0
#: Central-difference step in bearing (radians, 0.0057°).
STEP_RAD = 1e-4
#: Smallest ratio of a polar plot's cross-range and range variances (either way round):
#: a condition number of at most 10¹², so that the 2×2 determinant, ``Rxx Ryy − Rxy²``
#: computed with relative rounding 10⁻¹⁶, stays positive.
MIN_VARIANCE_RATIO = 1e-12

ArrayLike = Any  # float, sequence or np.ndarray


def _flat(*arrays: ArrayLike) -> tuple[tuple[int, ...], list[np.ndarray]]:
    """Broadcast the arguments together; their common shape and 1-D float copies."""
    b = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in arrays))
    return b[0].shape, [np.ascontiguousarray(a, dtype=float).ravel() for a in b]


def direct(
    lat: ArrayLike, lon: ArrayLike, azimuth_deg: ArrayLike, distance: ArrayLike
) -> tuple[np.ndarray, np.ndarray]:
    """Geodesic direct problem on WGS-84: ``(lat, lon)`` reached from ``(lat, lon)`` going
    ``distance`` metres (negative: backwards) at ``azimuth_deg`` (clockwise from north)."""
    shape, (la, lo, az, d) = _flat(lat, lon, azimuth_deg, distance)
    lo2, la2, _ = WGS84.fwd(lo, la, az, d)
    return np.reshape(la2, shape), np.reshape(lo2, shape)


def inverse(
    lat1: ArrayLike, lon1: ArrayLike, lat2: ArrayLike, lon2: ArrayLike
) -> tuple[np.ndarray, np.ndarray]:
    """Geodesic inverse problem on WGS-84: distance (m) from point 1 to point 2 and the
    azimuth at point 1 (degrees clockwise from north, in ``[0, 360)``)."""
    shape, (la1, lo1, la2, lo2) = _flat(lat1, lon1, lat2, lon2)
    az, _, d = WGS84.inv(lo1, la1, lo2, la2)
    return np.reshape(d, shape), np.reshape(np.mod(az, 360.0), shape)


@dataclass(frozen=True)
class LocalFrame:
    """The tracker's local east-north plane: azimuthal equidistant about ``(lat0, lon0)``
    (WGS-84 degrees); ``x`` east, ``y`` north, metres (see the module docstring)."""

    lat0: float
    lon0: float

    def __post_init__(self) -> None:
        lat0, lon0 = float(self.lat0), float(self.lon0)
        if not (np.isfinite(lat0) and -90.0 <= lat0 <= 90.0):
            raise ValueError(f"origin: latitude must be within [-90, 90] degrees, got {lat0:g}")
        if not (np.isfinite(lon0) and -180.0 <= lon0 <= 180.0):
            raise ValueError(f"origin: longitude must be within [-180, 180] degrees, "
                             f"got {lon0:g}")
        object.__setattr__(self, "lat0", lat0)
        object.__setattr__(self, "lon0", lon0)

    @cached_property
    def _proj(self) -> pyproj.Proj:
        return pyproj.Proj(proj="aeqd", lat_0=self.lat0, lon_0=self.lon0, ellps="WGS84")

    def __getstate__(self) -> dict[str, float]:
        """Pickle the origin only; the PROJ object is rebuilt on first use."""
        return {"lat0": self.lat0, "lon0": self.lon0}

    def to_local(self, lat: ArrayLike, lon: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """``(x, y)`` in metres of WGS-84 ``(lat, lon)`` in degrees."""
        shape, (la, lo) = _flat(lat, lon)
        x, y = self._proj(lo, la)
        return np.reshape(x, shape), np.reshape(y, shape)

    def to_geodetic(self, x: ArrayLike, y: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """WGS-84 ``(lat, lon)`` in degrees of local ``(x, y)`` in metres."""
        shape, (xx, yy) = _flat(x, y)
        lo, la = self._proj(xx, yy, inverse=True)
        return np.reshape(la, shape), np.reshape(lo, shape)

    def jacobian(self, lat: ArrayLike, lon: ArrayLike) -> np.ndarray:
        """``J = ∂(x, y)/∂(e, n)`` (…, 2, 2) at each point: how a small displacement east
        ``e`` and north ``n`` (metres, along the ground at the point) moves in the plane.
        Columns by central differences of ±:data:`STEP_M` along the geodesics of azimuth
        90° and 0° (meridian convergence and the transverse scale ``s/m12`` included)."""
        shape, (la, lo) = _flat(lat, lon)
        n = la.size
        az = np.repeat([90.0, 270.0, 0.0, 180.0], n)
        la4, lo4 = direct(np.tile(la, 4), np.tile(lo, 4), az, STEP_M)
        x, y = self.to_local(la4, lo4)
        p = np.stack((x, y), axis=-1).reshape(4, n, 2)
        J = np.stack(((p[0] - p[1]), (p[2] - p[3])), axis=-1) / (2 * STEP_M)
        return J.reshape((*shape, 2, 2))

    def velocity_to_local(
        self, lat: ArrayLike, lon: ArrayLike, ve: ArrayLike, vn: ArrayLike
    ) -> tuple[np.ndarray, np.ndarray]:
        """Grid velocity ``(vx, vy) = J (ve, vn)`` of a velocity east/north (m/s) at
        ``(lat, lon)``, ``J`` from :meth:`jacobian`."""
        shape, (la, lo, e, nn) = _flat(lat, lon, ve, vn)
        J = self.jacobian(la, lo)
        vx = J[:, 0, 0] * e + J[:, 0, 1] * nn
        vy = J[:, 1, 0] * e + J[:, 1, 1] * nn
        return np.reshape(vx, shape), np.reshape(vy, shape)

    def velocity_to_geodetic(
        self, x: ArrayLike, y: ArrayLike, vx: ArrayLike, vy: ArrayLike
    ) -> tuple[np.ndarray, np.ndarray]:
        """Velocity east/north (m/s) at the point ``(x, y)`` of a grid velocity
        ``(vx, vy)``: ``(ve, vn) = J⁻¹ (vx, vy)``, the inverse of :meth:`velocity_to_local`."""
        shape, (xx, yy, u, v) = _flat(x, y, vx, vy)
        Ji = inv2(self.jacobian(*self.to_geodetic(xx, yy)))
        ve = Ji[:, 0, 0] * u + Ji[:, 0, 1] * v
        vn = Ji[:, 1, 0] * u + Ji[:, 1, 1] * v
        return np.reshape(ve, shape), np.reshape(vn, shape)


def polar_to_local(
    frame: LocalFrame,
    site_lat: float,
    site_lon: float,
    range_m: ArrayLike,
    bearing_deg: ArrayLike,
    sigma_range: ArrayLike,
    sigma_bearing_deg: ArrayLike,
) -> tuple[np.ndarray, np.ndarray]:
    """A site's polar plots in the local frame: positions ``z`` (n, 2) and covariances
    ``R`` (n, 2, 2).

    ``range_m`` is the geodesic ground distance from the site (m), ``bearing_deg`` the
    geodesic azimuth at the site (degrees clockwise from true north). The position is
    the geodesic direct problem from the site, then :meth:`LocalFrame.to_local`;
    ``R = J diag(σr², σθ²) Jᵀ`` with ``J = ∂(x, y)/∂(r, θ)`` of that whole chain by
    central differences (±:data:`STEP_M` in range, ±:data:`STEP_RAD` in bearing), so the
    turn of the geodesic and the meridian convergence are in ``R``. Sigmas are scalars or
    one per plot.

    **Near the site** the bearing term vanishes with ``r`` (``|∂(x, y)/∂θ| = r``), and at
    ``r = 0`` ``R`` would be singular. A plot cannot be placed nearer its site than its
    range error, so the bearing column is taken at the minimum range
    ``r_min = max(σr, STEP_M)`` (``STEP_M`` = 10 m keeps the bearing difference's chord,
    2 mm, far above the positions' rounding): within ``r_min`` of the site the
    cross-range error is ``r_min σθ``. Beyond ``r_min`` nothing changes.
    **Conditioning:** the cross-range variance ``vθ = σθ² |∂(x, y)/∂θ|²`` and the range
    one ``vr = σr² |∂(x, y)/∂r|²`` are each kept at least :data:`MIN_VARIANCE_RATIO` of
    the other, so ``det R`` stays positive in float64 for every range and σ a sensors
    file may hold (this acts only when one error is over 10⁶ times the other, e.g.
    ``σr`` = 1 mm at 1000 km with σθ = 0.15°).
    """
    _, (r, b, sr, sb) = _flat(range_m, bearing_deg, sigma_range, sigma_bearing_deg)
    n = r.size
    db = np.degrees(STEP_RAD)
    rb = np.maximum(r, np.maximum(sr, STEP_M))  # the bearing column at r_min at least
    rr = np.concatenate((r, r + STEP_M, r - STEP_M, rb, rb))
    bb = np.concatenate((b, b, b, b + db, b - db))
    la, lo = direct(site_lat, site_lon, bb, rr)
    x, y = frame.to_local(la, lo)
    p = np.stack((x, y), axis=-1).reshape(5, n, 2)
    z = p[0]
    jr = (p[1] - p[2]) / (2 * STEP_M)  # ∂(x, y)/∂r
    jt = (p[3] - p[4]) / (2 * STEP_RAD)  # ∂(x, y)/∂θ, θ in radians
    vr = sr**2
    vt = np.radians(sb) ** 2
    lr = vr * (jr**2).sum(axis=1)  # the two principal variances (jr ⟂ jt)
    lt = vt * (jt**2).sum(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        vr = np.where(lr < MIN_VARIANCE_RATIO * lt, vr * (MIN_VARIANCE_RATIO * lt / lr), vr)
        vt = np.where(lt < MIN_VARIANCE_RATIO * lr, vt * (MIN_VARIANCE_RATIO * lr / lt), vt)
    R = np.empty((n, 2, 2))
    R[:, 0, 0] = vr * jr[:, 0] ** 2 + vt * jt[:, 0] ** 2
    R[:, 1, 1] = vr * jr[:, 1] ** 2 + vt * jt[:, 1] ** 2
    R[:, 0, 1] = R[:, 1, 0] = vr * jr[:, 0] * jr[:, 1] + vt * jt[:, 0] * jt[:, 1]
    return z, R


def local_to_polar(
    frame: LocalFrame, site_lat: float, site_lon: float, x: ArrayLike, y: ArrayLike
) -> tuple[np.ndarray, np.ndarray]:
    """Exact ``(range m, bearing deg in [0, 360))`` from a site of local points ``(x, y)``:
    :meth:`LocalFrame.to_geodetic`, then the geodesic inverse problem from the site."""
    lat, lon = frame.to_geodetic(x, y)
    return inverse(site_lat, site_lon, lat, lon)
