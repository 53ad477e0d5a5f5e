"""Benchmark domains, each already discretized into one planar straight-line graph.

Every mesher gets exactly the same input: the vertices, segments, hole points and
region points of a :class:`Case`.  The boundary is split here (uniformly, or by
integrating 1/size along the curve for the graded airfoil), never by the meshers, so
aftmesh runs with ``split_boundary=False``, Triangle may be told ``Y`` and Gmsh gets one
geometric line per segment with exactly two mesh nodes.
"""

from __future__ import annotations

import fnmatch
import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

__all__ = ["Case", "build_case", "case_names", "select_cases", "QUICK_CASES"]


@dataclass
class Case:
    """A discretized domain plus the target size every mesher is asked for."""

    name: str
    description: str
    vertices: np.ndarray  # (n, 2) float64
    segments: np.ndarray  # (m, 2) int32
    holes: np.ndarray  # (k, 2) float64 points inside holes
    h: float  # uniform target edge length (or the smallest one)
    size: Callable | None = None  # graded size f(x, y) -> array; None: uniform h
    gmsh_size_expr: str | None = None  # the same graded size as a Gmsh MathEval formula
    regions: np.ndarray | None = None  # (r, 3) x, y, marker
    notes: list[str] = field(default_factory=list)

    @property
    def size_arg(self):
        """What aftmesh gets as ``size`` (and what edge/size statistics compare with)."""
        return self.size if self.size is not None else self.h

    def target(self, x, y) -> np.ndarray:
        """Target edge length at the given points."""
        if self.size is None:
            return np.full(np.shape(x), self.h)
        return np.asarray(self.size(x, y), dtype=float)

    def as_triangle_dict(self, with_region_areas: bool = False) -> dict:
        """The Triangle-style dict given to aftmesh and Triangle alike."""
        d = {"vertices": self.vertices, "segments": self.segments}
        if len(self.holes):
            d["holes"] = self.holes
        if self.regions is not None and len(self.regions):
            reg = self.regions
            if with_region_areas:  # Triangle wants (x, y, attribute, max_area)
                reg = np.column_stack([reg, np.zeros(len(reg))])
            d["regions"] = reg
        return d


# --------------------------------------------------------------------------- helpers


def _ring(points: np.ndarray, offset: int) -> np.ndarray:
    n = len(points)
    idx = np.arange(n) + offset
    return np.column_stack([idx, np.roll(idx, -1)]).astype(np.int32)


def _split_polyline_uniform(corners: np.ndarray, h: float, closed: bool = True) -> np.ndarray:
    """Points along a polygon: each edge cut into ceil(L / h) equal pieces (ends kept)."""
    pts = []
    n = len(corners)
    stop = n if closed else n - 1
    for k in range(stop):
        a = corners[k]
        b = corners[(k + 1) % n]
        L = float(np.hypot(*(b - a)))
        m = max(1, math.ceil(L / h - 1e-9))
        t = np.arange(m) / m
        pts.append(a + t[:, None] * (b - a))
    if not closed:
        pts.append(corners[-1:])
    return np.concatenate(pts)


def _split_graded(curve: np.ndarray, size: Callable) -> np.ndarray:
    """Resample a densely sampled open curve so that each piece is about size() long.

    The number of pieces is the integral of ds / size rounded; the pieces are equal in
    that integral.  Both ends are kept."""
    d = np.hypot(*np.diff(curve, axis=0).T)
    mid = 0.5 * (curve[1:] + curve[:-1])
    w = np.concatenate([[0.0], np.cumsum(d / size(mid[:, 0], mid[:, 1]))])
    m = max(1, int(round(w[-1])))
    targets = np.linspace(0.0, w[-1], m + 1)
    x = np.interp(targets, w, curve[:, 0])
    y = np.interp(targets, w, curve[:, 1])
    out = np.column_stack([x, y])
    out[0], out[-1] = curve[0], curve[-1]
    return out


def _circle(cx: float, cy: float, r: float, h: float) -> np.ndarray:
    m = max(8, math.ceil(2 * math.pi * r / h))
    t = 2 * math.pi * np.arange(m) / m
    return np.column_stack([cx + r * np.cos(t), cy + r * np.sin(t)])


# --------------------------------------------------------------------------- cases


def square(h: float) -> Case:
    corners = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    v = _split_polyline_uniform(corners, h)
    return Case(f"square-{h:g}", f"unit square, h = {h:g}", v, _ring(v, 0), np.zeros((0, 2)), h)


