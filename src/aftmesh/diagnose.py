"""Where do a mesh's bad triangles come from?  A diagnosis for quality work.

:func:`diagnose` meshes a domain twice, once with the Python Basic_aft loop and no
smoothing (recording every step) and once as asked, and labels each triangle of the
final mesh whose radius ratio is below a threshold with the first class that applies:

``input_angle``
    it lies in a wedge between input segments at one vertex that is narrower than the
    smallest angle a triangle of radius ratio ``threshold`` can have (40 degrees at
    0.9; see :func:`smallest_angle`): no triangle there can be better, whatever the
    mesher does.  Exact up to the rounding of the angles.
``smoothing``
    no triangle around any of its vertices was bad before smoothing: the badness
    appeared when vertices moved (or edges were swapped after the moves).
``boundary``
    one of its vertices lies on an input segment (the boundary or an interface).
``size``
    a size transition: the size field's largest / smallest value over its vertices and
    centroid exceeds :data:`SIZE_RATIO`, or its mean edge length and a neighbour's
    differ by more than :data:`NEIGHBOUR_RATIO`.
``collision``
    fronts met there (a heuristic, from the recorded steps): two of its vertices
    belong to a step that took an existing candidate S making a triangle with one
    front edge (E joined to a front vertex that is not its neighbour: two fronts
    bridged) or three (the last triangle of a closing hole); or two of its vertices
    were created by Update_internal from front edges whose normals differ by more than
    :data:`OPPOSING_DEGREES` (fronts coming from opposite directions).
``other``
    none of these.

It needs the same vertex numbering in both meshes: smoothing moves vertices and adds
only the valence splits' points, numbered after all the others (``info
["valence_splits"]`` of them: no triangle was bad around them before smoothing), and
the Python loop gives the compiled loop's mesh.  So it diagnoses Basic_aft and
smoothing, before the minimum-angle pass (``min_angle=None`` unless given: the pass
adds vertices of its own), and without the scaffold (``scaffold=False`` in both runs:
the Python loop never plants it, and its removals change where the compiled loop's
fronts put their points).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ._typing import DomainArg, SizeArg
from .aft import Strategy
from .generate import generate
from .mesh import Mesh, triangle_quality

__all__ = ["CLASSES", "Diagnosis", "diagnose", "smallest_angle"]

CLASSES = ("input_angle", "smoothing", "boundary", "size", "collision", "other")
SIZE_RATIO = 1.3  # size field max / min over one triangle: a transition
NEIGHBOUR_RATIO = 1.5  # mean edge length of a triangle against a neighbour's
OPPOSING_DEGREES = 120.0  # front normals this far apart came from opposite sides
SMALLEST_ANGLE_BISECTIONS = 60  # halvings of 60 degrees: below a double's resolution


class _Recorder(Strategy):
    """The built-in subtasks, plus a record of what each step of the loop did."""

    def __init__(self):
        self.pending = None
        self.bridges: list[tuple] = []  # coordinates of T(E, S) for 1- and 3-front steps
        self.normals: dict[tuple, float] = {}  # new vertex -> angle of E's normal

    def get_next_edge(self, kernel) -> int:
        self._finish(kernel)
        E = kernel.get_next_edge()
        if E >= 0:
            a, b = kernel.edge(E)
            nxt = E - 2 if E % 3 == 2 else E + 1
            prv = E + 2 if E % 3 == 0 else E - 1
            fronts = 1 + kernel.is_front(nxt) + kernel.is_front(prv)
            S = kernel.compute_existing_candidate(E)
            self.pending = (
                kernel.vertex(a),
                kernel.vertex(b),
                kernel.vertex(S),
                fronts,
                kernel.n_vertices,
            )
        return E

    def _finish(self, kernel) -> None:
        if self.pending is None:
            return
        pa, pb, ps, fronts, nv = self.pending
        self.pending = None
        if kernel.n_vertices > nv:  # Update_internal added R
            self.normals[kernel.vertex(nv)] = math.atan2(pb[0] - pa[0], -(pb[1] - pa[1]))
        elif fronts != 2:
            self.bridges.append((pa, pb, ps))


@dataclass
class Diagnosis:
    """The labelled bad triangles of ``mesh`` (indices into ``mesh.triangles``)."""

    mesh: Mesh
    threshold: float
    bad: np.ndarray  # (k,) triangle indices
    labels: np.ndarray  # (k,) class names
    counts: dict[str, int] = field(default_factory=dict)

    def summary(self) -> str:
        n = len(self.mesh.triangles)
        share = 100 * len(self.bad) / max(n, 1)
        lines = [f"{len(self.bad)} of {n} triangles have RR < {self.threshold:g} ({share:.2f} %)"]
        for c in CLASSES:
            k = self.counts.get(c, 0)
            lines.append(f"  {c:11s} {k:7d}  {100 * k / max(len(self.bad), 1):5.1f} %")
        return "\n".join(lines)


def smallest_angle(threshold: float) -> float:
    """The smallest angle, in degrees, of a triangle whose radius ratio is at least
    `threshold`: for a given smallest angle a the isosceles triangle is the roundest,
    of radius ratio 8 sin(a / 2) sin((pi - a) / 4)^2, which grows with a up to 1 at
    60 degrees (solved here by bisection).

    >>> round(smallest_angle(0.9), 1)
    40.0
    >>> smallest_angle(1.0), smallest_angle(0.0)
    (60.0, 0.0)
    """
    if threshold >= 1.0:
        return 60.0
    if threshold <= 0.0:
        return 0.0
    lo, hi = 0.0, math.pi / 3
    for _ in range(SMALLEST_ANGLE_BISECTIONS):
        mid = 0.5 * (lo + hi)
        if 8 * math.sin(mid / 2) * math.sin((math.pi - mid) / 4) ** 2 < threshold:
            lo = mid
        else:
            hi = mid
    return math.degrees(lo)


def _across(mesh: Mesh) -> np.ndarray:
    """(t, 3, 2): for the corner k of triangle i at v, the corners at v of the two
    triangles across its edges at v (-1 across a segment or the outside)."""
    t, nb, n = mesh.triangles, mesh.neighbors, len(mesh.points)
    seg = np.sort(mesh.segments, axis=1).astype(np.int64)
    seg_keys = seg[:, 0] * n + seg[:, 1]
    out = np.full(t.shape + (2,), -1, dtype=np.int64)
    for k in range(3):
        v = t[:, k]
        for j, side in enumerate(((k + 1) % 3, (k + 2) % 3)):
            # the edge opposite corner `side` runs from v to the third corner
            other = t[:, 3 - k - side]
            key = np.minimum(v, other).astype(np.int64) * n + np.maximum(v, other)
            j_tri = nb[:, side]
            open_ = (j_tri >= 0) & ~np.isin(key, seg_keys)
            rows = np.flatnonzero(open_)
            pos = np.argmax(t[j_tri[rows]] == v[rows, None], axis=1)
            out[rows, k, j] = 3 * j_tri[rows] + pos
    return out


def _narrow_wedge(mesh: Mesh, threshold: float, angles: np.ndarray) -> np.ndarray:
    """Per triangle: does one of its corners lie in a wedge (the corners at one vertex
    between two segments, joined across the edges that are not) whose angle is below
    smallest_angle(threshold)?  A wedge around an inner vertex is a full turn.
    `angles`: triangle_quality's, in degrees."""
    angle = angles.ravel()
    across = _across(mesh).reshape(-1, 2)
    label = np.arange(len(angle))
    while True:  # each corner takes the least label of its wedge, a step at a time
        seen = np.where(across >= 0, label[np.maximum(across, 0)], len(label))
        new = np.minimum(label, seen.min(axis=1))
        if np.array_equal(new, label):
            break
        label = new
    wedge = np.bincount(label, weights=angle, minlength=len(label))
    narrow = wedge[label] < smallest_angle(threshold)
    return np.asarray(narrow.reshape(-1, 3).any(axis=1))


