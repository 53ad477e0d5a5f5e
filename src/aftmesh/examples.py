"""Example domains with matching size functions, used by ``aftmesh demo``.

Each builder returns ``(domain, size)`` ready for :func:`aftmesh.generate`:

* :func:`airfoil_channel`: a NACA 0012 airfoil at an angle of attack inside a
  rectangular channel, with a size graded from fine at the airfoil to coarse far away;
* :func:`inclusion`: a rectangle with a rectangular core of another material, as a
  list ``[annulus, core]`` so that the mesh has one region per material and the
  interface is a row of mesh edges.

Lengths are in chords (airfoil) or in the outer rectangle's units (inclusion).
"""

from __future__ import annotations

import numpy as np
import shapely
from numpy.typing import ArrayLike
from shapely.geometry import Polygon, box
from shapely.geometry.base import BaseGeometry

__all__ = ["GradedSize", "naca0012", "airfoil_channel", "inclusion"]


class GradedSize:
    """Target edge length growing linearly with the distance to a geometry.

    ``h(p) = min(h_far, h_near + rate * distance(p, geometry))``: ``h_near`` on (and
    inside) the geometry, growing by ``rate`` per unit of distance until ``h_far``.

    Parameters
    ----------
    geometry : shapely geometry
        What the size is fine at (a polygon: its inside counts as distance 0).
    h_near, h_far : float
        Sizes at the geometry and far from it, ``0 < h_near <= h_far``.
    rate : float
        Growth of the size per unit of distance.  Keep it below aftmesh's gradation
        limit (``gradation - 1`` = 0.3 by default) or the limit will flatten it.

    Examples
    --------
    >>> from shapely.geometry import Point
    >>> h = GradedSize(Point(0, 0), 0.1, 0.5, rate=0.2)
    >>> h(np.array([0.0, 1.0, 10.0]), np.zeros(3)).round(3).tolist()
    [0.1, 0.3, 0.5]
    """

    def __init__(
        self, geometry: BaseGeometry, h_near: float, h_far: float, rate: float = 0.25
    ) -> None:
        if not (0 < h_near <= h_far) or not rate > 0:
            raise ValueError(
                f"need 0 < h_near <= h_far and rate > 0, got "
                f"h_near={h_near!r}, h_far={h_far!r}, rate={rate!r}"
            )
        self.geometry = geometry
        self.h_near = float(h_near)
        self.h_far = float(h_far)
        self.rate = float(rate)
        shapely.prepare(geometry)
        self._bounds = np.asarray(geometry.bounds, dtype=np.float64)
        # beyond this distance the size is h_far whatever the exact distance
        self._saturation = (self.h_far - self.h_near) / self.rate

    def __call__(self, x: ArrayLike, y: ArrayLike) -> np.ndarray:
        x, y = np.broadcast_arrays(np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64))
        xmin, ymin, xmax, ymax = self._bounds
        # the distance to the bounding box is a cheap lower bound of the distance to
        # the geometry: exact distances (the costly part) are only needed near it
        dx = np.maximum(np.maximum(xmin - x, x - xmax), 0.0)
        dy = np.maximum(np.maximum(ymin - y, y - ymax), 0.0)
        near = np.hypot(dx, dy) < self._saturation
        d = np.full(x.shape, self._saturation)
        if near.any():
            d[near] = shapely.distance(shapely.points(x[near], y[near]), self.geometry)
        return np.minimum(self.h_far, self.h_near + self.rate * d)

    def __repr__(self) -> str:
        return (
            f"GradedSize({self.geometry.geom_type}, h_near={self.h_near:g}, "
            f"h_far={self.h_far:g}, rate={self.rate:g})"
        )


