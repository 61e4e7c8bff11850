"""The CLI offers exactly the library's names (``mhtrack.names``) as choices, and building
it imports none of the heavy modules."""

import subprocess
import sys

import click

from mhtrack import names
from mhtrack.cli.main import cli


def _choices(command: str, option: str) -> tuple[str, ...]:
    params = {p.name: p for p in cli.commands[command].params}
    kind = params[option].type
    assert isinstance(kind, click.Choice)
    return tuple(kind.choices)


def test_choices_are_the_library_names():
    for command in ("run", "track"):
        assert sorted(_choices(command, "tracker")) == sorted(names.TRACKERS)
        assert _choices(command, "birth") == names.BIRTHS
        assert _choices(command, "fusion") == names.TRACKER_FUSIONS
        assert _choices(command, "output") == names.OUTPUTS
    assert _choices("clutter", "estimator") == names.CLUTTER_ESTIMATORS


def test_building_the_cli_does_not_import_the_tracker_or_scipy():
    code = ("import sys; import mhtrack.cli.main as m; m.cli.to_info_dict(__import__('click')"
            ".Context(m.cli)); print(sorted(k for k in sys.modules if k.startswith(('scipy', "
            "'mhtrack.mht', 'mhtrack.experiments', 'mhtrack.build', 'sklearn', "
            "'matplotlib'))))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "[]", out.stdout
