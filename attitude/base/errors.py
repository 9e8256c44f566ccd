"""Exception classes of the package.

Every error raised on bad input is an :class:`InputError`, which is also a
``ValueError``: code that already catches ``ValueError`` keeps working, and code
that wants to tell our complaints apart from numpy's can catch ``InputError``.
"""

from __future__ import annotations

__all__ = ["AttitudeError", "InertiaWarning", "InputError"]


class AttitudeError(Exception):
    """Base class of the errors raised by ``attitude``."""


class InputError(AttitudeError, ValueError):
    """An input (argument, scenario key, file) has a bad value.

    The message names the field and the value, so that it can be shown to a user
    as it is.
    """


class InertiaWarning(UserWarning):
    """An inertia that no real body has (the triangle inequality Ia + Ib ≥ Ic fails).

    The motion is still computed: the solver needs no such property.
    """
