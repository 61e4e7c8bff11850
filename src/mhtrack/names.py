"""Every name a user chooses a part by, defined once.

The tracker builder (:mod:`mhtrack.build`) maps these names to classes, the MHT
configuration validates its ``birth`` against :data:`BIRTHS`, and the CLI offers them as
choices. This module imports nothing, so ``mhtrack --help`` and every command can build
their options without loading SciPy or the tracker.
"""

from __future__ import annotations

#: Trackers of P1 §3: the plain MHT with a known clutter density, and the MHT whose
#: clutter intensity is estimated online by a GMM or by the adaptive GMM; and ours: by a
#: per-radar range–azimuth clutter map or by a GMM with exponential forgetting.
TRACKERS: tuple[str, ...] = ("mht", "mht-agmm", "mht-gmm", "mht-map", "mht-fgmm",
                             "mht-mapgmm")
#: The tracker of a run when none is named: the MHT with P1's adaptive GMM.
DEFAULT_TRACKER = "mht-agmm"
#: Clutter-intensity estimators (``mhtrack.clutter``).
CLUTTER_ESTIMATORS: tuple[str, ...] = ("known", "gmm", "agmm", "map", "fgmm", "mapgmm")
#: Coordinates a radar's clutter is estimated in (asynchronous data): the local
#: east-north plane, or the radar's own range and bearing.
CLUTTER_FRAMES: tuple[str, ...] = ("plane", "polar")
#: The clutter frame when none is chosen: each radar's own range and bearing.
DEFAULT_CLUTTER_FRAME = "polar"
#: P2's track initiators and their modified variants (``mhtrack.initiation``).
INITIATORS: tuple[str, ...] = ("logic", "modified-logic", "hough", "modified-hough")
#: The MHT's default birth process: every plot may start a tree (P1).
EVERY_PLOT = "every-plot"
#: Birth processes of the MHT: every plot, or a P2 initiator over the last scans.
BIRTHS: tuple[str, ...] = (EVERY_PLOT, *INITIATORS)
#: Plot fusion of several radars before the tracker.
TRACKER_FUSIONS: tuple[str, ...] = ("none", "adaptive-kmeans")
#: Plot fusion before P2's initiators (P2 §1.2; random-start K-means as its baseline).
INITIATION_FUSIONS: tuple[str, ...] = ("adaptive-kmeans", "kmeans", "none")
#: K-means seedings compared in P2's clustering study.
CLUSTER_METHODS: tuple[str, ...] = ("adaptive", "random")
#: Tracker output modes: ``history`` adds each confirmed track's tentative past;
#: ``smoothed`` is that history smoothed over each whole track (:mod:`mhtrack.sinks.smoothed`).
OUTPUTS: tuple[str, ...] = ("history", "online", "smoothed")
#: The output mode when none is chosen.
DEFAULT_OUTPUT = OUTPUTS[0]
#: The output mode of timed plots of rotating radars when none is chosen (the run whose
#: defaults come from the radars, ``build.radar_rule``): the history smoothed.
RADAR_OUTPUT = OUTPUTS[2]
#: What ``mhtrack export`` writes: ASTERIX CAT048 plots (the default) or CAT062 tracks.
EXPORT_CATEGORIES: tuple[str, ...] = ("048", "062")
#: When ``live`` gives a closed frame (a sector) to the tracker
#: (:mod:`mhtrack.sources.framer`): in ``track``'s time order, or as soon as its own
#: plots are in.
RELEASES: tuple[str, ...] = ("time", "radar")
