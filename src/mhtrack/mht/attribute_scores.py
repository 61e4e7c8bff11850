"""Secondary-radar attributes in the track score: a Mode S address, a Mode 3/A code or a
flight level that agrees with a track raises its score, one that disagrees lowers it —
a likelihood ratio, never a hard rule, so that a garbled reply, a code change or a level
bust costs but does not forbid.

**Score.** An update with plot ``z`` that carries attributes ``a`` adds to P1 eq. 5's
kinematic increment the log-likelihood ratio of ``a`` under "from this track" against
"clutter or another target" (Blackman & Popoli 1999, *Design and Analysis of Modern
Tracking Systems* §6.2 and ch. 11: attribute data enter the track score as
``ln[p(a | track) / p(a | false or new target)]``, multiplied with the kinematic ratio
when independent of it)::

    ΔL = ln[p(z|T) P_D / (κ̂ + λ_v)] + Σ ln λ_a

one term per attribute the plot *and* the track both have (none: ``λ_a = 1``, the score
of a plot without attributes is exactly P1's):

* **Mode S address** ``s`` against the track's ``S``: ``λ = (1 − ε_S) / q_S`` when equal,
  ``ε_S / (1 − q_S)`` when not; ``ε_S`` the probability that the track's own aircraft
  reports another address (a decoding error), ``q_S`` that an unrelated plot has the
  track's address.
* **Mode 3/A code** ``c`` against the track's last validated code ``C``: the same form
  with ``ε_A`` (a code change or error) and ``q_A``; a code flagged garbled or not
  validated (I048/070 G, V) uses the larger ``ε_A,g``.
* **A Mode S address at all** (a reply, on an update and on a new tree's first plot
  alike): P1's reference explains a plot as clutter (density ``κ̂``) or a new target
  (``λ_v``), and clutter rarely carries an address, so ``λ = p_S (κ̂ + λ_v) /
  (κ̂ f_S + λ_v p_S)`` with ``p_S`` a target's plot carrying its address, ``f_S`` a false
  plot carrying one (:func:`reply_terms`). In clutter (``κ̂ ≫ λ_v``) it approaches
  ``p_S / f_S``; where ``κ̂ ≪ λ_v`` it is 1. A plot *without* an address is scored as a
  position only (no ratio ``(1 − p_S)/(1 − f_S)``): aircraft without Mode S, and
  primary-only plots, must stay trackable (our approximation).
* **Flight level** ``h`` against the track's vertical state (below): a Gaussian with an
  outlier floor, ``λ = (1 − ε_C) N(h; ĥ, S) W + ε_C``, where ``W`` (FL) is the span of
  the levels an unrelated plot may have (density ``1/W``) and ``ε_C`` the probability of
  a wrong Mode C reply (``ε_C,g`` when flagged garbled or not validated). The floor
  bounds the cost of any one reply at ``ln ε_C``.

**Vertical state.** Per leaf a 1-D Kalman filter on ``[h, ḣ]`` (FL, FL/s): constant
climb rate with continuous white-noise acceleration of spectral density ``q`` (Bar-Shalom,
Li & Kirubarajan 2001, §6.2.2): ``F = [[1, Δt], [0, 1]]``, ``Q = q [[Δt³/3, Δt²/2],
[Δt²/2, Δt]]``; measurement ``h`` with variance ``σ_C²`` (Mode C's 100 ft steps:
``100/√12`` ft ≈ 0.3 FL, rounded up for altimetry). ``S = P⁻_hh + σ_C²``. A validated
level within :attr:`AttributeModel.reset_sigmas` σ of the prediction updates the filter;
one farther is an outlier and leaves it as it is, until
:attr:`AttributeModel.reset_after` such levels in a row restart it there (a level bust,
or a branch that now follows another aircraft: each of those plots has paid ``ln ε_C``
first). The first validated level starts the filter (``ḣ = 0``, ``σ_ḣ``
:attr:`AttributeModel.sigma_rate0`). A leaf's
address is the first one its plots gave (an airframe's address does not change: a
branch that takes another aircraft's plots pays ``ln λ`` of a mismatch at each of them);
its code the last validated one (codes change on the controller's instruction).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mhtrack.attributes import PlotAttributes


@dataclass(frozen=True)
class AttributeModel:
    """The parameters of the attribute likelihood ratios (module docstring); defaults
    ours, each stated with its reason."""

    #: ε_S: a Mode S reply decoded with another aircraft's address (Mode S replies carry
    #: a 24-bit parity over the address: errors are rare).
    address_error: float = 1e-3
    #: q_S: an unrelated plot carries the track's address (another reply of the same
    #: aircraft seen as a second target: a split plot or a reflection).
    address_share: float = 1e-2
    #: ε_A: the track's aircraft replies with another validated code (a code change by
    #: ATC, a few per flight over hundreds of replies).
    code_error: float = 2e-2
    #: ε_A,g: the same for a code flagged garbled or not validated.
    code_error_garbled: float = 0.3
    #: q_A: an unrelated aircraft squawks the track's code (conspicuity codes such as
    #: 7000, 2000 are shared by many).
    code_share: float = 2e-2
    #: ε_C: a validated Mode C reply is wrong (garbling that the radar did not flag).
    level_error: float = 1e-2
    #: ε_C,g: the same for a level flagged garbled or not validated.
    level_error_garbled: float = 0.2
    #: W (FL): the span of flight levels of unrelated plots, density 1/W (FL 0–500).
    level_span: float = 500.0
    #: σ_C (FL): a Mode C level's error (100 ft steps: 0.29 FL; altimetry adds some).
    sigma_level: float = 0.5
    #: q (FL²/s³): the climb rate's random walk (σ_ḣ grows by √(q Δt): 0.32 FL/s in 10 s,
    #: about a level-off from 2 000 ft/min).
    q_level: float = 1e-2
    #: σ_ḣ (FL/s) of a new vertical state: 3 000 ft/min at 1σ.
    sigma_rate0: float = 0.5
    #: A validated level more than this many σ from the prediction restarts the state.
    reset_sigmas: float = 5.0
    #: Outliers in a row that restart the vertical state at the last one.
    reset_after: int = 3
    #: p_S: a target's plot carries its Mode S address (a Mode S aircraft's reply).
    address_reply: float = 0.9
    #: f_S: a false plot carries a Mode S address (fruit that passes the parity check).
    address_fruit: float = 1e-3
    #: A new track on the address of a track that ended at most this long ago (s) takes
    #: its id (:mod:`mhtrack.mht.resume`; the OpenSky data's longest gap is 660 s).
    resume_s: float = 900.0
    #: A reply whose address a tree that takes it already carries also starts a new tree
    #: (True: as before issue 30; default False, :mod:`mhtrack.mht.births.same_address`).
    birth_on_tracked_address: bool = False

    def __post_init__(self) -> None:
        for name in ("address_error", "address_share", "code_error", "code_error_garbled",
                     "code_share", "level_error", "level_error_garbled", "address_reply",
                     "address_fruit"):
            v = getattr(self, name)
            if not 0.0 < v < 1.0:
                raise ValueError(f"AttributeModel.{name}: must be in (0, 1), got {v!r}")
        for name in ("level_span", "sigma_level", "q_level", "sigma_rate0",
                     "reset_sigmas", "resume_s"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise ValueError(f"AttributeModel.{name}: must be > 0, got {v!r}")
        if self.reset_after < 1:
            raise ValueError(f"AttributeModel.reset_after: must be >= 1, got "
                             f"{self.reset_after!r}")

    def discrete(self, error: float, share: float) -> tuple[float, float]:
        """``(ln λ if equal, ln λ if not)`` of a code or address: ``ln((1 − ε)/q)``,
        ``ln(ε/(1 − q))``."""
        return math.log((1.0 - error) / share), math.log(error / (1.0 - share))


def predict_level(level: np.ndarray, t: np.ndarray, q: float
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(h⁻, P⁻_hh, P⁻_hḣ, P⁻_ḣḣ)`` of vertical states ``level`` (k, 6) predicted to
    times ``t`` (k,) (module docstring; ``|Δt|`` in ``Q``)."""
    h, r, phh, phr, prr, t0 = level[:, :6].T
    dt = t - t0
    a = np.abs(dt)
    return (h + r * dt,
            phh + 2 * dt * phr + dt * dt * prr + q * a ** 3 / 3,
            phr + dt * prr + q * a * a / 2 * np.sign(dt),
            prr + q * a)


