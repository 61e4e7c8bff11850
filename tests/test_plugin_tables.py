"""One plug-in mechanism: every name → part table's keys are the names of
:mod:`mhtrack.names`, and no module outside the builder branches on a part's name."""

from __future__ import annotations

import ast
from pathlib import Path

from mhtrack import build, names

SRC = Path(__file__).resolve().parents[1] / "src" / "mhtrack"


def test_table_keys_equal_the_name_lists() -> None:
    assert set(build.TRACKER_ESTIMATORS) == set(names.TRACKERS)
    assert set(build.TRACKER_ESTIMATORS.values()) <= set(names.CLUTTER_ESTIMATORS)
    assert set(build.CLUTTER_ESTIMATOR_CLASSES) == set(names.CLUTTER_ESTIMATORS)
    assert set(build.BIRTH_FACTORIES) == set(names.BIRTHS)
    assert set(build.INITIATOR_CLASSES) == set(names.INITIATORS)
    assert set(build.TRACKER_FUSERS) == set(names.TRACKER_FUSIONS)
    assert set(build.INITIATION_FUSER_CLASSES) == set(names.INITIATION_FUSIONS)
    assert names.DEFAULT_TRACKER in names.TRACKERS
    assert names.DEFAULT_CLUTTER_FRAME in names.CLUTTER_FRAMES
    assert names.DEFAULT_OUTPUT in names.OUTPUTS


def test_every_birth_builds_its_kind() -> None:
    from mhtrack.mht import MHTConfig

    for birth in names.BIRTHS:
        cfg = MHTConfig(birth=birth)
        made = build.make_birth(cfg, cfg.motion)
        assert getattr(made, "method", names.EVERY_PLOT) == birth
        trk = build.make_tracker("mht", cfg)
        assert type(trk.birth) is type(made)


#: Names of parts whose comparison (``x == "mht-agmm"``) would be a second table.
#: (Estimator names such as ``"gmm"`` are left out: a scenario's clutter kinds use them.)
PART_NAMES = set(names.TRACKERS) | set(names.BIRTHS) | set(names.TRACKER_FUSIONS)
#: The builder may compare (the MHT's refusal to default an initiator birth compares
#: with the constant EVERY_PLOT, not a literal).
BUILDER = ("build/",)


def test_no_branching_on_a_part_name_outside_the_builder() -> None:
    bad = []
    for path in SRC.rglob("*.py"):
        rel = path.relative_to(SRC).as_posix()
        if rel.startswith(BUILDER):
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Compare) and any(
                    isinstance(op, ast.Eq | ast.NotEq) for op in node.ops):
                for side in (node.left, *node.comparators):
                    if isinstance(side, ast.Constant) and side.value in PART_NAMES:
                        bad.append(f"{rel}:{node.lineno}: compares with {side.value!r}")
    assert not bad, "\n".join(bad)
