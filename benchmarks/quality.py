"""``python -m benchmarks.quality CASE [CASE ...] [--threshold 0.9] [--png out.png] [--split]``
or ``python -m benchmarks.quality --bands CASE [CASE ...] [--mesher NAME ...]``

Labels each triangle of aftmesh's mesh of a benchmark case whose radius ratio is below
the threshold by where it came from (:func:`aftmesh.diagnose.diagnose`: an input
angle too narrow for any better triangle, smoothing, boundary, size transition, front
collision, other), prints the counts per class and draws the bad triangles coloured by
class.  CASE is any benchmark case name (see ``python -m benchmarks --list``),
including the real-world group's ``rw-*``.

``--bands`` instead compares meshers band by band of distance from the input edges (in
target sizes): triangles, mean radius ratio, the count at or below the threshold, the
radius-ratio deficit sum(1 - RR), and the share of the triangles' corners that are
points the mesher added inside with six neighbours (a mesh's lattice regularity).
A mean radius ratio rises when a mesher fills the interior with more near-uniform
triangles; the bands show where each mesher's triangles and losses are.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from . import runner
from .cases import build_case

COLOURS = {
    "input_angle": "tab:green",
    "smoothing": "tab:purple",
    "boundary": "tab:blue",
    "size": "tab:orange",
    "collision": "tab:red",
    "other": "tab:gray",
}
OUT = Path(__file__).resolve().parent / "out"


def diagnose_case(name: str, threshold: float, split: bool = False):
    from aftmesh.diagnose import diagnose

    case = build_case(name)
    return diagnose(
        case.as_triangle_dict(), case.size_arg, threshold=threshold, split_boundary=split
    )


# Distance bands, in target sizes from the nearest input edge: the first layers, the
# size transitions, the interior.
BANDS = (0.0, 0.5, 1.0, 2.0, 4.0, 8.0, np.inf)
# What --bands compares when no --mesher is given (Gmsh only where it is installed).
BAND_MESHERS = ("aft", "aft-split", "gmsh-frontal")


def band_rows(name: str, mesher: str, threshold: float) -> list[dict]:
    """One row per distance band of `mesher`'s mesh of case `name`."""
    import shapely

    from aftmesh.mesh import triangle_quality

    from .meshers import prepare

    case = build_case(name)
    job = prepare(mesher, case)
    try:
        out = job.result(job.run())
    finally:
        job.close()
    pts, tris = np.asarray(out.points), np.asarray(out.triangles, dtype=np.int64)
    rr = triangle_quality(pts, tris)["radius_ratio"]
    cent = pts[tris].mean(axis=1)
    edges = shapely.linestrings(case.vertices[case.segments])
    _, dist = shapely.STRtree(edges).query_nearest(
        shapely.points(cent), return_distance=True, all_matches=False
    )
    depth = dist / case.target(cent[:, 0], cent[:, 1])
    regular = _six_neighbours(tris, pts, np.asarray(case.vertices, dtype=np.float64))
    rows = []
    for lo, hi in zip(BANDS[:-1], BANDS[1:]):
        sel = (depth >= lo) & (depth < hi)
        rows.append(
            {
                "mesher": mesher,
                "band": f"{lo:g}-{hi:g}",
                "triangles": int(sel.sum()),
                "rr_mean": float(rr[sel].mean()) if sel.any() else float("nan"),
                "bad": int((rr[sel] <= threshold).sum()),
                "deficit": float((1.0 - rr[sel]).sum()),
                "six": float(regular[tris[sel]].mean()) if sel.any() else float("nan"),
            }
        )
    return rows


def _six_neighbours(tris: np.ndarray, pts: np.ndarray, inputs: np.ndarray) -> np.ndarray:
    """Per point: 1 where a point the mesher added off the boundary (not an input
    vertex, every edge at it shared by two triangles) has exactly six neighbours, else
    0; the band's mean over its triangles' corners is then the share.

    >>> ring = np.array([(np.cos(a), np.sin(a)) for a in np.arange(6) * np.pi / 3])
    >>> pts = np.vstack([ring, [(0.0, 0.0)]])
    >>> fan = np.array([(6, k, (k + 1) % 6) for k in range(6)])
    >>> _six_neighbours(fan, pts, ring).tolist()
    [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]
    """
    n_points = len(pts)
    e = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1)
    key, count = np.unique(e[:, 0] * n_points + e[:, 1], return_counts=True)
    a, b = key // n_points, key % n_points
    neighbours = np.bincount(a, minlength=n_points) + np.bincount(b, minlength=n_points)
    on_boundary = np.zeros(n_points, dtype=bool)  # at an edge of one triangle
    on_boundary[a[count == 1]] = on_boundary[b[count == 1]] = True
    given = np.isin(pts[:, 0] + 1j * pts[:, 1], inputs[:, 0] + 1j * inputs[:, 1])
    return ((neighbours == 6) & ~on_boundary & ~given).astype(float)


