"""Per-call cost of ``aftmesh.generate`` on small and real-sized outlines.

``python -m benchmarks.overhead`` prints the fixed cost of one ``generate`` call on a
100-vertex polygon meshed into about 200 triangles (median and minimum over many
calls, wall and CPU time, Triangle ``pq30a`` on the same polygon beside it) and
where that time goes.  ``--real`` runs the "small and real" group instead: outlines
with 50 to 50,000 vertices (random star polygons and fractal coastlines, made here
with numpy, or the files under ``benchmarks/data/realworld`` when present) meshed at
one constant size each into 100 to 100,000 triangles, printing per case aftmesh's
time, Triangle's and their ratio, that ratio per triangle made (the two make
different counts from the same boundary and size), and the per-stage breakdown
(generate's ``info["timing"]``).  Beside the counts: the input's median edge length
over the size (``edge/h``) and the count a uniform mesh of the size would have
(``uniform``): where the input's vertices are closer than the size, every mesher
keeps them, and aftmesh grades its triangles from their spacing up to the size
(Triangle refines only as far as its angle bound needs).  ``--real --bare`` meshes
without smoothing and the minimum-angle pass (``BARE_OPTIONS``): Basic_aft alone,
what the front itself costs against Triangle.

Times are process CPU time unless marked wall.  aftmesh and Triangle are timed call
by call in turns, so a burst of load on a shared machine weighs on both; still run it
on a quiet machine, and alternate runs when comparing two versions.  Nothing here is
asserted.
"""

from __future__ import annotations

import argparse
import cProfile
import json
import math
import pstats
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .meshers import triangle_area_switch

# Vertices of the fixed-cost polygon.
OVERHEAD_VERTICES = 100
# Calls timed for the fixed cost: enough for a stable median on a shared machine.
OVERHEAD_CALLS = 300
# Relative amplitude of the star polygons' radii: rough enough that some edges are
# shorter than the size (as on real outlines), far from self-intersection.
STAR_ROUGHNESS = 0.3
# The fixed-cost strip: its width and the jitter of its vertices along it, in units
# of the vertex spacing (chosen so that size 1 gives ~200 triangles).
STRIP_WIDTH = 1.5
STRIP_JITTER = 0.2
# The star polygons' radii: a wave of this amplitude, and noise of at most this many
# vertex spacings (besides STAR_ROUGHNESS).
STAR_WAVE = 0.2
STAR_SPIKE = 3.0
# Jitter of the star polygons' angles, in units of their mean spacing (uniform random
# angles would give edges many orders of magnitude apart, which no real outline has).
STAR_JITTER = 0.4
# Midpoint displacement of the fractal coastlines, as a fraction of the edge length.
COAST_DISPLACEMENT = 0.25
# Area of an equilateral triangle of side h, over h^2: turns a triangle count into
# a size for a domain of known area.
EQUILATERAL = math.sqrt(3) / 4
# The stages of generate, named by the function that runs each (cProfile cumulative).
STAGES = (
    ("to_domain", "inputs.py", "to_domain"),
    ("size_field", "_stages.py", "size_field"),
    ("boundary_cdt", "_stages.py", "boundary_cdt"),
    ("  discretize", "boundary.py", "discretize"),
    ("  build_cdt", "pslg.py", "build_cdt"),
    ("prepare_front", "_stages.py", "prepare_front"),
    ("run_front", "_stages.py", "run_front"),
    ("smooth", "_stages.py", "smooth"),
    ("assemble", "_stages.py", "assemble"),
)
# The per-stage columns of the real group: generate's info["timing"] (the boundary
# stage includes reading the domain; basic_aft includes smoothing), then the rest.
TIMING_COLUMNS = ("boundary", "cdt", "basic_aft", "min_angle", "rest")
REALWORLD = Path(__file__).parent / "data" / "realworld"
# An outline file without a size is meshed at its bounding-box diagonal over this.
REAL_DIVISIONS = 100


