"""Output folders: ``attitude`` removes or overwrites only files it wrote itself.

A folder becomes *ours* when ``attitude`` writes a manifest into it,
``attitude-manifest.json``: the name, size and SHA-256 of every file of the run.
The rules, checked before anything is computed:

- a path that does not exist is created (with its missing parents);
- an empty folder is used (a manifest is written first, marking it ours);
- a folder with our manifest is reused: its previous outputs (the files the manifest
  lists, still as we wrote them) are replaced, every other file is left alone;
- anything else is refused with one line: a non-empty folder without our manifest
  (the user's home, the scenario's own folder, ``.``), a path that is a file, a file
  of ours that was edited since we wrote it, a file of the user's under a name we
  would write.  Nothing is ever deleted to make room, so no flag is offered to force
  it: the remedy is always to choose a new or empty folder.

Two more entries of a folder are the tool's own, and never make it foreign: the
lock of the run writing into it (``.attitude-lock``, :mod:`attitude.outputs.lock`)
and a long job's checkpoint (``.attitude-checkpoint/``: ``checkpoint.json`` and the
finished batches, ``part-NNNNNN.parquet``; :mod:`attitude.jobs.checkpoint`), a folder
holding nothing else.  Before anything is computed, :func:`claim` also tries
the folder: a file created and removed there (or, for a folder still to be made, the
folder itself), so that a read-only or unwritable folder is refused at the start, not
found after the whole computation.

The outputs are built in ``.attitude-partial-PID/`` *inside* the output folder (the
same file system, so each file moves into place with an atomic ``os.replace``), and
then moved in under a manifest that accepts either version of every file, so that a
run stopped at any instant, even by ``kill -9``, leaves a folder that the next run
recognizes and cleans.  On any failure or signal (SIGINT, SIGTERM), the partial
folder is removed, and so are a manifest and folders this run created: nothing is
left beside the user's files.  SIGINT and SIGTERM are held while the files move into
place and while cleaning up, and delivered right after.  A write that fails (a full
disk) is a :class:`~attitude.base.errors.MachineError` naming the folder as the user
wrote it, raised once nothing of the run is left in it.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import re
import signal
import threading
from collections.abc import Callable, Collection, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from attitude.base.errors import MachineError, OptionError
from attitude.base.signals import STOPPING

__all__ = [
    "CHECKPOINT_FILES",
    "CHECKPOINT_NAME",
    "LOCK_NAME",
    "MANIFEST_NAME",
    "OutputFolder",
    "OutputFolderError",
    "OutputWriteError",
    "claim",
    "held_signals",
    "is_checkpoint",
]

MANIFEST_NAME = "attitude-manifest.json"
LOCK_NAME = ".attitude-lock"
CHECKPOINT_NAME = ".attitude-checkpoint"
# The files of a checkpoint folder: its record, the parts of finished batches, and
# one being written (renamed into place once whole).
CHECKPOINT_FILES = re.compile(
    r"checkpoint\.json|part-\d{6}\.parquet|\.tmp-\d+-(part\.parquet|checkpoint\.json)"
)
_FORMAT = "attitude output manifest"
_FORMAT_VERSION = 1
_PARTIAL_PREFIX = ".attitude-partial-"
_PARTIAL = re.compile(re.escape(_PARTIAL_PREFIX) + r"\d+")
_HELD = STOPPING


class OutputFolderError(OptionError):
    """The output folder cannot be used without touching files that are not ours, or
    cannot be written at all.

    ``key`` is the command-line option that named the folder (``--out``,
    ``--emit-scenario``) and ``value`` the folder as given: ``--out results: reason``."""


class OutputWriteError(MachineError, OSError):
    """The outputs could not be written (a full disk, a folder that became unwritable);
    nothing of the run is left in the folder, named as the user wrote it.  Also an
    ``OSError``, as the write's own error was: code that catches that still does."""


