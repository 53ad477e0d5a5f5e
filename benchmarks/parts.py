"""Many parts in one ``generate`` call: regions, constraint lines, fixed points.

``python -m benchmarks.parts`` meshes domains with many parts against Triangle
``pq30Aa`` on the same planar graph, printing per case the CPU time of each (median,
timed call by call in turns), their ratio and generate's per-stage breakdown
(``info["timing"]``).  Cases:

* region lists (``generate([poly, ...], h)``, one region each), as parcels or
  multi-material parts come: unit squares in a k x k grid, Voronoi cells of random
  points clipped to the unit square, and the same cells with each cell's edges split
  on its own (``shapely.segmentize``), so that neighbours' shared edges differ by
  rounding: slivers and near crossings, as digitized parcel data has them (Triangle
  stops there with "Ran out of precision", and the row shows aftmesh alone);
* a square with short constraint lines (one per cell of a grid), with a grid of
  long lines crossing each other (noded by aftmesh), and with random fixed points
  (a ``GeometryCollection`` each).

Triangle gets the parts' linework noded by shapely here, the fixed points as
vertices and one region point per region.  The input side of such a call (region
checks, noding, the classification of the pieces into regions, the lines' and
points' checks) runs in Python with shapely, not in the compiled call; this measures
what it costs as the number of parts grows.  Nothing here is asserted.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import statistics
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .meshers import triangle_area_switch
from .overhead import (
    EQUILATERAL,
    TIMING_COLUMNS,
    _aftmesh,
    _calls_for,
    _time_alternating,
    stage_medians,
)

# The sliver case splits each cell's edges into pieces at most this many sizes long:
# denser than the mesh, as a digitized boundary is.
SEGMENTIZE_PER_SIZE = 0.5
# A short constraint line's length, in cells of its grid: well inside its cell.
SHORT_LINE = 0.3
# The crossing lines stop this far from the square's sides (they are constraints
# inside it, not splits of it).
LINE_INSET = 0.01
# The fixed points stay this far from the square's sides.
POINT_INSET = 0.05


@dataclass
class Parts:
    name: str
    domain: object  # a list of regions, or a GeometryCollection
    size: float
    regions: list = field(default_factory=list)  # the region polygons, for Triangle


def grid(k: int) -> list:
    from shapely.geometry import box

    return [box(i, j, i + 1, j + 1) for i in range(k) for j in range(k)]


def voronoi(n: int, seed: int, segment: float | None = None) -> list:
    """Voronoi cells of n random points clipped to the unit square; with `segment`,
    each cell's edges split on its own into pieces at most that long."""
    import shapely
    from shapely.geometry import MultiPoint, box

    rng = np.random.default_rng(seed)
    seeds = MultiPoint(rng.random((n, 2)))
    cells = shapely.get_parts(shapely.voronoi_polygons(seeds, extend_to=box(0, 0, 1, 1)))
    cells = shapely.intersection(cells, box(0, 0, 1, 1))
    return list(cells if segment is None else shapely.segmentize(cells, segment))


def short_lines(k: int, seed: int):
    """The unit square with a short line of random direction in each of k x k cells."""
    from shapely.geometry import GeometryCollection, LineString, box

    rng = np.random.default_rng(seed)
    lines = []
    for i in range(k):
        for j in range(k):
            c = np.array([(i + 0.5) / k, (j + 0.5) / k])
            d = rng.normal(size=2)
            d *= 0.5 * SHORT_LINE / k / np.linalg.norm(d)
            lines.append(LineString([c - d, c + d]))
    return GeometryCollection([box(0, 0, 1, 1), *lines])


def crossing_lines(k: int):
    """The unit square with k horizontal and k vertical lines crossing each other."""
    from shapely.geometry import GeometryCollection, LineString, box

    at = (np.arange(k) + 0.5) / k
    lo, hi = LINE_INSET, 1 - LINE_INSET
    lines = [LineString([(lo, y), (hi, y)]) for y in at]
    lines += [LineString([(x, lo), (x, hi)]) for x in at]
    return GeometryCollection([box(0, 0, 1, 1), *lines])


def fixed_points(n: int, seed: int):
    import shapely
    from shapely.geometry import GeometryCollection, box

    rng = np.random.default_rng(seed)
    xy = POINT_INSET + (1 - 2 * POINT_INSET) * rng.random((n, 2))
    return GeometryCollection([box(0, 0, 1, 1), *shapely.points(xy)])