@dataclass
class Outline:
    name: str
    ring: np.ndarray  # (n, 2), not closed; empty when `geometry` is given
    size: float
    geometry: object = None  # a shapely polygon or multipolygon instead of the ring

    @property
    def polygon(self):
        from shapely.geometry import Polygon

        return self.geometry if self.geometry is not None else Polygon(self.ring)

    @property
    def n_vertices(self) -> int:
        import shapely

        if self.geometry is None:
            return len(self.ring)
        return (
            len(shapely.get_coordinates(self.geometry))
            - shapely.get_num_geometries(shapely.get_rings(self.geometry)).sum()
        )

    @property
    def uniform_triangles(self) -> int:
        """Equilateral triangles of side `size` that the area holds: the count a mesh
        of that size alone would have, before any refinement towards the boundary."""
        return round(self.polygon.area / (EQUILATERAL * self.size**2))

    @property
    def edge_over_size(self) -> float:
        """The input's median edge length over the size: below 1, the input vertices
        (which every mesher keeps) are closer than the size asks, and well-shaped
        triangles next to them are smaller than it."""
        d = self.triangle_dict()
        ends = np.asarray(d["vertices"])[np.asarray(d["segments"])]
        return float(np.median(np.hypot(*(ends[:, 1] - ends[:, 0]).T))) / self.size

    def triangle_dict(self) -> dict:
        if self.geometry is not None:
            return _pslg(self.geometry)
        n = len(self.ring)
        idx = np.arange(n)
        return {"vertices": self.ring, "segments": np.c_[idx, (idx + 1) % n]}


