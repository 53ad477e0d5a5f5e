"""Triangle's file formats: ``.poly`` (a planar straight-line graph with holes and
regional attributes) read and written, and a mesh written as ``.poly`` or as the
``.node`` + ``.ele`` pair.

Triangle's formats number vertices from 0 or from 1: the first vertex's number decides
for the whole file (and for the segments of a ``.poly`` whose vertices are in a
``.node`` file).  aftmesh writes them numbered from 1, as Triangle itself does.
"""

from __future__ import annotations

from os import PathLike
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from .errors import InvalidInputError
from .topology import hole_points, region_points

if TYPE_CHECKING:
    from .mesh import Mesh

__all__ = ["read_poly", "write_mesh_poly", "write_node_ele", "write_poly"]

PathArg = str | PathLike


class _Fields:
    """The non-empty lines of a Triangle file, split into fields, with line numbers."""

    def __init__(self, path: Path):
        self.path = path
        text = path.read_text(encoding="utf-8", errors="replace")
        self.rows = []
        for number, line in enumerate(text.splitlines(), start=1):
            fields = line.split("#", 1)[0].split()
            if fields:
                self.rows.append((number, fields))
        self.pos = 0

    def at_end(self) -> bool:
        return self.pos >= len(self.rows)

    def next(self, what: str):
        if self.at_end():
            raise InvalidInputError(f"{self.path}: the file ends where {what} should be")
        row = self.rows[self.pos]
        self.pos += 1
        return row

    def error(self, line: int, msg: str) -> InvalidInputError:
        return InvalidInputError(f"{self.path}, line {line}: {msg}")

    def integer(self, line: int, field: str, what: str) -> int:
        try:
            return int(field)
        except ValueError:
            raise self.error(line, f"{what} must be an integer, got {field!r}") from None

    def count(self, line: int, field: str, what: str) -> int:
        n = self.integer(line, field, what)
        if n < 0:
            raise self.error(line, f"{what} must be >= 0, got {n}")
        return n

    def number(self, line: int, field: str, what: str) -> float:
        try:
            x = float(field)
        except ValueError:
            raise self.error(line, f"{what} must be a number, got {field!r}") from None
        if not np.isfinite(x):
            raise self.error(line, f"{what} must be finite, got {field!r}")
        return x

    def check_width(self, line: int, fields, least: int, most: int, what: str) -> None:
        """A line of ``what`` must have between ``least`` and ``most`` fields; too many
        usually means the count declared for the previous section is too small."""
        if len(fields) < least:
            raise self.error(
                line, f"{what} needs {least} fields, got {len(fields)}: {' '.join(fields)!r}"
            )
        if len(fields) > most:
            raise self.error(
                line,
                f"{what} has {len(fields)} fields, at most {most} "
                f"expected: {' '.join(fields)!r} (is a count declared "
                "earlier too small?)",
            )


def _read_vertex_section(f: _Fields):
    """Header line and vertex lines (the start of ``.node`` and ``.poly`` files)."""
    line, head = f.next("the vertex count line")
    f.check_width(
        line,
        head,
        1,
        4,
        "the vertex count line (<# vertices> <dimension> <# attributes> <# boundary markers>)",
    )
    n = f.count(line, head[0], "the number of vertices")
    dim = f.integer(line, head[1], "the dimension") if len(head) > 1 else 2
    if dim != 2:
        raise f.error(line, f"the dimension must be 2, got {dim}")
    n_attr = f.count(line, head[2], "the number of attributes") if len(head) > 2 else 0
    n_mark = f.count(line, head[3], "the number of boundary markers") if len(head) > 3 else 0
    if n_mark > 1:
        raise f.error(line, f"the number of boundary markers must be 0 or 1, got {n_mark}")
    xy = np.empty((n, 2))
    attributes = np.zeros((n, n_attr))
    markers = np.zeros(n, dtype=np.int32)
    base = None
    for i in range(n):
        vline, v = f.next(f"vertex {i + 1} of the {n} declared on line {line}")
        f.check_width(vline, v, 3, 3 + n_attr + n_mark, "a vertex line")
        number = f.integer(vline, v[0], "the vertex number")
        if base is None:
            if number not in (0, 1):
                raise f.error(vline, f"the first vertex must be numbered 0 or 1, got {number}")
            base = number
        elif number != base + i:
            raise f.error(
                vline,
                f"vertex number {number} out of sequence "
                f"(expected {base + i}: vertices are numbered consecutively)",
            )
        xy[i, 0] = f.number(vline, v[1], "x")
        xy[i, 1] = f.number(vline, v[2], "y")
        # Triangle reads missing attributes and markers as 0
        for k in range(min(n_attr, len(v) - 3)):
            attributes[i, k] = f.number(vline, v[3 + k], f"attribute {k + 1}")
        if n_mark and len(v) > 3 + n_attr:
            markers[i] = f.integer(vline, v[3 + n_attr], "the boundary marker")
    return xy, attributes, (markers if n_mark else None), (0 if base is None else base)


