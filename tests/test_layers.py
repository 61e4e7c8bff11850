"""The layers of docs/architecture.md hold: no module imports a later layer, and the
run-time imports between mhtrack's modules form no cycle (read from the source with ast)."""

from __future__ import annotations

import ast
import itertools
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "mhtrack"

#: First component under mhtrack → layer (docs/architecture.md, "Layers").
LAYER = {
    "records": 1, "attributes": 1, "names": 1, "errors": 1, "bounds": 1, "kernels": 1,
    "compiled": 1,
    "progress": 1,
    "models": 2, "frames": 2,
    "io": 3, "clutter": 3, "initiation": 3,
    "scenario": 4, "mht": 4, "sources": 4, "sinks": 4,
    "build": 5, "pipeline": 5, "metrics": 5,
    "experiments": 6,
    "plotting": 7, "stonesoup": 7,
    "reports": 8,
    "cli": 9,
}


def _module_name(path: Path) -> str:
    parts = path.relative_to(SRC.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path) -> set[str]:
    """mhtrack modules imported at run time (``if TYPE_CHECKING:`` blocks left out)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    out: set[str] = set()

    def visit(node: ast.AST) -> None:
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for child in node.orelse:
                visit(child)
            return
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names if a.name.startswith("mhtrack"))
        elif isinstance(node, ast.ImportFrom) and node.module and node.module.startswith(
                "mhtrack") and node.level == 0:
            out.add(node.module)
            out.update(f"{node.module}.{a.name}" for a in node.names)
        for child in ast.iter_child_nodes(node):
            visit(child)

    visit(tree)
    return out


def _graph() -> dict[str, set[str]]:
    files = {_module_name(p): p for p in SRC.rglob("*.py")}
    graph: dict[str, set[str]] = {}
    for name, path in files.items():
        graph[name] = {m for m in _imports(path) if m in files and m != name}
    return graph


def _layer(module: str) -> int | None:
    parts = module.split(".")
    return LAYER.get(parts[1]) if len(parts) > 1 else None


def test_every_package_has_a_layer() -> None:
    tops = {p.relative_to(SRC).parts[0].removesuffix(".py") for p in SRC.rglob("*.py")}
    assert tops - {"__init__", "__main__"} <= set(LAYER)


def test_no_import_against_the_data_flow() -> None:
    bad = [f"{a} (layer {_layer(a)}) imports {b} (layer {_layer(b)})"
           for a, deps in _graph().items() for b in deps
           if _layer(a) is not None and _layer(b) is not None and _layer(b) > _layer(a)]
    assert not bad, "\n".join(sorted(bad))


def test_no_import_cycle() -> None:
    graph = _graph()
    state: dict[str, int] = {}
    stack: list[str] = []
    cycles: list[list[str]] = []

    def dfs(node: str) -> None:
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                cycles.append([*stack[stack.index(nxt):], nxt])
            elif nxt not in state:
                dfs(nxt)
        stack.pop()
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            dfs(node)
    # a package's __init__ importing its own submodules is how packages export names
    real = [c for c in cycles if not any(
        b.startswith(a + ".") or a.startswith(b + ".") for a, b in itertools.pairwise(c))]
    assert not real, "\n".join(" -> ".join(c) for c in real)
