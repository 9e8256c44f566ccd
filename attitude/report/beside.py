"""One computation in a forked process beside the run, on the machine's other core.

A report's validity horizon by the splitting
(:func:`attitude.trajectory.horizon.splitting_horizon`: the scenario propagated again
under gravity gradient up to the crossing, splitting steps of exact free flows) is a
part of a run's CPU that needs none of the rest; it is a few numbers to the summary at
the end.  (When the averaged kicks' screen answers, in a tenth of a second for a day,
the run computes it itself: :meth:`Beside.known` holds that value, no process.)
:class:`Beside` computes such a function in a child process made by ``fork``
(nothing to import again, nothing to send but the result) while the parent streams
the outputs, and hands the result, or the exception the function raised, back
through a pipe (pickled) when it is asked for.

The child leaves nothing behind: it handles no signal itself (SIGINT, SIGTERM and
SIGHUP are back to their default action, so a Ctrl-C to the terminal's process group
ends it silently, and the parent prints the run's one line), except that it keeps
ignoring what the caller had the run ignore (``nohup``'s SIGHUP, a background job's
SIGINT: :func:`attitude.base.signals.keep_caller_dispositions`); a child a signal kills
is reported by :meth:`Beside.result` as the run stopped by that signal
(:class:`attitude.base.signals.Stopped`), not as an error of the function; it is
killed with its parent on Linux (``PR_SET_PDEATHSIG``), it never runs
the parent's exit handlers or flushes the parent's buffers (``os._exit``), and
leaving the ``with`` block kills and reaps it if it is still running: an
interrupted run has no child process left.  The function's result is the same bits
as in the parent (same code, same state, pickled floats are exact).  Where ``fork``
does not exist, the function runs in the parent when its result is asked for.
"""

from __future__ import annotations

import contextlib
import gc
import os
import pickle
import signal
import sys
from collections.abc import Callable
from typing import Any, Generic, TypeVar, cast

from attitude.base.signals import STOPPING, Stopped, keep_caller_dispositions

__all__ = ["Beside"]

T = TypeVar("T")

_PR_SET_PDEATHSIG = 1  # linux/prctl.h


class Beside(Generic[T]):
    """``function(*args)`` computed in a forked child from the moment of construction;
    :meth:`result` waits for it.  Use as a context manager: leaving the block kills
    and reaps a child still running (an exception, a signal in the parent)."""

    def __init__(self, function: Callable[..., T], *args: Any) -> None:
        self._function, self._args = function, args
        self._pid: int | None = None
        self._read: int | None = None
        self._done = False
        self._value: tuple[bool, Any] | None = None
        if hasattr(os, "fork") and hasattr(signal, "pthread_sigmask"):
            self._fork()

    def _fork(self) -> None:
        read, write = os.pipe()
        parent = os.getpid()
        sys.stdout.flush()
        sys.stderr.flush()
        # No signal between the fork and the child's default handlers: blocked meanwhile.
        blocked = signal.pthread_sigmask(signal.SIG_BLOCK, STOPPING)
        # The parent's objects out of the garbage collector's reach in the child: its
        # collections would otherwise write into every one of them and copy every page
        # they share with the parent (0.15 s of CPU for a run's horizon).
        gc.freeze()
        try:
            pid = os.fork()
        except OSError:
            gc.unfreeze()
            signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
            os.close(read)
            os.close(write)
            return  # no process to spare: computed in the parent instead
        if pid == 0:  # the child
            try:
                os.close(read)
                keep_caller_dispositions()
                _die_with(parent)
                signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
                _send(write, _outcome(self._function, self._args))
            finally:
                os._exit(0)
        gc.unfreeze()
        signal.pthread_sigmask(signal.SIG_SETMASK, blocked)
        os.close(write)
        self._pid, self._read = pid, read

    @classmethod
    def known(cls, value: T) -> Beside[T]:
        """A value already computed, behind the same interface (no process)."""
        done: Beside[T] = cls.__new__(cls)
        done._function, done._args = (lambda: value), ()
        done._pid, done._read, done._done = None, None, True
        done._value = (True, value)
        return done

    def ready(self, timeout_s: float) -> bool:
        """Whether the result is there, waiting at most ``timeout_s`` for it (True
        where there is no child: :meth:`result` computes it then)."""
        if self._value is not None or self._read is None:
            return True
        import select

        readable, _, _ = select.select([self._read], [], [], max(timeout_s, 0.0))
        return bool(readable)

    def result(self) -> T:
        """The function's value (or its exception, raised here)."""
        if self._value is None:
            if self._pid is None:
                self._value = _outcome(self._function, self._args)
            else:
                assert self._read is not None  # open until the child is reaped
                data = _receive(self._read)
                status = self._reap(kill=False)
                if status is not None and os.WIFSIGNALED(status):
                    # A signal the run did not get (sent to the child alone, or the
                    # kernel's SIGKILL when memory runs out): the run is stopped by it.
                    raise Stopped(os.WTERMSIG(status), "the process computing beside the run")
                self._value = (
                    pickle.loads(data)
                    if data
                    else (False, RuntimeError("the process computing beside the run died"))
                )
        ok, value = self._value
        if not ok:
            raise value
        return cast(T, value)

    def close(self) -> None:
        """Kill and reap the child if it is still there."""
        self._reap(kill=True)

    def _reap(self, kill: bool) -> int | None:
        """Close the pipe, wait for the child (killed first if ``kill``); its wait
        status, or None if it was reaped before."""
        if self._read is not None:
            os.close(self._read)
            self._read = None
        if self._pid is not None and not self._done:
            if kill:
                with contextlib.suppress(ProcessLookupError):
                    os.kill(self._pid, signal.SIGKILL)
            _, status = os.waitpid(self._pid, 0)
            self._done = True
            return status
        return None

    def __enter__(self) -> Beside[T]:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()


def _outcome(function: Callable[..., Any], args: tuple) -> tuple[bool, Any]:
    try:
        return True, function(*args)
    except Exception as exc:  # handed to the parent, raised there
        return False, exc


def _send(write: int, outcome: tuple[bool, Any]) -> None:
    try:
        data = pickle.dumps(outcome)
    except Exception as exc:  # an exception that does not pickle: its text does
        data = pickle.dumps((False, RuntimeError(f"{type(outcome[1]).__name__}: {exc}")))
    view = memoryview(data)
    while view:
        view = view[os.write(write, view) :]
    os.close(write)


def _receive(read: int) -> bytes:
    chunks = []
    while chunk := os.read(read, 1 << 16):
        chunks.append(chunk)
    return b"".join(chunks)


def _die_with(parent: int) -> None:
    """End this child if its parent dies (a SIGKILL leaves it no time to kill us)."""
    if sys.platform.startswith("linux"):
        with contextlib.suppress(Exception):
            import ctypes

            ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
    if os.getppid() != parent:  # the parent died before that took effect
        os._exit(0)
