"""Clutter models: Poisson count, spatial density, intensity ``κ(z) = λ·c(z)`` (P1 eq. 3).

Each model gives, for scan ``k``, the mean clutter count ``rate(k) = λ_k``, the spatial
density ``density(z, k) = c_k(z)`` (integrating to 1 over the surveillance region) and
``intensity(z, k) = λ_k c_k(z)``, and draws one scan of clutter with ``sample``.
Gaussian-mixture clutter is truncated to the region: plots outside it are redrawn, and the
density is renormalised by the mixture's mass inside the region.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Region:
    """Axis-aligned surveillance region ``[xmin, xmax] × [ymin, ymax]`` (m)."""

    xmin: float
    xmax: float
    ymin: float
    ymax: float

    def __post_init__(self) -> None:
        vals = (self.xmin, self.xmax, self.ymin, self.ymax)
        if not all(np.isfinite(vals)) or self.xmax <= self.xmin or self.ymax <= self.ymin:
            raise ValueError(f"region must be finite with xmin < xmax, ymin < ymax, got {vals}")

    @property
    def area(self) -> float:
        return (self.xmax - self.xmin) * (self.ymax - self.ymin)

    def contains(self, z: np.ndarray) -> np.ndarray:
        z = np.asarray(z, float).reshape(-1, 2)
        return (
            (z[:, 0] >= self.xmin)
            & (z[:, 0] <= self.xmax)
            & (z[:, 1] >= self.ymin)
            & (z[:, 1] <= self.ymax)
        )

    def uniform(self, rng: np.random.Generator, n: int) -> np.ndarray:
        lo = np.array([self.xmin, self.ymin])
        hi = np.array([self.xmax, self.ymax])
        return lo + (hi - lo) * rng.random((n, 2))

    def grid(self, n: int = 100) -> tuple[np.ndarray, float]:
        """Cell centres (n², 2) of an ``n × n`` grid and the cell area (for integrals)."""
        xs = np.linspace(self.xmin, self.xmax, n + 1)
        ys = np.linspace(self.ymin, self.ymax, n + 1)
        xc, yc = 0.5 * (xs[1:] + xs[:-1]), 0.5 * (ys[1:] + ys[:-1])
        gx, gy = np.meshgrid(xc, yc)
        return np.column_stack((gx.ravel(), gy.ravel())), self.area / n**2

    def as_tuple(self) -> tuple[float, float, float, float]:
        return (self.xmin, self.xmax, self.ymin, self.ymax)


@dataclass(frozen=True)
class UniformClutter:
    """Poisson clutter, mean ``rate`` per scan, uniform over ``region``:
    ``κ(z) = λ / A`` inside the region."""

    region: Region
    rate_per_scan: float

    def __post_init__(self) -> None:
        if not (np.isfinite(self.rate_per_scan) and self.rate_per_scan >= 0):
            raise ValueError(f"clutter rate must be finite and >= 0, got {self.rate_per_scan}")

    def rate(self, scan: int) -> float:
        return float(self.rate_per_scan)

    def density(self, z: np.ndarray, scan: int) -> np.ndarray:
        return self.region.contains(z) / self.region.area

    def intensity(self, z: np.ndarray, scan: int) -> np.ndarray:
        return self.rate(scan) * self.density(z, scan)

    def sample(self, rng: np.random.Generator, scan: int) -> np.ndarray:
        return self.region.uniform(rng, int(rng.poisson(self.rate(scan))))


def _box_mass(mean: np.ndarray, cov: np.ndarray, region: Region) -> float:
    """Probability mass of ``N(mean, cov)`` inside ``region``."""
    from scipy.stats import multivariate_normal  # heavy (~0.6 s): only when a mixture is built

    lo = np.array([region.xmin, region.ymin])
    hi = np.array([region.xmax, region.ymax])
    return float(
        multivariate_normal(mean, cov, allow_singular=False).cdf(hi, lower_limit=lo)
    )


@dataclass(frozen=True)
class GaussianMixtureClutter:
    """Poisson clutter, mean ``rate_per_scan``, spatially a Gaussian mixture
    ``c(z) ∝ b/A + (1−b) Σ_j π_j N(z; μ_j, Σ_j)`` truncated to ``region``, where ``b`` is an
    optional uniform ``background`` share (P1 Table 2 uses b = 0 and four components)."""

    region: Region
    rate_per_scan: float
    weights: np.ndarray
    means: np.ndarray
    covariances: np.ndarray
    background: float = 0.0
    _mass: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        w = np.asarray(self.weights, float).ravel()
        mu = np.asarray(self.means, float).reshape(-1, 2)
        cov = np.asarray(self.covariances, float).reshape(-1, 2, 2)
        if not (len(w) == len(mu) == len(cov)) or len(w) == 0:
            raise ValueError("clutter mixture needs equally many weights, means, covariances")
        if np.any(w < 0) or not np.isfinite(w).all() or w.sum() <= 0:
            raise ValueError(f"clutter mixture weights must be >= 0 with a positive sum: {w}")
        if not (np.isfinite(mu).all() and np.isfinite(cov).all()):
            raise ValueError("clutter mixture means and covariances must be finite")
        if np.any(np.linalg.eigvalsh(0.5 * (cov + cov.transpose(0, 2, 1))) <= 0):
            raise ValueError("clutter mixture covariances must be positive definite")
        if not 0.0 <= self.background <= 1.0:
            raise ValueError(f"background share must be in [0, 1], got {self.background}")
        if not (np.isfinite(self.rate_per_scan) and self.rate_per_scan >= 0):
            raise ValueError(f"clutter rate must be finite and >= 0, got {self.rate_per_scan}")
        object.__setattr__(self, "weights", w / w.sum())
        object.__setattr__(self, "means", mu)
        object.__setattr__(self, "covariances", cov)
        mass = np.array([_box_mass(m, c, self.region) for m, c in zip(mu, cov, strict=True)])
        if self.background == 0 and float(self.weights @ mass) < 1e-12:
            raise ValueError("clutter mixture has no mass inside the region")
        object.__setattr__(self, "_mass", mass)

    def rate(self, scan: int) -> float:
        return float(self.rate_per_scan)

    def density(self, z: np.ndarray, scan: int) -> np.ndarray:
        z = np.asarray(z, float).reshape(-1, 2)
        inside = self.region.contains(z)
        from scipy.stats import multivariate_normal

        mix = np.zeros(len(z))
        for w, m, c in zip(self.weights, self.means, self.covariances, strict=True):
            mix += w * multivariate_normal(m, c).pdf(z).reshape(-1)
        b = self.background
        in_mass = float(self.weights @ self._mass)
        mix_part = (1 - b) * mix / in_mass if in_mass > 0 else 0.0
        return inside * (b / self.region.area + mix_part)

    def intensity(self, z: np.ndarray, scan: int) -> np.ndarray:
        return self.rate(scan) * self.density(z, scan)

    def sample(self, rng: np.random.Generator, scan: int) -> np.ndarray:
        n = int(rng.poisson(self.rate(scan)))
        n_bg = int(rng.binomial(n, self.background)) if self.background > 0 else 0
        parts = [self.region.uniform(rng, n_bg)]
        need = n - n_bg
        chol = np.linalg.cholesky(self.covariances)
        for _ in range(1000):
            if need == 0:
                break
            comp = rng.choice(len(self.weights), size=need, p=self.weights)
            pts = self.means[comp] + np.einsum("nij,nj->ni", chol[comp], rng.normal(size=(need, 2)))
            pts = pts[self.region.contains(pts)]
            parts.append(pts)
            need -= len(pts)
        return np.concatenate(parts)


@dataclass(frozen=True)
class TimeVaryingClutter:
    """Clutter whose mixture and rate change over scans: linear interpolation between
    keyframes ``(scan, GaussianMixtureClutter)`` with the same number of components (weights,
    means, covariances, background share and rate all interpolate); constant before the
    first and after the last keyframe. Models drifting and swelling clutter."""

    keyframes: tuple[tuple[int, GaussianMixtureClutter], ...]
    region: Region = field(init=False)

    def __post_init__(self) -> None:
        kf = tuple(sorted(self.keyframes, key=lambda t: t[0]))
        if not kf:
            raise ValueError("time-varying clutter needs at least one keyframe")
        ncomp = {len(m.weights) for _, m in kf}
        if len(ncomp) != 1:
            raise ValueError("all clutter keyframes need the same number of components")
        if len({m.region for _, m in kf}) != 1:
            raise ValueError("all clutter keyframes need the same region")
        object.__setattr__(self, "keyframes", kf)
        object.__setattr__(self, "region", kf[0][1].region)

    def at(self, scan: int) -> GaussianMixtureClutter:
        """The interpolated mixture at ``scan``."""
        kf = self.keyframes
        if scan <= kf[0][0]:
            return kf[0][1]
        if scan >= kf[-1][0]:
            return kf[-1][1]
        i = int(np.searchsorted([k for k, _ in kf], scan, side="right")) - 1
        (k0, a), (k1, b) = kf[i], kf[i + 1]
        t = (scan - k0) / (k1 - k0)
        return _interpolate(a, b, t)

    def rate(self, scan: int) -> float:
        return self.at(scan).rate(scan)

    def density(self, z: np.ndarray, scan: int) -> np.ndarray:
        return self.at(scan).density(z, scan)

    def intensity(self, z: np.ndarray, scan: int) -> np.ndarray:
        return self.at(scan).intensity(z, scan)

    def sample(self, rng: np.random.Generator, scan: int) -> np.ndarray:
        return self.at(scan).sample(rng, scan)


def _lerp(a: float | np.ndarray, b: float | np.ndarray, t: float) -> np.ndarray:
    return (1 - t) * np.asarray(a) + t * np.asarray(b)


def _interpolate(
    a: GaussianMixtureClutter, b: GaussianMixtureClutter, t: float
) -> GaussianMixtureClutter:
    return GaussianMixtureClutter(
        region=a.region,
        rate_per_scan=float(_lerp(a.rate_per_scan, b.rate_per_scan, t)),
        weights=_lerp(a.weights, b.weights, t),
        means=_lerp(a.means, b.means, t),
        covariances=_lerp(a.covariances, b.covariances, t),
        background=float(_lerp(a.background, b.background, t)),
    )


# ---------------------------------------------------------------- a rotating radar's clutter
@dataclass(frozen=True)
class ClutterPatch:
    """A clump of a rotating radar's clutter in its own range–bearing: per rotation a
    Poisson number (mean ``rate``) of plots with range ``~ N(range, sigma_range²)`` (m)
    and bearing ``~ N(bearing, sigma_bearing_deg²)`` (degrees clockwise from north,
    wrapped to ``[0, 360)``). Ranges ``<= 0`` or beyond the radar's ``max_range`` are
    dropped (a Poisson thinning: the count stays Poisson, its mean is the mass inside)."""

    range: float
    bearing: float
    sigma_range: float
    sigma_bearing_deg: float
    rate: float

    def __post_init__(self) -> None:
        for key in ("range", "bearing", "sigma_range", "sigma_bearing_deg", "rate"):
            v = float(getattr(self, key))
            if not np.isfinite(v):
                raise ValueError(f"{key}: must be finite, got {v}")
            object.__setattr__(self, key, v)
        for key in ("sigma_range", "sigma_bearing_deg"):
            if getattr(self, key) <= 0:
                raise ValueError(f"{key}: must be > 0, got {getattr(self, key):g}")
        if self.rate < 0:
            raise ValueError(f"rate: must be >= 0, got {self.rate:g}")


def sample_range_azimuth(
    rng: np.random.Generator,
    rate: float,
    max_range: float | None,
    patches: tuple[ClutterPatch, ...] = (),
) -> tuple[np.ndarray, np.ndarray]:
    """One rotation of a radar's clutter: ``(range m, bearing deg)`` arrays.

    Uniform part: ``N ~ Poisson(rate)`` plots, range ``~ U(0, max_range)`` and bearing
    ``~ U(0, 360)`` — uniform in range–azimuth, so the density per unit *area* falls as
    ``1/r``, as a radar's range–azimuth cells do. Then each :class:`ClutterPatch` in turn.
    ``max_range`` may be ``None`` only when ``rate == 0``.
    """
    n = int(rng.poisson(rate)) if rate > 0 else 0
    if n and max_range is None:
        raise ValueError("uniform range-azimuth clutter needs the radar's max_range")
    r = [rng.random(n) * (max_range or 0.0)]
    b = [rng.random(n) * 360.0]
    for p in patches:
        k = int(rng.poisson(p.rate)) if p.rate > 0 else 0
        rp = p.range + p.sigma_range * rng.normal(size=k)
        bp = (p.bearing + p.sigma_bearing_deg * rng.normal(size=k)) % 360.0
        keep = (rp > 0) & (rp <= (np.inf if max_range is None else max_range))
        r.append(rp[keep])
        b.append(bp[keep])
    return np.concatenate(r), np.concatenate(b)
