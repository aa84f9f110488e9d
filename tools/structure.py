"""Structure figures of the checkout: modules per folder, lines per module (the largest first),
and the import depth of the app (the longest chain of gearwear-internal imports, module-level
and inside functions alike). For before/after comparisons of a renovation (issue 26):

    .venv/bin/python tools/structure.py [ROOT]

Reads files as text (ast), imports nothing of gearwear. The layer folders core/ geometry/
analytic/ fem/ dynamics/ install as gearwear.<layer>; gearwear/ is the app.
"""

from __future__ import annotations

import ast
import sys
from collections import Counter
from functools import lru_cache
from pathlib import Path

LAYERS = ("core", "geometry", "analytic", "fem", "dynamics")


def modules(root: Path) -> dict[str, Path]:
    """Module name (gearwear.X.Y) -> file, for the layers and the app."""
    out = {}
    for folder in (*LAYERS, "gearwear"):
        for f in sorted((root / folder).rglob("*.py")):
            rel = f.relative_to(root / folder).with_suffix("")
            parts = [p for p in rel.parts if p != "__init__"]
            base = ["gearwear"] if folder == "gearwear" else ["gearwear", folder]
            out[".".join(base + parts)] = f
    return out


def imports(name: str, path: Path, known: set[str]) -> set[str]:
    """The known modules ``name`` imports (absolute and relative, at any depth of the file)."""
    is_pkg = path.name == "__init__.py"
    pkg = name if is_pkg else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = ".".join(pkg.split(".")[: len(pkg.split(".")) - node.level + 1])
                base = f"{base}.{node.module}" if node.module else base
            else:
                base = node.module or ""
            found.add(base)
            found.update(f"{base}.{a.name}" for a in node.names)
    return {m for m in found if m in known and m != name}


def _components(graph: dict[str, set[str]]) -> dict[str, int]:
    """Strongly connected components (Tarjan, iterative): module -> component number."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    comp: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    counter = 0
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter
        counter += 1
        stack.append(root)
        on.add(root)
        while work:
            v, it = work[-1]
            w = next(it, None)
            if w is None:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    n = len(set(comp.values()))
                    while True:
                        x = stack.pop()
                        on.discard(x)
                        comp[x] = n
                        if x == v:
                            break
            elif w not in index:
                index[w] = low[w] = counter
                counter += 1
                stack.append(w)
                on.add(w)
                work.append((w, iter(sorted(graph[w]))))
            elif w in on:
                low[v] = min(low[v], index[w])
    return comp


def main(root: Path) -> None:
    mods = modules(root)
    known = set(mods)
    graph = {m: imports(m, p, known) for m, p in mods.items()}

    # the longest import chain: over the graph with every import cycle (a strongly connected
    # component) taken as one node, the most modules on one path (a cycle counts once)
    comp = _components(graph)
    dag: dict[int, set[int]] = {}
    for m, deps in graph.items():
        dag.setdefault(comp[m], set()).update(comp[d] for d in deps if comp[d] != comp[m])

    @lru_cache(maxsize=None)
    def chain(c: int) -> int:
        return 1 + max((chain(d) for d in dag.get(c, ())), default=0)

    def depth(m: str) -> int:
        return chain(comp[m])

    def folder(m: str) -> str:
        parts = m.split(".")
        if len(parts) > 1 and parts[1] in LAYERS:
            return parts[1] + "/"
        if len(parts) > 2 or (len(parts) == 2 and mods[m].name == "__init__.py"):
            return f"gearwear/{parts[1]}/"
        return "gearwear/ (app, top level)"

    folders = Counter(folder(m) for m in mods)
    lines = sorted(((len(p.read_text().splitlines()), m) for m, p in mods.items()), reverse=True)
    print("modules per folder:", ", ".join(f"{k} {v}" for k, v in sorted(folders.items())))
    app = [m for m in mods if m == "gearwear" or (m.startswith("gearwear.") and m.split(".")[1] not in LAYERS)]
    # the deepest chain from any app module (the command line loads its command modules by name,
    # gearwear.cli.app.COMMANDS, which an AST does not see; the deepest module counts either way)
    deepest = max(app, key=lambda m: depth(m))
    print(f"app modules: {len(app)}; import depth of the app: {depth(deepest)} (from {deepest})")
    print("largest modules (lines):", ", ".join(f"{m} {n}" for n, m in lines[:8]))
    print("modules over 600 lines:", sum(n > 600 for n, _ in lines))


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[1])
