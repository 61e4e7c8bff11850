"""An ASTERIX recording file as a source: its framing (pcap, pcapng, the recorder formats,
raw data blocks: :func:`mhtrack.io.asterix.framings.recognise`, by content) is read
through an ``mmap`` of the file as ``convert`` reads it
(:meth:`mhtrack.io.asterix.decode.Decoder.units`: each unit with its capture time, a raw
stream's blocks judged by their content) and its units fed to
:class:`~mhtrack.sources.datagrams.DatagramSource` — decoded in memory, chunk by chunk,
never through a temporary file.

Before the frames, one pass over the recording (:meth:`AsterixSource.survey`, done once)
finds every radar and its site (the sensors file's, else its own I034/120; radars with
neither are skipped, one warning line), the rotation periods its CAT034 messages give
(filled into the sensors where the file has none: they set the frame lengths, as
:func:`~mhtrack.io.asterix.api.sensors_with_periods` does) and every plot's ``x, y``.
"""

from __future__ import annotations

import mmap
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from mhtrack.errors import InputError
from mhtrack.io.asterix.api import sensors_with_periods
from mhtrack.io.asterix.decode import Decoder
from mhtrack.io.asterix.framings import recognise
from mhtrack.io.asterix.problems import Problems
from mhtrack.io.asterix.sites import radar_name
from mhtrack.io.paths import check_input_file
from mhtrack.models.radars import SensorSet
from mhtrack.progress import Count
from mhtrack.records import Scan
from mhtrack.sources.base import Survey
from mhtrack.sources.datagrams import DatagramSource


class AsterixSource(DatagramSource):
    """Frames from a recording file; errors name the file and the byte offset there.
    ``container`` is its framing (:func:`~mhtrack.io.asterix.framings.recognise`).
    ``sensors`` may be ``None``: the radars' own CAT034 sites are used."""

    def __init__(self, path: str | Path, *, sensors: SensorSet | None = None,
                 reorder_window_s: float | None = None, fast: bool = True,
                 sectors: bool = False) -> None:
        super().__init__((), sensors=sensors, name=str(path),
                         reorder_window_s=reorder_window_s, fast=fast, sectors=sectors)
        self.path = check_input_file(Path(path))
        self.categories = Decoder(fast=fast, duplicates=None).categories
        with self._mapped() as data:
            self.container = recognise(data, self.name, self.categories)
        self._survey: Survey | None = None
        self._bar: Count | None = None  # over the survey's pass (``progress``)

    @contextmanager
    def _mapped(self) -> Iterator[Any]:
        """The file's bytes, memory-mapped (an empty file as ``b""``)."""
        with self.path.open("rb") as fh:
            if self.path.stat().st_size == 0:
                yield b""
                return
            with mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) as data:
                yield data

    def _datagrams(self, problems: Problems, decoder: Decoder
                   ) -> Iterator[tuple[int, Any, float | None]]:
        """The recording's units as ``convert`` reads them (:meth:`Decoder.units`: a raw
        stream's blocks judged by their content, by the decoder that decodes them)."""
        with self._mapped() as data:
            for offset, when, payload in decoder.units(data, self.container, self.name,
                                                       problems):
                if self._bar is not None:
                    self._bar.to(offset)
                yield offset, payload, when

    def survey(self) -> Survey:
        """The recording's radars, plots' ``x, y`` and periods (one pass, kept)."""
        if self._survey is None:
            with Count(self.path.stat().st_size, "survey", "B", self.progress,
                       scale=True) as self._bar:
                periods, survey = self.periods_and_survey()
            self._bar = None
            if survey.n_plots == 0:
                radars = ", ".join(map(radar_name, sorted(self._seen)))
                why = "" if not radars else (
                    f" of a radar with a known site (radars {radars}: none in the sensors "
                    "file or with a CAT034 site I034/120)")
                raise InputError(f"{self.name}: no plot with a measured position{why} in "
                                 f"this {self.container} recording", file=self.name)
            assert self.sensors is not None
            self.sensors = sensors_with_periods(self.sensors, periods)
            self._survey = survey
        return self._survey

    def __iter__(self) -> Iterator[Scan]:
        self.survey()
        yield from super().__iter__()
