"""The EM of ``mhtrack.clutter.em`` written plainly, plot-major ``(n, K)`` arrays, every
density recomputed: the code as it was before the component-major layout (main 46050f2,
``src/mhtrack/clutter/em.py`` and ``seeding.py``). Tests compare the library with it bit for bit."""

import numpy as np

from mhtrack.clutter.density import Mixture
from mhtrack.models.linalg2 import LOG_2PI, det2, sym_mahalanobis2

EPS10 = 10.0 * np.finfo(float).eps


def logsumexp_rows(a):
    if a.shape[1] == 0:
        return np.full(a.shape[0], -np.inf)
    m = a.max(axis=1)
    m_safe = np.where(np.isfinite(m), m, 0.0)
    with np.errstate(divide="ignore"):
        return np.log(np.exp(a - m_safe[:, None]).sum(axis=1)) + m_safe


def maha_det(z, means, cov):
    return sym_mahalanobis2(z[:, 0:1] - means[:, 0], z[:, 1:2] - means[:, 1],
                            cov[:, 0, 0], cov[:, 0, 1], cov[:, 1, 1])


def gaussian_log_pdf(z, means, cov):
    maha, det = maha_det(z, means, cov)
    return -LOG_2PI - 0.5 * np.log(det) - 0.5 * maha


def log_background(mix, z):
    if mix.background_box is None:
        return np.full(len(z), -np.inf)
    x0, x1, y0, y1 = mix.background_box
    inside = (z[:, 0] >= x0) & (z[:, 0] <= x1) & (z[:, 1] >= y0) & (z[:, 1] <= y1)
    return np.where(inside, -np.log(mix.background_area), -np.inf)


def weighted_log_prob(mix, z):
    glp = gaussian_log_pdf(z, mix.means, mix.covariances)
    out = np.empty((len(z), mix.n_components + 1))
    with np.errstate(divide="ignore"):
        out[:, 0] = np.log(mix.background_weight) + log_background(mix, z)
        out[:, 1:] = np.log(mix.weights) + glp
    return out


def mean_ll(norm, sw):
    return float(norm.mean()) if sw is None else float(sw @ norm / sw.sum())


def m_step(z, resp, box, sw, reg_covar, background_floor):
    r = resp if sw is None else resp * sw[:, None]
    nk_all = r.sum(axis=0) + EPS10
    total = nk_all.sum()
    nk = nk_all[1:]
    rg = r[:, 1:]
    means = (rg.T @ z) / nk[:, None]
    dx = z[:, 0:1] - means[:, 0]
    dy = z[:, 1:2] - means[:, 1]
    cov = np.empty((len(nk), 2, 2))
    cov[:, 0, 0] = (rg * dx * dx).sum(axis=0) / nk + reg_covar
    cov[:, 1, 1] = (rg * dy * dy).sum(axis=0) / nk + reg_covar
    cov[:, 0, 1] = cov[:, 1, 0] = (rg * dx * dy).sum(axis=0) / nk
    if box is None:
        w0, w = 0.0, nk / nk.sum()
    else:
        w0 = max(nk_all[0] / total, background_floor)
        g = nk.sum()
        w = (1.0 - w0) * nk / g if g > 0 else nk * 0.0
    return Mixture(w, means, cov, float(w0), box), nk


def removal_gain(z, mix, sw):
    wlp = weighted_log_prob(mix, z)
    norm = logsumexp_rows(wlp)
    resp = np.exp(wlp[:, 1:] - norm[:, None])
    with np.errstate(divide="ignore"):
        to_bg = np.exp(np.log(mix.weights)[None, :] + log_background(mix, z)[:, None]
                       - norm[:, None])
    per = -np.log(np.maximum(1.0 - resp + to_bg, 1e-300))
    return per.sum(axis=0) if sw is None else sw @ per


