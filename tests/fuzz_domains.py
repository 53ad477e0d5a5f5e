"""Random domains, sizes and options for robustness fuzzing of ``aftmesh.generate``.

Used by ``tests/test_robustness.py`` (hypothesis, ``ci`` / ``long`` profiles) and by
``tools/fuzz.py`` (long sessions outside pytest).  Three parts:

* **generators** -- hypothesis strategies for valid domains of every awkward kind:
  star-shaped and non-star simple polygons, unions of grid cells (holes and parts that
  touch at corners), many holes, holes touching the outer ring or each other at a
  vertex, features 1e-7 of the size apart, slivers and spikes, near-collinear and
  repeated vertices, hundreds of (exactly or nearly) cocircular vertices, constraint
  lines, region lists with T-junctions; optionally moved by 1e7 or scaled by 1e-6;
  sizes that are constant, absent, or graded over four orders of magnitude.
* :class:`FuzzCase` -- one input (domain, size spec, options), serialisable to JSON
  without loss (floats are written with ``repr``), so a failing input can be saved and
  replayed exactly.
* :func:`verify` -- the oracle: ``check_mesh`` with the exact area (rational
  arithmetic), the boundary kept (corners exactly, input edges covered), regions and
  ``max_triangles`` respected, and the constrained Delaunay property against Triangle
  (exact empty-circle test where Triangle's choice differs on cocircular points).
"""

from __future__ import annotations

import json
import math
import os
import pickle
import re
import select
import signal
import time
import traceback
from dataclasses import dataclass, field
from fractions import Fraction
from functools import cache

import numpy as np
import shapely
import triangle
from hypothesis import assume
from hypothesis import strategies as st
from shapely.geometry import GeometryCollection, LineString, MultiPolygon, Point, Polygon, box

import aftmesh
from aftmesh import _kernel
from aftmesh.checks import check_mesh
from aftmesh.noding import SNAP_ULPS

__all__ = [
    "FuzzCase",
    "OracleError",
    "fuzz_cases",
    "verify",
    "run_case",
    "case_to_json",
    "case_from_json",
    "size_callable",
    "GENERATORS",
    "isolated",
    "Hang",
    "Crash",
    "ChildInterrupted",
]


# ============================================================ isolation from crashes
class Hang(AssertionError):
    """The call did not return within its time limit (the child was killed)."""


class Crash(AssertionError):
    """The call killed its process (a signal such as SIGSEGV, or an abort)."""


class ChildInterrupted(AssertionError):
    """The call raised KeyboardInterrupt (or SystemExit) in the child: reported as a
    failure here instead of being re-raised, which would stop the whole test run."""


def isolated(fn, *args, timeout: float = 30.0, memory_gb: float | None = None, **kwargs):
    """Run ``fn(*args, **kwargs)`` in a forked child and return its result, or raise
    the exception it raised (re-raised here), :class:`Hang` after ``timeout`` seconds,
    or :class:`Crash` when the child dies.  A segfault or an endless loop in the kernel
    thus fails one test instead of taking the whole run down."""
    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child
        code = 0
        try:
            os.close(r)
            if memory_gb:
                import resource

                lim = int(memory_gb * 2**30)
                resource.setrlimit(resource.RLIMIT_AS, (lim, lim))
            try:
                out = ("ok", fn(*args, **kwargs))
            except BaseException as exc:  # noqa: BLE001 - sent to the parent
                out = ("raised", exc, traceback.format_exc())
            try:
                data = pickle.dumps(out)
            except Exception:  # noqa: BLE001
                exc = out[1] if out[0] == "raised" else None
                data = pickle.dumps(
                    (
                        "raised",
                        RuntimeError(f"unpicklable result: {exc!r}"),
                        out[2] if len(out) > 2 else "",
                    )
                )
            with os.fdopen(w, "wb") as f:
                f.write(data)
        except BaseException:  # noqa: BLE001
            code = 3
        finally:
            os._exit(code)
    os.close(w)
    chunks = []
    end = time.monotonic() + timeout
    with os.fdopen(r, "rb") as f:
        fd = f.fileno()
        while True:
            left = end - time.monotonic()
            if left <= 0:
                os.kill(pid, signal.SIGKILL)
                os.waitpid(pid, 0)
                raise Hang(f"{getattr(fn, '__name__', fn)} did not finish in {timeout:g} s")
            ready, _, _ = select.select([fd], [], [], min(left, 1.0))
            if ready:
                block = os.read(fd, 1 << 20)
                if not block:
                    break
                chunks.append(block)
    _, status = os.waitpid(pid, 0)
    if os.WIFSIGNALED(status):
        sig = os.WTERMSIG(status)
        raise Crash(
            f"{getattr(fn, '__name__', fn)} killed its process with signal "
            f"{sig} ({signal.Signals(sig).name})"
        )
    if not chunks:
        raise Crash(
            f"{getattr(fn, '__name__', fn)}: the child exited with status "
            f"{os.waitstatus_to_exitcode(status)} without an answer"
        )
    out = pickle.loads(b"".join(chunks))
    if out[0] == "ok":
        return out[1]
    exc = out[1]
    if not isinstance(exc, Exception):
        raise ChildInterrupted(f"{type(exc).__name__} in the child:\n{out[2]}")
    exc.child_traceback = out[2]
    raise exc


# ============================================================== size specifications
# A size is given to generate() as None, a number, or a callable built from a spec so
# that the case can be stored as JSON: {"kind": "point", ...}.
def size_callable(spec):
    """The ``size`` argument described by ``spec`` (None, a number or a dict)."""
    if spec is None or isinstance(spec, (int, float)):
        return spec
    kind = spec["kind"]
    lo, hi = float(spec["lo"]), float(spec["hi"])
    cx, cy = spec.get("center", (0.0, 0.0))
    reach = float(spec.get("reach", 1.0))
    if not lo > 0:
        raise ValueError(f"size spec {spec}: lo must be positive")

    if kind == "point":
        # lo at the centre, growing linearly (slope >= 0.1, so the number of triangles
        # grows only with log(hi / lo)) up to hi
        slope = float(spec["slope"])

        def size(x, y):
            d = np.hypot(np.asarray(x) - cx, np.asarray(y) - cy)
            return np.minimum(hi, lo + slope * d)
    elif kind == "ramp":
        # linear in x across the domain's width
        x0, w = float(spec["x0"]), float(spec["width"])

        def size(x, y):
            t = np.clip((np.asarray(x, dtype=float) - x0) / w, 0.0, 1.0)
            return lo + (hi - lo) * t + 0.0 * np.asarray(y)
    elif kind == "wave":
        # between lo and hi in both directions, several periods over the domain
        def size(x, y):
            s = np.sin(np.asarray(x) * 2 * np.pi / reach) * np.cos(
                np.asarray(y) * 2 * np.pi / reach
            )
            return lo * (hi / lo) ** (0.5 + 0.5 * s)
    else:
        raise KeyError(kind)
    return size


