"""ASTERIX radar recordings in and out: CAT048 monoradar target reports and CAT034 north
markers / sector crossings, in pcap, pcapng or raw data-block files (recognised by
content), decoded and encoded by libasterix (the optional extra ``[asterix]``).

* :func:`read_recording` → :class:`Recording` (plots, sweep marks, skipped parts);
* :func:`convert` → a plots table (docs/file-formats.md, "ASTERIX recordings");
* :func:`export` a timed plots file → ``.pcap`` or ``.ast``;
* :mod:`~mhtrack.io.asterix.earth`: slant ↔ ground range.
"""

from mhtrack.io.asterix._lib import MissingExtra
from mhtrack.io.asterix.api import (
    Converted,
    convert,
    export,
    is_recording,
    plot_columns,
    sensors_with_periods,
)
from mhtrack.io.asterix.decode import Recording, read_recording

__all__ = ["Converted", "MissingExtra", "Recording", "convert", "export", "is_recording",
           "plot_columns", "read_recording", "sensors_with_periods"]
