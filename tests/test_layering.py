"""The package's layers import only the layers before them.

Data flows one way: elliptic kernels → the Euler solver → ... (see README "Layout").
A module that is not listed here fails the test, so a new module must be placed.
"""

import ast
from pathlib import Path

PACKAGE = Path(__file__).parents[1] / "attitude"

# In order; a module may import modules of its own layer or of earlier ones.
LAYERS = [
    [  # shared base
        "version",
        "errors",
        "quantities",
        "quaternions",
        "vectors",
        "float_math",
        "compiled",
        "compiled_double_double",
    ],
    ["elliptic", "compiled_elliptic", "phase_table"],  # elliptic kernels
    [  # the Euler solver
        "inertia",
        "invariants",
        "closed_form",
        "euler_solver",
        "compiled_flow",
        "free_flow",
    ],
    ["torques", "splitting", "torqued_solver"],  # torques and splitting
    [  # scenario and events
        "timescales",
        "epoch_texts",
        "spacecraft",
        "events",
        "scenario_torques",
        "scenario",
    ],
    ["torqued_segment", "trajectory", "horizon", "motion_analysis"],  # trajectory
    [  # pointing (skyfield)
        "ephemeris",
        "earth",
        "frames",
        "orbit",
        "keplerian",
        "ccsds_files",
        "oem",
        "aem_input",
        "intervals",
        "extrema",
        "eclipse",
        "pointing_spec",
        "surroundings",
        "pointing_sampling",
        "pointing_search",
        "pointing",
    ],
    [  # reports and exports
        "csv_files",
        "timeseries_parquet",
        "aem",
        "aem_sampling",
        "summaries",
        "plots",
        "report_figures",
        "report_page",
        "output_formats",
        "output_budget",
        "run_plan",
        "torques_summary",
        "beside",
        "output_folder",
        "report",
    ],
    [  # command line, and Monte Carlo beside it (it drives the scenario layer from above)
        "scenario_file",
        "dispersions",
        "scenario_writer",
        "montecarlo_metrics",
        "montecarlo_plan",
        "montecarlo_cluster",
        "montecarlo_simulation",
        "montecarlo_statistics",
        "montecarlo_report",
        "montecarlo",
        "cli_montecarlo",
        "cli",
        "__main__",
    ],
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
    heavy = "{'astropy', 'skyfield', 'matplotlib', 'dask', 'distributed', 'pandas', 'pyarrow'}"
    code = f"import sys, attitude; print(sorted({heavy} & set(sys.modules)))"
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert run.stdout.strip() == "[]"


def _readme_layout() -> list[list[str]]:
    """The modules of each row of the README's "Layout" table, in order."""
    import re

    readme = (PACKAGE.parent / "README.md").read_text()
    section = readme.split("\n## Layout\n", 1)[1].split("\n## ", 1)[0]
    rows = [line for line in section.splitlines() if line.startswith("| ")][1:]  # no header
    return [re.findall(r"`(\w+)\.py`", row.split("|")[2]) for row in rows]


def test_readme_layout_table_matches_the_layers():
    table = _readme_layout()
    assert table, "README.md has no Layout table"
    for index, (row, layer) in enumerate(zip(table, LAYERS, strict=False)):
        assert sorted(row) == sorted(layer), f"README Layout row {index}: {row} vs LAYERS {layer}"
    assert len(table) == len(LAYERS), f"README has {len(table)} layers, LAYERS {len(LAYERS)}"


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