@st.composite
def size_specs(draw, bounds):
    """A size for a domain with these bounds: None, a constant, or a graded field whose
    smallest value is down to 1e-4 of its largest (at a point; 1e-2 along a side,
    1e-1 in waves, so that the meshes stay small enough to make by the thousand)."""
    (x0, y0), (x1, y1) = bounds
    diam = math.hypot(x1 - x0, y1 - y0)
    kind = draw(st.sampled_from(["const", "const", "none", "point", "point", "ramp", "wave"]))
    if kind == "none":
        return None
    hi = diam * draw(st.floats(0.04, 0.4))
    if kind == "const":
        return hi
    if kind == "point":
        ratio = 10.0 ** -draw(st.floats(0.0, 4.0))
        return {
            "kind": "point",
            "lo": hi * ratio,
            "hi": hi,
            "center": [draw(st.floats(x0, x1)), draw(st.floats(y0, y1))],
            "slope": draw(st.floats(0.1, 1.0)),
        }
    if kind == "ramp":
        # fine along a whole side: kept to two orders of magnitude (the mesh has
        # (width / lo) triangles along that side)
        ratio = 10.0 ** -draw(st.floats(0.0, 2.0))
        return {"kind": "ramp", "lo": hi * ratio, "hi": hi, "x0": x0, "width": max(x1 - x0, 1e-300)}
    hi = diam * draw(st.floats(0.1, 0.4))
    ratio = 10.0 ** -draw(st.floats(0.0, 1.0))
    return {"kind": "wave", "lo": hi * ratio, "hi": hi, "reach": diam * draw(st.floats(0.2, 1.0))}


# ======================================================================== the case
@dataclass
class FuzzCase:
    """One input of generate(): ``domain`` in any accepted form, a size spec, options.

    ``geometry`` keeps the shapely view of the same domain (polygons, constraint lines,
    fixed points) for the oracle, whatever form ``domain`` takes."""

    kind: str
    domain: object
    size: object = None
    options: dict = field(default_factory=dict)
    polygons: list = field(default_factory=list)  # region polygons (or the parts)
    lines: list = field(default_factory=list)  # constraint LineStrings
    points: list = field(default_factory=list)  # fixed Points

    def call(self):
        return aftmesh.generate(self.domain, size_callable(self.size), **self.options)

    def __repr__(self):
        return f"FuzzCase({self.kind}, size={self.size!r}, options={self.options})"


def _geom_json(g):
    return {"wkb": shapely.to_wkb(g, hex=True), "wkt": shapely.to_wkt(g, rounding_precision=17)}


def _geom_from(d):
    return shapely.from_wkb(d["wkb"])


def case_to_json(case: FuzzCase) -> dict:
    """A JSON-able dict that :func:`case_from_json` turns back into the same case
    (coordinates exactly: WKB and repr floats)."""
    dom = case.domain
    if isinstance(dom, shapely.Geometry):
        form = {"form": "geometry", "geometry": _geom_json(dom)}
    elif isinstance(dom, dict):
        form = {
            "form": "dict",
            "vertices": np.asarray(dom["vertices"]).tolist(),
            "segments": np.asarray(dom["segments"]).tolist(),
            "holes": np.asarray(dom.get("holes", np.zeros((0, 2)))).tolist(),
        }
    elif isinstance(dom, np.ndarray):
        form = {"form": "ring", "coords": dom.tolist()}
    else:
        form = {"form": "regions", "items": [_geom_json(p) for p in dom]}
    return {
        "kind": case.kind,
        "domain": form,
        "size": case.size,
        "options": case.options,
        "polygons": [_geom_json(p) for p in case.polygons],
        "lines": [_geom_json(g) for g in case.lines],
        "points": [_geom_json(g) for g in case.points],
    }


def case_from_json(d: dict) -> FuzzCase:
    f = d["domain"]
    if f["form"] == "geometry":
        dom = _geom_from(f["geometry"])
    elif f["form"] == "dict":
        dom = {
            "vertices": np.array(f["vertices"], dtype=float).reshape(-1, 2),
            "segments": np.array(f["segments"], dtype=np.int64).reshape(-1, 2),
            "holes": np.array(f["holes"], dtype=float).reshape(-1, 2),
        }
    elif f["form"] == "ring":
        dom = np.array(f["coords"], dtype=float)
    else:
        dom = [_geom_from(g) for g in f["items"]]
    return FuzzCase(
        d["kind"],
        dom,
        d["size"],
        dict(d["options"]),
        [_geom_from(g) for g in d["polygons"]],
        [_geom_from(g) for g in d["lines"]],
        [_geom_from(g) for g in d["points"]],
    )


def dumps(case: FuzzCase) -> str:
    return json.dumps(case_to_json(case), indent=1)


# ====================================================================== the oracle
class OracleError(AssertionError):
    """A mesh (or a refusal) that is wrong for its input; the message says how."""


def _ring_coords(ring) -> np.ndarray:
    c = np.asarray(ring.coords, dtype=float)[:, :2]
    return c[:-1] if len(c) > 1 and (c[0] == c[-1]).all() else c


def _rings(polygons):
    for p in polygons:
        parts = p.geoms if isinstance(p, MultiPolygon) else [p]
        for q in parts:
            yield _ring_coords(q.exterior), False
            for h in q.interiors:
                yield _ring_coords(h), True


def _shoelace(c: np.ndarray) -> Fraction:
    xs = [Fraction(float(v)) for v in c[:, 0]]
    ys = [Fraction(float(v)) for v in c[:, 1]]
    n = len(xs)
    s = sum(xs[i] * ys[(i + 1) % n] - xs[(i + 1) % n] * ys[i] for i in range(n))
    return abs(s) / 2


def exact_area(polygons) -> float:
    """Area of polygons with disjoint interiors, in rational arithmetic from the
    float coordinates (so moving the domain by 1e7 costs no accuracy)."""
    total = Fraction(0)
    for c, is_hole in _rings(polygons):
        total += -_shoelace(c) if is_hole else _shoelace(c)
    return float(total)


def _exact_orient(a, b, c) -> int:
    ax, ay, bx, by, cx, cy = (Fraction(float(v)) for v in (*a, *b, *c))
    d = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    return (d > 0) - (d < 0)


def _merge_straight(c: np.ndarray, closed: bool) -> np.ndarray:
    """Drop the vertices where the chain goes straight on (exact orientation 0, same
    direction): the input edges that generate() may legitimately merge."""
    changed = True
    while changed and len(c) > (3 if closed else 2):
        changed = False
        n = len(c)
        keep = np.ones(n, dtype=bool)
        for i in range(n) if closed else range(1, n - 1):
            a, b, d = c[i - 1], c[i], c[(i + 1) % n]
            if keep[i - 1] and _exact_orient(a, b, d) == 0 and np.dot(b - a, d - b) > 0:
                keep[i] = False
                changed = True
        c = c[keep]
    return c


def _input_chains(case: FuzzCase, merge: bool = False):
    """Closed rings and open constraint chains, repeated vertices dropped (and with
    `merge`, straight runs joined into one edge)."""
    out = []
    for c, _ in _rings(case.polygons):
        keep = np.r_[True, (c[1:] != c[:-1]).any(axis=1)]
        c = c[keep]
        while len(c) > 1 and (c[-1] == c[0]).all():
            c = c[:-1]
        out.append((_merge_straight(c, True) if merge else c, True))
    for line in case.lines:
        c = np.asarray(line.coords, dtype=float)[:, :2]
        c = c[np.r_[True, (c[1:] != c[:-1]).any(axis=1)]]
        out.append((_merge_straight(c, False) if merge else c, False))
    return out


