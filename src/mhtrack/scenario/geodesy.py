"""WGS-84 geodetic coordinates to a local east-north-up (ENU) frame, closed form.

With semi-major axis ``a = 6 378 137 m``, flattening ``f = 1/298.257223563``,
``e² = f(2 − f)`` and the prime-vertical radius ``N(φ) = a / sqrt(1 − e² sin²φ)``
(latitude ``φ``, longitude ``λ``, height ``h``)::

    X = (N + h) cos φ cos λ,   Y = (N + h) cos φ sin λ,   Z = (N (1 − e²) + h) sin φ

and, about a reference point ``(φ0, λ0, h0)`` with ECEF ``P0``, ``d = P − P0``::

    [e]   [      −sin λ0            cos λ0        0    ]
    [n] = [ −sin φ0 cos λ0   −sin φ0 sin λ0   cos φ0 ] d   =  M(φ0, λ0) d
    [u]   [  cos φ0 cos λ0    cos φ0 sin λ0   sin φ0 ]

(e.g. Hofmann-Wellenhof, Lichtenegger & Wasle, *GNSS*, 2008, §5.6.1 and §10.2.2).
A velocity given in the local east/north frame of its own point is carried to the
reference frame by ``M(φ0, λ0) M(φ, λ)ᵀ`` (a rotation; over a few hundred km it turns the
vector by about ``Δλ·sin φ``, a few degrees).
"""

from __future__ import annotations

import numpy as np

WGS84_A = 6_378_137.0
WGS84_F = 1 / 298.257223563
WGS84_E2 = WGS84_F * (2 - WGS84_F)


def geodetic_to_ecef(
    lat_deg: np.ndarray | float, lon_deg: np.ndarray | float, h: np.ndarray | float = 0.0
) -> np.ndarray:
    """ECEF ``(…, 3)`` in metres of WGS-84 latitude, longitude (degrees) and height (m)."""
    lat, lon = np.radians(lat_deg), np.radians(lon_deg)
    n = WGS84_A / np.sqrt(1 - WGS84_E2 * np.sin(lat) ** 2)
    return np.stack(
        np.broadcast_arrays(
            (n + h) * np.cos(lat) * np.cos(lon),
            (n + h) * np.cos(lat) * np.sin(lon),
            (n * (1 - WGS84_E2) + h) * np.sin(lat),
        ),
        axis=-1,
    )


def enu_matrix(lat_deg: np.ndarray | float, lon_deg: np.ndarray | float) -> np.ndarray:
    """``M(φ, λ)`` (…, 3, 3): rows are the east, north, up unit vectors in ECEF."""
    lat, lon = np.radians(lat_deg), np.radians(lon_deg)
    sl, cl, sp, cp = np.sin(lon), np.cos(lon), np.sin(lat), np.cos(lat)
    zero = np.zeros_like(sl)
    return np.stack(
        [
            np.stack([-sl, cl, zero], axis=-1),
            np.stack([-sp * cl, -sp * sl, cp], axis=-1),
            np.stack([cp * cl, cp * sl, sp], axis=-1),
        ],
        axis=-2,
    )


def geodetic_to_enu(
    lat_deg: np.ndarray | float,
    lon_deg: np.ndarray | float,
    lat0_deg: float,
    lon0_deg: float,
    h: np.ndarray | float = 0.0,
    h0: float = 0.0,
) -> np.ndarray:
    """ENU ``(…, 3)`` (m) of points about the reference ``(lat0, lon0, h0)``."""
    d = geodetic_to_ecef(lat_deg, lon_deg, h) - geodetic_to_ecef(lat0_deg, lon0_deg, h0)
    return d @ enu_matrix(lat0_deg, lon0_deg).T


def local_to_reference_velocity(
    v_east: np.ndarray,
    v_north: np.ndarray,
    lat_deg: np.ndarray,
    lon_deg: np.ndarray,
    lat0_deg: float,
    lon0_deg: float,
) -> np.ndarray:
    """Horizontal velocities (n, 2) given in each point's own east/north frame, expressed
    in the reference ENU frame's east/north axes: ``(M(φ0,λ0) M(φ,λ)ᵀ [ve, vn, 0])[:2]``."""
    v = np.stack(np.broadcast_arrays(v_east, v_north, np.zeros_like(v_east)), axis=-1)
    v_ecef = np.einsum("nji,nj->ni", enu_matrix(lat_deg, lon_deg), v)
    return (v_ecef @ enu_matrix(lat0_deg, lon0_deg).T)[..., :2]