def _pslg(geom) -> dict:
    """Triangle's input for a polygonal geometry: its noded boundary's vertices and
    segments, and a point in each hole."""
    import shapely

    lines = shapely.get_parts(shapely.node(geom.boundary))
    coords, which = shapely.get_coordinates(lines, return_index=True)
    verts, inverse = np.unique(coords, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    same = which[:-1] == which[1:]
    segs = np.c_[inverse[:-1][same], inverse[1:][same]]
    segs = np.unique(np.sort(segs[segs[:, 0] != segs[:, 1]], axis=1), axis=0)
    edges = shapely.linestrings(np.stack([verts[segs[:, 0]], verts[segs[:, 1]]], axis=1))
    faces = shapely.get_parts(shapely.polygonize(edges))
    probes = shapely.point_on_surface(faces)
    holes = shapely.get_coordinates(probes[~shapely.covers(geom, probes)])
    out = {"vertices": verts, "segments": segs.astype(np.int32)}
    if len(holes):
        out["holes"] = holes
    return out


def star(n: int, seed: int) -> np.ndarray:
    """A star-shaped ring of n vertices around the origin: a wavy disk (radius
    1 +- STAR_WAVE) with random noise of at most STAR_ROUGHNESS or a few vertex
    spacings on the radii, so that spikes stay as blunt as on real outlines."""
    rng = np.random.default_rng(seed)
    angle = (np.arange(n) + STAR_JITTER * rng.uniform(-1, 1, n)) * (2 * np.pi / n)
    noise = min(STAR_ROUGHNESS, STAR_SPIKE * 2 * np.pi / n)
    wave = STAR_WAVE * np.sin(3 * angle + rng.uniform(0, 2 * np.pi))
    radius = 1.0 + wave + noise * rng.uniform(-1, 1, n)
    return np.c_[radius * np.cos(angle), radius * np.sin(angle)]


def coastline(n: int, seed: int) -> np.ndarray:
    """A fractal coastline of about n vertices: a square refined by random midpoint
    displacement (each edge bent outward or inward by a fraction of its length)."""
    rng = np.random.default_rng(seed)
    ring = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    while len(ring) < n:
        nxt = np.roll(ring, -1, axis=0)
        d = nxt - ring
        normal = np.c_[d[:, 1], -d[:, 0]]
        mid = 0.5 * (ring + nxt) + COAST_DISPLACEMENT * rng.uniform(-1, 1, (len(ring), 1)) * normal
        out = np.empty((2 * len(ring), 2))
        out[0::2], out[1::2] = ring, mid
        ring = out
    return ring


def _valid(ring: np.ndarray) -> bool:
    from shapely.geometry import Polygon

    return Polygon(ring).is_valid


def _sized(name: str, ring: np.ndarray, triangles: int) -> Outline:
    from shapely.geometry import Polygon

    area = Polygon(ring).area
    return Outline(name, ring, math.sqrt(area / (EQUILATERAL * triangles)))


def strip(n: int, seed: int, width: float) -> np.ndarray:
    """A river-like strip of n vertices: two jagged sides, unit spacing along x."""
    rng = np.random.default_rng(seed)
    m = n // 2
    x = np.arange(m) + STRIP_JITTER * rng.uniform(-1, 1, m)
    x[0], x[-1] = 0.0, m - 1.0
    bottom = np.c_[x, -STAR_ROUGHNESS * rng.uniform(-1, 1, m)]
    top = np.c_[x, width + STAR_ROUGHNESS * rng.uniform(-1, 1, m)]
    return np.r_[bottom, top[::-1]]


def overhead_outline() -> Outline:
    """The fixed-cost polygon: a 100-vertex strip meshed at size 1 into ~200
    triangles (a round 100-gon at its edge length would give ~1800)."""
    return Outline("strip-100", strip(OVERHEAD_VERTICES, seed=1, width=STRIP_WIDTH), 1.0)


def overhead_forms() -> dict[str, tuple[tuple, dict]]:
    """generate's arguments for the fixed-cost strip in the other forms users pass:
    without a size (the edges' sizes), as a multipolygon of three copies side by side,
    as a Triangle dict with a square hole and its hole point, with its input edges
    kept whole (split_boundary=False, as the main table's aftmesh column meshes), at
    a size callable (strip_ramp), cut in two regions at its middle (a list of two
    polygons), and with a constraint line along its middle (a GeometryCollection)."""
    from shapely import affinity
    from shapely.geometry import GeometryCollection, LineString, MultiPolygon, box

    case = overhead_outline()
    poly = case.polygon
    x0, y0, x1, y1 = poly.bounds
    step = 2.0 * (y1 - y0)
    copies = MultiPolygon([affinity.translate(poly, 0.0, k * step) for k in range(3)])
    cx, cy = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
    half = 0.25 * STRIP_WIDTH
    square = [[cx - half, cy - half], [cx + half, cy - half], [cx + half, cy + half],
              [cx - half, cy + half]]  # fmt: skip
    n = len(case.ring)
    holed = {
        "vertices": np.vstack([case.ring, square]),
        "segments": [[i, (i + 1) % n] for i in range(n)]
        + [[n + i, n + (i + 1) % 4] for i in range(4)],
        "holes": [[cx, cy]],
    }
    halves = [poly.intersection(box(x0 - 1, y0 - 1, cx, y1 + 1)),
              poly.intersection(box(cx, y0 - 1, x1 + 1, y1 + 1))]  # fmt: skip
    # the sides stay within STAR_ROUGHNESS of y = 0 and y = STRIP_WIDTH
    line = LineString([(x0 + 2.0, 0.5 * STRIP_WIDTH), (x1 - 2.0, 0.5 * STRIP_WIDTH)])
    return {
        f"{case.name}/none": ((poly,), {}),
        f"{case.name}/x3": ((copies, case.size), {}),
        f"{case.name}/dict-hole": ((holed, case.size), {}),
        f"{case.name}/whole": ((poly, case.size), {"split_boundary": False}),
        f"{case.name}/callable": ((poly, strip_ramp), {}),
        f"{case.name}/regions": ((halves, case.size), {}),
        f"{case.name}/line": ((GeometryCollection([poly, line]), case.size), {}),
    }


def strip_ramp(x, y):
    """The strip's size as a callable: its number size at the left end, growing by
    half of it along the strip's 100 units (about the same triangle count)."""
    return 0.8 + 0.004 * np.asarray(x)


def real_outlines(folder: Path = REALWORLD) -> list[Outline]:
    """The "small and real" group: files under data/realworld if any, else made."""
    files = sorted(folder.glob("*.json")) if folder.is_dir() else []
    if files:
        return [_from_file(f) for f in files]
    cases = []
    for n, tris in (
        (50, 100),
        (200, 500),
        (1000, 2000),
        (1000, 20000),
        (5000, 10000),
        (20000, 50000),
        (50000, 100000),
    ):
        cases.append(_sized(f"star-{n}-{tris}", star(n, seed=n), tris))
        ring = coastline(n, seed=n)
        if _valid(ring):
            cases.append(_sized(f"coast-{len(ring)}-{tris}", ring, tris))
    return cases


def _from_file(path: Path) -> Outline:
    """An outline file: ``domain_wkb`` (a valid geometry, hex WKB) or ``ring``; the
    size is ``size`` if given, else the bounding-box diagonal / 100."""
    data = json.loads(path.read_text())
    if "domain_wkb" in data:
        import shapely

        geom = shapely.orient_polygons(shapely.from_wkb(bytes.fromhex(data["domain_wkb"])))
        x0, y0, x1, y1 = geom.bounds
        size = data.get("size") or math.hypot(x1 - x0, y1 - y0) / REAL_DIVISIONS
        return Outline(path.stem, np.zeros((0, 2)), float(size), geom)
    ring = np.asarray(data["ring"], dtype=np.float64)
    if (ring[0] == ring[-1]).all():
        ring = ring[:-1]
    size = data.get("size")
    if size is None:
        lo, hi = ring.min(axis=0), ring.max(axis=0)
        size = float(np.hypot(*(hi - lo))) / REAL_DIVISIONS
    return Outline(path.stem, ring, float(size))


# ------------------------------------------------------------------------ timing


def _summary(wall: list, cpu: list) -> dict:
    return {
        "wall_med": statistics.median(wall),
        "wall_min": min(wall),
        "cpu_med": statistics.median(cpu),
        "cpu_min": min(cpu),
    }


def _time_alternating(first: Callable[[], object], second: Callable[[], object], calls: int):
    """Wall and CPU time of both (median and least), timed call by call in turns
    (which one goes first alternates), so that a burst of load on the machine weighs
    on both alike."""
    wall: tuple[list, list] = ([], [])
    cpu: tuple[list, list] = ([], [])
    fns = (first, second)
    for i in range(calls):
        for k in (0, 1) if i % 2 == 0 else (1, 0):
            w0, c0 = time.perf_counter(), time.process_time()
            fns[k]()
            cpu[k].append(time.process_time() - c0)
            wall[k].append(time.perf_counter() - w0)
    return _summary(wall[0], cpu[0]), _summary(wall[1], cpu[1])


def _calls_for(seconds: float, budget: float, lo: int = 3, hi: int = OVERHEAD_CALLS) -> int:
    return int(min(hi, max(lo, budget / max(seconds, 1e-6))))


def _aftmesh():
    """aftmesh as the benchmark workers import it: the in-place build under src/ when
    there is one, otherwise the installed package."""
    from . import runner

    runner.locate_aftmesh()
    import aftmesh

    return aftmesh


def _runners(case: Outline, options: dict | None = None):
    """aftmesh (with generate's `options`) and Triangle on the outline, as calls."""
    import triangle

    aftmesh = _aftmesh()
    poly = case.polygon
    tri_dict = case.triangle_dict()
    switches = "pq30" + triangle_area_switch(EQUILATERAL * case.size**2)
    kw = options or {}
    return (
        lambda: aftmesh.generate(poly, case.size, **kw),
        lambda: triangle.triangulate(tri_dict, switches),
    )


def _group(filename: str, name: str) -> str:
    """A cProfile entry's group: the aftmesh module, the kernel, shapely, numpy."""
    if "aftmesh" in filename:
        return "aftmesh." + Path(filename).stem
    if "shapely" in filename or "shapely" in name:
        return "shapely"
    if "numpy" in filename or "numpy" in name:
        return "numpy"
    if "aftmesh._kernel" in name or "Triangulation" in name:
        return "kernel"
    return "other"


def profile(fn: Callable[[], object], calls: int) -> tuple[dict, dict]:
    """(cumulative seconds per call of each stage, own seconds per call of each
    group of code) over `calls` calls of fn."""
    prof = cProfile.Profile()
    prof.enable()
    for _ in range(calls):
        fn()
    prof.disable()
    stats = pstats.Stats(prof).stats  # type: ignore[attr-defined]
    stages = {label: 0.0 for label, _, _ in STAGES}
    groups: dict[str, float] = {}
    for (filename, _line, name), (_cc, _nc, tt, ct, _callers) in stats.items():
        for label, file, func in STAGES:
            if name == func and filename.endswith(file) and "aftmesh" in filename:
                stages[label] += ct / calls
        group = _group(filename, name)
        groups[group] = groups.get(group, 0.0) + tt / calls
    return stages, groups


def _ms(x: float) -> str:
    return f"{1e3 * x:8.3f}"


def run_overhead(calls: int) -> None:
    aftmesh = _aftmesh()
    case = overhead_outline()
    aft, tri = _runners(case)
    mesh = aft()
    print(
        f"fixed cost: {case.name}, {case.n_vertices} vertices, size {case.size:.4g}, "
        f"{len(mesh.triangles)} triangles (Triangle: {len(tri()['triangles'])})"
    )
    ta, tt = _time_alternating(aft, tri, calls)
    print(f"{'ms per call':<16}{'wall med':>9}{'wall min':>9}{'cpu med':>9}{'cpu min':>9}")
    for label, t in (("aftmesh", ta), ("Triangle pq30a", tt)):
        print(
            f"{label:<16}{_ms(t['wall_med'])} {_ms(t['wall_min'])} "
            f"{_ms(t['cpu_med'])} {_ms(t['cpu_min'])}"
        )
    print(f"ratio (cpu med): {ta['cpu_med'] / tt['cpu_med']:.1f}x")
    timing = [aftmesh.generate(case.polygon, case.size).info["timing"] for _ in range(calls)]
    print(
        "info['timing'] medians (ms): "
        + ", ".join(f"{k} {1e3 * statistics.median(t[k] for t in timing):.3f}" for k in timing[0])
    )
    _print_profile(*profile(aft, calls))


def _print_profile(stages: dict, groups: dict) -> None:
    print("stages (cProfile cumulative, ms per call; profiling inflates Python code):")
    for label, t in stages.items():
        print(f"  {label:<16}{_ms(t)}")
    total = sum(groups.values())
    print("own time by code (ms per call, share):")
    for group, t in sorted(groups.items(), key=lambda kv: -kv[1]):
        if t >= 0.01 * total:
            print(f"  {group:<24}{_ms(t)}  {100 * t / total:4.0f} %")


def stage_medians(aft: Callable[[], object], calls: int) -> list[float]:
    """Median seconds of each of TIMING_COLUMNS over `calls` calls of aft: generate's
    own info["timing"], which the compiled common case fills as the stages do (a
    profiler sees that case as one call), and the rest of the call (the result)."""
    rows = []
    for _ in range(calls):
        timing = aft().info["timing"]  # type: ignore[attr-defined]
        stages = [timing[k] for k in TIMING_COLUMNS[:-1]]
        rows.append([*stages, timing["total"] - sum(stages)])
    return [statistics.median(column) for column in zip(*rows)]


# --bare: Basic_aft alone, without the passes after it (smoothing, the minimum-angle
# pass): what the front itself costs against Triangle on real outlines
BARE_OPTIONS = {"smooth": 0, "min_angle": None}


def run_real(
    budget: float, breakdown: bool, folder: Path = REALWORLD, options: dict | None = None
) -> None:
    rows, per_tri = [], []
    if options:
        print("aftmesh options: " + ", ".join(f"{k}={v!r}" for k, v in options.items()))
    header = (
        f"{'case':<22}{'verts':>7}{'edge/h':>7}{'uniform':>8}{'aft tri':>8}{'Tri tri':>8}"
        f"{'aft ms':>9}{'tri ms':>9}{'ratio':>7}{'per tri':>8}"
    )
    print(header + ("  " + " ".join(TIMING_COLUMNS) + " (wall ms)" if breakdown else ""))
    for case in real_outlines(folder):
        aft, tri = _runners(case, options)
        t0 = time.process_time()
        mesh = aft()
        once = time.process_time() - t0
        n_tri = len(tri()["triangles"])
        calls = _calls_for(once, budget)
        ta, tt = (t["cpu_med"] for t in _time_alternating(aft, tri, calls))
        # the ratio per triangle made: aftmesh and Triangle make different counts
        # from the same boundary and size
        per_tri.append((ta / len(mesh.triangles)) / (tt / n_tri))
        line = (
            f"{case.name:<22}{case.n_vertices:>7}{case.edge_over_size:7.2f}"
            f"{case.uniform_triangles:>8}{len(mesh.triangles):>8}{n_tri:>8}"
            f"{1e3 * ta:9.2f}{1e3 * tt:9.2f}{ta / tt:7.2f}{per_tri[-1]:8.2f}"
        )
        if breakdown:
            line += "  " + " ".join(f"{1e3 * t:.2f}" for t in stage_medians(aft, calls))
        print(line, flush=True)
        rows.append(ta / tt)
    print(
        f"median ratio {statistics.median(rows):.2f}x over {len(rows)} cases "
        f"(per triangle made: {statistics.median(per_tri):.2f}x)"
    )


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.overhead", description=__doc__)
    parser.add_argument("--real", action="store_true", help='the "small and real" group')
    parser.add_argument(
        "--calls", type=int, default=OVERHEAD_CALLS, help="calls timed for the fixed cost"
    )
    parser.add_argument(
        "--budget", type=float, default=1.0, help="seconds of aftmesh time per real case and timing"
    )
    parser.add_argument(
        "--no-breakdown",
        action="store_true",
        help="real group: skip the per-stage breakdown (info['timing'] medians)",
    )
    parser.add_argument(
        "--data", type=Path, default=REALWORLD, help="folder of outline .json files (--real)"
    )
    parser.add_argument(
        "--bare",
        action="store_true",
        help="real group: aftmesh without smoothing and the minimum-angle pass (Basic_aft alone)",
    )
    args = parser.parse_args(argv)
    if args.real:
        run_real(args.budget, not args.no_breakdown, args.data, BARE_OPTIONS if args.bare else None)
    else:
        run_overhead(args.calls)


if __name__ == "__main__":
    main()