def pair_increments(model: AttributeModel, level: np.ndarray, ident: np.ndarray,
                    attrs: PlotAttributes, plot_t: np.ndarray, leaf: np.ndarray,
                    plot: np.ndarray) -> np.ndarray:
    """``Σ ln λ_a`` (module docstring) of each gated pair (``leaf``, ``plot``): leaves'
    ``level`` (L, 6) and ``ident`` (L, 2), the frame's plots' ``attrs`` and times."""
    out = np.zeros(leaf.size)
    if leaf.size == 0:
        return out
    for col, value, error, garbled, share in (
            (1, attrs.address, model.address_error, None, model.address_share),
            (0, attrs.mode_3a, model.code_error, model.code_error_garbled,
             model.code_share)):
        mine, theirs = ident[leaf, col], value[plot]
        both = (mine >= 0) & (theirs >= 0)
        if not both.any():
            continue
        same, other = model.discrete(error, share)
        inc = np.where(mine == theirs, same, other)
        if garbled is not None:
            flagged = (attrs.mode_3a_v[plot] != 0) | (attrs.mode_3a_g[plot] != 0)
            same_g, other_g = model.discrete(garbled, share)
            inc = np.where(flagged, np.where(mine == theirs, same_g, other_g), inc)
        out += np.where(both, inc, 0.0)
    h = attrs.flight_level[plot]
    lv = level[leaf]
    both = np.isfinite(h) & np.isfinite(lv[:, 0])
    if both.any():
        k = both.nonzero()[0]
        hp, phh, _, _ = predict_level(lv[k], plot_t[plot[k]], model.q_level)
        S = phh + model.sigma_level ** 2
        nu = h[k] - hp
        flagged = (attrs.flight_level_v[plot[k]] != 0) | (attrs.flight_level_g[plot[k]] != 0)
        eps = np.where(flagged, model.level_error_garbled, model.level_error)
        dens = np.exp(-0.5 * nu * nu / S) / np.sqrt(2 * np.pi * S)
        out[k] += np.log((1 - eps) * dens * model.level_span + eps)
    return out