def read_poly(path: PathArg) -> dict:
    """Read a planar straight-line graph from a Triangle ``.poly`` file.

    The format: a vertex section (``<# vertices> 2 <# attributes> <# markers>`` then
    ``<i> <x> <y> [attributes] [marker]`` lines), a segment section (``<# segments>
    <# markers>`` then ``<i> <a> <b> [marker]``), a hole section (``<# holes>`` then
    ``<i> <x> <y>``) and optionally a regional attribute section (``<# regions>`` then
    ``<i> <x> <y> <attribute> [<max area>]``).  ``#`` starts a comment.  A ``.poly``
    declaring 0 vertices takes them from the ``.node`` file of the same name.  As in
    Triangle, missing attributes and markers read as 0, and a file that ends after
    the segments has no holes.

    Parameters
    ----------
    path : str or path-like

    Returns
    -------
    dict
        ``vertices`` (n, 2) float64; ``segments`` (m, 2) int32, numbered from 0 whatever
        the file's numbering; ``holes`` (h, 2) float64; ``regions`` (r, 4) float64 rows
        of x, y, attribute, maximum area (a region line with a single value after x
        and y uses it for both, as Triangle does); and when the
        file has them, ``vertex_attributes`` (n, k), ``vertex_markers`` (n,) int32 and
        ``segment_markers`` (m,) int32.  The dict is a valid domain for
        :func:`aftmesh.generate`.

    Raises
    ------
    aftmesh.InvalidInputError
        Malformed file: the message names the file and the line.
    FileNotFoundError
        No such file (or no ``.node`` file for a ``.poly`` with 0 vertices).

    Examples
    --------
    >>> import tempfile, os
    >>> text = '''# a unit square with a hole
    ... 4 2 0 0
    ... 1 0 0
    ... 2 1 0
    ... 3 1 1
    ... 4 0 1
    ... 4 0
    ... 1 1 2
    ... 2 2 3
    ... 3 3 4
    ... 4 4 1
    ... 0
    ... '''
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     p = os.path.join(tmp, "square.poly")
    ...     with open(p, "w") as fh:
    ...         _ = fh.write(text)
    ...     d = read_poly(p)
    >>> d["vertices"].shape, d["segments"][0].tolist(), d["holes"].shape
    ((4, 2), [0, 1], (0, 2))
    """
    path = Path(path)
    f = _Fields(path)
    xy, attributes, vmarkers, base = _read_vertex_section(f)
    vertex_file = path
    if len(xy) == 0:
        vertex_file = path.with_suffix(".node")
        if not vertex_file.exists():
            raise FileNotFoundError(
                f"{path} declares 0 vertices, so they should be in {vertex_file}, "
                "which does not exist"
            )
        xy, attributes, vmarkers, base = _read_vertex_section(_Fields(vertex_file))
        if len(xy) == 0:
            raise InvalidInputError(f"{vertex_file}: the file has no vertices")
    n = len(xy)

    line, head = f.next("the segment count line")
    f.check_width(line, head, 1, 2, "the segment count line (<# segments> <# markers>)")
    m = f.count(line, head[0], "the number of segments")
    s_mark = f.count(line, head[1], "the number of boundary markers") if len(head) > 1 else 0
    if s_mark > 1:
        raise f.error(line, f"the number of boundary markers must be 0 or 1, got {s_mark}")
    segments = np.empty((m, 2), dtype=np.int32)
    smarkers = np.zeros(m, dtype=np.int32)
    for i in range(m):
        sline, s = f.next(f"segment {i + 1} of the {m} declared on line {line}")
        f.check_width(sline, s, 3, 3 + s_mark, "a segment line")
        f.integer(sline, s[0], "the segment number")
        for k in (0, 1):
            v = f.integer(sline, s[1 + k], "a segment endpoint")
            if not base <= v < base + n:
                raise f.error(
                    sline,
                    f"segment endpoint {v} is not a vertex "
                    f"(vertices are numbered {base}..{base + n - 1}"
                    + (f" in {vertex_file}" if vertex_file != path else "")
                    + ")",
                )
            segments[i, k] = v - base
        if segments[i, 0] == segments[i, 1]:
            raise f.error(sline, f"the segment joins vertex {s[1]} to itself")
        if s_mark and len(s) > 3:
            smarkers[i] = f.integer(sline, s[3], "the segment marker")

    holes = np.zeros((0, 2))
    regions = np.zeros((0, 4))
    if not f.at_end():
        line, head = f.next("the hole count line")
        f.check_width(line, head, 1, 1, "the hole count line (<# holes>)")
        holes = np.empty((f.count(line, head[0], "the number of holes"), 2))
        for i in range(len(holes)):
            hline, h = f.next(f"hole {i + 1} of the {len(holes)} declared on line {line}")
            f.check_width(hline, h, 3, 3, "a hole line (<#> <x> <y>)")
            holes[i] = (f.number(hline, h[1], "x"), f.number(hline, h[2], "y"))
    if not f.at_end():
        line, head = f.next("the region count line")
        f.check_width(line, head, 1, 1, "the region count line (<# regional attributes>)")
        regions = np.empty((f.count(line, head[0], "the number of regions"), 4))
        for i in range(len(regions)):
            rline, r = f.next(f"region {i + 1} of the {len(regions)} declared on line {line}")
            f.check_width(rline, r, 4, 5, "a region line (<#> <x> <y> <attribute> [<max area>])")
            regions[i, 0] = f.number(rline, r[1], "x")
            regions[i, 1] = f.number(rline, r[2], "y")
            regions[i, 2] = f.number(rline, r[3], "the regional attribute")
            # as Triangle does, a lone value is both the attribute and the area bound
            regions[i, 3] = (
                f.number(rline, r[4], "the maximum area") if len(r) > 4 else regions[i, 2]
            )
    if not f.at_end():
        line, extra = f.next("")
        raise f.error(
            line,
            f"unexpected data after the last section: {' '.join(extra)!r} "
            "(is a count declared earlier too small?)",
        )

    out = {"vertices": xy, "segments": segments, "holes": holes, "regions": regions}
    if attributes.shape[1]:
        out["vertex_attributes"] = attributes
    if vmarkers is not None:
        out["vertex_markers"] = vmarkers
    if s_mark:
        out["segment_markers"] = smarkers
    return out


