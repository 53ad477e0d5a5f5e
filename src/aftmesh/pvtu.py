"""A partitioned mesh on disk: one VTK ``.vtu`` file per part and a ``.pvtu`` index.

This is the layout partitioned solvers and ParaView read.  Each part holds its
triangles (VTK_TRIANGLE) and the input segments it contains (VTK_LINE), its points
with a point array ``GlobalPointId``: the cut vertices that two parts share carry the
same id, so the parts join without comparing coordinates.  Cell arrays: ``region``
(-1 on lines) and ``segment_marker`` (-1 on triangles).  Arrays are inline base64
binary with a UInt64 byte-count header, little-endian.
"""

from __future__ import annotations

import base64
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ._typing import PathArg
from .errors import InvalidInputError
from .mesh import Mesh

__all__ = ["read_partitioned", "write_index", "write_part"]

VTK_LINE, VTK_TRIANGLE = 3, 5
_TYPES = {
    np.dtype("<f8"): "Float64",
    np.dtype("<i8"): "Int64",
    np.dtype("<i4"): "Int32",
    np.dtype("u1"): "UInt8",
}
_CELL_ARRAYS = (("region", "Int32"), ("segment_marker", "Int32"))


def _data_array(parent, name: str, arr: np.ndarray, components: int = 1) -> None:
    arr = np.ascontiguousarray(arr, dtype=arr.dtype.newbyteorder("<"))
    raw = arr.tobytes()
    node = ET.SubElement(
        parent,
        "DataArray",
        type=_TYPES[arr.dtype],
        Name=name,
        NumberOfComponents=str(components),
        format="binary",
    )
    node.text = base64.b64encode(np.uint64(len(raw)).tobytes() + raw).decode("ascii")


def write_part(
    path: PathArg,
    points: np.ndarray,
    global_ids: np.ndarray,
    triangles: np.ndarray,
    regions: np.ndarray,
    segments: np.ndarray,
    markers: np.ndarray,
) -> None:
    """One part as a ``.vtu`` file (see the module documentation)."""
    n_t, n_s = len(triangles), len(segments)
    root = ET.Element(
        "VTKFile",
        type="UnstructuredGrid",
        version="1.0",
        byte_order="LittleEndian",
        header_type="UInt64",
    )
    piece = ET.SubElement(
        ET.SubElement(root, "UnstructuredGrid"),
        "Piece",
        NumberOfPoints=str(len(points)),
        NumberOfCells=str(n_t + n_s),
    )
    xyz = np.zeros((len(points), 3))
    xyz[:, :2] = points
    _data_array(ET.SubElement(piece, "Points"), "Points", xyz, 3)
    pd = ET.SubElement(piece, "PointData", GlobalIds="GlobalPointId")
    _data_array(pd, "GlobalPointId", np.asarray(global_ids, dtype=np.int64))
    cells = ET.SubElement(piece, "Cells")
    conn = np.concatenate(
        [np.asarray(triangles, np.int64).ravel(), np.asarray(segments, np.int64).ravel()]
    )
    offsets = np.concatenate([3 * np.arange(1, n_t + 1), 3 * n_t + 2 * np.arange(1, n_s + 1)])
    _data_array(cells, "connectivity", conn)
    _data_array(cells, "offsets", offsets.astype(np.int64))
    _data_array(
        cells,
        "types",
        np.r_[np.full(n_t, VTK_TRIANGLE, np.uint8), np.full(n_s, VTK_LINE, np.uint8)],
    )
    cd = ET.SubElement(piece, "CellData")
    _data_array(cd, "region", np.r_[np.asarray(regions, np.int32), np.full(n_s, -1, np.int32)])
    _data_array(
        cd, "segment_marker", np.r_[np.full(n_t, -1, np.int32), np.asarray(markers, np.int32)]
    )
    ET.ElementTree(root).write(path, xml_declaration=True, encoding="utf-8")