def grow_attributes(model: AttributeModel, level: np.ndarray, ident: np.ndarray,
                    attrs: PlotAttributes, plot_t: np.ndarray, plot: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray]:
    """The children's ``(level, ident)`` from their parents' (rows of ``level``,
    ``ident``) and their plots ``plot`` (``-1``: a miss keeps the parent's): the first
    address, the last validated code and the vertical state (module docstring)."""
    level, ident = level.copy(), ident.copy()
    upd = plot >= 0
    j = np.where(upd, plot, 0)
    a = attrs.address[j]
    ident[:, 1] = np.where(upd & (a >= 0) & (ident[:, 1] < 0), a, ident[:, 1])
    c = attrs.mode_3a[j]
    ok = upd & (c >= 0) & (attrs.mode_3a_v[j] == 0) & (attrs.mode_3a_g[j] == 0)
    ident[:, 0] = np.where(ok, c, ident[:, 0])
    h = attrs.flight_level[j]
    valid = upd & np.isfinite(h) & (attrs.flight_level_v[j] == 0) & \
        (attrs.flight_level_g[j] == 0)
    if not valid.any():
        return level, ident
    k = valid.nonzero()[0]
    t = plot_t[j[k]]
    hk = h[k]
    known = np.isfinite(level[k, 0])
    hp, phh, phr, prr = predict_level(np.where(known[:, None], level[k], 0.0), t,
                                      model.q_level)
    S = phh + model.sigma_level ** 2
    nu = hk - hp
    update = known & (nu * nu <= model.reset_sigmas ** 2 * S)
    outliers = np.where(known & ~update, np.nan_to_num(level[k, 6]) + 1, 0.0)
    start = ~known | (outliers >= model.reset_after)
    kh, kr = phh / S, phr / S
    new = level[k].copy()  # an outlier below the count: the state as it was
    new[update, 0] = (hp + kh * nu)[update]
    new[update, 1] = (level[k, 1] + kr * nu)[update]
    new[update, 2] = (phh - kh * phh)[update]
    new[update, 3] = (phr - kh * phr)[update]
    new[update, 4] = (prr - kr * phr)[update]
    new[update, 5] = t[update]
    new[start, :6] = np.column_stack((hk, np.zeros(k.size), np.full(k.size, model.sigma_level ** 2),
                                      np.zeros(k.size), np.full(k.size, model.sigma_rate0 ** 2),
                                      t))[start]
    new[:, 6] = np.where(start, 0.0, outliers)
    level[k] = new
    return level, ident


def seed_attributes(model: AttributeModel, attrs: PlotAttributes, plot_t: np.ndarray,
                    plot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(level, ident)`` of new trees started by plots ``plot`` (``-1``: none known)."""
    n = plot.size
    return grow_attributes(model, np.full((n, 7), np.nan), np.full((n, 2), -1, np.int64),
                           attrs, plot_t, plot)


def positions(rows: np.ndarray, wanted: np.ndarray) -> np.ndarray:
    """The index in ``rows`` (a frame's plot row ids, not empty) of each of ``wanted``
    (a new tree's last plot), ``-1`` where it is not there."""
    order = np.argsort(rows, kind="stable")
    j = order[np.minimum(np.searchsorted(rows, wanted, sorter=order), rows.size - 1)]
    return np.where((wanted >= 0) & (rows[j] == wanted), j, -1)


def reply_terms(model: AttributeModel, attrs: PlotAttributes, kappa: np.ndarray,
                new_target_density: float) -> np.ndarray:
    """Per plot, ``ln[p_S (κ̂ + λ_v) / (κ̂ f_S + λ_v p_S)]`` for a plot with a Mode S
    address, 0 for the others (module docstring)."""
    p, f = model.address_reply, model.address_fruit
    lam = new_target_density
    k = np.broadcast_to(np.asarray(kappa, float), attrs.address.shape)
    return np.where(attrs.address >= 0, np.log(p * (k + lam)) - np.log(k * f + lam * p), 0.0)