def naca0012(spacing: float = 0.01, thickness: float = 0.12) -> np.ndarray:
    """Vertices of a symmetric NACA 4-digit airfoil of chord 1, closed trailing edge.

    The half thickness is ``y_t = 5 t (0.2969 sqrt(x) - 0.1260 x - 0.3516 x^2
    + 0.2843 x^3 - 0.1036 x^4)``; with the last coefficient -0.1036 (instead of the
    original -0.1015) it is exactly 0 at ``x = 1``, so the trailing edge is a sharp
    corner rather than a short blunt edge.

    Parameters
    ----------
    spacing : float
        Distance between consecutive vertices along the contour, in chords.  The
        vertices are equally spaced in arc length: a mesh of size ``spacing`` along
        the airfoil then needs no shorter boundary edge.
    thickness : float
        Largest thickness as a fraction of the chord (0.12 for NACA 0012).

    Returns
    -------
    (n, 2) array
        Counter-clockwise ring without repeated closing vertex, starting at the
        trailing edge ``(1, 0)``, the leading edge ``(0, 0)`` at index ``n // 2``.

    Examples
    --------
    >>> xy = naca0012(spacing=0.05)
    >>> xy[0].tolist(), xy[len(xy) // 2].tolist()
    ([1.0, 0.0], [0.0, 0.0])
    >>> bool(abs(xy[:, 1].max() - 0.06) < 1e-3)    # 12 % thick
    True
    """
    if not spacing > 0:
        raise ValueError(f"spacing must be positive, got {spacing!r}")
    # a dense cosine-spaced sampling (dense at the round nose) to measure arc length
    beta = np.linspace(0.0, np.pi, 4001)
    x = 0.5 * (1.0 - np.cos(beta))[::-1]  # from the trailing edge to the nose
    yt = (
        5.0
        * thickness
        * (0.2969 * np.sqrt(x) - 0.1260 * x - 0.3516 * x**2 + 0.2843 * x**3 - 0.1036 * x**4)
    )
    yt = np.maximum(yt, 0.0)  # rounding leaves -1e-17 at x = 1
    s = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(x), np.diff(yt)))])
    pieces = max(4, int(np.ceil(s[-1] / spacing)))
    t = np.linspace(0.0, s[-1], pieces + 1)
    ux, uy = np.interp(t, s, x), np.interp(t, s, yt)
    ux[0], uy[0], ux[-1], uy[-1] = 1.0, 0.0, 0.0, 0.0
    # upper surface trailing edge -> nose, then the mirrored lower surface back
    upper = np.c_[ux, uy]
    lower = np.c_[ux[-2:0:-1], -uy[-2:0:-1]]
    return np.concatenate([upper, lower])


def airfoil_channel(
    alpha: float = 4.0, h_near: float = 0.01, h_far: float = 0.125, rate: float = 0.25
) -> tuple[Polygon, GradedSize]:
    """A NACA 0012 airfoil of chord 1 at angle of attack ``alpha`` in a channel.

    The channel is the rectangle [-1.5, 3.5] x [-1.25, 1.25]; the airfoil's leading
    edge is at the origin before the nose-up rotation by ``alpha`` degrees about the
    quarter chord.  The size is ``h_near`` (chord/100 by default) on the airfoil and
    grows with the distance to it up to ``h_far`` (chord/8); the airfoil's vertices
    are ``h_near`` apart.

    Returns
    -------
    domain : shapely Polygon
        The channel with the airfoil as a hole.
    size : GradedSize
        Vectorized ``size(x, y)``.

    Examples
    --------
    >>> import aftmesh
    >>> domain, size = airfoil_channel(h_near=0.05, h_far=0.4)
    >>> len(domain.interiors), bool(domain.area < 12.5)
    (1, True)
    >>> mesh = aftmesh.generate(domain, size)
    >>> bool(abs(mesh.area() - domain.area) < 1e-9)
    True
    """
    xy = naca0012(spacing=h_near)
    a = np.radians(alpha)
    c, s = np.cos(a), np.sin(a)
    rel = xy - [0.25, 0.0]
    # a clockwise rotation by alpha raises the nose: a positive angle of attack
    foil = np.c_[rel[:, 0] * c + rel[:, 1] * s, -rel[:, 0] * s + rel[:, 1] * c] + [0.25, 0.0]
    channel = [(-1.5, -1.25), (3.5, -1.25), (3.5, 1.25), (-1.5, 1.25)]
    domain = Polygon(channel, [foil])
    size = GradedSize(Polygon(foil), h_near, h_far, rate)
    return domain, size


def inclusion(
    h_core: float = 0.04, h_far: float = 0.15, rate: float = 0.25
) -> tuple[list[Polygon], GradedSize]:
    """Two materials: a 3 x 2 rectangle with a 1 x 1 core in its middle.

    After the two-material domain of the paper's Figure 2: the mesh must follow the
    interface between the materials, and each triangle belongs to one of them.

    Parameters
    ----------
    h_core : float
        Size in and near the core.
    h_far : float
        Size far from the core.
    rate : float
        Growth of the size per unit of distance from the core.

    Returns
    -------
    domain : list of two shapely Polygons
        ``[annulus, core]``: the outer material (the rectangle with the core as a
        hole) and the core; ``Mesh.regions`` is 0 and 1 respectively.
    size : GradedSize

    Examples
    --------
    >>> import aftmesh, numpy as np
    >>> (annulus, core), size = inclusion(h_core=0.2, h_far=0.4)
    >>> annulus.area + core.area
    6.0
    >>> mesh = aftmesh.generate([annulus, core], size)
    >>> sorted(np.unique(mesh.regions).tolist())
    [0, 1]
    """
    outer = box(0.0, 0.0, 3.0, 2.0)
    core = box(1.0, 0.5, 2.0, 1.5)
    annulus = Polygon(outer.exterior.coords, [core.exterior.coords])
    return [annulus, core], GradedSize(core, h_core, h_far, rate)
