"""Writing a :class:`~aftmesh.Mesh`: Triangle's formats natively, every other format
through meshio, with the regions and the segments' markers and tags.

The segments go out as a block of line cells beside the triangles wherever the format
holds mixed cells (:data:`LINE_FORMATS`), so a solver finds its boundary parts:

* Gmsh (``.msh``): physical groups with names (``$PhysicalNames``).  Triangles of
  region r are in group r + 1, named ``region_<r>`` (Gmsh reads group 0 as "no
  group"; negative region markers shift every group up so the smallest is 1).  The
  segments' groups come after the regions': with ``R`` the largest region group, on a
  tagged mesh (``Mesh.segment_tags`` with ``Mesh.tag_names``) a segment tagged k is in
  group R + k, named by its tag, and untagged segments in one group named
  ``untagged`` after those; otherwise a segment of marker m is in group R + m + 1
  (shifted likewise for negative markers, such as -1 for a segment of unknown
  origin), named after its input ring or line when the mesh knows it
  (``info['sources']``), else ``segment_marker_<m>``.  Groups are
  per dimension in Gmsh, but readers such as scikit-fem's look a name up by its
  number alone, so no two groups share a number.  (Gmsh 4.1, ``file_format='gmsh'``,
  gets the triangles and their region groups only: meshio writes it with one cell
  type unless given Gmsh's entity information.)
* The other formats with the line block: cell data ``region`` (-1 on segments),
  ``segment_marker`` (-1 on triangles) and, when the mesh has them, ``segment_tag``
  (0 on triangles) and ``segment_source`` (-1 on triangles).
"""

from __future__ import annotations

from os import PathLike
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .domain_record import PositionalNames
from .errors import InvalidInputError
from .io_poly import write_mesh_poly, write_node_ele

if TYPE_CHECKING:
    from .mesh import Mesh

__all__ = ["LINE_FORMATS", "gmsh_physical_groups", "mesh_format", "write_mesh"]

PathArg = str | PathLike

# meshio formats that have a notion of a 2D mesh; the others get z = 0 added (most
# of them require 3D points and otherwise warn, or fail when reading back)
_MESHIO_2D = {"medit", "su2", "svg", "dolfin-xml", "netgen"}
_NATIVE = {"poly": "poly", "node": "node", "ele": "node", "triangle": "node"}
#: meshio formats written with the segments as a second cell block (line cells): the
#: ones that hold several cell types in one mesh and read them back
LINE_FORMATS = frozenset({"vtu", "vtk", "xdmf", "gmsh22", "medit"})
# the group of a tagged mesh's segments that carry no tag
_UNTAGGED = "untagged"


def _import_meshio(path: Path):
    try:
        import meshio
    except ImportError:
        raise ModuleNotFoundError(
            f"writing {path.name!r} needs meshio: pip install aftmesh[io] (without it, "
            "write .poly or .node/.ele)",
            name="meshio",
        ) from None
    return meshio


def _optional(mesh, name: str, length: int):
    """A per-segment array the mesh may have (fields added by later versions), as a
    1-D int32 array of the right length, or None."""
    value = getattr(mesh, name, None)
    if value is None:
        return None
    arr = np.asarray(value, dtype=np.int32).reshape(-1)
    if len(arr) != length:
        raise InvalidInputError(f"mesh.{name} has {len(arr)} entries for {length} segments")
    return arr


def _marker_names(mesh) -> dict[int, str]:
    """Name of each segment marker, where the marker is the index of a named input
    ring or line: ``info['sources']`` of a shapely domain.  A dict or ``.poly`` domain
    names its sources ``segments[i]`` by position, and its markers may be the user's
    own numbers rather than those positions, so they get no name from it."""
    sources = mesh.info.get("sources") if isinstance(mesh.info, dict) else None
    if (
        not sources
        or isinstance(sources, PositionalNames)
        or all(name == f"segments[{i}]" for i, name in enumerate(sources))
    ):
        return {}
    return {i: str(name) for i, name in enumerate(sources)}


def _add_group(names: dict, name: str, tag: int, dim: int) -> None:
    """Add a physical group's name; a name already taken (a ring named like a region,
    a tag named ``untagged``) gets the group's number appended, so each group keeps
    a name of its own."""
    if name in names:
        name = f"{name}_{tag}"
    names[name] = np.array([tag, dim])


