"""Clutter intensity estimation: the ``κ̂(z)`` the tracker scores plots against.

* :class:`KnownClutter` — a constant ``κ`` (P1's plain MHT);
* :class:`GMMClutter` — EM-fitted GMM with a fixed deletion threshold (MHT-GMM);
* :class:`AGMMClutter` — P1's adaptive GMM (eq. 12 pruning; MHT-AGMM);
* :mod:`mhtrack.clutter.em` — the shared EM core; :class:`MixtureClutter` — the shared
  online machinery (window, warm start, uniform background, Poisson ML count).

By name: :func:`mhtrack.build.make_clutter_estimator` (names in
:data:`mhtrack.names.CLUTTER_ESTIMATORS`).

See ``docs/clutter.md``.
"""

from mhtrack.clutter.agmm import AGMMClutter, keep_mass
from mhtrack.clutter.base import ClutterEstimator
from mhtrack.clutter.em import EMResult, Mixture, fit_em
from mhtrack.clutter.gmm import GMMClutter, keep_above
from mhtrack.clutter.known import KnownClutter
from mhtrack.clutter.mixture import MixtureClutter

__all__ = [
    "AGMMClutter",
    "ClutterEstimator",
    "EMResult",
    "GMMClutter",
    "KnownClutter",
    "Mixture",
    "MixtureClutter",
    "fit_em",
    "keep_above",
    "keep_mass",
]
