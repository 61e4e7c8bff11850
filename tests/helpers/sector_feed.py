"""A hand-built ASTERIX feed for the sector-frame tests: CAT048 plots and CAT034 north
markers / sector crossings of two radars, one datagram per message, at times that are
multiples of 1/8 s (exact in I048/140's and I034/030's LSB)."""

from __future__ import annotations

import numpy as np

SENSORS = """[origin]
lat = 52.0
lon = -1.0

[[sensors]]
id = 1
kind = "polar"
pd = 0.9
lat = 52.0
lon = -1.0
sigma_range = 30.0
sigma_bearing_deg = 0.08
period = 8.0

[[sensors]]
id = 2
kind = "polar"
pd = 0.9
lat = 52.2
lon = -1.2
sigma_range = 30.0
sigma_bearing_deg = 0.08
period = 8.0
"""
T0 = 36000.0  # 10:00:00


def plot(t: float, sensor: int) -> bytes:
    """One CAT048 plot of ``sensor`` at ``T0 + t`` (40 km, 90°)."""
    from mhtrack.io.asterix.encode import encode_blocks, plot_messages

    m = plot_messages(np.array([T0 + t]), np.array([sensor]), np.array([40e3]),
                      np.array([90.0]), {})
    return next(encode_blocks(m))[2]


def mark(t: float, sensor: int, north: bool) -> bytes:
    """One CAT034 north marker (``north``) or sector crossing (22.5°) at ``T0 + t``."""
    from mhtrack.io.asterix.encode import Message, encode_blocks, lsb, raw_tod

    items = {"000": 1 if north else 2, "010": (("SAC", 0), ("SIC", sensor)),
             "030": int(raw_tod(np.array([T0 + t]))[0])}
    if not north:
        items["020"] = round(22.5 / lsb()["azimuth_deg"])
    return next(encode_blocks([Message(T0 + t, sensor, 34, items)]))[2]


def datagrams(feed: list[tuple[str, float, int]]) -> list[bytes]:
    """The datagrams of ``feed`` (``("p"|"n"|"s", time − T0, sensor)``: plot, north
    marker, sector crossing)."""
    return [plot(t, s) if k == "p" else mark(t, s, k == "n") for k, t, s in feed]