def corner_points(case: FuzzCase) -> np.ndarray:
    """Input vertices where the boundary really turns (exact orientation != 0), plus
    the ends of constraint lines and the fixed points: all must be mesh vertices."""
    pts = []
    for c, closed in _input_chains(case):
        n = len(c)
        for i in range(n):
            if not closed and (i == 0 or i == n - 1):
                pts.append(c[i])
                continue
            a, b, d = c[i - 1], c[i], c[(i + 1) % n]
            if _exact_orient(a, b, d) != 0 or np.dot(b - a, d - b) <= 0:
                pts.append(b)
    for p in case.points:
        pts.append(np.asarray(p.coords, dtype=float)[0, :2])
    P = np.unique(np.array(pts, dtype=float).reshape(-1, 2), axis=0)
    if case.lines and len(P):
        # a line ending on the boundary at a rounded point may end just outside it:
        # such an end cannot be a mesh vertex (the line is cut at the boundary)
        union = shapely.union_all(case.polygons)
        P = P[shapely.covers(union, shapely.points(P))]
    return P


def input_edges(case: FuzzCase, merge: bool = False) -> np.ndarray:
    edges = []
    for c, closed in _input_chains(case, merge):
        n = len(c)
        for i in range(n if closed else n - 1):
            edges.append((c[i], c[(i + 1) % n]))
    return np.array(edges, dtype=float).reshape(-1, 2, 2)


def _dist_to_edges(pts: np.ndarray, E: np.ndarray, chunk: int = 256) -> np.ndarray:
    """Distance from each point to the nearest edge of E."""
    a, d = E[:, 0], E[:, 1] - E[:, 0]
    L2 = np.maximum((d * d).sum(axis=1), 1e-300)
    best = np.full(len(pts), np.inf)
    for s in range(0, len(pts), chunk):
        p = pts[s : s + chunk, None, :]
        t = np.clip(((p - a) * d).sum(axis=2) / L2, 0.0, 1.0)
        q = a + t[..., None] * d
        best[s : s + chunk] = np.sqrt(((p - q) ** 2).sum(axis=2)).min(axis=1)
    return best


def _uncovered(A: np.ndarray, B: np.ndarray, a: np.ndarray, b: np.ndarray, tol: float) -> float:
    """Length of the input edge a-b not covered by the mesh segments A[i]-B[i] that
    lie on it (both ends within tol of it)."""
    d = b - a
    L2 = float(d @ d)
    if L2 == 0:
        return 0.0
    near = _dist_to_edges(A, np.array([[a, b]])) <= tol
    near &= _dist_to_edges(B, np.array([[a, b]])) <= tol
    t0 = np.clip((A[near] - a) @ d / L2, 0, 1)
    t1 = np.clip((B[near] - a) @ d / L2, 0, 1)
    iv = np.sort(np.c_[t0, t1], axis=1)
    iv = iv[np.argsort(iv[:, 0])]
    covered, reach = 0.0, 0.0
    for lo, hi in iv:
        if hi > reach:
            covered += hi - max(lo, reach)
            reach = hi
    return (1.0 - covered) * math.sqrt(L2)


def _boundary_length(case: FuzzCase) -> float:
    parts = [p.boundary for p in case.polygons] + list(case.lines)
    return float(shapely.union_all(parts).length)


def check_cdt_with_triangle(mesh, holes: np.ndarray) -> None:
    """Every triangle of the mesh is a triangle of Triangle's CDT of the mesh's points
    and segments, unless it has a neighbour across a non-segment edge whose far vertex
    is exactly on its circumcircle (cocircular points: the CDT is not unique there;
    check_mesh has already done the exact empty-circle test on every edge)."""
    P = np.array(mesh.points, dtype=float)  # writable copies for Triangle
    T = np.array(mesh.triangles)
    S = np.array(mesh.segments, dtype=np.int32)
    if len(T) == 0:
        return
    tri_in = {"vertices": P, "segments": S}
    if len(holes):
        tri_in["holes"] = holes
    ref = triangle.triangulate(tri_in, "p")
    if len(ref["vertices"]) != len(P):
        raise OracleError(
            f"Triangle had to add {len(ref['vertices']) - len(P)} points to "
            "this mesh's segments: mesh segments cross or touch"
        )
    theirs = {tuple(sorted(t)) for t in np.asarray(ref.get("triangles", [])).tolist()}
    extra = [i for i, t in enumerate(T.tolist()) if tuple(sorted(t)) not in theirs]
    if not extra:
        return
    N = np.asarray(mesh.neighbors)
    seg = {tuple(sorted(s)) for s in S.tolist()}
    quads = []
    owner = []
    for i in extra:
        for k in range(3):
            u, v = int(T[i, (k + 1) % 3]), int(T[i, (k + 2) % 3])
            nb = N[i, k]
            if nb < 0 or (min(u, v), max(u, v)) in seg:
                continue
            far = [w for w in T[nb] if w != u and w != v][0]
            quads.append([*T[i], far])
            owner.append(i)
    ok = set()
    if quads:
        inc = _kernel.incircle_many(P, np.ascontiguousarray(quads, dtype=np.int32))
        ok = {owner[j] for j in np.flatnonzero(inc == 0)}
    unexplained = [i for i in extra if i not in ok]
    if unexplained and _triangle_not_delaunay(P, theirs, T, unexplained, seg):
        return
    if unexplained:
        i = unexplained[0]
        raise OracleError(
            f"{len(unexplained)} triangles are not in Triangle's CDT and have "
            f"no cocircular neighbour, e.g. {P[T[i]].tolist()}"
        )


def _incircle_exact(a, b, c, d) -> int:
    """Sign of the incircle determinant of (a, b, c) counter-clockwise and d, in
    rational arithmetic (independent of the kernel's predicates)."""
    a, b, c, d = ([Fraction(x) for x in p] for p in (a, b, c, d))
    rows = [(p[0] - d[0], p[1] - d[1]) for p in (a, b, c)]
    m = [(x, y, x * x + y * y) for x, y in rows]
    det = (
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    )
    return (det > 0) - (det < 0)


def _illegal_edges(P, tris, seg) -> int:
    """How many non-segment edges shared by two of `tris` fail the empty-circle test,
    decided in rational arithmetic."""
    by_edge: dict = {}
    for t in tris:
        for k in range(3):
            e = tuple(sorted((t[k], t[(k + 1) % 3])))
            by_edge.setdefault(e, []).append((t, t[(k + 2) % 3]))
    bad = 0
    for e, pair in by_edge.items():
        if len(pair) != 2 or e in seg:
            continue
        (t, _), (_, far) = pair
        a, b, c = (P[v] for v in t)
        if (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) < 0:
            b, c = c, b
        bad += _incircle_exact(a, b, c, P[far]) > 0
    return bad


def _triangle_not_delaunay(P, theirs, T, unexplained, seg) -> bool:
    """Where the two disagree, is Triangle's triangulation the one that breaks the
    empty-circle property (exactly), while this mesh's triangles keep it?  Triangle's
    incircle test can misjudge points cocircular to within rounding."""
    touched = {v for i in unexplained for v in T[i]}
    their_near = [t for t in theirs if touched & set(t)]
    our_near = [tuple(T[i]) for i in range(len(T)) if touched & set(T[i].tolist())]
    return _illegal_edges(P, their_near, seg) > 0 and _illegal_edges(P, our_near, seg) == 0


# How far (in units in the last place of the coordinates) a mesh vertex on a segment
# may lie off its input edge: noding.py puts a lone point or a line's free end within
# its snapping tolerance (SNAP_ULPS) on the segment, so a piece may run that far off
# the edge; a split point on such a piece adds its own rounding and refine.pxi's
# one-ulp nudge.
SEGMENT_POINT_ULPS = SNAP_ULPS + 2


