"""The result object: a small immutable mesh of plain numpy arrays."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ._typing import PathArg, SizeFunction
from .errors import InvalidOptionError
from .quality import triangle_quality

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["Mesh", "triangle_quality"]

# Per-segment int32 arrays a Mesh may carry (None when its maker has none).
_OPTIONAL_SEGMENT_ARRAYS = ("segment_sources", "segment_tags")


def _frozen(a, dtype) -> np.ndarray:
    arr = np.array(a, dtype=dtype, copy=True)
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True, repr=False, eq=False)
class Mesh:
    """A 2D triangle mesh.

    Attributes
    ----------
    points : (n, 2) float64
        Vertex coordinates; every point is used by some triangle.
    triangles : (t, 3) int32
        Vertex indices of each triangle, counter-clockwise.
    neighbors : (t, 3) int32
        ``neighbors[i, k]`` is the triangle across the edge opposite vertex
        ``triangles[i, k]``, or -1 on the boundary.
    segments : (s, 2) int32
        The constrained edges (input edges and the pieces they were split into).
    segment_markers : (s,) int32
        For each segment, the input ring / constraint line / segment it came from (or
        that segment's own marker, for a dict input that has them), -1 if unknown.
    regions : (t,) int32
        Region marker of each triangle.
    segment_sources : (s,) int32 or None
        For each segment, the index of the user's input edge it lies on, -1 if none
        (numbering: see :func:`aftmesh.generate`).
    segment_tags : (s,) int32 or None
        For each segment, the number of its named boundary part (``boundary_tags``
        of :func:`aftmesh.generate`), 0 if untagged.
    tag_names : dict
        Name -> tag number of the named boundary parts.
    info : dict
        What happened on the way: merged vertices, counters, timings.
    """

    points: np.ndarray
    triangles: np.ndarray
    neighbors: np.ndarray
    segments: np.ndarray
    regions: np.ndarray
    segment_markers: np.ndarray | None = None
    info: dict[str, Any] = field(default_factory=dict)
    segment_sources: np.ndarray | None = None
    segment_tags: np.ndarray | None = None
    tag_names: dict[str, int] = field(default_factory=dict)

    def __post_init__(self):
        object.__setattr__(self, "points", _frozen(self.points, np.float64).reshape(-1, 2))
        object.__setattr__(self, "triangles", _frozen(self.triangles, np.int32).reshape(-1, 3))
        object.__setattr__(self, "neighbors", _frozen(self.neighbors, np.int32).reshape(-1, 3))
        object.__setattr__(self, "segments", _frozen(self.segments, np.int32).reshape(-1, 2))
        object.__setattr__(self, "regions", _frozen(self.regions, np.int32).reshape(-1))
        markers = self.segment_markers
        if markers is None:
            markers = np.full(len(self.segments), -1, dtype=np.int32)
        object.__setattr__(self, "segment_markers", _frozen(markers, np.int32).reshape(-1))
        for name in _OPTIONAL_SEGMENT_ARRAYS:
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, _frozen(value, np.int32).reshape(-1))
        object.__setattr__(self, "tag_names", dict(self.tag_names or {}))

    @classmethod
    def _adopt(cls, **arrays) -> Mesh:
        """Build a Mesh from arrays the caller hands over (fresh, of the right dtype):
        they are frozen in place instead of copied, which keeps the peak memory of a
        large mesh at one copy of its arrays."""
        mesh = object.__new__(cls)
        dtypes = dict(
            points=np.float64,
            triangles=np.int32,
            neighbors=np.int32,
            segments=np.int32,
            regions=np.int32,
            segment_markers=np.int32,
        )
        for name, dtype in dtypes.items():
            arr = np.ascontiguousarray(arrays[name], dtype=dtype)
            arr.setflags(write=False)
            object.__setattr__(mesh, name, arr)
        for name in _OPTIONAL_SEGMENT_ARRAYS:
            value = arrays.get(name)
            if value is not None:
                value = np.ascontiguousarray(value, dtype=np.int32)
                value.setflags(write=False)
            object.__setattr__(mesh, name, value)
        object.__setattr__(mesh, "tag_names", dict(arrays.get("tag_names") or {}))
        object.__setattr__(mesh, "info", arrays.get("info", {}))
        return mesh

    def boundary_facets(self, tag: str | int) -> np.ndarray:
        """Indices into ``segments`` of one tagged boundary part.

        Parameters
        ----------
        tag : str or int
            A name from ``tag_names`` (the segments whose ``segment_tags`` is its
            number) or an integer (the segments whose ``segment_markers`` equal it).

        Examples
        --------
        >>> import aftmesh
        >>> from shapely.geometry import box
        >>> m = aftmesh.generate(box(0, 0, 2, 1), 0.25,
        ...                      boundary_tags={"left": lambda x, y: x == 0})
        >>> left = m.boundary_facets("left")
        >>> bool((m.points[m.segments[left]][..., 0] == 0).all()), len(left)
        (True, 4)
        """
        if isinstance(tag, str):
            if tag not in self.tag_names or self.segment_tags is None:
                raise InvalidOptionError(
                    f"no boundary part named {tag!r}: the names are {sorted(self.tag_names)}"
                )
            return np.flatnonzero(self.segment_tags == self.tag_names[tag])
        if isinstance(tag, (bool, np.bool_)) or not isinstance(tag, (int, np.integer)):
            raise InvalidOptionError(
                f"tag must be a name from tag_names or an integer marker, got {tag!r}"
            )
        return np.flatnonzero(self.segment_markers == tag)

    @property
    def n_points(self) -> int:
        return len(self.points)

    @property
    def n_triangles(self) -> int:
        return len(self.triangles)

    @property
    def edges(self) -> np.ndarray:
        """(e, 2) int32: each edge of the mesh once, as sorted vertex pairs."""
        t = self.triangles
        e = np.concatenate([t[:, [1, 2]], t[:, [2, 0]], t[:, [0, 1]]])
        e.sort(axis=1)
        return np.unique(e, axis=0).astype(np.int32)

    def area(self) -> float:
        """Total area of the triangles."""
        return float(triangle_quality(self.points, self.triangles)["area"].sum())

    def quality(self, size: float | SizeFunction | None = None, bins: int = 10) -> dict[str, Any]:
        """Summary of the triangles' shapes.

        Parameters
        ----------
        size : float or callable, optional
            Target edge length (a number or ``f(x, y) -> array``): adds the statistics
            of edge length / target size.
        bins : int
            Number of bins of the radius-ratio histogram over [0, 1].

        Returns
        -------
        dict
            ``min_angle``, ``max_angle`` (degrees), ``radius_ratio_mean``,
            ``radius_ratio_min``, ``fraction_rr_above_0.9``, ``fraction_rr_below_0.6``,
            ``radius_ratio_histogram`` (counts, edges), ``edge_length_mean``, and with a
            size, ``edge_to_size_mean`` and ``edge_to_size_std``.

        Examples
        --------
        >>> import aftmesh
        >>> m = aftmesh.generate([(0, 0), (1, 0), (1, 1), (0, 1)], size=0.2)
        >>> m.quality()["min_angle"] > 20
        True
        """
        q = triangle_quality(self.points, self.triangles)
        rr = q["radius_ratio"]
        edges = self.edges
        lengths = np.linalg.norm(self.points[edges[:, 1]] - self.points[edges[:, 0]], axis=1)
        counts, edges_hist = np.histogram(rr, bins=bins, range=(0.0, 1.0))
        out: dict[str, Any] = {
            "triangles": self.n_triangles,
            "points": self.n_points,
            "min_angle": float(q["min_angle"].min()) if len(rr) else float("nan"),
            "max_angle": float(q["max_angle"].max()) if len(rr) else float("nan"),
            "radius_ratio_mean": float(rr.mean()) if len(rr) else float("nan"),
            "radius_ratio_min": float(rr.min()) if len(rr) else float("nan"),
            "fraction_rr_above_0.9": float((rr > 0.9).mean()) if len(rr) else float("nan"),
            "fraction_rr_below_0.6": float((rr < 0.6).mean()) if len(rr) else float("nan"),
            "radius_ratio_histogram": (counts, edges_hist),
            "edge_length_mean": float(lengths.mean()) if len(lengths) else float("nan"),
        }
        if size is not None:
            mid = 0.5 * (self.points[edges[:, 0]] + self.points[edges[:, 1]])
            if callable(size):
                target = np.asarray(size(mid[:, 0], mid[:, 1]), dtype=float)
                target = np.broadcast_to(target, lengths.shape)
            else:
                target = np.full(lengths.shape, float(size))
            ratio = lengths / target
            out["edge_to_size_mean"] = float(ratio.mean())
            out["edge_to_size_std"] = float(ratio.std())
        return out

    def __repr__(self) -> str:
        lines = [
            f"aftmesh.Mesh: {self.n_points} points, {self.n_triangles} triangles, "
            f"{len(self.segments)} segments"
        ]
        if self.n_triangles:
            lo = self.points.min(axis=0)
            hi = self.points.max(axis=0)
            q = triangle_quality(self.points, self.triangles)
            lines.append(f"  bounds: x [{lo[0]:.6g}, {hi[0]:.6g}], y [{lo[1]:.6g}, {hi[1]:.6g}]")
            regions = np.unique(self.regions)
            lines.append(f"  regions: {regions.tolist() if len(regions) <= 8 else len(regions)}")
            lines.append(
                f"  angles: min {q['min_angle'].min():.2f} deg, max {q['max_angle'].max():.2f} deg;"
                f" radius ratio mean {q['radius_ratio'].mean():.4f}"
            )
        return "\n".join(lines)

    def write(self, path: PathArg, file_format: str | None = None) -> None:
        """Write the mesh to a file.

        ``.poly``, ``.node`` and ``.ele`` (Triangle's formats) are written natively: a
        ``.node`` path also writes the ``.ele`` beside it and vice versa.  Every other
        format (``.vtu``, ``.msh``, ``.xdmf``, ...) goes through meshio (``pip install
        aftmesh[io]``), with the region of each triangle as cell data ``region``.
        """
        from . import io as _io

        _io.write_mesh(self, Path(path), file_format)

    def plot(
        self,
        ax: Axes | None = None,
        color_by: str = "quality",
        show_segments: bool = True,
        **kwargs: Any,
    ) -> Axes:
        """Draw the mesh with matplotlib (``pip install aftmesh[plot]``).

        Parameters
        ----------
        ax : matplotlib Axes, optional
        color_by : {'quality', 'region', 'none'}
            Fill each triangle by its radius ratio, by its region, or leave it white.
        show_segments : bool
            Draw the constrained edges on top, thicker.

        Returns
        -------
        matplotlib Axes
        """
        from . import plotting

        return plotting.plot_mesh(
            self, ax=ax, color_by=color_by, show_segments=show_segments, **kwargs
        )
