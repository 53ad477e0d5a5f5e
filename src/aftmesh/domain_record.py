"""The record every input adapter returns: a PSLG plus what is needed to mesh it."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Domain", "PositionalNames"]


class PositionalNames(Sequence):
    """The names ``segments[0]``, ``segments[1]``, ... of a dict or ``.poly`` input's
    sources, one per segment, each made when it is read: a call on 50,000 segments
    would otherwise build 50,000 strings that nobody reads (``info['sources']``).

    >>> names = PositionalNames("segments", 3)
    >>> names[1], names[-1], len(names)
    ('segments[1]', 'segments[2]', 3)
    >>> names == ["segments[0]", "segments[1]", "segments[2]"]
    True
    """

    __slots__ = ("prefix", "n")

    def __init__(self, prefix: str, n: int) -> None:
        self.prefix = prefix
        self.n = n

    def __len__(self) -> int:
        return self.n

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self[k] for k in range(*i.indices(self.n))]
        k = i.__index__()
        if not -self.n <= k < self.n:
            raise IndexError(f"source {k} is out of range for {self.n} sources")
        return f"{self.prefix}[{k % self.n}]"

    def __eq__(self, other) -> bool:
        if isinstance(other, PositionalNames):
            return (self.prefix, self.n) == (other.prefix, other.n)
        if isinstance(other, Sequence) and not isinstance(other, str):
            return len(other) == self.n and all(a == b for a, b in zip(self, other))
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]  # like a list: equal to one, not hashable

    def __repr__(self) -> str:
        return f"PositionalNames({self.prefix!r}, {self.n})"

    def __reduce__(self):
        return (PositionalNames, (self.prefix, self.n))


@dataclass
class Domain:
    """A PSLG plus what is needed to mesh it.

    ``segment_edge[k]`` is the input edge segment k is a piece of (see the module
    doc); ``edge_source[e]`` the input ring / constraint line / segment edge e belongs
    to (``source_names`` says which; ``source_markers``, if the input had them, maps
    that number to the user's own segment marker); ``edge_is_ring[e]`` whether edge e
    is on a polygon ring.  ``polygons`` classify the pieces cut out by the segments
    into regions (index in the list; outside all: not meshed).  Dict and ``.poly``
    inputs instead carry Triangle's ``holes`` and ``region_points``."""

    vertices: np.ndarray
    segments: np.ndarray
    segment_edge: np.ndarray
    edge_source: np.ndarray
    source_names: Sequence[str]  # a list, or PositionalNames for dict / .poly input
    edge_is_ring: np.ndarray | None = None
    polygons: list | None = None
    holes: np.ndarray | None = None
    region_points: np.ndarray | None = None
    area: float | None = None
    cleanup: list[str] = field(default_factory=list)
    source_markers: np.ndarray | None = None  # the user's marker of each source
    edge_midpoints: np.ndarray | None = None  # (e, 2) the midpoint of each input edge
    report: dict = field(default_factory=dict)  # what repair / tolerance changed
    n_rings: int = 0  # the sources numbered first that are polygon rings (shapely input)
    # the polygon each ring bounds, where the rings are proved to meet nowhere
    # (inputs.proved_polygon): the compiled call then classifies the pieces by nesting
    ring_polygon: np.ndarray | None = None

    @property
    def segment_source(self) -> np.ndarray:
        """The input ring / line / segment each segment comes from."""
        return self.edge_source[self.segment_edge]
