"""The result of :func:`~mhtrack.metrics.evaluate.evaluate`: every metric of one run, and
how it is rendered — a JSON-able dict (:meth:`Evaluation.to_dict`) and a plain-text table
(:meth:`Evaluation.to_table`)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from mhtrack.io.jsonsafe import to_jsonable
from mhtrack.metrics.association import AssociationResult
from mhtrack.metrics.cardinality import CardinalityPerScan
from mhtrack.metrics.clearmot import CLEARMOTResult
from mhtrack.metrics.gospa import GOSPAPerScan
from mhtrack.metrics.hota import HOTA_KEYS, HOTAResult
from mhtrack.metrics.identity import IdentityFigures
from mhtrack.metrics.ospa import OSPAPerScan
from mhtrack.metrics.ospa2 import OSPA2PerScan
from mhtrack.metrics.resample import Alignment


@dataclass(frozen=True)
class Evaluation:
    """All metrics of one run (see :func:`evaluate`).

    Attributes
    ----------
    cutoff, order, match_distance : float
        OSPA/GOSPA ``c`` (m) and ``p``; CLEAR-MOT ``d_match`` (m).
    scans : (K,) int array
        Scan indices evaluated: with ``at = "scans"`` the union of truth, tracks, plots and
        explicit scans; with ``at = "truth-times"`` the truth's scans.
    ospa, gospa, cardinality : per-scan results on ``scans``.
    clear_mot : CLEARMOTResult
    n_tracks, n_targets : int
        Distinct track ids in the tracker output and distinct target ids in the truth.
    association : AssociationResult or None
        P1 Table 3's Rcc, Rmc, Rfg, Lmin/Lavg/Lmax on the CLEAR-MOT matching (``rcc`` and
        ``rmc`` are NaN unless the plots with their ``origin`` were given and share the
        truth's scans).
    at : {"scans", "truth-times"}
        How the tracks were aligned with the truth (see :func:`evaluate`).
    max_age_s : float or None
        Largest age of a track state used at a truth time (s); ``None`` with ``"scans"``.
    ospa2, hota : OSPA2PerScan, HOTAResult or None
        OSPA(2) on ``scans`` (``cutoff``, ``order``, ``ospa2.window`` scans); HOTA.
    identity : IdentityFigures or None
        Issue 29's identity figures (:mod:`mhtrack.metrics.identity`), when asked for.
    """

    cutoff: float
    order: float
    match_distance: float
    scans: np.ndarray
    ospa: OSPAPerScan
    gospa: GOSPAPerScan
    cardinality: CardinalityPerScan
    clear_mot: CLEARMOTResult
    n_tracks: int
    n_targets: int
    association: AssociationResult | None = None
    at: Alignment = "scans"
    max_age_s: float | None = None
    ospa2: OSPA2PerScan | None = None
    hota: HOTAResult | None = None
    identity: IdentityFigures | None = None

    @property
    def n_track_ids(self) -> int:
        """Distinct track ids in the tracker output (the issue's name for ``n_tracks``)."""
        return self.n_tracks

    @property
    def coverage(self) -> float:
        """Fraction of truth states (target, scan) matched to a track by CLEAR-MOT within
        the matching distance, ``n_matches / n_truth`` (switches included); NaN without
        truth."""
        m = self.clear_mot
        return m.n_matches / m.n_truth if m.n_truth else float("nan")

    @property
    def ospa_mean(self) -> float:
        """Mean OSPA over the evaluated scans (m); NaN when there is no scan."""
        return _mean(self.ospa.distance)

    @property
    def ospa2_mean(self) -> float:
        """Mean OSPA(2) over the evaluated scans (m); NaN when there is none."""
        return float("nan") if self.ospa2 is None else _mean(self.ospa2.distance)

    @property
    def gospa_mean(self) -> float:
        """Mean GOSPA over the evaluated scans (m); NaN when there is no scan."""
        return _mean(self.gospa.distance)

    @property
    def cardinality_error_mean(self) -> float:
        """Mean ``|n̂ − n|`` over the evaluated scans; NaN when there is no scan."""
        return _mean(self.cardinality.error)

    def to_dict(self) -> dict[str, Any]:
        """Plain-Python (JSON-serialisable) summary; NaN becomes ``None``.

        Scalars: ``cutoff, order, match_distance, n_scans, n_tracks, n_targets,
        ospa_mean, ospa_localisation_mean, ospa_cardinality_mean, gospa_mean,
        cardinality_error_mean, mota, motp, id_switches, fragmentations, n_matches,
        n_misses, n_false, n_truth`` and P1 Table 3's ``rcc, rmc, rfg, l_min, l_avg,
        l_max`` (always present; ``rcc``/``rmc`` are ``None`` without plot origins, all six
        ``None`` when undefined — see :func:`association_metrics`), and the confirmation
        delay ``delay_mean, delay_max`` (scans) with ``delay`` per target (by ascending
        target id, ``None`` for a target never confirmed). Per-scan lists (aligned
        with ``scans``): ``scans, ospa, gospa, cardinality`` (number of tracks),
        ``cardinality_true``. Issue 14's keys: ``at``, ``coverage``, ``n_track_ids`` and,
        with ``at = "truth-times"`` only, ``max_age_s``. Issue 19's: ``ospa2_mean,
        ospa2_window``, the per-scan list ``ospa2``, and ``hota, deta, assa, loca,
        hota_distance`` (means over α; ``None`` / empty when not computed). Issue 29's
        (only when :attr:`identity` was computed): :data:`~mhtrack.metrics.identity.
        IDENTITY_KEYS`.
        """
        m = self.clear_mot
        return {
            "cutoff": self.cutoff,
            "order": self.order,
            "match_distance": _num(self.match_distance),
            "n_scans": len(self.scans),
            "n_tracks": self.n_tracks,
            "n_targets": self.n_targets,
            "ospa_mean": _num(self.ospa_mean),
            "ospa_localisation_mean": _num(_mean(self.ospa.localisation)),
            "ospa_cardinality_mean": _num(_mean(self.ospa.cardinality)),
            "gospa_mean": _num(self.gospa_mean),
            "cardinality_error_mean": _num(self.cardinality_error_mean),
            "mota": _num(m.mota),
            "motp": _num(m.motp),
            "id_switches": m.id_switches,
            "fragmentations": m.fragmentations,
            "n_matches": m.n_matches,
            "n_misses": m.n_misses,
            "n_false": m.n_false,
            "n_truth": m.n_truth,
            **self._association_dict(),
            "at": self.at,
            **({} if self.max_age_s is None else {"max_age_s": _num(self.max_age_s)}),
            "coverage": _num(self.coverage),
            "n_track_ids": self.n_track_ids,
            **self._issue19_dict(),
            **({} if self.identity is None else
               {k: v if isinstance(v, int) else _num(v)
                for k, v in self.identity.to_dict().items()}),
            "scans": [int(s) for s in self.scans],
            "ospa": [float(v) for v in self.ospa.distance],
            "gospa": [float(v) for v in self.gospa.distance],
            "cardinality": [int(v) for v in self.cardinality.n_tracks],
            "cardinality_true": [int(v) for v in self.cardinality.n_true],
            "ospa2": [] if self.ospa2 is None else [float(v) for v in self.ospa2.distance],
        }

    def _issue19_dict(self) -> dict[str, Any]:
        h = {} if self.hota is None else self.hota.summary()
        return {"ospa2_mean": _num(self.ospa2_mean),
                "ospa2_window": None if self.ospa2 is None else self.ospa2.window,
                **{k: _num(h[k]) if h else None for k in HOTA_KEYS}}

    def _association_dict(self) -> dict[str, Any]:
        a = self.association
        keys = ("rcc", "rmc", "rfg", "l_min", "l_avg", "l_max", "delay_mean", "delay_max")
        if a is None:
            return {**dict.fromkeys(keys), "delay": []}
        delay = [] if a.delay is None else [_num(float(v)) for v in a.delay]
        return {**{k: _num(getattr(a, k)) for k in keys}, "delay": delay}

    def _alignment_rows(self) -> list[tuple[str, str]]:
        if self.at == "scans":
            return []
        return [("aligned at", f"truth times, states <= {_fmt(self.max_age_s or 0.0)} s old "
                 "predicted (CV)")]

    def _issue19_rows(self) -> list[tuple[str, str]]:
        o, h = self.ospa2, self.hota
        return ([] if o is None else [(f"OSPA(2) mean (window {o.window} scans)",
                                       _fmt(self.ospa2_mean, " m"))]) + ([] if h is None else [
            (f"HOTA (d_max={_fmt(h.d_max)} m)", _fmt(h.hota)),
            ("  DetA / AssA / LocA", f"{_fmt(h.deta)} / {_fmt(h.assa)} / {_fmt(h.loca)}")])

    def _identity_rows(self) -> list[tuple[str, str]]:
        i = self.identity
        if i is None:
            return []
        return [("ids per aircraft (mean)", _fmt(i.ids_per_aircraft)),
                (f"wrong code/address rate ({i.n_code_rows} rows)", _fmt(i.wrong_code_rate)),
                ("horizontal RMS position error", _fmt(i.rms_horizontal, " m")),
                (f"probability of update (T={_fmt(i.update_interval)} s)",
                 _fmt(i.p_update)),
                ("extra track rate (unmatched states)", _fmt(i.extra_track_rate)),
                ("  multiple / false track rate",
                 f"{_fmt(i.multiple_track_rate)} / {_fmt(i.false_track_rate)}"),
                (f"dubious track rate (> {_fmt(i.dubious_distance)} m)",
                 _fmt(i.dubious_track_rate))]

    def to_table(self, *, per_scan: bool = False) -> str:
        """Plain-text (ASCII) table of the summary metrics, for a terminal.

        With ``per_scan=True`` a second table lists, per scan, the true and estimated
        cardinalities, OSPA and GOSPA.
        """
        m = self.clear_mot
        c, p = _fmt(self.cutoff), _fmt(self.order)
        rows = [
            ("scans", str(len(self.scans))),
            *self._alignment_rows(),
            ("true targets (distinct ids)", str(self.n_targets)),
            ("tracks (distinct ids)", str(self.n_tracks)),
            (f"OSPA mean (c={c} m, p={p})", _fmt(self.ospa_mean, " m")),
            ("  localisation part", _fmt(_mean(self.ospa.localisation), " m")),
            ("  cardinality part", _fmt(_mean(self.ospa.cardinality), " m")),
            (f"GOSPA mean (alpha=2, c={c} m, p={p})", _fmt(self.gospa_mean, " m")),
            ("cardinality error mean |n_est - n|", _fmt(self.cardinality_error_mean)),
            *self._issue19_rows(),
            (f"MOTA (match distance {_fmt(self.match_distance)} m)", _fmt(m.mota)),
            ("MOTP (mean matched distance)", _fmt(m.motp, " m")),
            ("coverage (matched truth states)", _fmt(self.coverage)),
            ("identity switches", str(m.id_switches)),
            ("fragmentations", str(m.fragmentations)),
            *self._identity_rows(),
            (
                "matches / misses / false / truth",
                f"{m.n_matches} / {m.n_misses} / {m.n_false} / {m.n_truth}",
            ),
        ]
        a = self.association
        if a is not None:
            rows += [
                ("Rcc correct association rate", _fmt(a.rcc)),
                ("Rmc mis-association rate", _fmt(a.rmc)),
                ("Rfg track breaks per target", _fmt(a.rfg)),
                (
                    "track life Lmin / Lavg / Lmax",
                    f"{_fmt(a.l_min)} / {_fmt(a.l_avg)} / {_fmt(a.l_max)} s",
                ),
                ("confirmation delay mean / max",
                 f"{_fmt(a.delay_mean)} / {_fmt(a.delay_max)} scans"),
            ]
        out = _render(("metric", "value"), rows)
        if per_scan:
            scan_rows = [
                (str(s), str(nt), str(nk), _fmt(o), _fmt(g))
                for s, nt, nk, o, g in zip(
                    self.scans.tolist(),
                    self.cardinality.n_true.tolist(),
                    self.cardinality.n_tracks.tolist(),
                    self.ospa.distance.tolist(),
                    self.gospa.distance.tolist(),
                    strict=True,
                )
            ]
            out += "\n\n" + _render(("scan", "n_true", "n_tracks", "OSPA", "GOSPA"), scan_rows)
        return out


def _mean(a: np.ndarray) -> float:
    return float(np.mean(a)) if len(a) else float("nan")


def _num(v: float) -> float | None:
    """JSON-safe float (:func:`~mhtrack.io.jsonsafe.to_jsonable`): NaN and ±inf become
    ``None``."""
    return to_jsonable(float(v))  # type: ignore[no-any-return]


def _fmt(v: float, unit: str = "") -> str:
    if not math.isfinite(v):
        return "n/a" if math.isnan(v) else str(v)
    return f"{v:.1f}{unit}" if abs(v) >= 1000 else f"{v:.4g}{unit}"


def _render(header: tuple[str, ...], rows: list[tuple[str, ...]]) -> str:
    widths = [max(len(r[i]) for r in [header, *rows]) for i in range(len(header))]
    # first column left-aligned (labels), the others right-aligned (numbers)
    def line(r: tuple[str, ...]) -> str:
        cells = [r[0].ljust(widths[0])] + [
            x.rjust(w) for x, w in zip(r[1:], widths[1:], strict=True)
        ]
        return "  ".join(cells).rstrip()

    rule = "  ".join("-" * w for w in widths)
    return "\n".join([line(header), rule, *(line(r) for r in rows)])
