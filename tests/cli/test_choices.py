"""The CLI's literal choice lists (``mhtrack.cli.choices``) equal the library's, and
building the CLI imports none of the heavy modules."""

import subprocess
import sys

from mhtrack.cli import choices
from mhtrack.experiments import pipeline
from mhtrack.mht.config import BIRTHS


def test_choices_are_the_library_names():
    assert sorted(choices.TRACKERS) == sorted(pipeline.TRACKERS)
    assert choices.BIRTHS == BIRTHS
    assert choices.FUSIONS == pipeline.FUSIONS
    assert choices.OUTPUTS == pipeline.OUTPUTS


def test_building_the_cli_does_not_import_the_tracker_or_scipy():
    code = ("import sys; import mhtrack.cli.main as m; m.cli.to_info_dict(__import__('click')"
            ".Context(m.cli)); print(sorted(k for k in sys.modules if k.startswith(('scipy', "
            "'mhtrack.mht', 'mhtrack.experiments', 'sklearn', 'matplotlib'))))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == "[]", out.stdout
