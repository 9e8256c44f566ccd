"""The lines a command says on stderr, without its progress lines.

`attitude check` and `run` say what they are doing from their first second
(``[   1.2 s] propagating ...``, attitude.base.progress) unless `--quiet`; the tests of
what they refuse or note read the other lines: errors, warnings and notes.
"""

import re

PROGRESS = re.compile(r"^\[ *\d+\.\d s\] ")


def said(stderr: str) -> list[str]:
    """The lines of ``stderr`` that are not progress lines."""
    return [line for line in stderr.splitlines() if not PROGRESS.match(line)]


def progress_lines(stderr: str) -> list[str]:
    """The progress lines of ``stderr``."""
    return [line for line in stderr.splitlines() if PROGRESS.match(line)]