HOLES = [
    (0.25, 0.25, 0.10),
    (0.75, 0.25, 0.12),
    (0.50, 0.55, 0.15),
    (0.22, 0.80, 0.08),
    (0.78, 0.78, 0.10),
]


def holes(h: float) -> Case:
    corners = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    rings = [_split_polyline_uniform(corners, h)]
    rings += [_circle(cx, cy, r, h)[::-1] for cx, cy, r in HOLES]
    v, s, off = [], [], 0
    for ring in rings:
        v.append(ring)
        s.append(_ring(ring, off))
        off += len(ring)
    return Case(
        f"holes-{h:g}",
        f"unit square with {len(HOLES)} circular holes, h = {h:g}",
        np.concatenate(v),
        np.concatenate(s),
        np.array([[cx, cy] for cx, cy, _ in HOLES]),
        h,
    )


def naca_thickness(x: np.ndarray, t: float = 0.12) -> np.ndarray:
    """Half thickness of a symmetric 4-digit NACA section, closed trailing edge
    (last coefficient -0.1036 instead of -0.1015)."""
    return (
        5.0 * t * (0.2969 * np.sqrt(x) - 0.1260 * x - 0.3516 * x**2 + 0.2843 * x**3 - 0.1036 * x**4)
    )


# size around the airfoil: H0 on the chord, growing by SLOPE per unit distance, at most HMAX
NACA_H0, NACA_SLOPE, NACA_HMAX = 0.0025, 0.1, 0.3
NACA_BOX = (-4.0, -4.0, 5.0, 4.0)


def naca_size(x, y):
    """Graded target size: linear in the distance to the chord [0, 1] x {0}."""
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    dx = np.maximum(np.maximum(-x, x - 1.0), 0.0)
    return np.minimum(NACA_H0 + NACA_SLOPE * np.sqrt(dx * dx + y * y), NACA_HMAX)


def naca0012() -> Case:
    beta = np.linspace(0.0, math.pi, 20001)
    xs = 0.5 * (1.0 - np.cos(beta))  # dense near both ends
    upper = np.column_stack([xs[::-1], naca_thickness(xs[::-1])])  # TE -> LE
    up = _split_graded(upper, naca_size)  # TE ... LE
    low = up[::-1].copy()  # LE ... TE, mirrored
    low[:, 1] *= -1.0
    foil = np.concatenate([up[:-1], low[:-1]])  # clockwise ring (a hole boundary)
    x0, y0, x1, y1 = NACA_BOX
    box_pts = []
    corners = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
    for k in range(4):
        a, b = corners[k], corners[(k + 1) % 4]
        t = np.linspace(0.0, 1.0, 4001)[:, None]
        box_pts.append(_split_graded(a + t * (b - a), naca_size)[:-1])
    box = np.concatenate(box_pts)
    v = np.concatenate([box, foil])
    s = np.concatenate([_ring(box, 0), _ring(foil, len(box))])
    dxe = "Max(Max(-x, x - 1), 0)"
    expr = f"Min({NACA_H0} + {NACA_SLOPE} * Sqrt({dxe} * {dxe} + y * y), {NACA_HMAX})"
    return Case(
        "naca0012",
        f"NACA 0012 in a {x1 - x0:g} x {y1 - y0:g} box, size {NACA_H0:g} + "
        f"{NACA_SLOPE:g} * dist(chord), at most {NACA_HMAX:g}",
        v,
        s,
        np.array([[0.5, 0.0]]),
        NACA_H0,
        size=naca_size,
        gmsh_size_expr=expr,
    )


def comb(h: float = 0.01, teeth: int = 13, slit: float = 0.003) -> Case:
    """A 1 x 0.5 plate cut by (teeth - 1) slits of width ``slit`` (< h) from the top
    edge down to y = 0.1."""
    n_slits = teeth - 1
    tooth = (1.0 - n_slits * slit) / teeth
    corners = [[0.0, 0.0], [1.0, 0.0], [1.0, 0.5]]
    x = 1.0
    for _ in range(n_slits):
        x -= tooth
        corners += [[x, 0.5], [x, 0.1], [x - slit, 0.1], [x - slit, 0.5]]
        x -= slit
    corners += [[0.0, 0.5]]
    v = _split_polyline_uniform(np.array(corners), h)
    return Case(
        "comb",
        f"comb: 1 x 0.5 plate, {n_slits} slits {slit:g} wide, h = {h:g}",
        v,
        _ring(v, 0),
        np.zeros((0, 2)),
        h,
    )