def _numbers(row) -> str:
    # repr of a Python float is the shortest text that reads back to the same double
    return " ".join(repr(float(v)) for v in row)


def _as_array(value, name: str, columns: int | tuple, dtype) -> np.ndarray:
    try:
        arr = np.asarray(value, dtype=dtype)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(f"{name} must be an array of numbers: {exc}") from None
    if arr.size == 0:
        return arr.reshape(0, columns if isinstance(columns, int) else columns[0])
    allowed = (columns,) if isinstance(columns, int) else columns
    if arr.ndim != 2 or arr.shape[1] not in allowed:
        want = " or ".join(f"(k, {c})" for c in allowed)
        raise InvalidInputError(f"{name} must have shape {want}, got {arr.shape}")
    if np.issubdtype(arr.dtype, np.floating) and not np.isfinite(arr).all():
        i = int(np.flatnonzero(~np.isfinite(arr).all(axis=1))[0])
        raise InvalidInputError(f"{name}[{i}] = {arr[i].tolist()} is not finite")
    return arr


def write_poly(
    path: PathArg,
    vertices: npt.ArrayLike,
    segments: npt.ArrayLike,
    holes: npt.ArrayLike | None = None,
    regions: npt.ArrayLike | None = None,
    segment_markers: npt.ArrayLike | None = None,
) -> None:
    """Write a planar straight-line graph as a Triangle ``.poly`` file.

    Parameters
    ----------
    path : str or path-like
    vertices : (n, 2) array of float
    segments : (m, 2) array of int
        Vertex indices numbered from 0 (the file numbers them from 1).
    holes : (h, 2) array, optional
        A point inside each hole.
    regions : (r, 3) or (r, 4) array, optional
        Rows of x, y, regional attribute[, maximum area]; without a fourth column the
        maximum area is written as -1 (none).
    segment_markers : (m,) array of int, optional
        Written as the segments' boundary markers.

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     p = os.path.join(tmp, "tri.poly")
    ...     write_poly(p, [(0, 0), (1, 0), (0, 1)], [(0, 1), (1, 2), (2, 0)],
    ...                segment_markers=[5, 6, 7])
    ...     back = read_poly(p)
    >>> back["segments"].tolist(), back["segment_markers"].tolist()
    ([[0, 1], [1, 2], [2, 0]], [5, 6, 7])
    """
    xy = _as_array(vertices, "vertices", 2, np.float64)
    seg = _as_array(np.zeros((0, 2)) if segments is None else segments, "segments", 2, np.float64)
    if not np.array_equal(seg, np.round(seg)):
        raise InvalidInputError("segments must hold integer vertex indices")
    seg = seg.astype(np.int64)
    if len(seg) and (seg.min() < 0 or seg.max() >= len(xy)):
        i = int(np.flatnonzero(((seg < 0) | (seg >= len(xy))).any(axis=1))[0])
        raise InvalidInputError(
            f"segments[{i}] = {seg[i].tolist()} refers to a vertex outside 0..{len(xy) - 1}"
        )
    hl = _as_array(np.zeros((0, 2)) if holes is None else holes, "holes", 2, np.float64)
    rg = _as_array(np.zeros((0, 4)) if regions is None else regions, "regions", (3, 4), np.float64)
    if rg.shape[1] == 3:
        rg = np.c_[rg, np.full(len(rg), -1.0)]
    markers = None
    if segment_markers is not None:
        markers = np.asarray(segment_markers).reshape(-1)
        if len(markers) != len(seg):
            raise InvalidInputError(
                f"segment_markers has {len(markers)} entries for {len(seg)} segments"
            )
        if not np.issubdtype(markers.dtype, np.integer):
            if not np.array_equal(markers, np.round(markers)):
                raise InvalidInputError("segment_markers must be integers")
        markers = markers.astype(np.int64)
    lines = ["# written by aftmesh", f"{len(xy)} 2 0 0"]
    lines += [f"{i + 1} {_numbers(p)}" for i, p in enumerate(xy.tolist())]
    lines.append(f"{len(seg)} {0 if markers is None else 1}")
    for i, (a, b) in enumerate(seg.tolist()):
        tail = "" if markers is None else f" {markers[i]}"
        lines.append(f"{i + 1} {a + 1} {b + 1}{tail}")
    lines.append(f"{len(hl)}")
    lines += [f"{i + 1} {_numbers(p)}" for i, p in enumerate(hl.tolist())]
    if len(rg):
        lines.append(f"{len(rg)}")
        lines += [f"{i + 1} {_numbers(r)}" for i, r in enumerate(rg.tolist())]
    Path(path).write_text("\n".join(lines) + "\n", encoding="utf-8")


