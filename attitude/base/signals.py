"""How a run stops on a signal: the signals that stop it, the exception that carries
one, and the dispositions a caller set, which the run keeps.

The command line turns SIGINT, SIGTERM and SIGHUP into one line and an exit status
(``attitude.cli.main``): 130 interrupted, 143 terminated, 129 hung up, 128 + N for any
other signal N.  It does so only where the caller left a signal to its default
action.  A disposition the caller set to *ignore* is the caller's wish and is kept,
in the run and in every process the run starts: ``nohup`` ignores SIGHUP so that a
closed terminal does not stop the command, and a shell ignores SIGINT (and SIGQUIT)
in a job it starts in the background of a script (POSIX, Shell Command Language,
§2.11 "Signals and Error Handling"), so that a Ctrl-C meant for the script's
foreground does not reach it.  Python itself keeps an ignored SIGINT ignored at
start (it installs its KeyboardInterrupt handler only over the default action).
"""

from __future__ import annotations

import signal

__all__ = ["STOPPING", "Stopped", "caller_ignores", "keep_caller_dispositions"]

# The signals that stop a run (those this platform has).
STOPPING: tuple[int, ...] = tuple(
    getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, name)
)
_TEXT = {"SIGINT": "interrupted", "SIGTERM": "terminated", "SIGHUP": "hung up"}


class Stopped(BaseException):
    """A signal stopped the run: raised by the command line's handlers (like
    ``KeyboardInterrupt``, a ``BaseException``, so that no ``except Exception`` takes
    it for an error), or for a process of the run that a signal killed (``what``
    says which)."""

    def __init__(self, number: int, what: str = "") -> None:
        super().__init__(number, what)
        self.number = int(number)
        self.what = what

    @property
    def name(self) -> str:
        try:
            return signal.Signals(self.number).name
        except ValueError:
            return f"signal {self.number}"

    @property
    def exit_status(self) -> int:
        """128 + N, the status a shell reports for a command that signal N stopped."""
        return 128 + self.number

    @property
    def text(self) -> str:
        """What happened, in a few words: ``interrupted``, ``terminated``..."""
        said = _TEXT.get(self.name, f"stopped by {self.name}")
        return f"{said} ({self.what} got {self.name})" if self.what else said


def caller_ignores(number: int) -> bool:
    """True when ``number`` is ignored here: the caller's wish (see the module notes),
    which a handler must not replace."""
    return signal.getsignal(number) is signal.SIG_IGN


def keep_caller_dispositions() -> None:
    """In a process forked from the run: the stopping signals back to their default
    action, except those the caller ignores, which stay ignored (the run's own
    handlers, inherited by the fork, are the parent's and not for the child)."""
    for number in STOPPING:
        if not caller_ignores(number):
            signal.signal(number, signal.SIG_DFL)
