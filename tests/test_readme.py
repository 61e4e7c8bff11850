"""The README's Python example runs as written (so the front page cannot rot)."""

import re
from pathlib import Path

README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_python_example_runs(tmp_path, monkeypatch, capsys):
    text = README.read_text()
    block = re.search(r"## From Python\n\n```python\n(.*?)```", text, re.S)
    assert block, "README has no Python example"
    monkeypatch.chdir(tmp_path)
    exec(compile(block.group(1), "README.md", "exec"), {})
    out = capsys.readouterr().out
    assert "OSPA mean" in out and "Rcc" in out
    assert (tmp_path / "state.npz").is_file()


def test_readme_lists_every_command():
    """Each ``mhtrack`` command has a row in the README's command table."""
    from mhtrack.cli.main import cli

    text = README.read_text()
    missing = [name for name in cli.commands if f"| `mhtrack {name}" not in text]
    assert not missing, f"README's command table lacks {missing}"


def test_no_docstring_or_page_cites_the_internal_spec():
    """Users have the papers and docs/, not the project's SPEC.md: nothing cites it."""
    root = README.parent
    files = [README, *(root / "docs").glob("*.md"), *(root / "src").rglob("*.py")]
    cites = [f"{p.relative_to(root)}:{i}" for p in files
             for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1)
             if re.search(r"SPEC(\.md)?\s*§", line)]
    assert not cites, cites


def test_readme_pipeline_example_runs(tmp_path, monkeypatch, capsys):
    """The README's pipeline example, run beside a simulated plots.csv (its scenario.toml
    beside it), writes the tracks ``mhtrack track --output online`` writes, and its
    callback prints one line per frame."""
    from click.testing import CliRunner

    from mhtrack.cli.main import cli

    text = README.read_text()
    block = re.search(r"is `mhtrack.pipeline.Pipeline`:\n\n```python\n(.*?)```", text, re.S)
    assert block, "README has no pipeline example"
    r = CliRunner().invoke(cli, ["simulate", "crossing", "--seed", "1", "--scans", "20",
                                 "--out", str(tmp_path)])
    assert r.exit_code == 0, r.output
    monkeypatch.chdir(tmp_path)
    exec(compile(block.group(1), "README.md", "exec"), {})
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 21 and lines[-1].startswith("mht-agmm: 20 scans, ")
    assert [int(x.split()[0]) for x in lines[:-1]] == list(range(1, 21))  # scans 1..20
    r = CliRunner().invoke(cli, ["track", "plots.csv", "--output", "online",
                                 "--out", "cli.csv"])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "tracks.csv").read_bytes() == (tmp_path / "cli.csv").read_bytes()
