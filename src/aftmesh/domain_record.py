"""The record every input adapter returns: a PSLG plus what is needed to mesh it."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Domain"]


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
    source_names: list[str]
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

    @property
    def segment_source(self) -> np.ndarray:
        """The input ring / line / segment each segment comes from."""
        return self.edge_source[self.segment_edge]
