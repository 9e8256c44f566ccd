"""A long job's finished batches, kept as they arrive, so that an interrupted job
(Ctrl-C, SIGTERM, ``kill -9``, a lost scheduler) continues with ``--resume`` from what
was finished, to the same outputs byte for byte as an uninterrupted run.

The checkpoint is a folder inside the job's output folder, ``.attitude-checkpoint/``
(hidden, and named so that nobody takes it for results): ``checkpoint.json`` (which
job it belongs to, and a note saying what it is) and Parquet files
``part-NNNNNN.parquet``, each the rows of some finished batches (with what else the
job gathers from them, such as the Monte Carlo's Sun-angle extremes, in columns of
their own; their CPU time in the file's metadata), written whole and then renamed
into place, so that a job killed at any instant leaves only whole parts.  The
batches that come in are written together: once they hold 1 % of the job's items, or
once a minute has passed since the last part, and whenever the job stops (an error,
a signal).  So a job writes about a hundred parts, plus one a minute at most (a file
a task, with 26 kB of Parquet metadata each for the Monte Carlo's 92 columns, was
more than the table), and ``kill -9``, which leaves no time to write, loses at most a
minute's or 1 % of the job's results.  The folder rules know the checkpoint
(:func:`attitude.outputs.folder.is_checkpoint`): the tool never takes its own
checkpoint for a user's file, and removes only the files it writes there.  A job
that completes removes its checkpoint once its outputs are in place; a job that
fails keeps it, and says so in its last line.

A checkpoint belongs to one job: ``checkpoint.json`` holds the SHA-256 of the job's
identity (its kind, the scenario document and the files it names, the sample count
and seed or the failure times, the digest of the package's code:
:func:`attitude.jobs.fingerprint.code_digest`).  ``--resume`` continues only the job
it belongs to, and refuses another with one line; a run without ``--resume``
discards a checkpoint it finds, and says so.

The rows a batch adds to the table go through their Arrow form whether they were
computed now or read back (:func:`canonical_rows`): a table is the same built from
either, to the last bit.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import re
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

from attitude.base.errors import MachineError, OptionError
from attitude.base.version import __version__
from attitude.jobs.fingerprint import code_digest
from attitude.outputs.folder import (
    CHECKPOINT_FILES,
    CHECKPOINT_NAME,
    OutputFolderError,
    held_signals,
)
from attitude.outputs.lock import folder_lock

if TYPE_CHECKING:
    import pandas
    import pyarrow

__all__ = [
    "Checkpoint",
    "batch_table",
    "canonical_rows",
    "checkpoint_summary",
    "file_digests",
    "identity_digest",
    "job_folder",
    "kept_on_failure",
    "missing_ranges",
]

_FORMAT = "attitude job checkpoint"
_FORMAT_VERSION = 1
_RECORD = "checkpoint.json"
_PART = re.compile(r"part-(\d{6})\.parquet")
_META_KEY = b"attitude-part"
# A part is written once it holds this share of the job's items, or once this many
# seconds have passed since the last one (module notes).
_PART_SHARE = 0.01
_PART_EVERY_S = 60.0


def identity_digest(identity: dict[str, Any]) -> str:
    """SHA-256 of a job's identity (JSON, keys sorted), with the code's digest."""
    text = json.dumps({**identity, "code": code_digest()}, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def file_digests(paths: list[str]) -> dict[str, str]:
    """SHA-256 of each file a job's document names (an OEM, an AEM), so that a file
    changed since the checkpoint makes another job ("absent" for one not there)."""
    found = {}
    for name in paths:
        try:
            found[name] = hashlib.sha256(Path(name).read_bytes()).hexdigest()
        except OSError:
            found[name] = "absent"
    return found


def batch_table(frame: pandas.DataFrame) -> pyarrow.Table:
    """A batch's frame as the checkpoint keeps it: an Arrow table (its columns' types
    from their values; no index, no pandas metadata)."""
    import pyarrow as pa

    table = pa.Table.from_pandas(frame, preserve_index=False)
    return table.replace_schema_metadata(None)


def canonical_rows(table: pyarrow.Table) -> list[dict[str, Any]]:
    """A batch's rows as the table of the job takes them, from the batch's Arrow table
    (:func:`batch_table`, or as read back): each row's values as Python scalars, a
    null left out (as a key the row never had)."""
    rows = table.to_pandas().to_dict("records")
    return [{k: v for k, v in row.items() if v is not None} for row in rows]


def missing_ranges(count: int, done: list[int]) -> list[tuple[int, int]]:
    """[first, stop) of the runs of items ``0 … count − 1`` not in ``done``."""
    missing, cursor = [], 0
    for item in sorted(set(done)):
        if item > cursor:
            missing.append((cursor, item))
        cursor = max(cursor, item + 1)
    if cursor < count:
        missing.append((cursor, count))
    return missing


def _read_record(folder: Path) -> dict[str, Any] | None:
    try:
        data = json.loads((folder / _RECORD).read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError):
        return None
    return data if isinstance(data, dict) and data.get("format") == _FORMAT else None


def _parts(folder: Path) -> list[Path]:
    try:
        names = os.listdir(folder)
    except OSError:
        return []
    return sorted(folder / name for name in names if _PART.fullmatch(name))


def _done(parts: list[Path], index: str) -> list[int]:
    """The items the parts hold (their ``index`` column)."""
    import pyarrow.parquet as pq

    found: list[int] = []
    for part in parts:
        found += pq.read_table(part, columns=[index]).column(index).to_pylist()
    return found


def checkpoint_summary(out_dir: str | Path) -> str | None:
    """What a checkpoint in ``out_dir`` holds, in words (None if there is none): what
    ``attitude check`` says."""
    folder = Path(out_dir).expanduser() / CHECKPOINT_NAME
    record = _read_record(folder) if folder.is_dir() else None
    if record is None:
        return None
    return (
        f"{os.path.join(str(out_dir), CHECKPOINT_NAME)} holds "
        f"{Checkpoint(folder, '', record).done:,} of {record.get('count', '?'):,} "
        f"{record.get('noun', 'items')} of an interrupted `attitude {record.get('kind', '?')}` "
        f"job ({record.get('describe', '')}): the job's command with --resume continues it, "
        "and without --resume discards it"
    )


class Checkpoint:
    """The checkpoint of one job in its output folder (module notes); made by
    :meth:`open`.  :meth:`add` takes the batches as they come in, :meth:`flush` writes
    those not written yet as a part."""

    def __init__(self, folder: Path, shown: str, record: dict[str, Any]) -> None:
        self.folder = folder
        self.shown = shown  # as the user wrote the output folder, with our name
        self.record = record
        self._waiting: list[pyarrow.Table] = []
        self._waiting_meta: dict[str, float] = {}
        self._waiting_items = 0
        self._written = len(_parts(folder))
        self._last = time.monotonic()

    @property
    def count(self) -> int:
        return int(self.record["count"])

    @property
    def noun(self) -> str:
        return str(self.record["noun"])

    @property
    def index(self) -> str:
        """The column that numbers the items ("sample", "failure")."""
        return str(self.record.get("index"))

    @classmethod
    def open(
        cls,
        out_dir: str | Path,
        kind: str,
        identity: dict[str, Any],
        count: int,
        noun: str,
        index: str,
        describe: str,
        resume: bool,
        note: Callable[[str], None],
    ) -> Checkpoint:
        """The checkpoint of a job in ``out_dir`` (which exists, and whose lock the
        job holds): with ``resume``, the one found there if it is this job's (an
        :class:`OptionError` if it is another's; a note if there is none); without,
        a new one (a checkpoint found there is discarded, with a note).  ``index``:
        the rows' column numbering the items; ``describe``: the job in a few words,
        for the messages."""
        folder = Path(out_dir).expanduser() / CHECKPOINT_NAME
        shown = os.path.join(str(out_dir), CHECKPOINT_NAME)
        record = {
            "format": _FORMAT,
            "format_version": _FORMAT_VERSION,
            "kind": kind,
            "key": identity_digest(identity),
            "count": count,
            "noun": noun,
            "index": index,
            "describe": describe,
            "written_by": f"attitude {__version__}",
            "note": (
                "An interrupted job's finished batches: not results. `attitude "
                f"{kind} ... --resume` continues the job from them; attitude removes "
                "this folder when the job completes, or when a job starts here afresh."
            ),
        }
        if folder.is_symlink() or (folder.exists() and not folder.is_dir()):
            raise OutputFolderError(
                f"{CHECKPOINT_NAME} is not a checkpoint of attitude's: move it",
                key="--out",
                value=str(out_dir),
            )
        found = _read_record(folder) if folder.is_dir() else None
        if found is not None and resume:
            if found.get("key") != record["key"]:
                theirs = found.get("describe", "")
                differs = (
                    f"({theirs}; this job: {describe})"
                    if theirs != describe
                    else "(the same scenario file name, sample count and seed, but another "
                    "scenario document, files it names, or attitude's code)"
                )
                raise OptionError(
                    f"the checkpoint {shown} belongs to another job {differs}: run "
                    "without --resume to start this one afresh (the checkpoint is then "
                    "discarded)",
                    key="--resume",
                )
            return cls(folder, shown, record)
        if found is not None:
            earlier = cls(folder, shown, found)
            done = earlier.done
            earlier.discard()
            note(
                f"the checkpoint of an earlier job in {shown} ({done:,} of "
                f"{found.get('count', '?'):,} {found.get('noun', 'items')}: "
                f"{found.get('describe', '')}) was discarded: this job starts afresh "
                "(--resume continues a job)"
            )
        elif resume:
            note(f"--resume: no checkpoint in {out_dir}: the job starts from the beginning")
        checkpoint = cls(folder, shown, record)
        checkpoint._write_record()
        return checkpoint

    def _failed(self, exc: OSError, what: str) -> MachineError:
        return MachineError(
            f"--out {self.shown}: {what} ({exc.strerror or exc}); the finished batches "
            "before them are kept"
        )

    def _unreadable(self, exc: BaseException) -> OptionError:
        return OptionError(
            f"the checkpoint {self.shown} cannot be read ({' '.join(str(exc).split())}): run "
            "without --resume to start afresh",
            key="--resume",
        )

    def _write_record(self) -> None:
        try:
            self.folder.mkdir(exist_ok=True)
            tmp = self.folder / f".tmp-{os.getpid()}-checkpoint.json"
            tmp.write_text(json.dumps(self.record, indent=2) + "\n", encoding="utf-8")
            os.replace(tmp, self.folder / _RECORD)
        except OSError as exc:
            raise self._failed(exc, "the checkpoint could not be written") from None

    @property
    def done(self) -> int:
        """How many items the checkpoint holds: those written (a part that cannot be
        read counts none), and those taken and not written yet."""
        try:
            written = len(_done(_parts(self.folder), self.index))
        except (OSError, ValueError, KeyError):
            written = 0
        return written + self._waiting_items

    def finished(self) -> list[int]:
        """The items of the parts written, in order (what a resumed job has)."""
        try:
            items = _done(_parts(self.folder), self.index)
        except (OSError, ValueError, KeyError) as exc:  # pyarrow's: ValueError, OSError
            raise self._unreadable(exc) from None
        return sorted(i for i in items if 0 <= i < self.count)

    def parts(self) -> Iterator[tuple[pyarrow.Table, dict[str, Any]]]:
        """The parts written: each one's table and ``meta``."""
        import pyarrow.parquet as pq

        for path in _parts(self.folder):
            try:
                table = pq.read_table(path)
                meta = json.loads((table.schema.metadata or {}).get(_META_KEY, b"{}"))
            except (OSError, ValueError) as exc:
                raise self._unreadable(exc) from None
            yield table.replace_schema_metadata(None), meta

    def add(self, table: pyarrow.Table, meta: dict[str, float]) -> None:
        """Take a finished batch (:func:`batch_table`: its rows, and the job's other
        columns) with its ``meta`` (numbers: those named ``*_s``, its CPU time, are
        summed over a part, the others the same for every batch); written with others
        as a part (module notes)."""
        self._waiting.append(table)
        for key, value in meta.items():
            summed = self._waiting_meta.get(key, 0.0) if key.endswith("_s") else 0.0
            self._waiting_meta[key] = summed + value
        self._waiting_items += table.num_rows
        full = self._waiting_items >= max(1, math.ceil(_PART_SHARE * self.count))
        if full or time.monotonic() - self._last >= _PART_EVERY_S:
            self.flush()

    def flush(self) -> None:
        """Write the batches taken and not written yet as one part, whole, then
        renamed into place (no column statistics: a part's own metadata is most of a
        small one's size)."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        if not self._waiting:
            return
        # A column of nulls in one batch and of numbers in another is of numbers.
        table = pa.concat_tables(self._waiting, promote_options="permissive")
        table = table.replace_schema_metadata({_META_KEY: json.dumps(self._waiting_meta)})
        tmp = self.folder / f".tmp-{os.getpid()}-part.parquet"
        try:
            pq.write_table(table, tmp, write_statistics=False)
            os.replace(tmp, self.folder / f"part-{self._written + 1:06d}.parquet")
        except OSError as exc:
            with contextlib.suppress(OSError):
                tmp.unlink()
            raise self._failed(exc, "finished batches could not be kept") from None
        self._written += 1
        self._waiting, self._waiting_meta, self._waiting_items = [], {}, 0
        self._last = time.monotonic()

    def discard(self) -> None:
        """Remove the checkpoint: its files (only those a checkpoint holds), then the
        folder if nothing else is left in it."""
        self._waiting, self._waiting_meta, self._waiting_items = [], {}, 0
        with contextlib.suppress(OSError):
            for name in os.listdir(self.folder):
                if CHECKPOINT_FILES.fullmatch(name):
                    with contextlib.suppress(OSError):
                        (self.folder / name).unlink()
        with contextlib.suppress(OSError):
            self.folder.rmdir()

    def kept_text(self) -> str | None:
        """What is kept, for a failed job's last line (None if nothing is)."""
        done = self.done
        if not done:
            return None
        return (
            f"{done:,} of {self.count:,} {self.noun} are kept in {self.shown}: the same "
            "command with --resume continues the job"
        )