def print_bands(name: str, meshers, threshold: float) -> None:
    from .meshers import mesher_available

    print(f"{name}: by distance from the input edges, in target sizes")
    print("  mesher          band     triangles  RR mean  RR<=thr  deficit  six-neighbour")
    for mesher in meshers:
        why = mesher_available(mesher)
        if why:
            print(f"  {mesher:14s}  not available: {why}")
            continue
        rows = band_rows(name, mesher, threshold)
        for r in rows:
            print(
                f"  {mesher:14s}  {r['band']:7s}  {r['triangles']:9d}  {r['rr_mean']:7.4f}  "
                f"{r['bad']:7d}  {r['deficit']:7.1f}  {r['six']:7.3f}"
            )
        n, total = sum(r["triangles"] for r in rows), sum(r["deficit"] for r in rows)
        print(f"  {mesher:14s}  all      {n:9d}  deficit {total:.1f}")


def draw(diag, title: str, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection
    from matplotlib.patches import Patch

    m = diag.mesh
    fig, ax = plt.subplots(figsize=(10, 8))
    ax.triplot(m.points[:, 0], m.points[:, 1], m.triangles, lw=0.1, color="0.75")
    seg = m.points[m.segments]
    ax.plot(seg[:, :, 0].T, seg[:, :, 1].T, lw=0.6, color="k")
    handles = []
    for c, colour in COLOURS.items():
        sel = diag.bad[diag.labels == c]
        if len(sel):
            ax.add_collection(
                PolyCollection(
                    m.points[m.triangles[sel]], facecolor=colour, edgecolor=colour, lw=0.3
                )
            )
            handles.append(Patch(color=colour, label=f"{c} ({len(sel)})"))
    ax.set_aspect("equal")
    ax.set_title(title)
    ax.legend(handles=handles, loc="upper right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=150)
    plt.close(fig)


def main(argv=None) -> int:
    doc = (__doc__ or "").split("\n\n")
    p = argparse.ArgumentParser(prog="python -m benchmarks.quality", description=doc[1])
    p.add_argument("cases", nargs="+", metavar="CASE")
    p.add_argument(
        "--threshold",
        type=float,
        default=0.9,
        help="radius ratio below which a triangle is bad (default 0.9)",
    )
    p.add_argument(
        "--png",
        type=Path,
        help="picture path (one case), default benchmarks/out/quality_<case>.png",
    )
    p.add_argument(
        "--split",
        action="store_true",
        help="mesh as generate's default does, input segments split (the aft-split "
        "mesher); without it they are kept whole (aft)",
    )
    p.add_argument(
        "--bands",
        action="store_true",
        help="compare meshers by distance from the input edges (see above) instead",
    )
    p.add_argument(
        "--mesher",
        action="append",
        help=f"with --bands: a mesher to compare (repeatable; default {' '.join(BAND_MESHERS)})",
    )
    args = p.parse_args(sys.argv[1:] if argv is None else argv)
    print(f"aftmesh: {runner.locate_aftmesh()}")
    if args.bands:
        for name in args.cases:
            print_bands(name, args.mesher or BAND_MESHERS, args.threshold)
        return 0
    OUT.mkdir(parents=True, exist_ok=True)
    total: dict[str, int] = {}
    for name in args.cases:
        diag = diagnose_case(name, args.threshold, args.split)
        print(f"{name}:")
        print(diag.summary())
        for c, k in diag.counts.items():
            total[c] = total.get(c, 0) + k
        mode = "-split" if args.split else ""
        path = args.png if args.png and len(args.cases) == 1 else OUT / f"quality_{name}{mode}.png"
        draw(diag, f"{name}{mode}: RR < {args.threshold:g} by cause", path)
        print(f"  picture: {path}")
    if len(args.cases) > 1:
        n = max(sum(total.values()), 1)
        print("all cases: " + ", ".join(f"{c} {k} ({100 * k / n:.1f} %)" for c, k in total.items()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