def fit_em(z, init, *, sample_weight=None, reg_covar=1e-6, tol=1e-4, max_iter=100,
           prune=None, min_points=0.0, background_floor=0.0, min_contrast=0.0, bic=False):
    """(mixture, L, n_iter, converged, n_pruned), as ``mhtrack.clutter.em.fit_em``."""
    sw, mix, prev = sample_weight, init, -np.inf
    converged, n_pruned, n_iter = False, 0, 0
    for n_iter in range(1, max_iter + 1):  # noqa: B007
        wlp = weighted_log_prob(mix, z)
        norm = logsumexp_rows(wlp)
        ll = mean_ll(norm, sw)
        mix, nk = m_step(z, np.exp(wlp - norm[:, None]), mix.background_box, sw, reg_covar,
                         background_floor)
        keep = nk >= min_points
        if min_contrast > 0 and mix.background_box is not None:
            peak = mix.weights / (2.0 * np.pi * np.sqrt(det2(mix.covariances)))
            keep &= peak >= min_contrast * mix.background_weight / mix.background_area
        if bic and mix.background_box is not None and mix.n_components:
            n_eff = float(len(z) if sw is None else sw.sum())
            keep &= removal_gain(z, mix, sw) >= 3.0 * np.log(max(n_eff, 1.0))
        if prune is not None and keep.any():
            w = np.where(keep, mix.weights, 0.0)
            keep &= prune(w / w.sum())
        deleted = int((~keep).sum())
        if deleted and not (keep.any() or mix.background_box is not None):
            deleted = 0
        if deleted:
            w = mix.weights[keep]
            s = w.sum()
            if s > 0:
                w = w * (1.0 - mix.background_weight) / s
            bg = mix.background_weight if len(w) else (
                1.0 if mix.background_box is not None else 0.0)
            mix = Mixture(w, mix.means[keep], mix.covariances[keep], bg, mix.background_box)
            n_pruned += deleted
        if mix.n_components == 0:
            break
        if not deleted and abs(ll - prev) < tol * abs(prev):
            converged = True
            break
        prev = ll
    final = float(np.average(logsumexp_rows(weighted_log_prob(mix, z)), weights=sw))
    return mix, final, n_iter, converged, n_pruned


def kmeanspp_centres(
    z, k, rng, existing=None
):
    chosen = []
    if existing is not None and len(existing):
        d2 = ((z[:, None, :] - existing[None, :, :]) ** 2).sum(axis=2).min(axis=1)
    else:
        first = z[int(rng.integers(len(z)))]
        chosen.append(first)
        d2 = ((z - first) ** 2).sum(axis=1)
    while len(chosen) < k:
        total = d2.sum()
        if not total > 0:
            break
        i = int(np.searchsorted(np.cumsum(d2), rng.random() * total, side="right"))
        c = z[min(i, len(z) - 1)]
        chosen.append(c)
        d2 = np.minimum(d2, ((z - c) ** 2).sum(axis=1))
    return np.array(chosen, float).reshape(-1, 2)


def mixture_from_centres(
    z,
    centres,
    *,
    reg_covar,
    background_box=None,
    background_weight=0.0,
):
    k = len(centres)
    d2 = ((z[:, None, :] - centres[None, :, :]) ** 2).sum(axis=2)
    lab = d2.argmin(axis=1)
    counts = np.bincount(lab, minlength=k).astype(float)
    data_cov = np.cov(z.T, bias=True).reshape(2, 2) if len(z) > 1 else np.zeros((2, 2))
    broad = data_cov / k + reg_covar * np.eye(2)
    means = centres.astype(float).copy()
    cov = np.repeat(broad[None], k, axis=0)
    for j in np.flatnonzero(counts >= 1):
        pts = z[lab == j]
        means[j] = pts.mean(axis=0)
        if len(pts) >= 3:
            d = pts - means[j]
            cov[j] = d.T @ d / len(pts) + reg_covar * np.eye(2)
    w = np.maximum(counts, 1e-3)
    w = (1.0 - background_weight) * w / w.sum()
    return Mixture(w, means, cov, float(background_weight), background_box)
