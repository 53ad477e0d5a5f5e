"""Domains from GIS text formats: a shapely geometry from a WKT or GeoJSON file."""

from __future__ import annotations

from os import PathLike
from pathlib import Path
from typing import TYPE_CHECKING

from .errors import InvalidInputError

if TYPE_CHECKING:
    import shapely

__all__ = ["read_geojson", "read_wkt"]

PathArg = str | PathLike


def _read_text(path: PathArg, what: str) -> tuple[Path, str]:
    path = Path(path)
    text = path.read_text(encoding="utf-8", errors="replace")
    if not text.strip():
        raise InvalidInputError(f"{path}: the file is empty, expected {what}")
    return path, text


def _checked_geometry(geom, path: Path, what: str):
    if geom is None or geom.is_empty:
        raise InvalidInputError(f"{path}: the {what} geometry is empty")
    return geom


def read_wkt(path: PathArg) -> shapely.Geometry:
    """Read a shapely geometry from a file holding one WKT string.

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     p = os.path.join(tmp, "tri.wkt")
    ...     with open(p, "w") as fh:
    ...         _ = fh.write("POLYGON ((0 0, 1 0, 0 1, 0 0))")
    ...     read_wkt(p).area
    0.5
    """
    import shapely

    path, text = _read_text(path, "a WKT geometry")
    try:
        geom = shapely.from_wkt(text.strip())
    except shapely.errors.ShapelyError as exc:
        raise InvalidInputError(f"{path}: not a valid WKT geometry ({exc})") from None
    return _checked_geometry(geom, path, "WKT")


def read_geojson(path: PathArg) -> shapely.Geometry:
    """Read a shapely geometry from a GeoJSON file.

    A ``Feature`` gives its geometry; a ``FeatureCollection`` a ``GeometryCollection``
    of its features' geometries (polygons are the domain, lines and points inside
    them become constraints, see :func:`aftmesh.generate`).

    Examples
    --------
    >>> import tempfile, os
    >>> with tempfile.TemporaryDirectory() as tmp:
    ...     p = os.path.join(tmp, "tri.geojson")
    ...     with open(p, "w") as fh:
    ...         _ = fh.write('{"type": "Polygon", '
    ...                      '"coordinates": [[[0, 0], [2, 0], [0, 1], [0, 0]]]}')
    ...     read_geojson(p).area
    1.0
    """
    import shapely

    path, text = _read_text(path, "a GeoJSON object")
    try:
        geom = shapely.from_geojson(text)
    except shapely.errors.ShapelyError as exc:
        raise InvalidInputError(f"{path}: not a valid GeoJSON geometry ({exc})") from None
    return _checked_geometry(geom, path, "GeoJSON")