def write_mesh_poly(mesh: Mesh, path: Path) -> None:
    """A mesh as a ``.poly``: its points and segments with their markers, a point in
    each hole and, when the mesh has several regions, a regional attribute point in
    each piece enclosed by segments, so that meshing the file gives back the same
    holes and regions."""
    regions = region_points(mesh) if mesh.regions.any() else None
    write_poly(
        path,
        mesh.points,
        mesh.segments,
        holes=hole_points(mesh),
        regions=regions,
        segment_markers=mesh.segment_markers,
    )


def write_node_ele(mesh: Mesh, path: Path) -> None:
    """A mesh as Triangle's ``.node`` + ``.ele`` pair beside ``path``: vertex boundary
    markers 1 on the mesh boundary, each triangle's region as its attribute."""
    P, T = mesh.points, mesh.triangles
    on_boundary = np.zeros(len(P), dtype=np.int64)
    ti, k = np.nonzero(mesh.neighbors < 0)
    on_boundary[T[ti, (k + 1) % 3]] = 1
    on_boundary[T[ti, (k + 2) % 3]] = 1
    node = [
        "# written by aftmesh: vertex, x, y, boundary marker (1 on the boundary)",
        f"{len(P)} 2 0 1",
    ]
    node += [
        f"{i + 1} {_numbers(p)} {m}"
        for i, (p, m) in enumerate(zip(P.tolist(), on_boundary.tolist()))
    ]
    ele = [
        "# written by aftmesh: triangle, three vertices (counter-clockwise), region",
        f"{len(T)} 3 1",
    ]
    ele += [
        f"{i + 1} {a + 1} {b + 1} {c + 1} {r}"
        for i, ((a, b, c), r) in enumerate(zip(T.tolist(), mesh.regions.tolist()))
    ]
    path.with_suffix(".node").write_text("\n".join(node) + "\n", encoding="utf-8")
    path.with_suffix(".ele").write_text("\n".join(ele) + "\n", encoding="utf-8")


# meshio formats that have a notion of a 2D mesh; the others get z = 0 added (most