def _vertex_index(points: np.ndarray) -> dict:
    return {(float(x), float(y)): i for i, (x, y) in enumerate(points)}


def _bad_around(tris: np.ndarray, bad: np.ndarray, n_points: int) -> np.ndarray:
    """For each vertex: is it a corner of a bad triangle?"""
    out = np.zeros(n_points, dtype=bool)
    out[tris[bad].ravel()] = True
    return out


def _size_transition(mesh: Mesh, q: dict) -> np.ndarray:
    p, t = mesh.points, mesh.triangles
    corners = np.concatenate([p[t], p[t].mean(axis=1, keepdims=True)], axis=1)
    field_ = mesh.info["size_field"]  # generate always records it
    hs = np.asarray(field_(corners[..., 0].ravel(), corners[..., 1].ravel())).reshape(-1, 4)
    by_field = hs.max(axis=1) > SIZE_RATIO * hs.min(axis=1)
    mean_edge = q["edge_lengths"].mean(axis=1)
    nb = mesh.neighbors
    other = np.where(nb >= 0, mean_edge[np.maximum(nb, 0)], mean_edge[:, None])
    ratio = np.maximum(other / mean_edge[:, None], mean_edge[:, None] / other).max(axis=1)
    return by_field | (ratio > NEIGHBOUR_RATIO)