@contextlib.contextmanager
def kept_on_failure(checkpoint: Checkpoint | None) -> Iterator[None]:
    """The block of a job with ``checkpoint``: on success the checkpoint is removed;
    on any failure (signals included) the batches taken are written, and the
    checkpoint stays if it holds any, the exception getting a note that says so
    (``add_note``: the command line's last line ends with it), else it is removed."""
    if checkpoint is None:
        yield
        return
    try:
        yield
    except BaseException as exc:
        with held_signals():
            try:
                checkpoint.flush()
            except MachineError as failed:  # the disk that failed the job, say
                exc.add_note(str(failed))
                checkpoint._waiting, checkpoint._waiting_items = [], 0
            kept = checkpoint.kept_text()
            if kept is None:
                checkpoint.discard()
            else:
                exc.add_note(kept)
        raise
    checkpoint.discard()


@contextlib.contextmanager
def job_folder(
    out_dir: str | Path,
    kind: str,
    identity: dict[str, Any],
    count: int,
    noun: str,
    index: str,
    describe: str,
    resume: bool,
    note: Callable[[str], None],
) -> Iterator[Checkpoint]:
    """The block of a job writing into ``out_dir``: the folder's lock held
    (:func:`attitude.outputs.lock.folder_lock`), the job's checkpoint open
    (:meth:`Checkpoint.open`), removed when the block ends well and kept if it holds
    a batch when it does not (:func:`kept_on_failure`)."""
    with folder_lock(out_dir, kind):
        checkpoint = Checkpoint.open(
            out_dir, kind, identity, count, noun, index, describe, resume, note
        )
        with kept_on_failure(checkpoint):
            yield checkpoint