def area_tolerance(case: FuzzCase, area: float) -> float:
    """Relative area error allowed: 1e-9, or more far from the origin, where the
    points that split a slanted input edge can only be put within half an ulp of the
    coordinates' magnitude of it (a sliver of that width along the boundary)."""
    perimeter = _boundary_length(case)
    big = max(float(np.abs(np.asarray(p.bounds)).max()) for p in case.polygons)
    return max(1e-9, 4.0 * perimeter * np.spacing(big) / max(area, 1e-300))


def verify(mesh, case: FuzzCase, check=check_mesh) -> None:
    """Raise (OracleError or the checker's MeshCheckError) unless ``mesh`` is a correct
    mesh of ``case``.  ``check`` is the invariant checker (the test fixture)."""
    opts = case.options
    swaps = opts.get("swaps", True)
    split = opts.get("split_boundary", True)
    area = exact_area(case.polygons)
    check(mesh, domain_area=area, delaunay=swaps, area_rtol=area_tolerance(case, area))
    P = np.asarray(mesh.points)
    S = np.asarray(mesh.segments)
    if not np.isfinite(P).all():
        raise OracleError("non-finite mesh points")
    mt = opts.get("max_triangles")
    if mt is not None and len(mesh.triangles) > mt:
        raise OracleError(f"{len(mesh.triangles)} triangles > max_triangles={mt}")
    # every corner of the input is a mesh vertex, exactly
    have = {(float(x), float(y)) for x, y in P.tolist()}
    for x, y in corner_points(case).tolist():
        if (x, y) not in have:
            raise OracleError(f"input corner {(x, y)} is not a mesh vertex")
    # the segments lie on the input edges and cover them
    E = input_edges(case, merge=True)
    if len(S) and len(E):
        scale = max(float(np.abs(E).max()), 1e-300)
        ends = np.concatenate([P[S[:, 0]], P[S[:, 1]], 0.5 * (P[S[:, 0]] + P[S[:, 1]])])
        dist = _dist_to_edges(ends, E.reshape(-1, 2, 2))
        span = float(np.ptp(E.reshape(-1, 2), axis=0).max()) or scale
        # a split point is rounded (about an ulp off its edge) and the min-angle pass
        # may move one by one more ulp to keep a sliver next to it counter-clockwise
        tol = 1e-9 * span + SEGMENT_POINT_ULPS * float(np.spacing(scale))
        if (dist > tol).any():
            i = int(np.argmax(dist))
            raise OracleError(
                f"mesh segment point {ends[i].tolist()} is {dist[i]:.3g} away from every input edge"
            )
        for a, b in E:
            short = _uncovered(P[S[:, 0]], P[S[:, 1]], a, b, tol)
            if short > 1e-9 * float(np.hypot(*(b - a))) + 2 * tol:
                raise OracleError(
                    f"input edge {a.tolist()} -> {b.tolist()} is not covered by "
                    f"mesh segments over a length of {short:.3g}"
                )
    if not split and not case.lines:
        _check_unsplit(mesh, case, have)
    # regions: each triangle's centroid is inside the region it is labelled with
    if isinstance(case.domain, list) and len(mesh.triangles):
        cen = P[np.asarray(mesh.triangles)].mean(axis=1)
        reg = np.asarray(mesh.regions)
        for k, poly in enumerate(case.polygons):
            sel = np.flatnonzero(reg == k)
            out = sel[~shapely.contains_xy(poly, cen[sel, 0], cen[sel, 1])]
            # a triangle an ulp or two wide has its rounded centroid on its edge or
            # beyond: decide those by the exact centroid
            for i in out:
                if not _exact_winding_inside(poly, P[np.asarray(mesh.triangles)[i]]):
                    raise OracleError(
                        f"a triangle labelled region {k} is not inside it: "
                        f"{P[np.asarray(mesh.triangles)[i]].tolist()}"
                    )
        if ((reg < 0) | (reg >= len(case.polygons))).any():
            raise OracleError(f"region labels {np.unique(reg).tolist()} out of range")
    if swaps:
        check_cdt_with_triangle(mesh, _void_points(case.polygons))


def _winding_exact(polys, px, py) -> tuple[int, bool]:
    """The winding number of the polygons' rings around (px, py) (Fractions), and
    whether the point lies on one of their edges, in rational arithmetic."""
    from fractions import Fraction

    winding, on_edge = 0, False
    for poly in polys:
        for part in shapely.get_parts(poly):
            part = shapely.geometry.polygon.orient(part, 1.0)
            for ring in [part.exterior, *part.interiors]:
                c = [(Fraction(x), Fraction(y)) for x, y in np.asarray(ring.coords)[:, :2].tolist()]
                for (xa, ya), (xb, yb) in zip(c[:-1], c[1:]):
                    side = (xb - xa) * (py - ya) - (yb - ya) * (px - xa)
                    if side == 0 and min(xa, xb) <= px <= max(xa, xb):
                        on_edge = on_edge or min(ya, yb) <= py <= max(ya, yb)
                    if ya <= py < yb and side > 0:
                        winding += 1
                    elif yb <= py < ya and side < 0:
                        winding -= 1
    return winding, on_edge


def _exact_winding_inside(poly, corners) -> bool:
    """Whether the exact centroid of a triangle is inside `poly`: the winding number of
    its rings around the point, in rational arithmetic (independent of the even-odd
    test aftmesh uses for the same question)."""
    from fractions import Fraction

    px = sum(Fraction(float(v)) for v in corners[:, 0]) / 3
    py = sum(Fraction(float(v)) for v in corners[:, 1]) / 3
    return _winding_exact([poly], px, py)[0] != 0


def _check_unsplit(mesh, case: FuzzCase, have: set) -> None:
    """split_boundary=False: every input edge is a mesh segment unless an input
    vertex lies exactly on it; with greedy, no point is added at all."""
    P = np.asarray(mesh.points)
    segs = set()
    for u, v in np.asarray(mesh.segments).tolist():
        a, b = tuple(P[u].tolist()), tuple(P[v].tolist())
        segs.add((min(a, b), max(a, b)))
    E = input_edges(case)
    V = np.unique(E.reshape(-1, 2), axis=0)
    for a, b in E:
        key = (min(tuple(a), tuple(b)), max(tuple(a), tuple(b)))
        if key in segs:
            continue
        d = b - a
        between = [
            p
            for p in V
            if np.dot(p - a, d) > 0 and np.dot(p - b, -d) > 0 and _exact_orient(a, b, p) == 0
        ]
        if not between:
            raise OracleError(
                f"input edge {a.tolist()} -> {b.tolist()} is not a mesh segment "
                "although split_boundary=False"
            )
    if case.options.get("greedy"):
        inputs = {tuple(p) for p in V.tolist()}
        inputs |= {tuple(np.asarray(p.coords, dtype=float)[0, :2].tolist()) for p in case.points}
        extra = have - inputs
        if extra:
            raise OracleError(
                f"greedy with split_boundary=False added {len(extra)} points, "
                f"e.g. {sorted(extra)[0]}"
            )


def _seed_on_a_segment(case: FuzzCase, message: str) -> bool:
    """The dict case's holes[i] / regions[i] named in the message lies on one of its
    segments, decided in rational arithmetic."""
    m = re.match(r"(holes|regions)\[(\d+)\]", message)
    if m is None or not isinstance(case.domain, dict) or m.group(1) not in case.domain:
        return False
    x, y = (Fraction(float(v)) for v in np.asarray(case.domain[m.group(1)])[int(m.group(2))][:2])
    V = np.asarray(case.domain["vertices"], dtype=float)
    for a, b in np.asarray(case.domain.get("segments", np.zeros((0, 2))), dtype=int):
        (ax, ay), (bx, by) = ((Fraction(float(c)) for c in V[k]) for k in (a, b))
        inside = min(ax, bx) <= x <= max(ax, bx) and min(ay, by) <= y <= max(ay, by)
        if inside and (bx - ax) * (y - ay) == (by - ay) * (x - ax):
            return True
    return False


