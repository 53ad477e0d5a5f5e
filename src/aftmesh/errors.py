"""Exceptions raised by aftmesh.

Every problem with the caller's input is a ``ValueError`` subclass whose message names
the offending ring, segment, index or value.  ``KernelError`` (a ``RuntimeError``) means
an internal invariant broke: a bug in aftmesh, never the user's fault.
"""

from collections.abc import Iterable

from ._kernel import KernelError  # noqa: F401  (re-exported)


class InvalidInputError(ValueError):
    """Malformed input: wrong shapes, non-finite numbers, out-of-range indices."""


class InvalidDomainError(InvalidInputError):
    """The geometry does not describe a meshable domain (self-intersecting ring,
    crossing constraints, zero area, a hole outside the domain, ...)."""


class CrossingSegmentsError(InvalidDomainError):
    """Two input segments cross; ``segments`` holds the indices of both."""

    def __init__(self, msg: str, segments: Iterable[int] = ()) -> None:
        super().__init__(msg)
        self.segments = tuple(segments)


class InvalidSizeError(InvalidInputError):
    """A size, size callable result, or size-related option is not usable."""


class InvalidOptionError(InvalidInputError):
    """A keyword option has an invalid value."""
