"""Radar plot characteristics (issue 29 item 1, amplitude): CAT048 I048/130 decoded by
libasterix into columns, and CAT001 I001/131 as the plot's amplitude
(docs/file-formats.md, "Radar plot characteristics")."""

from __future__ import annotations

from typing import Any

import numpy as np

from mhtrack.io.asterix._lib import quantity

#: One nautical mile (m), the unit of I048/130 RPD.
NM_M = 1852.0

#: The columns a plot with radar plot characteristics adds to
#: :data:`mhtrack.io.asterix.decode.PLOT_COLUMNS` (CAT048 I048/130; NaN where a
#: subfield is absent): SSR plot runlength (°), number of received replies, amplitude of
#: the (M)SSR reply (dBm), primary plot runlength (°), amplitude of the primary plot
#: (dBm), range difference PSR − SSR (m; the item's 1/256 NM × 1 852) and azimuth
#: difference PSR − SSR (°); then ``amplitude`` (dBm), the plot's amplitude as
#: :class:`~mhtrack.attributes.PlotAttributes` holds it: SAM, else PAM (a primary-only
#: plot). A CAT001 plot gives only ``amplitude``, its I001/131 received power (I001/130's
#: contents are defined by each radar, not by the standard).
CHARACTERISTICS = ("srl", "srr", "sam", "prl", "pam", "rpd", "apd", "amplitude")
#: The subfields of I048/130 in :data:`CHARACTERISTICS` order, with the unit read.
SUBFIELDS_130 = (("SRL", "°"), ("SRR", None), ("SAM", "dBm"), ("PRL", "°"), ("PAM", "dBm"),
                 ("RPD", "NM"), ("APD", "°"))


def characteristics(item: Any) -> tuple[float, ...]:
    """The :data:`CHARACTERISTICS` of a libasterix I048/130, NaN for an absent subfield;
    RPD in metres; ``amplitude`` SAM, else PAM."""
    out: list[float] = []
    for name, unit in SUBFIELDS_130:
        sub = item.variation.get_item(name)
        if sub is None:
            out.append(np.nan)
        elif unit is None:
            out.append(float(sub.variation.content.as_uint()))
        else:
            v = float(quantity(sub, unit))
            out.append(v * NM_M if unit == "NM" else v)
    sam, pam = out[2], out[4]
    return (*out, sam if sam == sam else pam)
