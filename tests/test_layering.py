"""The package's layers are its folders, and data flows one way through them.

The order is the one ``attitude/__init__.py`` lists (README "Layout" shows the same):
a module imports only modules of its own folder or of earlier folders, and no import
loop exists at any level: not between modules (same folder included, lazy imports
included), hence not between folders either.
"""

import ast
import re
from pathlib import Path

PACKAGE = Path(__file__).parents[1] / "attitude"
TOP_LEVEL = {"__init__", "__main__"}  # the public names, and ``python -m attitude``


def _layers() -> list[str]:
    """The layer folders in order, as ``attitude/__init__.py`` lists them."""
    docstring = ast.get_docstring(ast.parse((PACKAGE / "__init__.py").read_text()))
    return re.findall(r"^\d+\. ``attitude\.(\w+)``", docstring, flags=re.MULTILINE)


def _module_names() -> dict[str, Path]:
    """Every module as ``folder.module`` (``__main__`` for the top-level one)."""
    found = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE).with_suffix("").parts
        if parts == ("__init__",):
            continue
        found[".".join(parts)] = path
    return found


def _imports(path: Path, modules: dict[str, Path]) -> set[str]:
    """The package modules ``path`` imports, wherever the import statement stands.

    ``from attitude.solver import free_flow`` is the module ``solver.free_flow``; an
    import of a folder's ``__init__`` counts as an import of that folder.
    """
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            if node.module != "attitude" and not node.module.startswith("attitude."):
                continue
            base = node.module.removeprefix("attitude").lstrip(".")
            for alias in node.names:
                candidate = f"{base}.{alias.name}".lstrip(".")
                found.add(candidate if candidate in modules else base or alias.name)
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith("attitude."):
                    found.add(alias.name.removeprefix("attitude."))
        elif isinstance(node, ast.ImportFrom) and node.level > 0:
            raise AssertionError(f"{path}: relative import (the package uses absolute ones)")
    return found


def _graph() -> dict[str, set[str]]:
    modules = _module_names()
    return {name: _imports(path, modules) for name, path in modules.items()}


def test_every_module_lives_in_a_layer_folder():
    layers = _layers()
    assert layers, "attitude/__init__.py lists no layers"
    folders = sorted(p.name for p in PACKAGE.iterdir() if (p / "__init__.py").exists())
    assert sorted(layers) == folders, f"layers {layers} against folders {folders}"
    for name in _module_names():
        folder = name.split(".")[0]
        assert folder in layers or name in TOP_LEVEL, f"attitude/{name}.py is in no layer"
        assert name.count(".") <= 1, f"attitude.{name}: one folder level per layer"


def test_every_module_imports_only_its_own_and_earlier_layers():
    layers = _layers()
    rank = {folder: index for index, folder in enumerate(layers)}
    for name, imported in _graph().items():
        if name in TOP_LEVEL:
            continue
        own = rank[name.split(".")[0]]
        for target in imported:
            folder = target.split(".")[0]
            assert folder in rank, f"attitude.{name} imports attitude.{target}: no such layer"
            assert rank[folder] <= own, f"attitude.{name} imports attitude.{target} (a later layer)"


def test_no_import_loop_between_modules():
    graph = _graph()
    state: dict[str, int] = {}  # 1 on the path being walked, 2 done

    def walk(node: str, path: list[str]) -> None:
        state[node] = 1
        for target in sorted(graph.get(node, ())):
            if target not in graph:  # a folder's __init__: imports nothing
                continue
            if state.get(target) == 1:
                loop = [*path[path.index(target) :], target] if target in path else [node, target]
                raise AssertionError("import loop: " + " -> ".join(loop))
            if state.get(target) is None:
                walk(target, [*path, target])
        state[node] = 2

    for node in sorted(graph):
        if state.get(node) is None:
            walk(node, [node])


def test_the_loop_check_finds_a_loop(monkeypatch):
    """The check above can fail: a same-folder loop planted in a copy of the graph."""
    graph = _graph()
    graph["solver.free_flow"] = {*graph["solver.free_flow"], "solver.numba_backend"}
    graph["solver.numba_backend"] = {*graph["solver.numba_backend"], "solver.free_flow"}
    monkeypatch.setitem(globals(), "_graph", lambda: graph)
    try:
        test_no_import_loop_between_modules()
    except AssertionError as error:
        assert "solver.free_flow" in str(error) and "solver.numba_backend" in str(error)
    else:
        raise AssertionError("a planted loop was not found")


def test_each_folder_lists_its_modules():
    """Each layer's ``__init__`` docstring names every module of its folder, once."""
    for folder in _layers():
        docstring = ast.get_docstring(ast.parse((PACKAGE / folder / "__init__.py").read_text()))
        listed = re.findall(r"^- ``(\w+)``", docstring or "", flags=re.MULTILINE)
        present = sorted(p.stem for p in (PACKAGE / folder).glob("*.py") if p.stem != "__init__")
        assert sorted(listed) == present, f"attitude/{folder}/__init__.py lists {listed}"


def test_ci_runs_the_readme_test_command():
    readme = (PACKAGE.parent / "README.md").read_text()
    ci = (PACKAGE.parent / ".ci" / "run").read_text()
    test_line = next(line for line in readme.splitlines() if "pytest" in line)
    install, _, run = test_line.partition("pip install ")[2].partition(" && ")
    assert f"pip install {install}" in ci
    assert run.strip() in ci


def test_every_public_name_resolves_and_import_stays_light():
    import subprocess
    import sys

    import attitude

    for name in attitude.__all__:
        assert getattr(attitude, name) is not None, name
    # `import attitude` alone loads none of the heavy dependencies of the later layers.
    heavy = "{'astropy', 'skyfield', 'matplotlib', 'dask', 'distributed', 'pandas', 'pyarrow'}"
    code = f"import sys, attitude; print(sorted({heavy} & set(sys.modules)))"
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert run.stdout.strip() == "[]"


def _readme_layout() -> list[tuple[str, list[str]]]:
    """(folder, its modules) of each row of the README's "Layout" table, in order."""
    readme = (PACKAGE.parent / "README.md").read_text()
    section = readme.split("\n## Layout\n", 1)[1].split("\n## ", 1)[0]
    rows = [line for line in section.splitlines() if line.startswith("| `")]
    table = []
    for row in rows:
        cells = row.split("|")
        table.append((cells[1].strip(" `/"), re.findall(r"`(\w+)\.py`", cells[3])))
    return table


def test_readme_layout_table_matches_the_layers():
    table = _readme_layout()
    assert [folder for folder, _ in table] == _layers(), "README Layout rows against __init__"
    for folder, modules in table:
        present = sorted(p.stem for p in (PACKAGE / folder).glob("*.py") if p.stem != "__init__")
        assert sorted(modules) == present, f"README Layout row {folder}: {modules}"


def test_lazy_names_are_declared_for_type_checkers_and_dir():
    import attitude

    init = PACKAGE / "__init__.py"
    tree = ast.parse(init.read_text())
    declared = {}  # name -> module, from the `if TYPE_CHECKING:` imports
    for node in tree.body:
        if isinstance(node, ast.If) and getattr(node.test, "id", None) == "TYPE_CHECKING":
            for item in node.body:
                assert isinstance(item, ast.ImportFrom)
                declared.update({alias.name: item.module for alias in item.names})
    assert declared == attitude._LAZY
    eager = {"AttitudeError", "EulerSolver", "InertiaWarning", "InputError", "__version__"}
    assert set(attitude.__all__) == eager | set(attitude._LAZY)
    assert set(attitude.__all__) <= set(dir(attitude))
