"""The hypothesis store: the leaves of all track trees as stacked arrays.

A *track tree* grows from one plot; each of its *leaves* is one track hypothesis (the
chain of plots or misses from the root to now). Each scan every leaf spawns a miss child
and one child per plot in its gate (:mod:`mhtrack.mht.extend`), and new trees start
from plots (:mod:`mhtrack.mht.births`) (P1 §1.3, Fig. 1).

Leaves are kept sorted by tree id, so a tree is a contiguous segment and per-tree
reductions are ``np.maximum.reduceat`` over segment starts. Nothing here holds a Python
object per leaf.
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import numpy as np

from mhtrack.kernels import changes
from mhtrack.models.motion import States, row_index

NO_PLOT = -1


@dataclass(frozen=True, slots=True)
class Leaves:
    """All leaves, one row each, sorted by ``tree``.

    Attributes
    ----------
    x, P : (L, 4), (L, 4, 4) state ``[x, vx, y, vy]`` and covariance at the last scan.
    score : (L,) track score ``L(k)`` (log-likelihood ratio, P1 eq. 4).
    peak : (L,) highest score along the leaf's branch (for SPRT deletion by score drop).
    tree : (L,) tree id (consecutive, never reused).
    track : (L,) track id of the tree once confirmed, ``-1`` while tentative.
    birth : (L,) scan index at which the tree was started.
    n_updates : (L,) number of plots on the branch (the root plot included).
    window : (L, N+1) plot row ids used at scans ``k−N … k`` (``-1`` for a miss or before
        the tree existed); column 0 is the scan N-scan pruning decides.
    chosen : (L,) leaf is in the current best global hypothesis.
    mu, xm, Pm : (L, r), (L, r, 4), (L, r, 4, 4) model probabilities, states and
        covariances of an IMM with ``r`` models (:mod:`mhtrack.models.imm`); ``x, P`` are
        then their moment-matched mixture. ``r = 0`` (empty trailing axes) for the single
        constant-velocity model.
    node, parent : (L,) id of this leaf (unique over the run, ascending in row order) and of
        the leaf it grew from (``-1`` for a tree's root). New leaves get ``-1`` here and
        their ids from the tracker; they link a track back to its tentative past
        (:mod:`mhtrack.mht.history`).
    time : (L,) time (s) of the leaf's state ``x, P``: its last plot's own time, or the
        time of the frame that last predicted it (a miss). With synchronous scans every
        leaf's time is the last scan's.
    level : (L, 7) the vertical state of :mod:`mhtrack.mht.attribute_scores`: flight
        level ``h`` (FL), climb rate ``ḣ`` (FL/s), covariance ``P_hh, P_hḣ, P_ḣḣ``, the
        time (s) they are at and the count of validated levels in a row far from it; NaN
        ``h`` when no plot of the branch gave a flight level.
    ident : (L, 2) the branch's last Mode 3/A code and Mode S address (``-1``: none).
    ``level`` and ``ident`` default to "nothing known" for every leaf.
    """

    x: np.ndarray
    P: np.ndarray
    score: np.ndarray
    peak: np.ndarray
    tree: np.ndarray
    track: np.ndarray
    birth: np.ndarray
    n_updates: np.ndarray
    window: np.ndarray
    chosen: np.ndarray
    mu: np.ndarray
    xm: np.ndarray
    Pm: np.ndarray
    node: np.ndarray
    parent: np.ndarray
    time: np.ndarray
    level: np.ndarray = None  # type: ignore[assignment]  # filled by __post_init__
    ident: np.ndarray = None  # type: ignore[assignment]

    def __post_init__(self) -> None:
        n = self.score.shape[0]
        if self.level is None:
            object.__setattr__(self, "level", no_level(n))
        if self.ident is None:
            object.__setattr__(self, "ident", np.full((n, 2), -1, np.int64))

    def __len__(self) -> int:
        return int(self.score.shape[0])

    @classmethod
    def empty(cls, width: int, r: int = 0) -> Leaves:
        """No leaves; ``r`` IMM models (0: single model)."""
        i = np.zeros(0, np.int64)
        f = np.zeros(0)
        return cls(np.zeros((0, 4)), np.zeros((0, 4, 4)), f, f, i, i, i, i,
                   np.zeros((0, width), np.int64), np.zeros(0, bool), np.zeros((0, r)),
                   np.zeros((0, r, 4)), np.zeros((0, r, 4, 4)), i, i, f)

    def take(self, idx: np.ndarray | slice) -> Leaves:
        """Rows ``idx`` (an index array, boolean mask or slice), in that order."""
        if isinstance(idx, slice):
            return Leaves(*[getattr(self, f)[idx] for f in FIELDS])
        idx = row_index(idx)
        return Leaves(*[getattr(self, f).take(idx, axis=0) for f in FIELDS])

    @classmethod
    def concat(cls, a: Leaves, b: Leaves) -> Leaves:
        if len(b) == 0:  # the arrays are never written in place: share them
            return a
        return cls(*[np.concatenate((getattr(a, f), getattr(b, f))) for f in FIELDS])

    def arrays(self) -> dict[str, np.ndarray]:
        """The columns by name (for saving)."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    @classmethod
    def from_arrays(cls, arrays: dict[str, np.ndarray]) -> Leaves:
        """The store of :meth:`arrays` (``level``, ``ident`` may be missing: a state
        saved before they existed)."""
        return cls(**{f.name: np.asarray(arrays[f.name]) for f in fields(cls)
                      if f.name in arrays or f.name not in ("level", "ident")})

    def states(self) -> States:
        """The leaves' filter states (``x, P`` and the per-model ``xm, Pm, mu``)."""
        return States(self.x, self.P, self.xm, self.Pm, self.mu)

    @property
    def n_models(self) -> int:
        """IMM models per leaf (0: single constant-velocity model)."""
        return int(self.mu.shape[1])

    def reported(self) -> np.ndarray:
        """Mask of the leaves that report a track: chosen (best hypothesis) and
        confirmed."""
        return self.chosen & (self.track >= 0)

    @property
    def n_trees(self) -> int:
        tree = self.tree  # the runs of equal tree ids (leaves are sorted by tree)
        return int(np.count_nonzero(changes(tree))) if tree.size else 0


def no_level(n: int) -> np.ndarray:
    """``n`` rows of :attr:`Leaves.level` with nothing known (all NaN)."""
    return np.full((n, 7), np.nan)


#: The store's columns, in order.
FIELDS = tuple(f.name for f in fields(Leaves))
#: The filter-state columns: most of a leaf's bytes (an IMM's ``Pm`` alone half of them).
STATE = ("x", "P", "xm", "Pm", "mu")


def deferred_concat(a: Leaves, b: Leaves, **columns: np.ndarray) -> Leaves:
    """``Leaves.concat(a, b)`` without copying the :data:`STATE` columns: in their place
    read-only NaN placeholders of the right shape (no memory; any use shows), and
    ``columns`` in place of theirs. :func:`take_deferred` then copies the states of the
    rows kept once, from ``a`` and ``b`` (the store after a scan: the solve and N-scan
    pruning read no state)."""
    n = len(a) + len(b)
    cols = {f: (columns[f] if f in columns
                else placeholder((n, *getattr(a, f).shape[1:])) if f in STATE
                else np.concatenate((getattr(a, f), getattr(b, f))))
            for f in FIELDS}
    return Leaves(**cols)


#: The one NaN behind every :func:`deferred_concat` placeholder (read-only).
_NAN = np.array([np.nan])
_NAN.setflags(write=False)


def placeholder(shape: tuple[int, ...]) -> np.ndarray:
    """A read-only array of ``shape`` whose every element is the one NaN of :data:`_NAN`
    (all strides 0: ``np.broadcast_to`` without its Python set-up)."""
    return np.ndarray(shape, float, buffer=_NAN, strides=(0,) * len(shape))


def take_deferred(leaves: Leaves, rows: np.ndarray | None, parts: tuple[Leaves, Leaves],
                  **columns: np.ndarray) -> Leaves:
    """Rows ``rows`` (ascending; ``None``: all) of ``leaves``, a :func:`deferred_concat`
    of ``parts``, with their states copied from the parts and ``columns`` replacing
    others: the same arrays as ``replace(Leaves.concat(*parts).take(rows), **columns)``
    in one copy of each state row (``tests/mht/test_deferred.py``)."""
    a, b = parts
    if rows is None:
        cols = {f: np.concatenate((getattr(a, f), getattr(b, f))) for f in STATE}
        return replace(leaves, **cols, **columns)
    split = int(rows.searchsorted(len(a)))
    ra, rb = rows[:split], rows[split:] - len(a)
    cols = {}
    for f in FIELDS:
        if f in columns:
            continue
        if f not in STATE:
            cols[f] = getattr(leaves, f).take(rows, axis=0)
            continue
        u, v = getattr(a, f), getattr(b, f)
        out = np.empty((rows.size, *u.shape[1:]), np.result_type(u, v))
        # mode "clip": no buffered copy (the rows are in range, nothing is clipped); the
        # ndarray method: no wrapper set-up
        u.take(ra, axis=0, out=out[:split], mode="clip")
        v.take(rb, axis=0, out=out[split:], mode="clip")
        cols[f] = out
    return Leaves(**cols, **columns)


def contains(values: np.ndarray, query: np.ndarray) -> np.ndarray:
    """``np.isin(query, values)`` by one sort and a binary search (no set-up cost of
    ``np.isin`` on the few values of one scan)."""
    if values.size == 0:
        return np.zeros(query.shape, bool)
    v = np.sort(values)
    j = v.searchsorted(query)
    np.minimum(j, v.size - 1, out=j)
    return v[j] == query


def segment_starts(sorted_keys: np.ndarray) -> np.ndarray:
    """Start index of each run of equal values in ``sorted_keys`` (empty for no rows)."""
    if sorted_keys.size == 0:
        return np.zeros(0, np.int64)
    return changes(sorted_keys).nonzero()[0]


def segment_ids(sorted_keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(starts, seg)``: segment starts and, per row, the index of its segment."""
    starts = segment_starts(sorted_keys)
    seg = np.zeros(sorted_keys.size, np.int64)
    if starts.size > 1:
        seg[starts[1:]] = 1
        np.cumsum(seg, out=seg)
    return starts, seg


def one_point_state(z: np.ndarray, R: np.ndarray, v_max: float) -> tuple[np.ndarray,
                                                                          np.ndarray]:
    """One-point initialisation of plots ``z`` (n, 2): ``x = [zx, 0, zy, 0]``, position
    covariance ``R``, velocity variance ``(v_max/2)²`` per axis (the velocity is unknown
    but bounded by ``v_max`` at 2σ)."""
    n = len(z)
    x = np.zeros((n, 4))
    x[:, 0], x[:, 2] = z[:, 0], z[:, 1]
    P = np.zeros((n, 4, 4))
    P[:, 0, 0], P[:, 0, 2] = R[..., 0, 0], R[..., 0, 1]
    P[:, 2, 0], P[:, 2, 2] = R[..., 1, 0], R[..., 1, 1]
    P[:, 1, 1] = P[:, 3, 3] = (0.5 * v_max) ** 2
    return x, P


def new_trees(
    states: States, score: np.ndarray, peak: np.ndarray, tree: np.ndarray, scan_index: int,
    n_updates: np.ndarray, window: np.ndarray, time: np.ndarray,
) -> Leaves:
    """Root leaves of new trees (tentative, not chosen, node ids not yet given) with
    states at ``time`` (n,)."""
    n = len(score)
    return Leaves(
        x=states.x,
        P=states.P,
        score=score,
        peak=peak,
        tree=tree,
        track=np.full(n, -1, np.int64),
        birth=np.full(n, scan_index, np.int64),
        n_updates=n_updates,
        window=window,
        chosen=np.zeros(n, bool),
        mu=states.mu,
        xm=states.xm,
        Pm=states.Pm,
        node=np.full(n, -1, np.int64),
        parent=np.full(n, -1, np.int64),
        time=np.asarray(time, float),
    )