def is_checkpoint(path: Path) -> bool:
    """Whether ``path`` is a checkpoint folder of ours: a folder (not a link) holding
    only the files of a checkpoint (:data:`CHECKPOINT_FILES`)."""
    if path.is_symlink() or not path.is_dir():
        return False
    try:
        names = os.listdir(path)
    except OSError:
        return False
    return all(CHECKPOINT_FILES.fullmatch(name) for name in names)


def _ours(folder: Path, name: str) -> bool:
    """Whether the entry ``name`` of ``folder`` is one of the tool's own that no
    manifest lists: a run's lock, a job's checkpoint."""
    path = folder / name
    if name == LOCK_NAME:
        return path.is_file() and not path.is_symlink()
    return name == CHECKPOINT_NAME and is_checkpoint(path)


def _unwritable(folder: Path) -> str | None:
    """Why the existing ``folder`` cannot take a new file (None if it can), in the
    words of the system: a file is created there and removed.  ``os.access`` alone
    would not do: it says nothing of a read-only file system's reason, and root
    writes into a folder whatever its mode (then the folder is writable)."""
    probe = folder / f".attitude-probe-{os.getpid()}-{threading.get_ident()}"
    try:
        descriptor = os.open(probe, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    except OSError as exc:
        return exc.strerror or str(exc)
    os.close(descriptor)
    probe.unlink(missing_ok=True)
    return None


@contextlib.contextmanager
def held_signals() -> Iterator[None]:
    """SIGINT, SIGTERM and SIGHUP are held in this scope and delivered on exit.

    Only the main thread can handle signals; elsewhere this scope does nothing.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    received: list[int] = []
    previous = {}
    for number in _HELD:
        handler = signal.getsignal(number)
        # None: set outside Python, and could not be restored; SIG_IGN: the caller's
        # wish (nohup's SIGHUP), nothing to hold (attitude.base.signals).
        if handler is not None and handler is not signal.SIG_IGN:
            previous[number] = signal.signal(number, lambda n, frame: received.append(n))
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)
        for number in dict.fromkeys(received):
            signal.raise_signal(number)


def _digest(path: Path) -> tuple[int, str]:
    """(size in bytes, SHA-256 hex) of the file at ``path``."""
    sha = hashlib.sha256()
    size = 0
    with open(path, "rb") as stream:
        while chunk := stream.read(1 << 20):
            sha.update(chunk)
            size += len(chunk)
    return size, sha.hexdigest()


def _read_manifest(folder: Path, allowed: Collection[str]) -> dict[str, Any] | None:
    """Our manifest in ``folder``, or None if there is none (or not one of ours)."""
    path = folder / MANIFEST_NAME
    if path.is_symlink() or not path.is_file():
        return None
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError):
        return None
    if not (isinstance(data, dict) and data.get("format") == _FORMAT):
        return None
    entries: dict[str, list[tuple[int, str]]] = {}
    for key in ("files", "previous"):
        files = data.get(key, {})
        if not isinstance(files, dict):
            return None
        for name, entry in files.items():
            # Only names we write: a manifest edited to list anything else is not ours.
            if name not in allowed or not (
                isinstance(entry, dict)
                and isinstance(entry.get("bytes"), int)
                and isinstance(entry.get("sha256"), str)
            ):
                return None
            entries.setdefault(name, []).append((entry["bytes"], entry["sha256"]))
    data["_accepted"] = entries
    return data


def _write_manifest(folder: Path, files: dict, previous: dict, source: str, version: str) -> None:
    """Write the manifest atomically (a temporary file renamed over it)."""
    data = {
        "format": _FORMAT,
        "format_version": _FORMAT_VERSION,
        "written_by": f"attitude {version}",
        "scenario": source,
        "note": "attitude replaces only the files listed here; it never touches other files",
        "files": files,
    }
    if previous:
        data["previous"] = previous
    tmp = folder / f".{MANIFEST_NAME}.{os.getpid()}"
    try:
        tmp.write_text(json.dumps(data, indent=2, ensure_ascii=False) + "\n", encoding="utf-8")
        os.replace(tmp, folder / MANIFEST_NAME)
    finally:
        tmp.unlink(missing_ok=True)


@dataclass
class OutputFolder:
    """An output folder claimed for a run: see :func:`claim` and :meth:`write`."""

    path: Path
    names: frozenset[str]
    created: list[Path]  # folders this run created, deepest last
    owned: dict[str, dict[str, Any]]  # our files already there: name -> manifest entry
    stat: dict[str, tuple[int, int]]  # their (size, mtime_ns) when checked
    new_manifest: bool  # no manifest before this run
    shown: str = ""  # the folder as the user wrote it, for messages
    option: str = "--out"

    def write(
        self, build: Callable[[Path], list[str]], source: str = "", version: str = ""
    ) -> list[str]:
        """Run ``build(tmp)``, which writes files into ``tmp`` and returns their names,
        then move them into the folder in place of our previous outputs.

        On any exception (signals included) nothing of this run is left behind and
        the previous outputs are untouched; a write that fails (``OSError``: a full
        disk) is raised as :class:`OutputWriteError`, naming the folder as given.
        """
        try:
            return self._write(build, source, version)
        except OSError as exc:
            what = exc.strerror or " ".join(str(exc).split())
            raise OutputWriteError(
                f"{self.option} {self.shown or self.path}: the outputs could not be written "
                f"({what}); nothing of this run was left in the folder"
            ) from exc

    def _write(self, build: Callable[[Path], list[str]], source: str, version: str) -> list[str]:
        partial = self.path / f"{_PARTIAL_PREFIX}{os.getpid()}"
        moving = False
        try:
            if self.new_manifest:
                _write_manifest(self.path, {}, {}, source, version)
            partial.mkdir()
            names = build(partial)
            unknown = sorted(set(names) - self.names)
            if unknown:
                raise ValueError(f"build wrote files outside the output names: {unknown}")
            files = {}
            for name in names:
                size, sha = _digest(partial / name)
                files[name] = {"bytes": size, "sha256": sha}
            with held_signals():
                self._check_unchanged()
                # While the files move, the manifest accepts either version of each.
                _write_manifest(self.path, files, self.owned, source, version)
                moving = True
                for name in names:
                    os.replace(partial / name, self.path / name)
                for name in set(self.owned) - set(names):
                    (self.path / name).unlink(missing_ok=True)
                _write_manifest(self.path, files, {}, source, version)
                partial.rmdir()
            return names
        except BaseException:
            with held_signals():
                self._discard(partial, keep_manifest=moving)
            raise

    def _check_unchanged(self) -> None:
        """Our previous files are still as they were when the folder was claimed."""
        for name, (size, mtime) in self.stat.items():
            path = self.path / name
            try:
                now = path.lstat()
            except FileNotFoundError:
                continue
            if (now.st_size, now.st_mtime_ns) != (size, mtime):
                raise OutputFolderError(
                    f"{path} was changed during the run: attitude leaves it alone"
                )
        for name in self.names - set(self.owned) - {MANIFEST_NAME}:
            if os.path.lexists(self.path / name):
                raise OutputFolderError(
                    f"{self.path / name} appeared during the run and is not attitude's: "
                    "attitude will not replace it"
                )

    def _discard(self, partial: Path, keep_manifest: bool) -> None:
        """Remove what this run wrote: the partial folder, a new manifest, new folders.

        Once files have started to move into place, the manifest stays: it lists them
        (in either version), so that the next run recognizes and replaces them.
        """
        _remove_partial(partial, self.names)
        if self.new_manifest and not keep_manifest:
            (self.path / MANIFEST_NAME).unlink(missing_ok=True)
        for folder in reversed(self.created):
            with contextlib.suppress(OSError):
                folder.rmdir()  # only if empty: never anything of the user's


def _running(partial_name: str) -> bool:
    """True if the run that owns this partial folder (by its PID) is still running."""
    pid = int(partial_name.removeprefix(_PARTIAL_PREFIX))
    if pid == os.getpid():
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # alive, but another user's
        return True
    return True


def _remove_partial(partial: Path, names: Collection[str]) -> None:
    """Remove a partial folder of ours: the output files in it, then the folder if empty."""
    if partial.is_symlink() or not partial.is_dir():
        return
    for entry in partial.iterdir():
        if entry.name in names and entry.is_file() and not entry.is_symlink():
            entry.unlink(missing_ok=True)
    with contextlib.suppress(OSError):
        partial.rmdir()


def claim(
    out_dir: str | Path, names: Collection[str], dry_run: bool = False, option: str = "--out"
) -> OutputFolder:
    """Check that ``out_dir`` can take a run's outputs without touching the user's files.

    ``names``: every file name the run may write.  Creates the folder if it does not
    exist (unless ``dry_run``: then nothing is cleaned, and a folder made to try it is
    removed), and tries it (module notes).  Raises :class:`OutputFolderError` (one
    line, naming ``option``, the folder as given and the reason) if the folder is not
    ours, or cannot be created or written.
    """
    names = frozenset(names) | {MANIFEST_NAME}
    path = Path(out_dir).expanduser()
    shown = str(out_dir)

    def refused(reason: str) -> OutputFolderError:
        return OutputFolderError(reason, key=option, value=shown)

    if path.is_symlink() and not path.exists():
        raise refused("a broken symbolic link")
    if path.exists() and not path.is_dir():
        raise refused("is a file, not a folder; attitude leaves it alone")
    path = path.resolve()
    created: list[Path] = []

    def folder(
        created: list[Path], owned: dict | None = None, stat: dict | None = None, new=True
    ) -> OutputFolder:
        return OutputFolder(path, names, created, owned or {}, stat or {}, new, shown, option)

    if not path.exists():
        missing = [path, *[p for p in path.parents if not p.exists()]]
        for made in reversed(missing):
            try:
                made.mkdir()
            except FileExistsError:
                continue
            except OSError as exc:
                _remove_folders(created)
                raise refused(f"cannot create the folder: {exc.strerror or exc}") from None
            created.append(made)
        why = _unwritable(path)
        if why is not None or dry_run:  # a dry run: the folder made and removed, a probe
            _remove_folders(created)
            created = []
        if why is not None:
            raise refused(f"cannot be written: {why}")
        return folder(created)

    try:
        entries = sorted(name for name in os.listdir(path) if not _ours(path, name))
    except OSError as exc:
        raise refused(f"cannot be read: {exc.strerror or exc}") from None
    manifest = _read_manifest(path, names)
    if manifest is None and entries:
        listed = ", ".join(entries[:3]) + (", ..." if len(entries) > 3 else "")
        raise refused(
            "the folder holds files that attitude did not write "
            f"({listed}); attitude writes only into a new or empty folder, or one it "
            f"wrote before (with {MANIFEST_NAME}): choose another folder"
        )
    why = _unwritable(path)  # tried once it is known to be ours (or empty)
    if why is not None:
        raise refused(f"cannot be written: {why}")
    if manifest is None:
        return folder(created)

    # Our folder: clean the partial folders of runs that were killed, check our files.
    for entry in entries:
        if _PARTIAL.fullmatch(entry) and not dry_run and not _running(entry):
            _remove_partial(path / entry, names)
    accepted = manifest["_accepted"]
    owned, stat = {}, {}
    for name in sorted(names - {MANIFEST_NAME}):
        file = path / name
        if not os.path.lexists(file):
            continue
        if name not in accepted:
            raise refused(
                f"{name} is not listed in {MANIFEST_NAME}, so it is not "
                "attitude's: attitude will not replace it; move it or choose another folder"
            )
        digest = None if file.is_symlink() or not file.is_file() else _digest(file)
        if digest is None or digest not in accepted[name]:
            raise refused(
                f"{name} was changed after attitude wrote it: attitude will "
                "not replace it; move it or choose another folder"
            )
        owned[name] = {"bytes": digest[0], "sha256": digest[1]}
        status = file.lstat()
        stat[name] = (status.st_size, status.st_mtime_ns)
    return folder(created, owned, stat, new=False)


def _remove_folders(created: list[Path]) -> None:
    for made in reversed(created):
        with contextlib.suppress(OSError):
            made.rmdir()  # only if empty
