"""The real-world benchmark group: 20 public outlines plus built domains.

The outlines are the earcut and poly2tri test polygons in ``benchmarks/data/realworld``
(sources and licences in its README.md); each is meshed in its valid interpretation
(the file's ``domain_wkb``: shapely's ``make_valid`` of the raw rings) with one
constant size, the bounding-box diagonal / :data:`DIVISIONS`.  The built domains are in
:mod:`benchmarks.domains`.

Every geometry becomes one planar straight-line graph here, like the other cases: its
boundary is noded, each edge cut into pieces no longer than the size (or, for a graded
size, about size() long), vertices shared by touching rings merged, and a hole point
put in every bounded face of the segment graph that the geometry does not cover.
"""

from __future__ import annotations

import json
import math
from itertools import pairwise
from pathlib import Path

import numpy as np
import shapely

from .cases import Case
from .domains import BUILT

__all__ = ["REALWORLD_CASES", "build_realworld", "geometry_to_case", "summary_table"]

DATA = Path(__file__).resolve().parent / "data" / "realworld"
DIVISIONS = 60  # h = bbox diagonal / 60: 1e3-1e5 triangles on these outlines
PREFIX = "rw-"
GRADED_SAMPLES = 64  # samples per edge when integrating 1/size along it

OUTLINES = sorted(p.stem for p in DATA.glob("*.json"))
REALWORLD_CASES = [PREFIX + n for n in OUTLINES] + [PREFIX + n for n in BUILT]


def load_outline(name: str):
    """The valid geometry of one outline file."""
    d = json.loads((DATA / f"{name}.json").read_text())
    geom = shapely.from_wkb(bytes.fromhex(d["domain_wkb"]))
    return shapely.orient_polygons(geom), d


def _pieces(a: np.ndarray, b: np.ndarray, h: float, size) -> np.ndarray:
    """Interior split points of edge a-b (uniform: ceil(L / h) pieces; graded: pieces
    equal in the integral of 1/size, as many as that integral rounded)."""
    L = float(np.hypot(*(b - a)))
    if size is None:
        m = max(1, math.ceil(L / h - 1e-9))
        t = np.arange(1, m) / m
    else:
        s = np.linspace(0.0, 1.0, GRADED_SAMPLES + 1)
        mid = a + 0.5 * (s[1:] + s[:-1])[:, None] * (b - a)
        w = np.concatenate([[0.0], np.cumsum(L / GRADED_SAMPLES / size(mid[:, 0], mid[:, 1]))])
        m = max(1, round(float(w[-1])))
        t = np.interp(np.arange(1, m) / m * w[-1], w, s)
    return a + t[:, None] * (b - a)


def geometry_to_pslg(geom, h: float, size=None):
    """(vertices, segments, hole points) of a polygonal geometry's boundary."""
    lines = shapely.node(geom.boundary)
    index: dict[tuple[float, float], int] = {}
    verts: list[tuple[float, float]] = []
    segs = set()

    def vid(p) -> int:
        key = (float(p[0]), float(p[1]))
        if key not in index:
            index[key] = len(verts)
            verts.append(key)
        return index[key]

    for line in getattr(lines, "geoms", [lines]):
        c = np.asarray(line.coords)
        for a, b in pairwise(c):
            if a[0] == b[0] and a[1] == b[1]:
                continue
            chain = [vid(a), *(vid(p) for p in _pieces(a, b, h, size)), vid(b)]
            for u, v in pairwise(chain):
                segs.add((min(u, v), max(u, v)))
    V = np.array(verts, dtype=np.float64)
    S = np.array(sorted(segs), dtype=np.int32)
    faces = shapely.polygonize(shapely.linestrings(np.stack([V[S[:, 0]], V[S[:, 1]]], axis=1)))
    probes = [f.representative_point() for f in faces.geoms]
    holes = [(p.x, p.y) for p in probes if not geom.covers(p)]
    return V, S, np.array(holes, dtype=np.float64).reshape(-1, 2)


def geometry_to_case(
    name: str, description: str, geom, h: float, size=None, gmsh_size_expr=None
) -> Case:
    V, S, holes = geometry_to_pslg(geom, h, size)
    notes = [f"{geom.geom_type}, {len(V)} boundary vertices"]
    return Case(
        name, description, V, S, holes, h, size=size, gmsh_size_expr=gmsh_size_expr, notes=notes
    )


def build_realworld(name: str) -> Case:
    """A case of the group by name (``rw-<outline>`` or ``rw-<built domain>``)."""
    base = name.removeprefix(PREFIX)
    if base in BUILT:
        b = BUILT[base]()
        return geometry_to_case(name, b.description, b.geometry, b.h, b.size, b.gmsh_size_expr)
    if base in OUTLINES:
        geom, meta = load_outline(base)
        x0, y0, x1, y1 = geom.bounds
        h = math.hypot(x1 - x0, y1 - y0) / DIVISIONS
        desc = (
            f"{meta['source_repo']}:{meta['source_path']} ({meta['licence']}), "
            f"h = bbox diagonal / {DIVISIONS} = {h:.4g}"
        )
        return geometry_to_case(name, desc, geom, h)
    raise KeyError(f"unknown real-world case {name!r}; known: {', '.join(REALWORLD_CASES)}")


# ----------------------------------------------------------------------- the table

