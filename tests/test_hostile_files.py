"""Every hostile file in tests/hostile/ ends in exit 0, or exit 2 with one line.

Each file is copied into a folder of the user's (beside a thesis, a data file and
the orbit and attitude files that the hostile scenarios name) and run through
`attitude check --out` and `attitude run --out` a new folder (the disk is the one
check that needs the folder), then `attitude run --out` the user's folder itself.
After each: exit 0 (stderr holds only
one-line warnings or notes, and the outputs are there) or exit 2 (exactly one line on
stderr and no output folder); never a traceback; `check` and `run` agree; and every
file of the user's is byte for byte as it was.
"""

import shutil
from pathlib import Path

import pytest

from attitude.cli.main import main

HOSTILE = sorted((Path(__file__).parent / "hostile").glob("*.toml"))
# The OEM and AEM files the hostile scenarios read (beside them, as a user keeps them).
COMPANIONS = sorted(
    p for p in (Path(__file__).parent / "hostile").iterdir() if p.suffix in (".oem", ".aem")
)


def _snapshot(folder: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()
    }


def _call(capsys, argv) -> tuple[int, list[str], str]:
    code = main(argv)
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err and "Traceback" not in captured.out
    return code, captured.err.splitlines(), captured.out


def test_there_are_hostile_files():
    assert len(HOSTILE) >= 40


@pytest.mark.parametrize("path", HOSTILE, ids=[p.stem for p in HOSTILE])
def test_a_hostile_file_ends_cleanly(path, tmp_path, capsys):
    user = tmp_path / "user"
    user.mkdir()
    scenario = user / path.name
    shutil.copyfile(path, scenario)
    for companion in COMPANIONS:
        shutil.copyfile(companion, user / companion.name)
    (user / "thesis.tex").write_text("months of work\n")
    (user / "data.csv").write_text("t,x\n0,1\n")
    before = _snapshot(user)

    out = tmp_path / "out"
    checked, check_err, _ = _call(capsys, ["check", str(scenario), "--out", str(out)])
    ran, run_err, _ = _call(capsys, ["run", str(scenario), "--out", str(out), "--quiet"])
    assert checked == ran, (check_err, run_err)  # check refuses whatever run refuses
    assert ran in (0, 2), run_err
    if ran == 2:
        assert len(check_err) == 1 and check_err == run_err, (check_err, run_err)
        assert check_err[0].startswith("attitude: error: ")
        assert not out.exists()
    else:
        assert all(line.startswith(("attitude: warning: ", "attitude: note: ")) for line in run_err)
        assert (out / "attitude-manifest.json").is_file() and (out / "report.html").is_file()
    assert _snapshot(user) == before

    # The user's own folder as the output folder: refused, nothing touched.
    code, err, _ = _call(capsys, ["run", str(scenario), "--out", str(user), "--quiet"])
    assert code == 2 and len(err) == 1, err
    assert _snapshot(user) == before
