"""The kernel's named numbers, as Python enums.

Each mirrors a named ``cdef enum`` of ``cython_ext/halfedge.pxd``; the kernel
exports the same names and values as ``_kernel.*_VALUES`` dicts and
``tests/test_states.py`` checks that the two agree, so neither side can drift.
"""

from __future__ import annotations

from enum import IntEnum, IntFlag

__all__ = ["EdgeFlag", "Location", "Order", "TriangleState"]


class TriangleState(IntEnum):
    """``tstate`` of a triangle slot (``TriState`` in the kernel)."""

    FREE = 0  # slot not in use (only inside a re-triangulation)
    EXTERIOR = 1  # ghost triangles, outside the domain, holes
    UNMESHED = 2  # the unmeshed region S(E) of the paper
    MESHED = 3  # the mesh T built so far


class Order(IntEnum):
    """Get_next_edge's order of the front (``Order`` in the kernel)."""

    SHORTEST = 0
    LONGEST = 1
    OLDEST = 2


class Location(IntEnum):
    """Where ``locate()`` found a point (``Location`` in the kernel)."""

    IN_TRIANGLE = 0
    ON_EDGE = 1
    ON_VERTEX = 2
    OUTSIDE = 3


class EdgeFlag(IntFlag):
    """Bits of a half-edge's ``eflag`` (``EdgeFlag`` in the kernel)."""

    SEGMENT = 1  # an input edge: never flipped
    FIXED = 2  # a temporary constraint (Update_internal's F, G)