def gmsh_physical_groups(mesh: Mesh) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]:
    """The Gmsh physical groups :func:`write_mesh` gives a mesh (see the module notes).

    Returns
    -------
    triangle_tags : (t,) int32
    segment_tags : (s,) int32
    names : dict
        name -> ``[tag, dimension]``, meshio's ``field_data``.

    Examples
    --------
    >>> import aftmesh
    >>> from shapely.geometry import box
    >>> m = aftmesh.generate(box(0, 0, 2, 2).difference(box(0.5, 0.5, 1, 1)), size=0.5)
    >>> tri, seg, names = gmsh_physical_groups(m)
    >>> sorted((k, v.tolist()) for k, v in names.items())
    [('region_0', [1, 2]), ('the polygon, exterior ring', [2, 1]), ('the polygon, hole 0', [3, 1])]
    """
    regions = np.asarray(mesh.regions, dtype=np.int64)
    low = min(0, int(regions.min())) if len(regions) else 0
    tri = regions - low + 1
    names = {f"region_{r}": np.array([r - low + 1, 2]) for r in np.unique(regions).tolist()}
    top = int(tri.max()) if len(tri) else 0
    s = len(mesh.segments)
    tags = _optional(mesh, "segment_tags", s)
    tag_names = getattr(mesh, "tag_names", None) or {}
    if tags is not None and tag_names:
        by_tag = {int(k): str(name) for name, k in tag_names.items()}
        last = max([*by_tag, int(tags.max()) if s else 0])
        seg = np.where(tags > 0, top + tags, top + last + 1).astype(np.int64)
        # the user's names first: a clash renames the group of untagged segments
        for k in sorted(np.unique(tags).tolist(), key=lambda k: k <= 0):
            name = by_tag.get(k, f"segment_tag_{k}") if k > 0 else _UNTAGGED
            _add_group(names, name, top + (k if k > 0 else last + 1), 1)
    else:
        markers = np.asarray(mesh.segment_markers, dtype=np.int64)
        low = min(0, int(markers.min())) if s else 0
        seg = top + markers - low + 1
        known = _marker_names(mesh)
        for m in np.unique(markers).tolist():
            _add_group(names, known.get(m, f"segment_marker_{m}"), top + m - low + 1, 1)
    return tri.astype(np.int32), seg.astype(np.int32), names


def _cells_and_data(mesh, fmt: str):
    """meshio cells, cell data and field data for ``mesh`` in the format ``fmt``."""
    region = np.asarray(mesh.regions, dtype=np.int32)
    triangles = np.asarray(mesh.triangles)
    if fmt not in LINE_FORMATS:
        cell_data = {"region": [region]}
        field_data = None
        if fmt.startswith("gmsh"):
            # Gmsh 4.1 in meshio takes one cell type only without entity information
            tri_tags, _, names = gmsh_physical_groups(mesh)
            cell_data["gmsh:physical"] = cell_data["gmsh:geometrical"] = [tri_tags]
            field_data = {k: v for k, v in names.items() if v[1] == 2}
        return [("triangle", triangles)], cell_data, field_data
    t, s = len(triangles), len(mesh.segments)
    cell_data = {}
    if fmt == "medit":
        # medit keeps one integer reference per cell: the first integer cell data
        cell_data["medit:ref"] = [region, np.asarray(mesh.segment_markers, dtype=np.int32)]
    cell_data["region"] = [region, np.full(s, -1, dtype=np.int32)]
    cell_data["segment_marker"] = [
        np.full(t, -1, dtype=np.int32),
        np.asarray(mesh.segment_markers, dtype=np.int32),
    ]
    tags = _optional(mesh, "segment_tags", s)
    if tags is not None:
        cell_data["segment_tag"] = [np.zeros(t, dtype=np.int32), tags]
    sources = _optional(mesh, "segment_sources", s)
    if sources is not None:
        cell_data["segment_source"] = [np.full(t, -1, dtype=np.int32), sources]
    field_data = None
    if fmt.startswith("gmsh"):
        # the physical groups and their names say it all; meshio reads element data
        # of a file with two cell blocks back wrongly, so none is written
        tri_tags, seg_tags, field_data = gmsh_physical_groups(mesh)
        cell_data = {
            "gmsh:physical": [tri_tags, seg_tags],
            "gmsh:geometrical": [tri_tags, seg_tags],
        }
    cells = [("triangle", triangles), ("line", np.asarray(mesh.segments))]
    return cells, cell_data, field_data