def acceptable_refusal(case: FuzzCase, exc: BaseException) -> bool:
    """Refusals that are right for a valid domain: max_triangles below what the
    boundary alone needs (formula (3)); a size finer than the coordinates can
    resolve; coordinates far outside the range of the exact predicates."""
    if (
        isinstance(exc, aftmesh.InvalidSizeError)
        and case.options.get("max_triangles") is not None
        and "triangles" in str(exc)
    ):
        return True
    # a size finer than the coordinates resolve (sizing.MIN_SIZE_ULPS of their
    # spacing), refused as such: only when the case's smallest size really is
    if isinstance(exc, aftmesh.InvalidSizeError) and "coordinates can resolve" in str(exc):
        from aftmesh.sizing import MIN_SIZE_ULPS

        spec = case.size
        smallest = float(spec["lo"]) if isinstance(spec, dict) else spec
        mag = max(float(np.abs(np.asarray(p.bounds)).max()) for p in case.polygons)
        return smallest is not None and smallest < MIN_SIZE_ULPS * float(np.spacing(mag))
    # a hole or region point that the generator's rounding put exactly on a segment
    # (extreme coordinates): refused, rightly, only if it really is on one
    if isinstance(exc, aftmesh.InvalidDomainError) and "lies on a segment" in str(exc):
        return _seed_on_a_segment(case, str(exc))
    # coordinates beyond the exact predicates' range, refused as such
    if isinstance(exc, aftmesh.InvalidInputError) and "coordinate" in str(exc).lower():
        c = np.abs(np.concatenate([np.asarray(p.bounds).reshape(2, 2) for p in case.polygons]))
        return bool((c > 1e50).any() or ((c > 0) & (c < 1e-40)).any())
    return False


def run_case(case: FuzzCase, check=check_mesh, timeout: float | None = None):
    """generate() the case and verify the mesh; returns the mesh (None when the
    refusal was acceptable).  With a ``timeout`` generate() runs in a forked child
    (see :func:`isolated`)."""
    try:
        mesh = case.call() if timeout is None else isolated(case.call, timeout=timeout)
    except (Hang, Crash):
        raise
    except Exception as exc:
        if acceptable_refusal(case, exc):
            return None
        raise
    verify(mesh, case, check)
    return mesh


# ==================================================================== generators
def _finite_floats(lo, hi):
    """Floats in [lo, hi] without the magnitudes below 1e-12 of the range that
    hypothesis likes to try (subnormals, 1e-300): coordinate differences that small
    make the exact predicates underflow, a known limit pinned once in
    test_regressions.py, which would otherwise drown every other failure."""
    tiny = 1e-12 * max(abs(lo), abs(hi), hi - lo)
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False, allow_subnormal=False).map(
        lambda v: 0.0 if abs(v) < tiny else v
    )


def _valid(g) -> bool:
    return isinstance(g, (Polygon, MultiPolygon)) and not g.is_empty and g.is_valid and g.area > 0


@st.composite
def star_polygons(draw, max_vertices=40):
    """Star-shaped around the origin: sorted angles, every angular gap below pi."""
    n = draw(st.integers(3, max_vertices))
    w = np.array(draw(st.lists(_finite_floats(1.0, 3.0), min_size=n, max_size=n)))
    assume(w.max() / w.sum() < 0.49)
    theta = np.cumsum(w) / w.sum() * 2 * np.pi
    rmin = draw(st.sampled_from([0.05, 0.3, 0.9]))
    r = np.array(draw(st.lists(_finite_floats(rmin, 1.0), min_size=n, max_size=n)))
    poly = Polygon(np.c_[r * np.cos(theta), r * np.sin(theta)])
    assume(_valid(poly))
    return "star", poly


def _cross(p, q, r, s) -> bool:
    """Whether the open segments pq and rs cross (float orientation, general position)."""

    def o(a, b, c):
        return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])

    return (o(p, q, r) * o(p, q, s) < 0) and (o(r, s, p) * o(r, s, q) < 0)


def untangle(pts: np.ndarray) -> np.ndarray:
    """2-opt: reverse sub-paths until no two edges cross; the perimeter drops at every
    reversal, so this ends, with a simple polygon (in general position)."""
    order = list(range(len(pts)))
    n = len(order)
    for _ in range(20 * n * n):
        changed = False
        for i in range(n - 2):
            for j in range(i + 2, n):
                if i == 0 and j == n - 1:
                    continue
                a, b = pts[order[i]], pts[order[i + 1]]
                c, d = pts[order[j]], pts[order[(j + 1) % n]]
                if _cross(a, b, c, d):
                    order[i + 1 : j + 1] = order[i + 1 : j + 1][::-1]
                    changed = True
        if not changed:
            break
    return pts[order]


@st.composite
def walk_polygons(draw, max_vertices=30):
    """Non-star simple polygons: random points joined in an order made simple by 2-opt."""
    n = draw(st.integers(4, max_vertices))
    xs = draw(st.lists(_finite_floats(0.0, 1.0), min_size=n, max_size=n, unique=True))
    ys = draw(st.lists(_finite_floats(0.0, 1.0), min_size=n, max_size=n))
    ring = untangle(np.c_[xs, ys])
    poly = Polygon(ring)
    assume(_valid(poly) and poly.area > 1e-3)
    return "walk", poly


@st.composite
def grid_unions(draw):
    """Unions of grid cells: orthogonal polygons, holes and parts touching at corners."""
    k = draw(st.integers(2, 6))
    cells = draw(st.lists(st.booleans(), min_size=k * k, max_size=k * k))
    assume(any(cells))
    sx = draw(_finite_floats(0.2, 3.0))
    sy = draw(_finite_floats(0.2, 3.0))
    boxes = [
        box(i * sx, j * sy, (i + 1) * sx, (j + 1) * sy)
        for i in range(k)
        for j in range(k)
        if cells[i * k + j]
    ]
    g = shapely.union_all(boxes)
    assume(_valid(g))
    return "cells", g


def _ngon(cx, cy, r, m, rot):
    t = rot + 2 * np.pi * np.arange(m) / m
    return np.c_[cx + r * np.cos(t), cy + r * np.sin(t)]


@st.composite
def many_holes(draw):
    """A rectangle with up to 49 disjoint polygonal holes, one per grid cell."""
    g = draw(st.integers(2, 7))
    W = draw(_finite_floats(0.5, 4.0))
    H = draw(_finite_floats(0.5, 4.0))
    cw, ch = W / g, H / g
    holes = []
    for i in range(g):
        for j in range(g):
            if not draw(st.booleans()):
                continue
            m = draw(st.integers(3, 8))
            r = min(cw, ch) * draw(_finite_floats(0.05, 0.4))
            jx = (cw / 2 - r) * draw(_finite_floats(-0.9, 0.9))
            jy = (ch / 2 - r) * draw(_finite_floats(-0.9, 0.9))
            holes.append(
                _ngon(
                    (i + 0.5) * cw + jx,
                    (j + 0.5) * ch + jy,
                    r,
                    m,
                    draw(_finite_floats(0, 2 * np.pi)),
                )
            )
    assume(holes)
    poly = Polygon([(0, 0), (W, 0), (W, H), (0, H)], holes)
    assume(_valid(poly))
    return "holes", poly


