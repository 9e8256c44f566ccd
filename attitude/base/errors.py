"""Exception classes of the package.

Every error raised on bad input is an :class:`InputError`, which is also a
``ValueError``: code that already catches ``ValueError`` keeps working, and code
that wants to tell our complaints apart from numpy's can catch ``InputError``.

An :class:`InputError` carries where the bad value is as data: ``key`` (the scenario
key path such as ``torques.burns[0].torque``, an argument name, or a command-line
option such as ``--seed``), ``file`` (the scenario file's name) and ``value`` (the bad
value, where there is one), beside ``reason`` (what is wrong with it).  The one line a
user sees is ``str(error)``, ``file: key: reason``.  A layer that knows more of the
place (the reader knows the table an argument came from) makes a new error with
:meth:`InputError.under` or :meth:`InputError.located`: nothing ever reads the key
back out of the text.
"""

from __future__ import annotations

import copy
from typing import Any

__all__ = [
    "NO_VALUE",
    "AttitudeError",
    "InertiaWarning",
    "InputError",
    "LawRateWarning",
    "MachineError",
    "OptionError",
]


class _NoValue:
    """The ``value`` of an error that has none (a missing key, a conflict of two keys)."""

    def __repr__(self) -> str:
        return "NO_VALUE"

    def __reduce__(self) -> str:
        return "NO_VALUE"  # one instance, also across pickling (Dask workers, forked children)


NO_VALUE: Any = _NoValue()


class AttitudeError(Exception):
    """Base class of the errors raised by ``attitude``."""


class InputError(AttitudeError, ValueError):
    """An input (argument, scenario key, file) has a bad value.

    ``reason``: what is wrong, one line that can be shown to a user as it is;
    ``key``: what holds the bad value (a key path of the scenario file, an argument,
    an option), or None; ``file``: the name of the file it was read from, or None;
    ``value``: the bad value, or :data:`NO_VALUE` where there is none.
    ``str(error)`` is ``file: key: reason`` (the parts that are known).
    """

    def __init__(
        self,
        reason: str,
        *,
        key: str | None = None,
        file: str | None = None,
        value: Any = NO_VALUE,
    ) -> None:
        super().__init__(reason)
        self.reason = reason
        self.key = key or None
        self.file = file or None
        self.value = value

    def __str__(self) -> str:
        return ": ".join(part for part in (self.file, self.key, self.reason) if part)

    @property
    def has_value(self) -> bool:
        return self.value is not NO_VALUE

    def located(self, *, key: str | None = None, file: str | None = None) -> InputError:
        """The same error (same class, reason and value) with ``key`` and/or ``file``
        replaced where given."""
        other = copy.copy(self)
        if key is not None:
            other.key = key or None
        if file is not None:
            other.file = file or None
        return other

    def under(self, prefix: str) -> InputError:
        """The same error seen from one level up: its key inside ``prefix`` (a table,
        an event: ``events[2]`` + ``impulse`` is ``events[2].impulse``), or ``prefix``
        itself when it has no key."""
        if not prefix:
            return self.located()
        if self.key is None:
            return self.located(key=prefix)
        joiner = "" if self.key.startswith("[") else "."
        return self.located(key=f"{prefix}{joiner}{self.key}")


class OptionError(InputError):
    """A command-line option's value is refused: ``key`` is the option, ``value`` what
    was given, and the line reads as the command was typed, ``--out results: reason``
    (with the scenario file first when it has one)."""

    def __str__(self) -> str:
        if not (self.key and self.has_value):
            return super().__str__()
        parts = (self.file, f"{self.key} {self.value}", self.reason)
        return ": ".join(part for part in parts if part)


class MachineError(AttitudeError):
    """The machine failed what the input asked, through no fault of the input: a disk
    that filled or cannot be written, a cluster that lost its scheduler or its workers,
    a worker out of memory.  The same input may succeed elsewhere or later (a job with
    ``--resume``).  ``str(error)`` is one line naming what failed (the folder as the
    user wrote it, the scheduler's address); the command line exits 1 with it."""


class InertiaWarning(UserWarning):
    """An inertia that no real body has (the triangle inequality Ia + Ib ≥ Ic fails).

    The motion is still computed: the solver needs no such property.  Like an
    :class:`InputError`, it carries ``key`` (the argument that holds the inertia) and
    ``reason``; ``str(warning)`` is ``key: reason``.
    """

    def __init__(self, reason: str, *, key: str | None = None) -> None:
        super().__init__(reason)
        self.reason = reason
        self.key = key or None

    def __str__(self) -> str:
        return f"{self.key}: {self.reason}" if self.key else self.reason


class LawRateWarning(UserWarning):
    """An attitude law that demands a body rate beyond the scenario's slew limits (or,
    with none given, beyond what agile spacecraft turn at): the motion is computed as
    the law says, and the warning says how fast and when.  ``key``: the law's scenario
    key; ``str(warning)`` is ``key: reason``."""

    def __init__(self, reason: str, *, key: str | None = None) -> None:
        super().__init__(reason)
        self.reason = reason
        self.key = key or None

    def __str__(self) -> str:
        return f"{self.key}: {self.reason}" if self.key else self.reason
