"""Every code block of README.md and docs/*.md does what it shows.

- A ``python`` block runs: the blocks of one page run in order in one fresh process,
  as a script of them run with ``python script.py`` (a script, not ``python -c``: a
  process that Dask or multiprocessing starts imports a script again, which ``-c``
  hid, so the README's envelope once failed as written), from a scratch folder that
  holds the repository's ``scenarios/`` and ``docs/`` (so relative paths work and
  nothing is written into the clone).  It imports the package only as ``from attitude import``
  or ``import attitude``: the public API is what ``attitude`` exports.
- A ``toml`` block parses.
- A ``sh`` block's ``attitude check``, ``attitude run`` and ``attitude fit`` lines run to
  exit 0 (the others install, build or benchmark: CI's own steps, or ``benchmarks/``).
"""

import os
import re
import shlex
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
_BLOCK = re.compile(r"^```(\w*)\n(.*?)^```", re.S | re.M)
_DEEP_IMPORT = re.compile(r"^\s*(?:from|import)\s+attitude\.\w", re.M)
# Blocks that still name a module path, each with what makes it public.
_NOT_YET_PUBLIC: dict[str, str] = {}
_PLACEHOLDER = re.compile(r"^[A-Z][A-Z_]*(\.toml)?$")  # FILE, DIR, SCENARIO.toml: a template


def _blocks(language: str) -> list[tuple[Path, int, str]]:
    found = []
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        for match in _BLOCK.finditer(text):
            if match.group(1) == language:
                line = text.count("\n", 0, match.start()) + 1
                found.append((page, line, match.group(2)))
    return found


def _name(page: Path) -> str:
    return str(page.relative_to(ROOT))


def _scratch(tmp_path: Path) -> Path:
    """A working folder where ``scenarios/...`` and ``docs/...`` resolve, and
    ``results/...`` is written into the scratch folder."""
    for name in ("scenarios", "docs"):
        (tmp_path / name).symlink_to(ROOT / name)
    return tmp_path


def _environment() -> dict[str, str]:
    env = dict(os.environ, MPLBACKEND="Agg")
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), env.get("PYTHONPATH")]))
    return env


_PYTHON_PAGES = sorted({page for page, _, _ in _blocks("python")}, key=str)


@pytest.mark.parametrize("page", _PYTHON_PAGES, ids=_name)
def test_python_blocks_run(page, tmp_path):
    blocks = [(line, code) for p, line, code in _blocks("python") if p == page]
    program = "\n".join(
        f"print('--- block at line {line}', flush=True)\n{code}" for line, code in blocks
    )
    script = _scratch(tmp_path) / "blocks.py"
    script.write_text(program, encoding="utf-8")
    run = subprocess.run(
        [sys.executable, str(script)],
        cwd=tmp_path,
        env=_environment(),
        capture_output=True,
        text=True,
        timeout=600,
    )
    failed_at = re.findall(r"--- block at line (\d+)", run.stdout)
    where = f"{_name(page)}:{failed_at[-1] if failed_at else '?'}"
    assert run.returncode == 0, f"{where}\n{run.stderr[-3000:]}"


@pytest.mark.parametrize(
    ("page", "line", "code"),
    _blocks("python"),
    ids=[f"{_name(p)}:{line}" for p, line, _ in _blocks("python")],
)
def test_python_blocks_use_the_public_api(page, line, code):
    deep = _DEEP_IMPORT.findall(code)
    if deep and f"{_name(page)}:{line}" in _NOT_YET_PUBLIC:
        pytest.xfail(_NOT_YET_PUBLIC[f"{_name(page)}:{line}"])
    assert not deep, f"{_name(page)}:{line} imports a module path: {deep} (use `from attitude`)"


@pytest.mark.parametrize(
    ("page", "line", "code"),
    _blocks("toml"),
    ids=[f"{_name(p)}:{line}" for p, line, _ in _blocks("toml")],
)
def test_toml_blocks_parse(page, line, code):
    tomllib.loads(code)


def _commands() -> list[tuple[str, list[str]]]:
    found = []
    for page, line, code in _blocks("sh"):
        for offset, text in enumerate(code.splitlines()):
            for part in text.split("#", 1)[0].split("&&"):
                words = shlex.split(part)
                template = any(_PLACEHOLDER.match(word) for word in words)
                commands = (["attitude", "check"], ["attitude", "run"], ["attitude", "fit"])
                if words[:2] in commands and not template:
                    found.append((f"{_name(page)}:{line + 1 + offset}", words))
    return found


@pytest.mark.parametrize(("where", "words"), _commands(), ids=[w for w, _ in _commands()])
def test_shell_commands_run(where, words, tmp_path):
    files = [word for word in words if word.endswith(".toml")]
    if any(word.startswith("results/") for word in files):
        pytest.skip(f"{where}: reads what an earlier command of the block writes")
    missing = [word for word in files if not (ROOT / word).exists()]
    assert not missing, f"{where}: names scenario files not in the repository: {missing}"
    run = subprocess.run(
        [sys.executable, "-m", "attitude", *words[1:]],
        cwd=_scratch(tmp_path),
        env=_environment(),
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 0, f"{where}: {' '.join(words)}\n{run.stderr[-2000:]}"