@st.composite
def touching(draw):
    """Holes touching the outer ring or each other at a vertex; parts touching."""
    which = draw(st.sampled_from(["chain", "shared-vertex", "notch", "regions-T"]))
    if which == "chain":
        # diamonds tip to tip along a row; the first tip on the outer ring's left edge
        # (inside the edge or at a vertex of it)
        n = draw(st.integers(1, 6))
        hh = draw(_finite_floats(0.05, 0.9))
        w = draw(_finite_floats(0.1, 1.0))
        y = 1.0
        holes = [
            [(w * k, y), (w * k + w / 2, y - hh), (w * (k + 1), y), (w * k + w / 2, y + hh)]
            for k in range(n)
        ]
        right = w * n + draw(_finite_floats(0.1, 1.0))
        if draw(st.booleans()):
            shell = [(0, 0), (right, 0), (right, 2), (0, 2)]
        else:
            shell = [(0, 0), (right, 0), (right, 2), (0, 2), (0, y)]
        poly = Polygon(shell, holes)
    elif which == "shared-vertex":
        # two to four triangles around one common vertex
        c = np.array([draw(_finite_floats(0.3, 0.7)), draw(_finite_floats(0.3, 0.7))])
        k = draw(st.integers(2, 4))
        holes = []
        for j in range(k):
            a0 = 2 * np.pi * j / k
            a1 = a0 + draw(_finite_floats(0.3, 2 * np.pi / k - 0.2))
            r0 = draw(_finite_floats(0.05, 0.25))
            r1 = draw(_finite_floats(0.05, 0.25))
            holes.append(
                [
                    tuple(c),
                    tuple(c + r0 * np.array([np.cos(a0), np.sin(a0)])),
                    tuple(c + r1 * np.array([np.cos(a1), np.sin(a1)])),
                ]
            )
        poly = Polygon([(0, 0), (1, 0), (1, 1), (0, 1)], holes)
    elif which == "notch":
        # a hole's vertex at a reflex vertex of the outer ring
        d = draw(_finite_floats(0.1, 0.8))
        shell = [(0, 0), (2, 0), (2, 2), (1, 2), (1, 2 - d), (1 - d / 2, 2), (0, 2)]
        hole = [
            (1, 2 - d),
            (1.0 + draw(_finite_floats(0.1, 0.9)), 0.5),
            (1.0 - draw(_finite_floats(0.1, 0.9)), 0.5),
        ]
        poly = Polygon(shell, [hole])
    else:
        # rows of rectangles of random widths: shared edges with T-junctions
        rows = draw(st.integers(2, 4))
        regions = []
        for j in range(rows):
            cuts = sorted(set(draw(st.lists(_finite_floats(0.05, 0.95), max_size=4))))
            xs = [0.0, *cuts, 1.0]
            regions += [box(a, j * 0.5, b, (j + 1) * 0.5) for a, b in zip(xs[:-1], xs[1:])]
        assume(all(_valid(r) for r in regions))
        return "touch-regions", regions
    assume(_valid(poly))
    return f"touch-{which}", poly


@st.composite
def nearly_touching(draw):
    """Features about 1e-7 of the size apart (or closer)."""
    gap = draw(st.sampled_from([1e-5, 1e-7, 1e-9, 1e-12])) * draw(_finite_floats(1.0, 3.0))
    which = draw(st.sampled_from(["hole-to-edge", "hole-to-hole", "slot", "parts", "regions"]))
    if which == "hole-to-edge":
        hh = draw(_finite_floats(0.05, 0.5))
        hole = [(gap, 1.0), (0.5, 1 - hh), (1.0, 1.0), (0.5, 1 + hh)]
        g = Polygon([(0, 0), (2, 0), (2, 2), (0, 2)], [hole])
    elif which == "hole-to-hole":
        a = [(0.2, 1.0), (0.6, 0.7), (1.0, 1.0), (0.6, 1.3)]
        b = [(1.0 + gap, 1.0), (1.4, 0.6), (1.8, 1.0), (1.4, 1.4)]
        g = Polygon([(0, 0), (2, 0), (2, 2), (0, 2)], [a, b])
    elif which == "slot":
        depth = draw(_finite_floats(0.1, 0.9))
        x = draw(_finite_floats(0.2, 0.8))
        g = Polygon(
            [
                (0, 0),
                (1, 0),
                (1, 1),
                (x + gap, 1),
                (x + gap, 1 - depth),
                (x, 1 - depth),
                (x, 1),
                (0, 1),
            ]
        )
    elif which == "parts":
        dy = draw(_finite_floats(-0.5, 0.5))
        g = MultiPolygon([box(0, 0, 1, 1), box(1 + gap, dy, 2, dy + 1)])
    else:
        return "near-regions", [box(0, 0, 1, 1), box(1 + gap, 0, 2, 1), box(0, 1 + gap, 2, 2)]
    assume(_valid(g))
    return f"near-{which}", g


@st.composite
def slivers_and_spikes(draw):
    """Needles: thin triangles and rectangles, and spikes out of a polygon."""
    which = draw(st.sampled_from(["needle", "strip", "spikes"]))
    eps = 10.0 ** -draw(_finite_floats(2.0, 6.0))
    if which == "needle":
        g = Polygon([(0, 0), (1, 0), (draw(_finite_floats(0.0, 1.0)), eps)])
    elif which == "strip":
        g = box(0, 0, 1, eps)
    else:
        n = draw(st.integers(5, 16))
        spikes = draw(st.lists(st.integers(0, n - 1), min_size=1, max_size=4, unique=True))
        pts = []
        for i in range(n):
            t = 2 * np.pi * i / n
            if i in spikes:
                R = draw(_finite_floats(1.5, 4.0))
                pts += [
                    (np.cos(t - eps), np.sin(t - eps)),
                    (R * np.cos(t), R * np.sin(t)),
                    (np.cos(t + eps), np.sin(t + eps)),
                ]
            else:
                pts.append((np.cos(t), np.sin(t)))
        g = Polygon(pts)
    assume(_valid(g))
    return f"sliver-{which}", g


@st.composite
def near_collinear(draw):
    """Extra vertices on the edges, off the line by 0, one ulp, or up to 1e-9 of the
    edge's length; repeated vertices (given twice in a row)."""
    _, base = draw(
        st.one_of(star_polygons(max_vertices=8), st.just(("box", box(0.25, 0.25, 1.25, 0.95))))
    )
    c = _ring_coords(base.exterior)
    out = []
    for i in range(len(c)):
        a, b = c[i], c[(i + 1) % len(c)]
        out.append(a)
        m = draw(st.integers(0, 4))
        ts = sorted(draw(st.lists(_finite_floats(0.01, 0.99), min_size=m, max_size=m, unique=True)))
        d = b - a
        nrm = np.array([-d[1], d[0]])
        for t in ts:
            p = a + t * d
            off = draw(st.sampled_from(["zero", "ulp", "-ulp", "1e-15", "-1e-12", "1e-9"]))
            if off == "ulp":
                p = np.nextafter(p, p + nrm)
            elif off == "-ulp":
                p = np.nextafter(p, p - nrm)
            elif off != "zero":
                p = p + float(off) * nrm
            out.append(p)
            if draw(st.integers(0, 4)) == 0:
                out.append(p.copy())  # a repeated vertex
    ring = np.array(out)
    if draw(st.booleans()):
        ring = np.r_[ring, ring[:1], ring[:1]]  # closed, and the closing vertex twice
    assume(_valid(Polygon(ring)))
    return "collinear", ring