def write_index(path: PathArg, pieces: Sequence[str]) -> None:
    """The ``.pvtu`` file naming the parts (file names relative to it)."""
    root = ET.Element(
        "VTKFile",
        type="PUnstructuredGrid",
        version="1.0",
        byte_order="LittleEndian",
        header_type="UInt64",
    )
    grid = ET.SubElement(root, "PUnstructuredGrid", GhostLevel="0")
    ET.SubElement(
        ET.SubElement(grid, "PPoints"),
        "PDataArray",
        type="Float64",
        Name="Points",
        NumberOfComponents="3",
    )
    ET.SubElement(
        ET.SubElement(grid, "PPointData", GlobalIds="GlobalPointId"),
        "PDataArray",
        type="Int64",
        Name="GlobalPointId",
    )
    pcd = ET.SubElement(grid, "PCellData")
    for name, kind in _CELL_ARRAYS:
        ET.SubElement(pcd, "PDataArray", type=kind, Name=name)
    for piece in pieces:
        ET.SubElement(grid, "Piece", Source=str(piece))
    ET.ElementTree(root).write(path, xml_declaration=True, encoding="utf-8")


def _arrays(path: Path) -> dict:
    out = {}
    kinds = {v: k for k, v in _TYPES.items()}
    for node in ET.parse(path).getroot().iter("DataArray"):
        raw = base64.b64decode(node.text or "")
        n = int(np.frombuffer(raw[:8], "<u8")[0])
        kind = kinds[str(node.get("type"))]
        out[str(node.get("Name"))] = np.frombuffer(raw[8 : 8 + n], kind)  # type: ignore[call-overload]
    return out


def read_partitioned(path: PathArg) -> Mesh:
    """Read a mesh written by ``aftmesh.generate(..., partitions=k, out=dir)``.

    Parameters
    ----------
    path : str or Path
        The directory (holding one ``.pvtu``) or the ``.pvtu`` file.

    Returns
    -------
    Mesh
        The whole mesh, vertices numbered by ``GlobalPointId``.
    """
    path = Path(path)
    if path.is_dir():
        found = sorted(path.glob("*.pvtu"))
        if len(found) != 1:
            raise InvalidInputError(f"{path} holds {len(found)} .pvtu files, expected one")
        path = found[0]
    parts = [_arrays(path.parent / p.get("Source")) for p in ET.parse(path).getroot().iter("Piece")]  # type: ignore[operator]
    n = 1 + max(int(a["GlobalPointId"].max()) for a in parts)
    points = np.zeros((n, 2))
    tris, regions, segs, markers = [], [], [], []
    for a in parts:
        gid = a["GlobalPointId"]
        points[gid] = a["Points"].reshape(-1, 3)[:, :2]
        conn = gid[a["connectivity"]]
        tri = a["types"] == VTK_TRIANGLE
        n_t = int(tri.sum())
        tris.append(conn[: 3 * n_t].reshape(-1, 3))
        segs.append(conn[3 * n_t :].reshape(-1, 2))
        regions.append(a["region"][tri])
        markers.append(a["segment_marker"][~tri])
    seg = np.sort(np.concatenate(segs), axis=1)
    seg, first = np.unique(seg, axis=0, return_index=True)
    T = np.concatenate(tris)
    return Mesh(
        points=points,
        triangles=T,
        neighbors=neighbors(T),
        segments=seg,
        regions=np.concatenate(regions),
        segment_markers=np.concatenate(markers)[first],
    )


def neighbors(T: np.ndarray) -> np.ndarray:
    """(t, 3): the triangle across the edge opposite each vertex, -1 on the boundary."""
    T = np.asarray(T, dtype=np.int64)
    n = int(T.max()) + 1 if len(T) else 1
    a, b = T[:, [1, 2, 0]].ravel(), T[:, [2, 0, 1]].ravel()
    key, rev = a * n + b, b * n + a
    order = np.argsort(key)
    pos = np.minimum(np.searchsorted(key[order], rev), len(key) - 1)
    hit = key[order][pos] == rev
    return np.where(hit, order[pos] // 3, -1).reshape(-1, 3).astype(np.int32)
