"""The API reference (docs/api, Sphinx) against ``attitude.__all__``, and its example run.

Every name that ``import attitude`` exports must be documented by an autodoc directive
at its home module (or one that re-exports it), so that a name added to the API
without a page fails here rather than in a user's ``dir()``.  The Python example that
the scenario page includes is run as a user would, and its report checked.
"""

import importlib.util
import re
from pathlib import Path

import numpy as np
import pytest

import attitude

DOCS = Path(__file__).resolve().parents[1] / "docs"
_DIRECTIVE = re.compile(r"^\.\. auto(?:class|function|exception|data)::\s+(\S+)", re.M)


def _documented() -> set[str]:
    return {
        name
        for page in sorted((DOCS / "api").glob("*.rst"))
        for name in _DIRECTIVE.findall(page.read_text(encoding="utf-8"))
    }


def _resolve(dotted: str):
    module, _, name = dotted.rpartition(".")
    return getattr(importlib.import_module(module), name)


@pytest.mark.parametrize("name", sorted(set(attitude.__all__) - {"__version__"}))
def test_every_exported_name_has_an_autodoc_entry(name):
    obj = getattr(attitude, name)
    # At its home module, or at a module that re-exports it (attitude.pointing).
    assert any(_resolve(dotted) is obj for dotted in _documented()), (
        f"attitude.{name} is exported but no page of docs/api documents it "
        f"(its home: {obj.__module__}.{name})"
    )


def test_version_is_documented():
    text = "".join(page.read_text(encoding="utf-8") for page in (DOCS / "api").glob("*.rst"))
    assert ".. py:data:: attitude.__version__" in text


def test_every_documented_name_exists():
    for dotted in _documented():
        _resolve(dotted)  # AttributeError or ImportError names what is gone


def test_scenario_in_python_example_runs(tmp_path, capsys):
    path = DOCS / "examples" / "scenario_in_python.py"
    spec = importlib.util.spec_from_file_location("scenario_in_python", path)
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)

    summary = example.main(tmp_path / "out")

    printed = capsys.readouterr().out
    assert "q_body_to_icrf (w, x, y, z)" in printed
    assert {"timeseries.csv", "attitude.aem", "summary.json", "report.html"} <= {
        p.name for p in (tmp_path / "out").iterdir()
    }
    # The impulse at 60 s starts a second segment; both are periodic tumbles.
    assert len(summary["motion"]) == 2
    # The T-handle flips: its first quaternion row is the identity, scalar first.
    scenario = example.build()
    q0 = attitude.propagate(scenario).attitude_quaternion(scenario.times(0.0))
    np.testing.assert_allclose(np.abs(q0), [1.0, 0.0, 0.0, 0.0], atol=1e-12)
