"""The names the CLI offers as choices, as plain literals.

Building the command-line options must not import the library's heavy modules (SciPy,
the tracker, the experiments): ``mhtrack --help`` and every command would pay for them at
start-up. ``tests/cli/test_choices.py`` checks that these lists equal the library's own.
"""

from __future__ import annotations

#: ``mhtrack.experiments.pipeline.TRACKERS``
TRACKERS: tuple[str, ...] = ("mht", "mht-agmm", "mht-gmm")
#: ``mhtrack.mht.config.BIRTHS``
BIRTHS: tuple[str, ...] = ("every-plot", "logic", "modified-logic", "hough", "modified-hough")
#: ``mhtrack.experiments.pipeline.FUSIONS``
FUSIONS: tuple[str, ...] = ("none", "adaptive-kmeans")
#: ``mhtrack.experiments.pipeline.OUTPUTS``
OUTPUTS: tuple[str, ...] = ("history", "online")
