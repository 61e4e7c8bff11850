"""The sensors file of the timed-plots tests: one polar radar at a site west of the origin
(46.4253 N, 6.0989 E; σr 80 m, σθ 0.15°, P_D 0.9) rotating with ``period``, and with
``cartesian`` a second sensor (id 2) reporting x/y or lat/lon with σ 50 m."""

from __future__ import annotations

from pathlib import Path

#: The origin of the local frame and the polar radar's site (lat, lon degrees).
ORIGIN = (46.8, 8.2)
SITE = (46.4253, 6.0989)


def sensors_toml(period: float = 12.0, *, cartesian: bool = True) -> str:
    """The sensors file's text (module docstring)."""
    text = f"""\
[origin]
lat = {ORIGIN[0]}
lon = {ORIGIN[1]}
[[sensors]]
id = 1
kind = "polar"
lat = {SITE[0]}
lon = {SITE[1]}
sigma_range = 80.0
sigma_bearing_deg = 0.15
pd = 0.9
period = {period}
"""
    if cartesian:
        text += '[[sensors]]\nid = 2\nkind = "cartesian"\nsigma = 50.0\npd = 1.0\n'
    return text


def write_sensors_toml(path: Path, period: float = 12.0, *, cartesian: bool = True) -> Path:
    """:func:`sensors_toml` written to ``path``; returns ``path``."""
    path.write_text(sensors_toml(period, cartesian=cartesian))
    return path
