"""The meshers under comparison, each behind the same small interface.

``prepare(case)`` does everything that is not meshing (building the Gmsh geometry,
formatting Triangle's switches) and returns a :class:`Runner`; ``runner.run()`` is the
timed call; ``runner.result(raw)`` turns what it returned into plain arrays.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from .cases import Case

__all__ = [
    "MESHERS",
    "DEFAULT_MESHERS",
    "REFERENCE",
    "Runner",
    "MeshOut",
    "prepare",
    "mesher_available",
    "triangle_area_switch",
]

REFERENCE = "tri-pq30"


@dataclass
class MeshOut:
    points: np.ndarray
    triangles: np.ndarray
    n_segments: int  # constrained edges in the output (input ones and pieces)


@dataclass
class Runner:
    run: Callable[[], Any]
    result: Callable[[Any], MeshOut]
    reset: Callable[[], None] = lambda: None  # untimed, between repetitions
    close: Callable[[], None] = lambda: None
    passes: int | None = None  # Triangle refinement passes (graded)


# name -> (label for the tables, short description)
MESHERS = {
    "aft": ("aftmesh", "aftmesh.generate(..., split_boundary=False)"),
    "aft-split": (
        "aftmesh (segments may split)",
        "aftmesh.generate(...): like Triangle pq30a, may split input segments",
    ),
    "aft-greedy": ("aftmesh greedy", "aftmesh.generate(..., greedy=True): no new points"),
    "tri-pq30": ("Triangle pq30a", "triangle 'pq30a<A>', A = sqrt(3)/4 h^2 (may split segments)"),
    "tri-pq30Y": ("Triangle pq30aY", "triangle 'pq30a<A>Y': no Steiner points on segments"),
    "tri-pq33": ("Triangle pq33a", "triangle 'pq33a<A>'"),
    "tri-p": ("Triangle p", "triangle 'p': CDT of the input only (speed-of-light reference)"),
    "gmsh-frontal": ("Gmsh alg 6", "gmsh Frontal-Delaunay (Mesh.Algorithm=6), 1 thread"),
    "gmsh-delaunay": ("Gmsh alg 5", "gmsh Delaunay (Mesh.Algorithm=5), 1 thread"),
}
DEFAULT_MESHERS = list(MESHERS)


def mesher_available(name: str) -> str | None:
    """None if the mesher can run here, else why not."""
    try:
        if name.startswith("tri"):
            import triangle  # noqa: F401
        elif name.startswith("gmsh"):
            import gmsh  # noqa: F401
        else:
            import aftmesh  # noqa: F401
    except Exception as exc:  # an optional dependency is missing
        return f"{type(exc).__name__}: {exc}"
    return None


def triangle_area_switch(area: float) -> str:
    """Triangle reads the number after 'a' as digits and dots only ('1e-05' would
    be read as 1 followed by the 'e' switch), so write it in positional notation."""
    digits = max(6, 6 - int(math.floor(math.log10(area))))
    return f"a{area:.{digits}f}"


# ----------------------------------------------------------------------- aftmesh


def _aft(case: Case, greedy: bool, split: bool = False) -> Runner:
    import aftmesh

    dom = case.as_triangle_dict()
    size = case.size_arg

    def run():
        return aftmesh.generate(dom, size, split_boundary=split, greedy=greedy)

    def result(m):
        return MeshOut(np.asarray(m.points), np.asarray(m.triangles), len(m.segments))

    return Runner(run, result)


# ----------------------------------------------------------------------- Triangle


def _triangle(case: Case, switches: str) -> Runner:
    import triangle

    regions = case.regions is not None and len(case.regions) > 0
    dom = case.as_triangle_dict(with_region_areas=True)
    extra = "A" if regions else ""
    quality = "q" in switches

    def result(r):
        return MeshOut(
            np.asarray(r["vertices"]), np.asarray(r["triangles"]), len(r.get("segments", ()))
        )

    if not quality:
        return Runner(lambda: triangle.triangulate(dom, switches + extra), result)

    if case.size is None:
        area = math.sqrt(3) / 4 * case.h**2
        opts = switches + triangle_area_switch(area) + extra
        return Runner(lambda: triangle.triangulate(dom, opts), result)

    # Graded size: Triangle has no size function in its Python binding, so refine in
    # passes with a per-triangle area bound sqrt(3)/4 size(centroid)^2 until every
    # triangle meets it (all passes are timed).
    runner = Runner(None, result)
    size = case.size

    def run():
        r = triangle.triangulate(dom, switches + extra)
        passes = 1
        for _ in range(12):
            p = r["vertices"][r["triangles"]]
            c = p.mean(axis=1)
            target = math.sqrt(3) / 4 * size(c[:, 0], c[:, 1]) ** 2
            e1 = p[:, 1] - p[:, 0]
            e2 = p[:, 2] - p[:, 0]
            area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
            if (area <= 1.02 * target).all():
                break
            inp = {
                "vertices": r["vertices"],
                "triangles": r["triangles"],
                "segments": r["segments"],
                "triangle_max_area": target,
            }
            if "triangle_attributes" in r:
                inp["triangle_attributes"] = r["triangle_attributes"]
            r = triangle.triangulate(inp, "r" + switches + "a" + extra)
            passes += 1
        runner.passes = passes
        return r

    runner.run = run
    return runner


# ----------------------------------------------------------------------- Gmsh


def _faces(case: Case):
    """The bounded faces of the segment graph that are not holes, each as
    (outer ring, [inner rings]) of vertex indices, plus the segments and vertices that
    bound no face (to be embedded) with the face each lies in."""
    import shapely
    from shapely.ops import polygonize_full

    V, S = case.vertices, case.segments
    lines = shapely.linestrings(np.stack([V[S[:, 0]], V[S[:, 1]]], axis=1))
    polys, cuts, dangles, invalid = polygonize_full(list(lines))
    index = {(float(x), float(y)): i for i, (x, y) in enumerate(V)}

    def ring_ids(ring):
        c = np.asarray(ring.coords)[:-1]
        return [index[(float(x), float(y))] for x, y in c]

    faces = []
    for poly in polys.geoms:
        if len(case.holes) and shapely.contains_xy(poly, case.holes[:, 0], case.holes[:, 1]).any():
            continue
        faces.append((poly, ring_ids(poly.exterior), [ring_ids(r) for r in poly.interiors]))
    used = set()
    for _, outer, inners in faces:
        for ring in [outer, *inners]:
            n = len(ring)
            used.update(
                (min(ring[k], ring[(k + 1) % n]), max(ring[k], ring[(k + 1) % n])) for k in range(n)
            )
    loose_segments = [k for k, (a, b) in enumerate(S) if (min(a, b), max(a, b)) not in used]
    on_segment = np.zeros(len(V), dtype=bool)
    on_segment[S.ravel()] = True
    loose_points = np.flatnonzero(~on_segment).tolist()

    def face_of(x, y):
        for k, (poly, _, _) in enumerate(faces):
            if shapely.contains_xy(poly, x, y) or shapely.intersects_xy(poly, x, y):
                return k
        return None

    embed_lines = [(k, face_of(*(0.5 * (V[S[k, 0]] + V[S[k, 1]])))) for k in loose_segments]
    embed_points = [(i, face_of(*V[i])) for i in loose_points]
    return faces, embed_lines, embed_points


def _gmsh(case: Case, algorithm: int) -> Runner:
    import gmsh

    if not gmsh.isInitialized():
        gmsh.initialize(readConfigFiles=False, interruptible=False)
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("General.Verbosity", 1)
    gmsh.clear()
    gmsh.option.setNumber("General.NumThreads", 1)
    gmsh.option.setNumber("Mesh.Algorithm", algorithm)
    gmsh.model.add(case.name)
    geo = gmsh.model.geo
    V, S = case.vertices, case.segments
    lc = case.h if case.size is None else float(np.min(case.target(V[:, 0], V[:, 1])))
    for i, (x, y) in enumerate(V):
        geo.addPoint(float(x), float(y), 0.0, lc, i + 1)
    for k, (a, b) in enumerate(S):
        geo.addLine(int(a) + 1, int(b) + 1, k + 1)
        geo.mesh.setTransfiniteCurve(k + 1, 2)  # exactly the given segment

    seg_of = {}
    for k, (a, b) in enumerate(S):
        seg_of[(int(a), int(b))] = k + 1
        seg_of[(int(b), int(a))] = -(k + 1)

    def loop(ring):
        n = len(ring)
        return geo.addCurveLoop([seg_of[(ring[k], ring[(k + 1) % n])] for k in range(n)])

    faces, embed_lines, embed_points = _faces(case)
    surfaces = []
    for _, outer, inners in faces:
        surfaces.append(geo.addPlaneSurface([loop(outer)] + [loop(r) for r in inners]))
    geo.synchronize()
    for k, f in embed_lines:
        if f is not None:
            gmsh.model.mesh.embed(1, [k + 1], 2, surfaces[f])
    for i, f in embed_points:
        if f is not None:
            gmsh.model.mesh.embed(0, [i + 1], 2, surfaces[f])

    if case.size is not None:
        field = gmsh.model.mesh.field.add("MathEval")
        gmsh.model.mesh.field.setString(field, "F", case.gmsh_size_expr)
        gmsh.model.mesh.field.setAsBackgroundMesh(field)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)

    def run():
        gmsh.model.mesh.generate(2)

    def reset():
        gmsh.model.mesh.clear()

    def result(_):
        tags, coords, _ = gmsh.model.mesh.getNodes()
        pts = coords.reshape(-1, 3)[:, :2]
        where = np.zeros(int(tags.max()) + 1, dtype=np.int64)
        where[tags.astype(np.int64)] = np.arange(len(tags))
        _, tri_nodes = gmsh.model.mesh.getElementsByType(2)
        tris = where[tri_nodes.astype(np.int64)].reshape(-1, 3)
        n_lines = 0
        if gmsh.model.mesh.getElementTypes(1):
            n_lines = len(gmsh.model.mesh.getElementsByType(1)[0])
        # gmsh's triangles may be clockwise: orient them counter-clockwise
        p = pts[tris]
        cw = (
            (p[:, 1, 0] - p[:, 0, 0]) * (p[:, 2, 1] - p[:, 0, 1])
            - (p[:, 1, 1] - p[:, 0, 1]) * (p[:, 2, 0] - p[:, 0, 0])
        ) < 0
        tris[cw] = tris[cw][:, ::-1]
        return MeshOut(pts, tris, n_lines)

    return Runner(run, result, reset=reset, close=gmsh.finalize)


def prepare(name: str, case: Case) -> Runner:
    if name == "aft":
        return _aft(case, greedy=False)
    if name == "aft-split":
        return _aft(case, greedy=False, split=True)
    if name == "aft-greedy":
        return _aft(case, greedy=True)
    if name == "tri-pq30":
        return _triangle(case, "pq30")
    if name == "tri-pq30Y":
        return _triangle(case, "pq30Y")
    if name == "tri-pq33":
        return _triangle(case, "pq33")
    if name == "tri-p":
        return _triangle(case, "p")
    if name == "gmsh-frontal":
        return _gmsh(case, 6)
    if name == "gmsh-delaunay":
        return _gmsh(case, 5)
    raise KeyError(f"unknown mesher {name!r}; known: {', '.join(MESHERS)}")