def _collision(mesh: Mesh, rec: _Recorder, index: dict) -> np.ndarray:
    n = len(mesh.points)
    bridged = np.zeros(n, dtype=np.int32)
    for tri in rec.bridges:
        ids = [index.get(c) for c in tri]
        for i in ids:
            if i is not None:
                bridged[i] += 1
    angle = np.full(n, np.nan)
    for c, a in rec.normals.items():
        i = index.get(c)
        if i is not None:
            angle[i] = a
    t = mesh.triangles
    by_bridge = (bridged[t] > 0).sum(axis=1) >= 2
    a = angle[t]
    opposing = np.zeros(len(t), dtype=bool)
    for i, j in ((0, 1), (1, 2), (2, 0)):
        d = np.abs((a[:, i] - a[:, j] + math.pi) % (2 * math.pi) - math.pi)
        opposing |= np.nan_to_num(d, nan=0.0) > math.radians(OPPOSING_DEGREES)
    return by_bridge | opposing


def diagnose(
    domain: DomainArg, size: SizeArg = None, *, threshold: float = 0.9, **options: Any
) -> Diagnosis:
    """Mesh ``domain`` with ``generate(domain, size, **options)`` and label its
    triangles with radius ratio below ``threshold`` by cause (see the module's
    docstring for the classes and the heuristics).

    Examples
    --------
    >>> from shapely.geometry import box
    >>> d = diagnose(box(0, 0, 1, 1), 0.1, threshold=0.95)
    >>> sorted(d.counts) == sorted(CLASSES) and sum(d.counts.values()) == len(d.bad)
    True
    """
    rec = _Recorder()
    options = {"min_angle": None, **options, "scaffold": False}
    plain = generate(domain, size, **{**options, "smooth": 0, "strategy": rec})
    mesh = generate(domain, size, **options)
    if len(plain.points) + mesh.info["valence_splits"] != len(mesh.points):
        raise RuntimeError("the two meshes have different vertices: cannot compare them")
    index = _vertex_index(plain.points)
    q = triangle_quality(mesh.points, mesh.triangles)
    bad = np.flatnonzero(q["radius_ratio"] < threshold)
    q0 = triangle_quality(plain.points, plain.triangles)
    was_bad = _bad_around(plain.triangles, q0["radius_ratio"] < threshold, len(mesh.points))
    on_segment = np.zeros(len(mesh.points), dtype=bool)
    on_segment[mesh.segments.ravel()] = True
    t = mesh.triangles[bad]
    tests = {
        "input_angle": _narrow_wedge(mesh, threshold, q["angles"])[bad],
        "smoothing": ~was_bad[t].any(axis=1),
        "boundary": on_segment[t].any(axis=1),
        "size": _size_transition(mesh, q)[bad],
        "collision": _collision(mesh, rec, index)[bad],
    }
    labels = np.full(len(bad), "other", dtype=object)
    for name in reversed(list(tests)):  # the first class that applies wins
        labels[tests[name]] = name
    counts = {c: int((labels == c).sum()) for c in CLASSES}
    return Diagnosis(mesh, threshold, bad, labels.astype(str), counts)
