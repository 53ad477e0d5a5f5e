"""Many regions in one ``generate`` call: tilings of parcels or materials.

``python -m benchmarks.tilings`` meshes region lists (``generate([poly, ...], h)``,
one region each) against Triangle ``pq30Aa`` on the same planar graph (the regions'
boundaries noded by shapely here, one region point per region), printing per case
the CPU time of each (median, timed call by call in turns), their ratio and
generate's per-stage breakdown (``info["timing"]``).  Cases: unit squares in a k x k
grid, Voronoi cells of random points clipped to the unit square, and the same cells
with each cell's edges split on its own (``shapely.segmentize``), so that neighbours'
shared edges differ by rounding: slivers and near crossings, as digitized parcel
data has them (Triangle refuses that one).

The input side of such a call (region checks, noding, the classification of the
pieces into regions) runs in Python with shapely, not in the compiled call; this
measures what it costs as the number of regions grows.  Nothing here is asserted.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass

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


@dataclass
class Tiling:
    name: str
    polygons: list
    size: float


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


def tilings() -> list[Tiling]:
    out = [Tiling("grid-10x10", grid(10), 0.25), Tiling("grid-30x30", grid(30), 0.25)]
    for n, h in ((100, 0.02), (900, 0.01)):
        out.append(Tiling(f"voronoi-{n}", voronoi(n, seed=1), h))
    h = 0.01
    out.append(Tiling("voronoi-900-slivers", voronoi(900, 1, SEGMENTIZE_PER_SIZE * h), h))
    return out


def triangle_dict(polygons: list) -> dict:
    """The regions' boundaries as one noded planar graph (shapely's union of the
    rings), with a region point inside each region, attribute its index."""
    import shapely

    lines = shapely.union_all(shapely.get_exterior_ring(polygons))
    edges = [np.asarray(part.coords)[:, :2] for part in shapely.get_parts(lines)]
    xy = np.concatenate(edges)
    points, inverse = np.unique(xy, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    segments, start = [], 0
    for e in edges:
        ids = inverse[start : start + len(e)]
        segments.append(np.c_[ids[:-1], ids[1:]])
        start += len(e)
    seg = np.concatenate(segments)
    seg = seg[seg[:, 0] != seg[:, 1]]
    inner = shapely.get_coordinates(shapely.point_on_surface(polygons))
    regions = np.c_[inner, np.arange(len(polygons)), np.zeros(len(polygons))]
    return {"vertices": points, "segments": seg, "regions": regions}


def _runners(case: Tiling) -> tuple[Callable[[], object], Callable[[], object]]:
    import triangle

    aftmesh = _aftmesh()
    tri_dict = triangle_dict(case.polygons)
    switches = "pq30A" + triangle_area_switch(EQUILATERAL * case.size**2)
    return (
        lambda: aftmesh.generate(case.polygons, case.size),
        lambda: triangle.triangulate(tri_dict, switches),
    )


def run(budget: float) -> None:
    print(
        f"{'case':<22}{'regions':>8}{'aft tri':>8}{'Tri tri':>8}{'aft ms':>9}{'tri ms':>9}"
        f"{'ratio':>7}  " + " ".join(TIMING_COLUMNS) + " (wall ms)"
    )
    for case in tilings():
        aft, tri = _runners(case)
        mesh = aft()
        try:
            n_tri = str(len(tri()["triangles"]))  # type: ignore[index]
        except RuntimeError:  # Triangle's "Ran out of precision" on the slivers
            n_tri, tri = "fails", None
        calls = _calls_for(_cpu(aft), budget)
        if tri is None:
            ta = statistics.median(_cpu(aft) for _ in range(calls))
            tt_ms, ratio = f"{'-':>9}", f"{'-':>7}"
        else:
            ta, tt = (t["cpu_med"] for t in _time_alternating(aft, tri, calls))
            tt_ms, ratio = f"{1e3 * tt:9.2f}", f"{ta / tt:7.2f}"
        stages = " ".join(f"{1e3 * t:.2f}" for t in stage_medians(aft, calls))
        print(
            f"{case.name:<22}{len(case.polygons):>8}{len(mesh.triangles):>8}{n_tri:>8}"  # type: ignore[attr-defined]
            f"{1e3 * ta:9.2f}{tt_ms}{ratio}  {stages}",
            flush=True,
        )


def _cpu(fn: Callable[[], object]) -> float:
    t0 = time.process_time()
    fn()
    return time.process_time() - t0


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.tilings", description=__doc__)
    parser.add_argument(
        "--budget", type=float, default=1.0, help="seconds of aftmesh time per case and timing"
    )
    args = parser.parse_args(argv)
    run(args.budget)


if __name__ == "__main__":
    main()
