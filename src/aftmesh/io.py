"""Reading domains and writing meshes.

* :func:`read_poly` / :func:`write_poly`: Triangle's ``.poly`` format (a planar
  straight-line graph with holes and regional attributes), in :mod:`aftmesh.io_poly`;
* :func:`write_mesh`: a :class:`~aftmesh.Mesh` as ``.poly``, as Triangle's ``.node`` +
  ``.ele`` pair, or in any format meshio writes (``.vtu``, ``.msh``, ``.xdmf``, ...)
  with its regions and the segments' markers and tags, in :mod:`aftmesh.io_mesh`;
* :func:`read_wkt` / :func:`read_geojson`: a shapely geometry from a text file, in
  :mod:`aftmesh.io_gis`.
"""

from __future__ import annotations

from .io_gis import read_geojson, read_wkt
from .io_mesh import gmsh_physical_groups, mesh_format, write_mesh
from .io_poly import read_poly, write_poly

__all__ = [
    "gmsh_physical_groups",
    "mesh_format",
    "read_geojson",
    "read_poly",
    "read_wkt",
    "write_mesh",
    "write_poly",
]
