"""One run at a time in an output folder: a lock the tool owns, taken before anything
is computed (``attitude run``, ``montecarlo``, ``envelope``).

Two jobs started into one folder seconds apart used to both compute; the later wrote
its outputs, and the earlier died at its end blaming files "not attitude's" (the
later's), leaving the folder without its manifest.  Now the second is refused at its
start, with one line naming the run that holds the folder.

The lock is ``.attitude-lock`` in the output folder (created, with its missing
parents, if it does not exist yet): a small JSON file (the holder's PID, host,
command and start) held with an exclusive ``flock`` for as long as the run lasts.
The kernel releases a ``flock`` when its holder dies, whatever kills it (``kill -9``
too), so a lock file left by a dead run is stale by construction and the next run
takes it over; where the file system has no ``flock`` (some network file systems),
the PID it names is asked instead, as for the partial folders
(:mod:`attitude.outputs.folder`).  On its way out (success, error or signal) the run
removes the lock file and the folders it created, if they are empty: a run that
wrote nothing leaves nothing.  :func:`attitude.outputs.folder.claim` knows the lock
file as the tool's own.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import socket
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from attitude.outputs.folder import LOCK_NAME, OutputFolderError, held_signals

__all__ = ["LOCK_NAME", "folder_lock", "lock_holder", "refuse_if_held"]

_FORMAT = "attitude output folder lock"


def _holder_text(data: dict[str, Any]) -> str:
    """The run that holds a lock, in words."""
    started = data.get("started")
    when = (
        time.strftime(" since %Y-%m-%d %H:%M:%S", time.localtime(started))
        if isinstance(started, int | float)
        else ""
    )
    return f"`attitude {data.get('command', '?')}` (PID {data.get('pid', '?')}{when})"


def _read(path: Path) -> dict[str, Any]:
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError):
        return {}
    return data if isinstance(data, dict) and data.get("format") == _FORMAT else {}


def _alive(data: dict[str, Any]) -> bool:
    """Whether the run a lock names is running (on this host; another host's: yes)."""
    pid = data.get("pid")
    if not isinstance(pid, int) or pid == os.getpid():
        return False
    if data.get("host") != socket.gethostname():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # alive, another user's
        return True
    return True


def lock_holder(out_dir: str | Path) -> str | None:
    """The run that holds ``out_dir``'s lock now, in words, or None (no lock, or a
    stale one), without taking it: what ``attitude check`` says."""
    path = Path(out_dir).expanduser() / LOCK_NAME
    if not path.is_file() or path.is_symlink():
        return None
    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return None
    try:
        import fcntl

        try:
            fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except BlockingIOError:
            return _holder_text(_read(path))
        except OSError:  # no flock here: the PID it names
            data = _read(path)
            return _holder_text(data) if _alive(data) else None
        return None
    finally:
        os.close(fd)


def refuse_if_held(out_dir: str | Path, option: str = "--out") -> None:
    """Refuse (:class:`OutputFolderError`) a folder another run holds now, without
    taking its lock: a job's first check, before it plans for seconds."""
    holder = lock_holder(out_dir)
    if holder is not None:
        raise OutputFolderError(
            f"another run, {holder}, is writing into this folder: wait for it to end, or "
            "choose another folder",
            key=option,
            value=str(out_dir),
        )


def _make_folders(path: Path, option: str, shown: str) -> list[Path]:
    """Create ``path`` and its missing parents; the folders created, deepest last."""
    created: list[Path] = []
    missing = [path, *[p for p in path.parents if not p.exists()]]
    for folder in reversed(missing):
        try:
            folder.mkdir()
        except FileExistsError:
            continue
        except OSError as exc:
            for made in reversed(created):
                with contextlib.suppress(OSError):
                    made.rmdir()
            raise OutputFolderError(
                f"cannot create the folder: {exc.strerror or exc}", key=option, value=shown
            ) from None
        created.append(folder)
    return created


def _acquire(path: Path, command: str, option: str, shown: str) -> int:
    """The lock file at ``path`` opened and locked (its descriptor), our data in it."""
    import fcntl

    while True:
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, 0o644)
        except OSError as exc:
            raise OutputFolderError(
                f"cannot write into the folder: {exc.strerror or exc}", key=option, value=shown
            ) from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise OutputFolderError(
                f"another run, {_holder_text(_read(path))}, is writing into this folder: "
                "wait for it to end, or choose another folder",
                key=option,
                value=shown,
            ) from None
        except OSError as exc:
            if exc.errno not in (errno.ENOLCK, errno.EOPNOTSUPP, errno.ENOSYS):
                os.close(fd)
                raise
            data = _read(path)  # no flock on this file system: the PID it names
            if _alive(data):
                os.close(fd)
                raise OutputFolderError(
                    f"another run, {_holder_text(data)}, is writing into this folder: wait "
                    "for it to end, or choose another folder",
                    key=option,
                    value=shown,
                ) from None
        # The file may have been removed (its holder ending) between our open and our
        # lock: then we hold a lock on a file no one else sees; open it again.
        try:
            same = os.path.samestat(os.fstat(fd), os.stat(path, follow_symlinks=False))
        except FileNotFoundError:
            same = False
        if same:
            break
        os.close(fd)
    data = {
        "format": _FORMAT,
        "pid": os.getpid(),
        "host": socket.gethostname(),
        "command": command,
        "started": time.time(),
        "note": "attitude writes into this folder now; it removes this file when it ends",
    }
    os.ftruncate(fd, 0)
    os.write(fd, (json.dumps(data) + "\n").encode())
    return fd


@contextlib.contextmanager
def folder_lock(out_dir: str | Path, command: str, option: str = "--out") -> Iterator[Path]:
    """Hold ``out_dir``'s lock for the block (module notes); yields the folder.

    Creates the folder (with its missing parents) if it does not exist.  Raises
    :class:`~attitude.outputs.folder.OutputFolderError` (one line naming ``option``
    and the folder as given) if another run holds it, or if the folder cannot be
    created or written.  On the way out, the lock file is removed and so are the
    folders created here, if they are empty."""
    shown = str(out_dir)
    path = Path(out_dir).expanduser()
    if path.is_symlink() and not path.exists():
        raise OutputFolderError("a broken symbolic link", key=option, value=shown)
    if path.exists() and not path.is_dir():
        raise OutputFolderError(
            "is a file, not a folder; attitude leaves it alone", key=option, value=shown
        )
    with held_signals():  # a Ctrl-C between the folder and its lock leaves nothing
        created = _make_folders(path.absolute(), option, shown)
        lock = path / LOCK_NAME
        try:
            fd = _acquire(lock, command, option, shown)
        except BaseException:
            _remove_created(created)
            raise
    try:
        yield path
    finally:
        with held_signals():
            with contextlib.suppress(OSError):
                lock.unlink()  # ours: held until here
            os.close(fd)
            _remove_created(created)


def _remove_created(created: list[Path]) -> None:
    for folder in reversed(created):
        with contextlib.suppress(OSError):
            folder.rmdir()  # only if empty: never anything of the user's
