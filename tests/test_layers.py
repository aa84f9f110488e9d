"""Architecture: one import package, and imports that go one way.

core <- geometry <- (analytic, fem) <- gearwear (the app wires them); dynamics takes
arrays and uses only core. Checked on the source text (ast), so a violation fails
even if no test happens to import the offending module."""

import ast
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LAYERS = ("core", "geometry", "analytic", "fem", "dynamics")
#: which gearwear sub-packages each layer may import
ALLOWED = {
    "core": set(),
    "geometry": {"core"},
    "analytic": {"core", "geometry"},
    "fem": {"core", "geometry"},
    "dynamics": {"core"},
}


def _imports(path: Path):
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            yield from (a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and not node.level and node.module:
            yield node.module


def test_layers_import_one_way():
    bad = []
    for layer in LAYERS:
        for path in sorted((ROOT / layer).glob("*.py")):
            for name in _imports(path):
                parts = name.split(".")
                if parts[0] in LAYERS:
                    bad.append(f"{layer}/{path.name} imports top-level {name} (must be gearwear.{name})")
                if parts[0] == "gearwear":
                    sub = parts[1] if len(parts) > 1 else ""
                    if sub != layer and sub not in ALLOWED[layer]:
                        bad.append(f"{layer}/{path.name} imports {name}")
    assert not bad, "\n".join(bad)


#: the app's rooms (gearwear/<room>/) and what each may import of the app, so that the app too
#: imports one way: stiffness <- scene <- jobs <- (diagnose, reports) <- cli. The top-level
#: helpers io and plotting are open to every room; io reads the schema (the resolved scene in
#: provenance) and api sits above the rooms it wires.
ROOMS = {
    "stiffness": {"stiffness", "io", "plotting"},
    "scene": {"scene", "stiffness", "io"},
    "jobs": {"jobs", "scene", "stiffness", "io", "plotting"},
    "diagnose": {"diagnose", "jobs", "scene", "stiffness", "io", "plotting"},
    "reports": {"reports", "jobs", "scene", "stiffness", "io", "plotting"},
    "cli": {"cli", "diagnose", "reports", "jobs", "scene", "stiffness", "io", "plotting"},
    "io": {"scene"},
    "plotting": set(),
}


def test_the_app_rooms_import_one_way():
    app = ROOT / "gearwear"
    rooms = {p.name for p in app.iterdir() if (p / "__init__.py").exists() and p.name != "data"}
    assert rooms == set(ROOMS) - {"io", "plotting"}, rooms
    bad = []
    for room, allowed in ROOMS.items():
        paths = sorted((app / room).glob("*.py")) if room in rooms else [app / f"{room}.py"]
        for path in paths:
            for node in ast.walk(ast.parse(path.read_text())):
                names = (
                    [a.name for a in node.names]
                    if isinstance(node, ast.Import)
                    else [node.module]
                    if isinstance(node, ast.ImportFrom) and node.module and not node.level
                    else []
                )
                for name in names:
                    parts = name.split(".")
                    if (
                        parts[0] == "gearwear"
                        and len(parts) > 1
                        and parts[1] in set(ROOMS) | {"api"}
                        and parts[1] not in allowed
                    ):
                        bad.append(f"gearwear/{room}/{path.name} imports {name}")
    assert not bad, "\n".join(bad)


def test_nothing_imports_the_layers_as_top_level_packages():
    for folder in ("gearwear", "tests", "benchmarks", "examples"):
        for path in sorted((ROOT / folder).rglob("*.py")):
            for name in _imports(path):
                assert name.split(".")[0] not in LAYERS, f"{path.relative_to(ROOT)} imports {name}"


def test_importing_everything_loads_only_gearwear_names():
    """From a neutral folder, the whole package imports, and no module is loaded under a
    second, top-level name (which would make two copies of every class)."""
    code = (
        "import sys, gearwear, gearwear.cli.app, gearwear.scene.schema, gearwear.scene.model, gearwear.fem.pair, "
        "gearwear.analytic.tvms, gearwear.dynamics, gearwear.geometry.wear\n"
        f"bad = [m for m in sys.modules if m.split('.')[0] in {LAYERS!r}]\n"
        "assert not bad, bad\n"
        "assert gearwear.geometry.__file__.endswith('geometry/__init__.py'), gearwear.geometry.__file__\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True, cwd=ROOT.parent)


def test_no_module_shadows_a_facade_name():
    """``gw.sweep`` etc. are functions; a sub-module of the same name would replace the
    function on the package as soon as anything imported it."""
    import gearwear

    for name in gearwear._API:
        assert not (ROOT / "gearwear" / f"{name}.py").exists(), name
        assert not (ROOT / name).is_dir() or name in LAYERS, name


def test_low_layers_name_their_own_parameters_not_flags_or_scene_keys():
    """Errors below the app name the function's parameters; the CLI renames them to
    flags and scene keys (gearwear.core.validation.renamed)."""
    import re

    pattern = re.compile(
        r"""(fail\(|fail_range\(|fail_text\(|InputError\()f?["']"""
        r"""(--|pair\.|effects\.|solver\.|bodies\.|operating\.|dynamics\.)"""
    )
    bad = [
        f"{layer}/{p.name}:{i}"
        for layer in LAYERS
        for p in sorted((ROOT / layer).glob("*.py"))
        for i, line in enumerate(p.read_text().splitlines(), 1)
        if pattern.search(line)
    ]
    assert not bad, bad


def test_the_parser_and_help_import_no_heavy_library():
    """``gearwear --help`` and every command's parser are built before any work: building
    them must not import scipy, matplotlib, numba, gmsh or scikit-fem (a parser that
    imported a job module cost 0.8 s on every command and on --help)."""
    code = (
        "import sys, contextlib, io\n"
        "import gearwear.cli.app as a\n"
        "a.build_parser()\n"
        "with contextlib.redirect_stdout(io.StringIO()), contextlib.suppress(SystemExit):\n"
        "    a.build_parser().parse_args(['--help'])\n"
        "heavy = {'scipy', 'matplotlib', 'numba', 'gmsh', 'skfem', 'meshio', 'dask'}\n"
        "bad = sorted(heavy & {m.split('.')[0] for m in sys.modules})\n"
        "assert not bad, bad\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True, cwd=ROOT.parent)
