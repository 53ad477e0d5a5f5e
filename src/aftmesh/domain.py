"""Domain input -> a validated planar straight-line graph with regions.

Accepted forms (see :func:`aftmesh.generate`):

* a shapely ``Polygon`` or ``MultiPolygon`` (holes, parts touching at a point);
* a shapely ``GeometryCollection``: its polygons are the domain, its ``LineString`` /
  ``Point`` members inside them are internal constraints (cracks, interfaces, fixed
  nodes);
* a sequence of shapely polygons with disjoint interiors: a multi-region domain whose
  shared boundaries are discretized once; ``Mesh.regions`` is the index in the sequence;
* an (n, 2) array of coordinates: one polygon ring;
* a Triangle-style dict (``vertices``, ``segments``, ``holes``, ``regions``) or the
  path of a Triangle ``.poly`` file.

Three modules do the work, one job each: :mod:`aftmesh.inputs` (one adapter per
form, validation with :mod:`aftmesh.validity`, ring clean-up), :mod:`aftmesh.noding`
(merge, snap, split at vertices, node crossings) and :mod:`aftmesh.regions` (which
region each piece of the CDT is in).  This module keeps their public names in one
place.

Clean-up done and reported in ``Mesh.info['cleanup']``: repeated vertices, a repeated
closing vertex, rings in either orientation, segments split at the vertices lying on
them (or within rounding of them, see :func:`snap_tolerance`) and at their crossings.
"""

from __future__ import annotations

from .inputs import Domain, to_domain
from .noding import node_crossings, snap_tolerance
from .regions import classify_pieces

__all__ = ["Domain", "classify_pieces", "node_crossings", "snap_tolerance", "to_domain"]