def write_mesh(mesh: Mesh, path: PathArg, file_format: str | None = None) -> None:
    """Write a mesh to a file (what :meth:`aftmesh.Mesh.write` does).

    Parameters
    ----------
    mesh : aftmesh.Mesh
    path : str or path-like
    file_format : str, optional
        ``'poly'``; ``'node'``, ``'ele'`` or ``'triangle'`` (the ``.node`` + ``.ele``
        pair); or a meshio format name (``'vtu'``, ``'gmsh22'``, ``'xdmf'``, ...).  By
        default taken from the file name's extension; ``.msh`` means Gmsh 2.2 (whose
        physical groups meshio and scikit-fem read back), not ANSYS.

    Notes
    -----
    ``.poly``: the mesh's points and segments with their markers, a point in each
    hole and, when the mesh has several regions, a regional attribute point in each
    piece of it enclosed by segments.  ``.node`` / ``.ele``: writing either writes
    both; vertex boundary markers are 1 on the mesh boundary, and each triangle has
    its region as attribute.  Other formats go through meshio: triangle cells with
    the cell data ``region`` and, in ``.vtu``, ``.vtk``, ``.xdmf``, ``.msh`` and
    ``.mesh``, the segments as line cells with their markers and tags; ``.msh`` has
    named physical groups for the regions and the boundary parts (see
    :mod:`aftmesh.io_mesh`).  ``.xdmf`` needs h5py (``pip install aftmesh[io]``).

    Raises
    ------
    aftmesh.InvalidInputError
        Unknown format.
    ModuleNotFoundError
        meshio is needed but not installed.

    Examples
    --------
    >>> import aftmesh, tempfile, os
    >>> mesh = aftmesh.generate([(0, 0), (1, 0), (1, 1), (0, 1)], size=0.5)
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     write_mesh(mesh, os.path.join(tmp, "square.node"))
    ...     sorted(os.listdir(tmp))
    ['square.ele', 'square.node']
    """
    path = Path(path)
    fmt = mesh_format(path, file_format)
    if fmt == "poly":
        write_mesh_poly(mesh, path)
        return
    if fmt == "node":
        write_node_ele(mesh, path)
        return
    meshio = _import_meshio(path)
    points = mesh.points
    if fmt not in _MESHIO_2D:
        points = np.c_[points, np.zeros(len(points))]
    cells, cell_data, field_data = _cells_and_data(mesh, fmt)
    out = meshio.Mesh(points, cells, cell_data=cell_data, field_data=field_data)
    try:
        meshio.write(path, out, file_format=fmt)
    except meshio.WriteError as exc:
        raise InvalidInputError(f"meshio cannot write {path.name!r}: {exc}") from None
    except ModuleNotFoundError as exc:
        # meshio imports a format's own dependency (h5py for XDMF) only when writing
        raise ModuleNotFoundError(
            f"writing {path.name!r} needs {exc.name}: pip install aftmesh[io]", name=exc.name
        ) from None


def mesh_format(path: PathArg, file_format: str | None = None) -> str:
    """The format :func:`write_mesh` would write ``path`` in.

    Returns ``'poly'``, ``'node'`` (the ``.node`` + ``.ele`` pair) or a meshio format
    name.  Lets a caller find out that a file name is unusable before meshing.

    Raises
    ------
    aftmesh.InvalidInputError
        Unknown extension (a format name is checked by meshio, when writing).
    ModuleNotFoundError
        The format needs meshio, which is not installed.

    Examples
    --------
    >>> mesh_format("wing.ele"), mesh_format("wing.msh"), mesh_format("wing.dat", "vtu")
    ('node', 'gmsh22', 'vtu')
    """
    path = Path(path)
    if file_format is not None:
        native = _NATIVE.get(file_format.lower())
    else:
        native = _NATIVE.get(path.suffix.lower().lstrip("."))
    if native is not None:
        return native
    meshio = _import_meshio(path)
    if file_format is not None:
        # a meshio format name: meshio itself says if it does not know it, when writing
        return file_format
    suffixes = [s.lower() for s in path.suffixes]
    double = "".join(suffixes[-2:])
    ext = (
        double
        if len(suffixes) >= 2 and double in meshio.extension_to_filetypes
        else (suffixes[-1] if suffixes else "")
    )
    if ext == ".msh":
        # meshio lists ANSYS first for .msh; Gmsh is what nearly everyone means
        return "gmsh22"
    if ext in meshio.extension_to_filetypes:
        return meshio.extension_to_filetypes[ext][0]
    known = sorted({".poly", ".node", ".ele", *meshio.extension_to_filetypes})
    raise InvalidInputError(
        f"cannot tell the mesh format from the file name {path.name!r}: use one of the "
        f"extensions {', '.join(known)} or give file_format"
    )
