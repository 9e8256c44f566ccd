"""The package's layers import only the layers before them.

Data flows one way: elliptic kernels → the Euler solver → ... (see README "Layout").
A module that is not listed here fails the test, so a new module must be placed.
"""

import ast
from pathlib import Path

PACKAGE = Path(__file__).parents[1] / "attitude"

# In order; a module may import modules of its own layer or of earlier ones.
LAYERS = [
    ["version", "errors", "quantities", "quaternions", "vectors"],  # shared base
    ["elliptic"],  # elliptic kernels
    ["inertia", "euler_solver", "free_flow"],  # the Euler solver and its free-flow map
    ["torques", "splitting", "torqued_solver"],  # torques and splitting
    ["timescales", "spacecraft", "events", "scenario"],  # spacecraft, scenario and events
    ["trajectory", "motion_analysis"],  # trajectory
    ["ephemeris", "orbit", "eclipse", "pointing", "intervals"],  # pointing (skyfield)
    ["exports", "aem", "plots", "report_page", "report"],  # reports and exports
    ["scenario_file", "cli"],  # command line
]


def _layer_of(module: str) -> int:
    for index, modules in enumerate(LAYERS):
        if module in modules:
            return index
    raise AssertionError(f"attitude.{module} is in no layer of tests/test_layering.py")


def _attitude_imports(path: Path) -> set[str]:
    tree = ast.parse(path.read_text())
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("attitude"):
            parts = node.module.split(".")
            if len(parts) > 1:
                found.add(parts[1])
            else:
                found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.startswith("attitude."):
                    found.add(alias.name.split(".")[1])
    return found


def _modules():
    for path in sorted(PACKAGE.rglob("*.py")):
        relative = path.relative_to(PACKAGE).with_suffix("")
        if relative.name == "__init__" and relative.parent == Path("."):
            continue
        yield relative.parts[0], path


def test_every_module_imports_only_earlier_layers():
    for module, path in _modules():
        own = _layer_of(module)
        for imported in _attitude_imports(path):
            assert _layer_of(imported) <= own, f"attitude.{module} imports attitude.{imported}"


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
    heavy = "{'astropy', 'skyfield', 'matplotlib'}"
    code = f"import sys, attitude; print(sorted({heavy} & set(sys.modules)))"
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert run.stdout.strip() == "[]"