@cache
def lattice_circle(R: int) -> np.ndarray:
    """All integer points on the circle x^2 + y^2 = R^2, sorted by angle: exactly
    cocircular in floating point."""
    pts = set()
    for x in range(R + 1):
        y2 = R * R - x * x
        y = math.isqrt(y2)
        if y * y == y2:
            pts |= {(x, y), (-x, y), (x, -y), (-x, -y)}
    P = np.array(sorted(pts), dtype=float)
    return P[np.argsort(np.arctan2(P[:, 1], P[:, 0]))]


@st.composite
def cocircular(draw):
    """Hundreds of cocircular vertices: a regular polygon (cos/sin, nearly cocircular)
    or integer points of one circle (exactly cocircular), maybe with a concentric hole."""
    if draw(st.booleans()):
        n = draw(st.integers(100, 800))
        shell = _ngon(0.0, 0.0, 1.0, n, draw(_finite_floats(0, 1)))
        holes = []
        if draw(st.booleans()):
            holes = [
                _ngon(0.0, 0.0, draw(_finite_floats(0.2, 0.8)), draw(st.integers(3, 400)), 0.0)
            ]
        g = Polygon(shell, holes)
        kind = "regular"
    else:
        R = draw(st.sampled_from([5525, 32045]))  # 180 and 324 lattice points
        P = lattice_circle(R)
        keep = draw(st.lists(st.booleans(), min_size=len(P), max_size=len(P)))
        shell = P[np.array(keep)] if sum(keep) >= 3 else P
        holes = []
        if draw(st.booleans()):
            holes = [lattice_circle(1105)]  # 32 points, same centre
        g = Polygon(shell, holes)
        kind = "lattice"
    assume(_valid(g))
    return f"cocircular-{kind}", g


@st.composite
def with_constraints(draw):
    """A polygon with constraint lines (maybe crossing each other) and fixed points."""
    _, poly = draw(st.one_of(star_polygons(max_vertices=12), grid_unions()))
    if isinstance(poly, MultiPolygon):
        poly = max(poly.geoms, key=lambda p: p.area)
    inner = poly.buffer(-0.02 * math.sqrt(poly.area))
    assume(not inner.is_empty)
    x0, y0, x1, y1 = inner.bounds
    lines, points = [], []
    for _ in range(draw(st.integers(0, 4))):
        k = draw(st.integers(2, 4))
        c = [(draw(_finite_floats(x0, x1)), draw(_finite_floats(y0, y1))) for _ in range(k)]
        line = LineString(c)
        if line.length > 0 and line.is_simple and inner.contains(line):
            lines.append(line)
    for _ in range(draw(st.integers(0, 4))):
        p = Point(draw(_finite_floats(x0, x1)), draw(_finite_floats(y0, y1)))
        if inner.contains(p):
            points.append(p)
    # lines ending on the boundary (at a rounded point of an edge, or at a vertex)
    ring = _ring_coords(poly.exterior)
    for _ in range(draw(st.integers(0, 2))):
        i = draw(st.integers(0, len(ring) - 1))
        a, b = ring[i], ring[(i + 1) % len(ring)]
        end = a if draw(st.booleans()) else a + draw(_finite_floats(0.1, 0.9)) * (b - a)
        q = (draw(_finite_floats(x0, x1)), draw(_finite_floats(y0, y1)))
        line = LineString([q, tuple(end)])
        if (
            inner.contains(Point(q))
            and line.length > 0
            and line.difference(poly).length <= 1e-9 * line.length
        ):
            lines.append(line)
    # fixed points on the lines
    for line in list(lines):
        if draw(st.integers(0, 2)) == 0:
            points.append(line.interpolate(0.5, normalized=True))
    assume(lines or points)
    return "constraints", GeometryCollection([poly, *lines, *points])


@st.composite
def nested_regions(draw):
    """Region lists: a rectangle with holes, regions filling some of the holes
    (inclusions), and a neighbour sharing part of an edge."""
    W = draw(_finite_floats(1.0, 3.0))
    H = draw(_finite_floats(1.0, 3.0))
    k = draw(st.integers(1, 3))
    holes = []
    for j in range(k):
        cx = W * (j + 0.5) / k
        r = min(W / k, H) * draw(_finite_floats(0.1, 0.4))
        holes.append(_ngon(cx, H / 2, r, draw(st.integers(3, 9)), draw(_finite_floats(0, 6.3))))
    regions = [Polygon([(0, 0), (W, 0), (W, H), (0, H)], holes)]
    for h in holes:
        if draw(st.booleans()):
            regions.append(Polygon(h))
    y0 = draw(_finite_floats(0.0, H / 2))
    regions.append(
        box(W, y0, W + draw(_finite_floats(0.3, 2.0)), y0 + draw(_finite_floats(0.2, H)))
    )
    assume(all(_valid(r) for r in regions))
    return "nested-regions", regions


@st.composite
def parcels(draw):
    """Region lists of many parcels: Voronoi cells of random points clipped to a box
    (neighbours share their edges exactly), or a grid of rectangles of random widths
    row by row (T-junctions), up to a few dozen regions."""
    if draw(st.booleans()):
        n = draw(st.integers(3, 40))
        seeds = [(draw(_finite_floats(0, 2)), draw(_finite_floats(0, 1))) for _ in range(n)]
        frame = box(0, 0, 2, 1)
        try:
            diagram = shapely.voronoi_polygons(shapely.MultiPoint(seeds), extend_to=frame)
        except shapely.errors.GEOSException:
            # GEOS's own Voronoi fails on some near-degenerate seeds (a side location
            # conflict): no domain to draw, not aftmesh's failure
            assume(False)
        cells = shapely.get_parts(diagram)
        regions = [c for c in shapely.intersection(cells, frame) if isinstance(c, Polygon)]
        assume(len(regions) >= 2 and all(_valid(r) and r.area > 1e-6 for r in regions))
        return "parcels-voronoi", regions
    regions = []
    rows = draw(st.integers(2, 6))
    for j in range(rows):
        cuts = sorted(set(draw(st.lists(_finite_floats(0.02, 0.98), min_size=1, max_size=8))))
        xs = [0.0, *cuts, 1.0]
        regions += [box(a, j / rows, b, (j + 1) / rows) for a, b in zip(xs[:-1], xs[1:])]
    assume(all(_valid(r) for r in regions))
    return "parcels-rows", regions


@st.composite
def many_constraints(draw):
    """A polygon with many short constraint lines (a few of them crossing) and many
    fixed points: the input side takes them all at once."""
    W = draw(_finite_floats(1.0, 3.0))
    poly = box(0, 0, W, 1)
    lines, points = [], []
    for _ in range(draw(st.integers(5, 40))):
        x, y = draw(_finite_floats(0.1, W - 0.1)), draw(_finite_floats(0.1, 0.9))
        dx, dy = draw(_finite_floats(-0.08, 0.08)), draw(_finite_floats(-0.08, 0.08))
        line = LineString([(x, y), (x + dx, y + dy)])
        if line.length > 0:
            lines.append(line)
    for _ in range(draw(st.integers(0, 40))):
        points.append(Point(draw(_finite_floats(0.05, W - 0.05)), draw(_finite_floats(0.05, 0.95))))
    assume(lines)
    return "many-constraints", GeometryCollection([poly, *lines, *points])


