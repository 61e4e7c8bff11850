"""The runtime dependencies are what ``src/mhtrack`` imports, and nothing more (issue 31):
read from pyproject.toml and from the source with ``ast``. Optional packages are imported
only by the commands that need them, each in the extra its error message names."""

from __future__ import annotations

import ast
import re
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src" / "mhtrack"
#: Import name → distribution name where they differ.
DISTRIBUTION = {"tomli_w": "tomli-w", "distributed": "dask", "sklearn": "scikit-learn",
                "asterix": "libasterix",
                "mpl_toolkits": "matplotlib"}
#: Packages src/mhtrack may import only as an extra: import name → the extra.
OPTIONAL = {"plotly": "report", "asterix": "asterix", "stonesoup": "stonesoup",
            "distributed": "dask", "pandas": "pandas", "numba": "fast"}


def _name(requirement: str) -> str:
    """``"dask[distributed]>=2024.1"`` → ``"dask"``."""
    return re.split(r"[\[<>=!~; ]", requirement, maxsplit=1)[0].lower()


def _project() -> dict:
    return tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]


def imported() -> set[str]:
    """Top-level names of the third-party modules any file of src/mhtrack imports."""
    out: set[str] = set()
    for path in SRC.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                out.update(a.name.split(".")[0] for a in node.names)
            elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                out.add(node.module.split(".")[0])
    return {m for m in out if m not in sys.stdlib_module_names and m != "mhtrack"}


def test_every_dependency_is_imported_and_optional_ones_are_extras() -> None:
    deps = {_name(r) for r in _project()["dependencies"]}
    extras = {k: {_name(r) for r in v} for k, v in _project()["optional-dependencies"].items()}
    used = {DISTRIBUTION.get(m, m) for m in imported()}
    assert deps <= used, f"dependencies src/mhtrack never imports: {sorted(deps - used)}"
    for module, extra in OPTIONAL.items():
        dist = DISTRIBUTION.get(module, module)
        assert dist not in deps, f"{dist} is a dependency; it belongs to the extra [{extra}]"
        assert dist in extras[extra], f"extra [{extra}] lacks {dist}"
    missing = used - deps - {DISTRIBUTION.get(m, m) for m in OPTIONAL}
    assert not missing, f"src/mhtrack imports {sorted(missing)}, neither dependency nor extra"


def test_the_readme_names_each_extra() -> None:
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    for extra in ("report", "asterix", "stonesoup", "dask", "pandas", "fast"):
        assert f"mhtrack[{extra}]" in readme, extra
