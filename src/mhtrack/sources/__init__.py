"""Sources: plots from a table, a recording or a network feed, yielded frame by frame in
time order (:mod:`mhtrack.sources.base`, ``docs/sources.md``).

* :func:`open_source` — a file by its content: :class:`~mhtrack.sources.tables.TableSource`
  (CSV/Parquet plots, timed or scans) or :class:`~mhtrack.sources.recording.AsterixSource`;
* :class:`~mhtrack.sources.datagrams.DatagramSource` — any iterable of ASTERIX datagrams.

ASTERIX sources need libasterix (``mhtrack[asterix]``), imported when one is made.
"""

from mhtrack.sources.base import Source, SourceStats, Survey
from mhtrack.sources.open import open_source

__all__ = ["Source", "SourceStats", "Survey", "open_source"]