GROUP_MESHERS = ["aft", "aft-split", "gmsh-frontal", "tri-pq30"]
_SHORT = {"aft": "aft", "aft-split": "aft-split", "gmsh-frontal": "Gmsh6", "tri-pq30": "Tri"}


def bad_triangles(stats: dict) -> int:
    """How many triangles have RR <= 0.9: the share above 0.9 is a mean over the
    triangles, so this is the count it was taken from.  Beside the shares it says
    what they hide: a mesher that refines the interior more than asked gains share
    without having fewer bad triangles."""
    return round(stats["triangles"] * (1.0 - stats["rr_above_0.9"]))


def _cells(r: dict) -> list[str] | None:
    s = r.get("stats")
    if not s or "median" not in r:
        return None
    return [
        f"{s['rr_mean']:.4f}",
        f"{100 * s['rr_above_0.9']:.1f}",
        str(bad_triangles(s)),
        f"{s['min_angle']:.1f}",
        str(s["triangles"]),
        f"{r['median']:.3g}",
    ]


def summary_table(sec: dict) -> str:
    """Per case: mean RR, % RR > 0.9, the number of triangles with RR <= 0.9, min
    angle, triangles and time of each mesher (aftmesh / Gmsh alg 6 / Triangle pq30a),
    then the averages over the cases that every mesher meshed (so that a failure does
    not move one mesher's average)."""
    by = {(r["case"], r["mesher"]): r for r in sec["rows"]}
    meshers = [m for m in GROUP_MESHERS if any(k[1] == m for k in by)]
    lab = " / ".join(_SHORT[m] for m in meshers)
    hdr = (
        f"| case | RR mean {lab} | % RR > 0.9 {lab} | RR <= 0.9 count {lab} | "
        f"min angle {lab} | triangles {lab} | time {lab} |"
    )
    out = [hdr, "|" + "---|" * 7]
    common, missing = [], []
    for cname in dict.fromkeys(r["case"] for r in sec["rows"]):
        cells = [_cells(by.get((cname, m), {})) for m in meshers]
        if all(cells):
            common.append(cname)
        else:
            missing.append(cname)
        cols = zip(*[c or ["err"] * 6 for c in cells])
        out.append(f"| {cname} | " + " | ".join(" / ".join(col) for col in cols) + " |")
    # (stat of each case, how the column's average is written), in the table's order
    columns = (
        (lambda s: s["rr_mean"], "{:.4f}"),
        (lambda s: 100 * s["rr_above_0.9"], "{:.1f}"),
        (bad_triangles, "{:.0f}"),
        (lambda s: s["min_angle"], "{:.1f}"),
        (lambda s: s["triangles"], "{:.0f}"),
    )
    cells = []
    for stat, fmt in columns:
        means = []
        for m in meshers:
            st = [by[(c, m)]["stats"] for c in common]
            means.append(fmt.format(np.mean([stat(s) for s in st]) if st else np.nan))
        cells.append(" / ".join(means))
    out.append(f"| **average ({len(common)} cases)** | " + " | ".join(cells) + " | - |")
    if missing:
        out.append("")
        out.append(f"Left out of the averages (a mesher failed): {', '.join(missing)}.")
    return "\n".join(out) + "\n"


def _run(args) -> dict:
    import fnmatch

    from . import runner

    names = REALWORLD_CASES
    if args.cases:
        names = [c for c in names if any(fnmatch.fnmatch(c, p) for p in args.cases)]
    meshers = args.meshers or GROUP_MESHERS
    limit = args.gmsh_limit if args.gmsh_limit is not None else 3e5
    print(f"real-world group: {len(names)} cases x {len(meshers)} meshers")
    # before any availability check: it puts src/ on this process's path when the
    # kernel is built in place there, as the workers get it
    print(f"aftmesh: {runner.locate_aftmesh()}")
    return runner.run_mesh_suite(
        names, meshers, quick=True, repeat=min(args.repeat, 3), gmsh_limit=limit
    )


def run_group(args, out: Path) -> int:
    """``python -m benchmarks --realworld``: mesh the group (or the cases of it that
    --cases selects) with aftmesh (input segments kept whole, and allowed to split),
    Gmsh alg 6 and Triangle, print the table, keep the raw results in
    out/results.json under "realworld" and the table in out/realworld.md.  With
    --report-only, the table is rebuilt from out/results.json."""
    store = out / "results.json"
    results = json.loads(store.read_text()) if store.exists() else {}
    if args.report_only:
        if "realworld" not in results:
            print(f"{store} holds no real-world results: run without --report-only first")
            return 2
        sec = results["realworld"]
    else:
        sec = _run(args)
        results["realworld"] = sec
        store.write_text(json.dumps(results, indent=1))
    text = (
        "Real-world group: per case aftmesh with input segments kept whole (`aft`, as the "
        "main table) / aftmesh allowed to split them, as Triangle is (`aft-split`) / Gmsh "
        "alg 6 / Triangle pq30a; RR = radius ratio, time = median wall seconds.\n\n"
        + summary_table(sec)
    )
    (out / "realworld.md").write_text(text)
    print()
    print(text)
    if args.update_readme:
        from .report import update_readme

        readme = Path(__file__).resolve().parent.parent / "README.md"
        marks = ("<!-- realworld:start -->", "<!-- realworld:end -->")
        if update_readme(readme, text, *marks):
            print(f"updated {readme}")
        else:
            print(f"{readme} has no {marks[0]} ... {marks[1]} block: not updated")
    return 0
