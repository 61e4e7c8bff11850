"""The ``crossing-changing`` preset: P1's crossing targets in a clutter field whose
structure changes over the run — the case P1's adaptive GMM is motivated by ("在杂波强度
时变的观测场景中, 固定的删除阈值会降低杂波空间密度估计的准确性", P1 §2). All of it is
our choice (``docs/clutter.md``, *A clutter that changes*).

The clutter is a :class:`~mhtrack.models.clutter.TimeVaryingClutter`: seven Gaussian
components whose weights, means and covariances are interpolated linearly between the
keyframes of :data:`CHANGING_KEYFRAMES` (a weight 0 is an absent component), with
``λ = 40`` plots per scan as in ``crossing``:

* **vanishes** — ``A``, a clump at (−2000, 1000) (P1's first component, σ = 150 m),
  fades from scan 30 to scan 50;
* **appears** — ``B``, a clump at (1500, −1500), σ = 150 m, grows from scan 30 to 40;
* **splits** — ``C`` and ``D`` start as one clump at (700, 700) (P1's second–fourth
  components) with σ = 120 m and move apart from scan 30 to 60, to (1800, 1600) and
  (−300, −200) — across the targets' crossing;
* **merge** — ``E`` at (−2800, −2500) and ``F`` at (−600, −2900), σ = 200 m, move
  together from scan 20 to 60, to (−1700, −2700);
* **drifts** — ``G``, a broad patch (σ = 400 m), moves from (2800, −3000) to (0, −300)
  over the whole run, into the targets' paths.
"""

from __future__ import annotations

import numpy as np

from mhtrack.models.clutter import GaussianMixtureClutter, Region, TimeVaryingClutter

#: Standard deviations (m) of the components A–G.
CHANGING_SIGMA = (150.0, 150.0, 120.0, 120.0, 200.0, 200.0, 400.0)
#: Scans of the keyframes; between them everything is linear.
CHANGING_SCANS = (1, 20, 30, 40, 50, 60, 90)
CHANGING_RATE = 40.0  # plots per scan, as crossing


def _ramp(scan: int, k0: int, k1: int) -> float:
    """0 before ``k0``, 1 after ``k1``, linear between."""
    return float(np.clip((scan - k0) / (k1 - k0), 0.0, 1.0))


def _lerp2(a: tuple[float, float], b: tuple[float, float], t: float) -> tuple[float, float]:
    return (a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]))


def changing_components(scan: int) -> tuple[np.ndarray, np.ndarray]:
    """Weights (before normalisation) and means of the components A–G at ``scan``
    (module docstring)."""
    vanish, appear = 1 - _ramp(scan, 30, 50), _ramp(scan, 30, 40)
    split, merge, drift = _ramp(scan, 30, 60), _ramp(scan, 20, 60), _ramp(scan, 1, 90)
    w = (0.25 * vanish, 0.25 * appear, 0.125, 0.125, 0.125, 0.125, 0.25)
    mu = ((-2000.0, 1000.0), (1500.0, -1500.0),
          _lerp2((700.0, 700.0), (1800.0, 1600.0), split),
          _lerp2((700.0, 700.0), (-300.0, -200.0), split),
          _lerp2((-2800.0, -2500.0), (-1700.0, -2700.0), merge),
          _lerp2((-600.0, -2900.0), (-1700.0, -2700.0), merge),
          _lerp2((2800.0, -3000.0), (0.0, -300.0), drift))
    return np.asarray(w, float), np.asarray(mu, float)


def changing_clutter(region: Region, rate: float = CHANGING_RATE) -> TimeVaryingClutter:
    """The clutter of ``crossing-changing`` (module docstring): keyframes at
    :data:`CHANGING_SCANS`, ``rate`` plots per scan. Every change is linear between two
    of these scans, so the interpolated means are those of :func:`changing_components`
    at every scan (the weights too, up to the normalisation of each keyframe)."""
    cov = (np.asarray(CHANGING_SIGMA) ** 2)[:, None, None] * np.eye(2)
    frames = []
    for scan in CHANGING_SCANS:
        w, mu = changing_components(scan)
        frames.append((scan, GaussianMixtureClutter(region, rate, w, mu, cov)))
    return TimeVaryingClutter(tuple(frames))