@st.composite
def extreme_scales(draw):
    """A valid domain scaled by 10**k, k from -70 to 80: far beyond what the exact
    predicates can handle at both ends, where the only right answers are a correct
    mesh or an InvalidInputError about the coordinates."""
    _, g = draw(st.one_of(star_polygons(max_vertices=12), many_holes(), grid_unions()))
    k = draw(st.integers(-70, 80))
    scale = 10.0**k
    g = shapely.transform(g, lambda c: c * scale)
    assume(_valid(g))
    return "extreme", g


GENERATORS = {
    "star": star_polygons(),
    "walk": walk_polygons(),
    "cells": grid_unions(),
    "holes": many_holes(),
    "touching": touching(),
    "nearly": nearly_touching(),
    "slivers": slivers_and_spikes(),
    "collinear": near_collinear(),
    "cocircular": cocircular(),
    "constraints": with_constraints(),
    "regions": nested_regions(),
    "parcels": parcels(),
    "many-constraints": many_constraints(),
    "extreme": extreme_scales(),
}


# ======================================================== transforms, forms, options
def _transform_geom(g, scale, off):
    return shapely.transform(g, lambda c: c * scale + off)


@st.composite
def options(draw, rich=True):
    """Keyword options of generate(); `rich` draws all of them, else a few."""
    out = {}
    if not rich:
        return out
    if draw(st.integers(0, 2)) == 0:
        out["order"] = draw(st.sampled_from(["shortest", "longest", "oldest"]))
    if draw(st.integers(0, 3)) == 0:
        out["swaps"] = False
    if draw(st.integers(0, 3)) == 0:
        out["split_boundary"] = False
    if draw(st.integers(0, 6)) == 0:
        out["greedy"] = True
    if draw(st.integers(0, 3)) == 0:
        out["smooth"] = draw(st.integers(0, 5))
    if draw(st.integers(0, 3)) == 0:
        out["close_factor"] = draw(st.sampled_from([0.0, 0.1, 0.5, 1.0, 1.9]))
    if draw(st.integers(0, 3)) == 0:
        out["gradation"] = draw(st.sampled_from([1.0, 1.05, 1.3, 2.0, 100.0]))
    if draw(st.integers(0, 3)) == 0:
        out["max_triangles"] = draw(st.integers(1, 3000))
    if draw(st.integers(0, 3)) == 0:
        out["scaffold"] = False
    return out


@st.composite
def fuzz_cases(draw, kinds=None, transform=True, forms=True, rich_options=False, sizes=True):
    """One FuzzCase: a domain from GENERATORS (`kinds` restricts), maybe moved by
    1e7 or scaled by 1e-6, in one of the accepted input forms, with a size spec and
    options."""
    names = sorted(GENERATORS) if kinds is None else list(kinds)
    name = draw(st.sampled_from(names))
    kind, geom = draw(GENERATORS[name])
    lines, points = [], []
    if isinstance(geom, GeometryCollection):
        parts = list(geom.geoms)
        polys = [p for p in parts if isinstance(p, (Polygon, MultiPolygon))]
        lines = [p for p in parts if isinstance(p, LineString)]
        points = [p for p in parts if isinstance(p, Point)]
    elif isinstance(geom, np.ndarray):
        polys = [Polygon(geom)]
    elif isinstance(geom, list):
        polys = list(geom)
    else:
        polys = [geom]
    tf = draw(st.sampled_from(["none", "none", "offset", "small"])) if transform else "none"
    if tf != "none":
        scale, off = (
            (1.0, np.array([1e7, -1e7]) * draw(_finite_floats(1.0, 9.0)))
            if tf == "offset"
            else (1e-6 * draw(_finite_floats(1.0, 9.0)), np.zeros(2))
        )
        if isinstance(geom, np.ndarray):
            geom = geom * scale + off
        elif isinstance(geom, list):
            geom = [_transform_geom(p, scale, off) for p in geom]
        else:
            geom = _transform_geom(geom, scale, off)
        polys = [_transform_geom(p, scale, off) for p in polys]
        lines = [_transform_geom(p, scale, off) for p in lines]
        points = [_transform_geom(p, scale, off) for p in points]
        kind += f"+{tf}"
        # rounding may move touching features apart or make them cross
        assume(all(_valid(p) for p in polys))
        if len(polys) > 1:
            for i in range(len(polys)):
                for j in range(i):
                    assume(polys[i].intersection(polys[j]).area == 0)
    domain = geom
    if forms and isinstance(geom, (Polygon, MultiPolygon)):
        form = draw(st.sampled_from(["shapely", "shapely", "dict", "ring"]))
        if form == "ring" and isinstance(geom, Polygon) and not geom.interiors:
            domain = np.asarray(geom.exterior.coords, dtype=float)
        elif form == "dict":
            domain = _as_dict(polys)
            kind += "/dict"
    bounds = _bounds(polys)
    size = draw(size_specs(bounds)) if sizes else None
    if size is None and not sizes:
        (x0, y0), (x1, y1) = bounds
        size = 0.1 * math.hypot(x1 - x0, y1 - y0)
    opts = draw(options(rich_options))
    return FuzzCase(kind, domain, size, opts, polys, lines, points)


def _bounds(polys):
    b = np.array([p.bounds for p in polys])
    return (float(b[:, 0].min()), float(b[:, 1].min())), (
        float(b[:, 2].max()),
        float(b[:, 3].max()),
    )


def _strictly_outside(polys, p) -> bool:
    """Whether point p is outside every polygon and on none of their edges, in
    rational arithmetic."""
    from fractions import Fraction

    winding, on_edge = _winding_exact(polys, Fraction(float(p[0])), Fraction(float(p[1])))
    return winding == 0 and not on_edge


def _void_points(polys) -> np.ndarray:
    """A point inside each bounded piece of the complement of the polygons: their
    holes and the gaps enclosed by parts that touch only at corners.  A void only a
    few ulps wide may have no double strictly inside it, and its rounded
    representative point can then lie on or inside a polygon, where Triangle's hole
    would eat the domain: such a point is left out (the CDT itself does not depend on
    the holes, and the check keeps only the mesh's triangles)."""
    union = shapely.union_all(polys)
    x0, y0, x1, y1 = union.bounds
    pad = max(x1 - x0, y1 - y0)
    frame = box(x0 - pad, y0 - pad, x1 + pad, y1 + pad)
    pts = []
    for piece in shapely.get_parts(frame.difference(union)):
        if isinstance(piece, Polygon) and not piece.intersects(frame.exterior):
            p = np.asarray(piece.representative_point().coords)[0]
            if _strictly_outside(polys, p):
                pts.append(p)
    return np.array(pts, dtype=float).reshape(-1, 2)


def _as_dict(polys):
    """Triangle's PSLG form of valid polygons: ring edges, a point in each void."""
    verts, segs = [], []
    for c, _ in _rings(polys):
        n = len(c)
        base = sum(len(v) for v in verts)
        verts.append(c)
        segs.append(np.c_[np.arange(n), (np.arange(n) + 1) % n] + base)
    V = np.concatenate(verts)
    # merge exactly repeated vertices (touching rings): the dict form wants one index
    uniq, inv = np.unique(V, axis=0, return_inverse=True)
    S = inv.reshape(-1)[np.concatenate(segs)]
    S = S[S[:, 0] != S[:, 1]]
    key = np.sort(S, axis=1)
    _, first = np.unique(key, axis=0, return_index=True)
    return {"vertices": uniq, "segments": S[np.sort(first)], "holes": _void_points(polys)}