def inclusion(h: float = 0.01) -> Case:
    outer = _split_polyline_uniform(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]), h)
    inner = _split_polyline_uniform(np.array([[0.3, 0.3], [0.7, 0.3], [0.7, 0.7], [0.3, 0.7]]), h)
    v = np.concatenate([outer, inner])
    s = np.concatenate([_ring(outer, 0), _ring(inner, len(outer))])
    return Case(
        "inclusion",
        f"unit square with a 0.4 x 0.4 inclusion (2 regions), h = {h:g}",
        v,
        s,
        np.zeros((0, 2)),
        h,
        regions=np.array([[0.1, 0.1, 1.0], [0.5, 0.5, 2.0]]),
    )


POLY_FILES = ("A", "face", "la", "double_hex3")
POLY_DIVISIONS = 150  # h = bounding-box diagonal / POLY_DIVISIONS


def poly(name: str) -> Case:
    """One of Triangle's sample .poly files; every segment cut into pieces <= h."""
    import triangle

    d = triangle.get_data(name)
    v0 = np.asarray(d["vertices"], dtype=float)
    s0 = np.asarray(d["segments"], dtype=np.int64).reshape(-1, 2)
    h = float(np.linalg.norm(v0.max(axis=0) - v0.min(axis=0))) / POLY_DIVISIONS
    verts = [v0]
    segs = []
    nxt = len(v0)
    for a, b in s0:
        L = float(np.linalg.norm(v0[b] - v0[a]))
        m = max(1, math.ceil(L / h - 1e-9))
        if m == 1:
            segs.append([a, b])
            continue
        t = (np.arange(1, m) / m)[:, None]
        verts.append(v0[a] + t * (v0[b] - v0[a]))
        chain = [a, *range(nxt, nxt + m - 1), b]
        nxt += m - 1
        segs += [[chain[i], chain[i + 1]] for i in range(m)]
    holes_ = np.asarray(d.get("holes", np.zeros((0, 2))), dtype=float).reshape(-1, 2)
    regions = None
    notes = []
    if "regions" in d:
        r = np.asarray(d["regions"], dtype=float)
        regions = np.column_stack([r[:, :2], np.arange(1, len(r) + 1)])
        notes.append("the file's per-region area bounds are ignored (uniform h)")
    n_free = int((np.bincount(s0.ravel(), minlength=len(v0)) == 0).sum())
    if n_free:
        notes.append(f"{n_free} free input vertices")
    return Case(
        f"poly-{name}",
        f"Triangle sample {name}.poly, h = bbox diagonal / {POLY_DIVISIONS} = {h:.4g}",
        np.concatenate(verts),
        np.asarray(segs, dtype=np.int32),
        holes_,
        h,
        regions=regions,
        notes=notes,
    )


# --------------------------------------------------------------------------- registry

SQUARE_H = (0.02, 0.01, 0.005, 0.0025, 0.001)
HOLES_H = (0.01, 0.005)

ALL_CASES = (
    [f"square-{h:g}" for h in SQUARE_H]
    + [f"holes-{h:g}" for h in HOLES_H]
    + ["naca0012"]
    + [f"poly-{p}" for p in POLY_FILES]
    + ["comb", "inclusion"]
)

QUICK_CASES = [
    "square-0.01",
    "square-0.005",
    "naca0012",
    "poly-A",
    "poly-face",
    "comb",
    "inclusion",
]


def case_names() -> list[str]:
    return list(ALL_CASES)


def build_case(name: str) -> Case:
    """Build a case by name; ``square-<h>`` and ``holes-<h>`` accept any h."""
    kind, _, arg = name.partition("-")
    if kind == "square" and arg:
        return square(float(arg))
    if kind == "holes" and arg:
        return holes(float(arg))
    if name == "naca0012":
        return naca0012()
    if kind == "poly" and arg:
        return poly(arg)
    if name == "comb":
        return comb()
    if name == "inclusion":
        return inclusion()
    if kind == "rw" and arg:
        from .realworld import build_realworld  # the real-world group (--realworld)

        return build_realworld(name)
    raise KeyError(f"unknown case {name!r}; known: {', '.join(ALL_CASES)}")


def select_cases(patterns: list[str] | None, quick: bool) -> list[str]:
    """Case names matching the patterns (fnmatch, or an exact name such as
    ``square-0.0007`` not in the list), in the order given by the registry."""
    if not patterns:
        return list(QUICK_CASES if quick else ALL_CASES)
    out = []
    for pat in patterns:
        hits = [c for c in ALL_CASES if fnmatch.fnmatch(c, pat)]
        if not hits:
            hits = [pat]  # e.g. square-0.0007: built on demand
        out += [c for c in hits if c not in out]
    return out
