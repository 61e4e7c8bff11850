"""What a plot says besides its position: plot type, Mode 3/A code, Mode C flight level,
Mode S address, aircraft identification and amplitude (docs/file-formats.md, "Plot
attributes").

A civil radar's plot is primary (PSR: position only), secondary (SSR: a reply with a
Mode 3/A code and a Mode C flight level), combined (both) or Mode S (a reply that also
carries the aircraft's 24-bit ICAO address and often its identification). The columns
follow ASTERIX CAT048 (EUROCONTROL, edition 1.32): I048/070 (Mode 3/A code with its bits
V "code not validated", G "garbled"), I048/090 (flight level, 1/4 FL, with V and G),
I048/220 (address), I048/240 (identification), I048/020 TYP (plot type, coded as
:data:`PLOT_TYPES`), I048/130 SAM (amplitude, dBm).

Every column may be absent on a row: ``-1`` for the integer codes, NaN for the numbers,
``""`` for the text. A plot without any attribute is a position only, and the tracker
scores it exactly as without this record (:mod:`mhtrack.mht.attribute_scores`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields

import numpy as np

#: Plot type codes (I048/020 TYP grouped as in :mod:`mhtrack.io.asterix.notplots`).
PLOT_TYPES = {0: "none", 1: "primary", 2: "secondary", 3: "combined", 4: "mode_s",
              5: "adsb"}
PRIMARY, SECONDARY, COMBINED, MODE_S = 1, 2, 3, 4
#: A missing code or address.
ABSENT = -1
#: The columns, in file order (``docs/file-formats.md``).
COLUMNS = ("plot_type", "mode_3a", "mode_3a_v", "mode_3a_g", "flight_level",
           "flight_level_v", "flight_level_g", "address", "callsign", "amplitude")
_INT = ("plot_type", "mode_3a", "mode_3a_v", "mode_3a_g", "flight_level_v",
        "flight_level_g", "address")
_FLOAT = ("flight_level", "amplitude")
#: The plot's measured position from its sensor, carried for the tracks' ``meas_range``,
#: ``meas_bearing`` (I062/340 POS) but not written as attributes (they are the plots
#: table's own ``range`` and ``bearing``): range (m) and bearing (degrees), NaN absent.
POLAR = ("polar_range", "polar_bearing")


def code_value(text: str) -> int:
    """A Mode 3/A code written as four octal digits (``"7000"``) as its 12-bit value
    (``0o7000``); ``""`` → :data:`ABSENT`. ``ValueError`` for anything else."""
    if text == "":
        return ABSENT
    if len(text) != 4 or any(c not in "01234567" for c in text):
        raise ValueError(f"Mode 3/A code {text!r} is not four octal digits")
    return int(text, 8)


def code_text(value: int) -> str:
    """The four octal digits of a 12-bit Mode 3/A code (:data:`ABSENT` → ``""``)."""
    return "" if value < 0 else f"{int(value):04o}"


def address_value(text: str) -> int:
    """A 24-bit ICAO address written in hexadecimal (``"3C4591"``) as an integer;
    ``""`` → :data:`ABSENT`. ``ValueError`` for anything else."""
    if text == "":
        return ABSENT
    v = int(text, 16)
    if len(text) > 6 or v < 0:
        raise ValueError(f"Mode S address {text!r} is not 24 bits of hexadecimal")
    return v


def address_text(value: int) -> str:
    """Six upper-case hexadecimal digits (:data:`ABSENT` → ``""``)."""
    return "" if value < 0 else f"{int(value):06X}"


@dataclass(frozen=True)
class PlotAttributes:
    """One row per plot (module docstring): ``plot_type`` (:data:`PLOT_TYPES`, 0 unknown),
    ``mode_3a`` (12-bit code, ``-1`` absent) with ``mode_3a_v`` / ``mode_3a_g`` (1: not
    validated / garbled), ``flight_level`` (FL, NaN absent) with ``flight_level_v`` /
    ``flight_level_g``, ``address`` (24 bits, ``-1`` absent), ``callsign`` (text) and
    ``amplitude`` (dBm, NaN absent)."""

    plot_type: np.ndarray
    mode_3a: np.ndarray
    mode_3a_v: np.ndarray
    mode_3a_g: np.ndarray
    flight_level: np.ndarray
    flight_level_v: np.ndarray
    flight_level_g: np.ndarray
    address: np.ndarray
    callsign: np.ndarray
    amplitude: np.ndarray
    polar_range: np.ndarray = None  # type: ignore[assignment]  # None: NaN on every row
    polar_bearing: np.ndarray = None  # type: ignore[assignment]

    def __post_init__(self) -> None:
        n = len(self.plot_type)
        for name in POLAR:
            if getattr(self, name) is None:
                object.__setattr__(self, name, np.full(n, np.nan))
        for f in fields(self):
            if len(getattr(self, f.name)) != n:
                raise ValueError(f"PlotAttributes column {f.name!r} has "
                                 f"{len(getattr(self, f.name))} rows, expected {n}")

    def __len__(self) -> int:
        return len(self.plot_type)

    @classmethod
    def from_columns(cls, cols: Mapping[str, np.ndarray], n: int | None = None
                     ) -> PlotAttributes:
        """The attributes among ``cols`` (any subset of :data:`COLUMNS`, already decoded:
        codes and addresses as integers), the others absent on every row."""
        if n is None:
            n = len(next(iter(cols.values())))
        out = {}
        for name in COLUMNS:
            v = cols.get(name)
            if name in _INT:
                fill = 0 if name.endswith(("_v", "_g")) or name == "plot_type" else ABSENT
                out[name] = np.full(n, fill, np.int64) if v is None else \
                    np.asarray(v, np.int64)
            elif name in _FLOAT:
                out[name] = np.full(n, np.nan) if v is None else np.asarray(v, float)
            else:
                out[name] = np.full(n, "", object) if v is None else np.asarray(v, object)
        for name in POLAR:
            if cols.get(name) is not None:
                out[name] = np.asarray(cols[name], float)
        return cls(**out)

    @classmethod
    def absent(cls, n: int) -> PlotAttributes:
        """``n`` plots without any attribute."""
        return cls.from_columns({}, n)

    def columns(self, polar: bool = False) -> dict[str, np.ndarray]:
        """The columns by name (:data:`COLUMNS`; ``polar``: and :data:`POLAR`)."""
        return {name: getattr(self, name) for name in COLUMNS + (POLAR if polar else ())}

    def take(self, idx: np.ndarray | slice) -> PlotAttributes:
        """Rows ``idx`` (index array, mask or slice), in that order."""
        return PlotAttributes(**{k: v[idx] for k, v in self.columns(polar=True).items()})

    @classmethod
    def concat(cls, parts: list[PlotAttributes]) -> PlotAttributes:
        return cls(**{k: np.concatenate([getattr(p, k) for p in parts])
                      for k in COLUMNS + POLAR})

    def any(self) -> bool:
        """Some plot carries a code, a flight level or an address."""
        return bool((self.mode_3a >= 0).any() or (self.address >= 0).any()
                    or np.isfinite(self.flight_level).any())


def of_columns(cols: Mapping[str, np.ndarray]) -> PlotAttributes | None:
    """:meth:`PlotAttributes.from_columns` of the attribute columns among ``cols`` (a
    source's batch), ``None`` when there are none."""
    mine = {k: v for k, v in cols.items() if k in COLUMNS + POLAR}
    return PlotAttributes.from_columns(mine, len(cols["time"])) \
        if any(k in COLUMNS for k in mine) else None


#: Feet per minute in one flight level per second (1 FL = 100 ft).
FPM_PER_FL_S = 6000.0
#: The columns of :class:`TrackAttributes`, in tracks-file order (``docs/file-formats.md``).
TRACK_COLUMNS = ("flight_level", "rate_of_climb", "mode_3a", "address", "callsign",
                 "sigma_major", "sigma_minor", "sigma_orient", "sensors", "sensor_ages",
                 "age_psr", "age_ssr", "age_mds", "meas_sensor", "meas_type", "meas_mode_3a",
                 "meas_mode_3a_vg", "meas_flight_level", "meas_flight_level_vg",
                 "meas_range", "meas_bearing", "existence_probability")
#: The plot types that count as a detection of each technology of I062/290's ages:
#: primary (PSR), secondary (SSR: Mode A/C replies) and Mode S.
TECHNOLOGIES = {"psr": (PRIMARY, COMBINED), "ssr": (SECONDARY, COMBINED), "mds": (MODE_S,)}


def accuracy(P: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(σ_major, σ_minor, orientation)`` of the position covariances of states ``P``
    (n, 4, 4) ``[x, vx, y, vy]``: the square roots of the eigenvalues of ``[[Pxx, Pxy],
    [Pxy, Pyy]]``, ``λ = (a + c)/2 ± √(((a − c)/2)² + b²)``, and the major axis' bearing
    in degrees clockwise from the frame's north (y), in [0, 180): ``90° − ½ atan2(2b,
    a − c)`` (the eigenvector's angle from x, counter-clockwise)."""
    a, b, c = P[:, 0, 0], P[:, 0, 2], P[:, 2, 2]
    mid, half = (a + c) / 2, np.hypot((a - c) / 2, b)
    theta = 0.5 * np.degrees(np.arctan2(2 * b, a - c))
    return (np.sqrt(mid + half), np.sqrt(np.maximum(mid - half, 0.0)),
            np.mod(90.0 - theta, 180.0))


def existence(score: np.ndarray) -> np.ndarray:
    """The probability that a track is a true target from its score ``L``, the
    log-likelihood ratio of target against false track with the prior odds in its
    initial value: ``P_T = e^L / (1 + e^L) = 1 / (1 + e^−L)`` (Blackman & Popoli 1999,
    §6.2), computed as ``exp(−ln(1 + e^−L))`` (``np.logaddexp``: no overflow at either
    end; NumPy, as this module is loaded by every run and SciPy is not)."""
    return np.exp(-np.logaddexp(0.0, -np.asarray(score, float)))


@dataclass(frozen=True)
class TrackAttributes:
    """What a track says besides its state, one row per track row: ``flight_level`` (FL)
    and ``rate_of_climb`` (ft/min) of its vertical state at the row's time, NaN when
    unknown; its last validated ``mode_3a`` code and its Mode S ``address`` (``-1``
    absent); its latest ``callsign`` (``""`` absent); its position's ``sigma_major``,
    ``sigma_minor`` (m) and ``sigma_orient`` (degrees, the major axis' bearing from north
    clockwise in [0, 180); :func:`accuracy`), NaN when unknown; the ``sensors`` that
    updated it (text, ids in increasing order joined by ``;``) and the ``sensor_ages``
    of their last updates (text, seconds, the same order; :mod:`mhtrack.mht.sensor_ages`),
    ``""`` when none is known; ``age_psr``, ``age_ssr``, ``age_mds`` the age (s) of the
    track's last update by a plot of each technology (:data:`TECHNOLOGIES`), NaN when
    none is known; and what the row's own plot measured (I062/340; on a miss: absent):
    ``meas_sensor`` (its sensor id, ``-1``), ``meas_type`` (:data:`PLOT_TYPES` code, 0),
    ``meas_mode_3a`` (its code as received, ``-1``) and ``meas_flight_level`` (FL, NaN)
    with their validity bits ``meas_mode_3a_vg``, ``meas_flight_level_vg`` (``2·V + G``),
    ``meas_range`` (m) and ``meas_bearing`` (degrees) its position as its sensor measured
    it (NaN: unknown, e.g. a Cartesian sensor's);
    and the track's ``existence_probability`` from its score (:func:`existence`), NaN
    when unknown."""

    flight_level: np.ndarray
    rate_of_climb: np.ndarray
    mode_3a: np.ndarray
    address: np.ndarray
    callsign: np.ndarray
    sigma_major: np.ndarray
    sigma_minor: np.ndarray
    sigma_orient: np.ndarray
    sensors: np.ndarray
    sensor_ages: np.ndarray
    age_psr: np.ndarray
    age_ssr: np.ndarray
    age_mds: np.ndarray
    meas_sensor: np.ndarray
    meas_type: np.ndarray
    meas_mode_3a: np.ndarray
    meas_mode_3a_vg: np.ndarray
    meas_flight_level: np.ndarray
    meas_flight_level_vg: np.ndarray
    meas_range: np.ndarray
    meas_bearing: np.ndarray
    existence_probability: np.ndarray

    def __len__(self) -> int:
        return len(self.mode_3a)

    def __getitem__(self, idx: np.ndarray | slice) -> TrackAttributes:
        """Rows ``idx`` (index array, mask or slice), in that order."""
        return TrackAttributes(**{k: getattr(self, k)[idx] for k in TRACK_COLUMNS})

    @classmethod
    def absent(cls, n: int, P: np.ndarray | None = None) -> TrackAttributes:
        """``n`` rows with nothing known, but the accuracy of covariances ``P`` when
        given (the tentative past of a track: its states, without its attributes)."""
        nan = np.full(n, np.nan)
        sig = (nan, nan, nan) if P is None else accuracy(P)
        return cls(nan, nan, np.full(n, ABSENT, np.int64), np.full(n, ABSENT, np.int64),
                   np.full(n, "", object), *sig, np.full(n, "", object),
                   np.full(n, "", object), nan.copy(), nan.copy(), nan.copy(),
                   np.full(n, ABSENT, np.int64), np.zeros(n, np.int64),
                   np.full(n, ABSENT, np.int64), np.zeros(n, np.int64), nan.copy(),
                   np.zeros(n, np.int64), nan.copy(), nan.copy(), nan.copy())

    @classmethod
    def concat(cls, parts: list[TrackAttributes]) -> TrackAttributes:
        return cls(**{k: np.concatenate([getattr(p, k) for p in parts])
                      for k in TRACK_COLUMNS})
