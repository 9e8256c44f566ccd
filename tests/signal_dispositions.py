"""The signal dispositions a test gives the command it starts, explicitly.

A process inherits the signals its parent ignores, across fork and exec.  A shell
ignores SIGINT in a job it starts in the background of a script (POSIX, Shell
Command Language, §2.11), so a `pytest &` would start every `attitude` with SIGINT
ignored, and `attitude` rightly keeps a disposition its caller set to ignore
(attitude.base.signals): a test that sends SIGINT would then test nothing.  Each test
says the dispositions its command starts with, whatever pytest started with.
"""

import signal

STOPPING = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


def starting_with(*ignored: int):
    """A ``preexec_fn`` for ``subprocess.Popen``: the stopping signals at their default
    action in the child, except ``ignored``, ignored (as nohup ignores SIGHUP, or a
    shell SIGINT in a background job)."""

    def preexec() -> None:
        for number in STOPPING:
            signal.signal(number, signal.SIG_IGN if number in ignored else signal.SIG_DFL)

    return preexec


defaults = starting_with()  # every stopping signal at its default action