def cases() -> list[Parts]:
    out = []
    for name, regions, h in (
        ("grid-10x10", grid(10), 0.25),
        ("grid-30x30", grid(30), 0.25),
        ("voronoi-100", voronoi(100, 1), 0.02),
        ("voronoi-900", voronoi(900, 1), 0.01),
        ("voronoi-900-slivers", voronoi(900, 1, SEGMENTIZE_PER_SIZE * 0.01), 0.01),
    ):
        out.append(Parts(name, regions, h, regions))
    out.append(Parts("lines-961", short_lines(31, 0), 0.02))
    out.append(Parts("crossing-lines-80", crossing_lines(40), 0.01))
    out.append(Parts("points-2000", fixed_points(2000, 0), 0.02))
    return out


def triangle_dict(case: Parts) -> dict:
    """The case's linework as one noded planar graph (shapely's union of the rings and
    lines), its fixed points, and a region point inside each region, attribute its
    index."""
    import shapely

    geoms = case.regions or list(shapely.get_parts(case.domain))
    linework = [
        shapely.get_exterior_ring(g) if g.geom_type == "Polygon" else g
        for g in geoms
        if g.geom_type in ("Polygon", "LineString")
    ]
    lines = shapely.union_all(linework)
    edges = [np.asarray(part.coords)[:, :2] for part in shapely.get_parts(lines)]
    loose = [np.asarray(g.coords)[:, :2] for g in geoms if g.geom_type == "Point"]
    points, inverse = np.unique(np.concatenate(edges + loose), axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    segments, start = [], 0
    for e in edges:
        ids = inverse[start : start + len(e)]
        segments.append(np.c_[ids[:-1], ids[1:]])
        start += len(e)
    seg = np.concatenate(segments)
    out = {"vertices": points, "segments": seg[seg[:, 0] != seg[:, 1]]}
    if case.regions:
        inner = shapely.get_coordinates(shapely.point_on_surface(case.regions))
        n = len(case.regions)
        out["regions"] = np.c_[inner, np.arange(n), np.zeros(n)]
    return out


def _runners(case: Parts) -> tuple[Callable[[], object], Callable[[], object]]:
    import triangle

    aftmesh = _aftmesh()
    tri_dict = triangle_dict(case)
    switches = "pq30" + ("A" if case.regions else "")
    switches += triangle_area_switch(EQUILATERAL * case.size**2)
    return (
        lambda: aftmesh.generate(case.domain, case.size),
        lambda: triangle.triangulate(tri_dict, switches),
    )


@contextlib.contextmanager
def _quiet_stdout():
    """Standard output silenced at the file descriptor: Triangle prints its errors
    from C, past Python's sys.stdout."""
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 1)
            yield
    finally:
        os.dup2(saved, 1)
        os.close(saved)


def _cpu(fn: Callable[[], object]) -> float:
    t0 = time.process_time()
    fn()
    return time.process_time() - t0


def run(budget: float) -> None:
    print(
        f"{'case':<22}{'parts':>7}{'aft tri':>8}{'Tri tri':>8}{'aft ms':>9}{'tri ms':>9}"
        f"{'ratio':>7}  " + " ".join(TIMING_COLUMNS) + " (wall ms)"
    )
    for case in cases():
        aft, tri = _runners(case)
        mesh = aft()
        n_parts = len(case.regions) if case.regions else len(case.domain.geoms) - 1  # type: ignore[attr-defined]
        runs: Callable[[], object] | None = tri
        try:
            with _quiet_stdout():
                n_tri = str(len(tri()["triangles"]))  # type: ignore[index]
        except RuntimeError:  # Triangle's "Ran out of precision" on the slivers
            n_tri, runs = "fails", None
        calls = _calls_for(_cpu(aft), budget)
        if runs is None:
            ta = statistics.median(_cpu(aft) for _ in range(calls))
            tt_ms, ratio = f"{'-':>9}", f"{'-':>7}"
        else:
            ta, tt = (t["cpu_med"] for t in _time_alternating(aft, runs, calls))
            tt_ms, ratio = f"{1e3 * tt:9.2f}", f"{ta / tt:7.2f}"
        stages = " ".join(f"{1e3 * t:.2f}" for t in stage_medians(aft, calls))
        n_aft = len(mesh.triangles)  # type: ignore[attr-defined]
        print(
            f"{case.name:<22}{n_parts:>7}{n_aft:>8}{n_tri:>8}{1e3 * ta:9.2f}{tt_ms}{ratio}  "
            + stages,
            flush=True,
        )


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.parts", description=__doc__)
    parser.add_argument(
        "--budget", type=float, default=1.0, help="seconds of aftmesh time per case and timing"
    )
    args = parser.parse_args(argv)
    run(args.budget)


if __name__ == "__main__":
    main()
