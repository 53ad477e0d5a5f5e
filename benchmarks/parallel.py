"""``python -m benchmarks --parallel``: many domains and one big domain, in parallel.

* 1,000 small polygons: serial ``generate`` calls against ``generate_many`` on 2
  threads and on a 2-worker Dask LocalCluster (processes);
* the unit square at ~1e6 and ~1e7 triangles: serial against ``partitions=2`` on 2
  threads and as Dask tasks (quality: mean radius ratio against the serial mesh);
* the ~1e7 square written with ``out=`` by the Dask workers: peak resident memory of
  the largest process against the size of the whole mesh's arrays.

Each case runs its backends in turn, several rounds; the speed-ups are the medians,
with their range, of the ratios within a round.  The threads run against serial runs
while no Dask cluster exists, as a user of threads has none; the Dask backends then
run against serial runs of their own beside the cluster ("serial, cluster up").
Wall time and the CPU time of this process (Dask workers' CPU is not in it) are
printed as a Markdown table and written to ``benchmarks/out/parallel.md``, with the
load average at the start and the end.
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from shapely.geometry import Point, Polygon, box

import aftmesh

SQUARE_SIZES = {"1e6": 0.0015, "1e7": 0.00048}  # edge lengths giving ~1e6 / ~1e7 triangles
QUICK_SIZES = {"1e5": 0.0047, "1e6": 0.0015}
SMALL_SIZE = 0.08  # ~300 triangles per small polygon
# rounds of each timing: the speed-ups quoted are medians over them (see _rounds)
MANY_ROUNDS = 7
SQUARE_ROUNDS = 3
QUICK_ROUNDS = 2


def small_polygons(n: int, seed: int = 0) -> list:
    """Star-shaped polygons, some with a hole: every one meshes in about a millisecond."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        k = int(rng.integers(5, 12))
        # one vertex per sector around the origin: star-shaped, so a valid ring
        t = 2 * np.pi * (np.arange(k) + rng.uniform(0.2, 0.8, k)) / k
        r = rng.uniform(0.7, 1.0, k)
        poly = Polygon(np.c_[r * np.cos(t), r * np.sin(t)])
        if i % 3 == 0:
            poly = poly.difference(Point(0, 0).buffer(0.2, quad_segs=4))
        out.append(poly)
    return out


def _timed(fn):
    t, c = time.perf_counter(), time.process_time()
    result = fn()
    return result, time.perf_counter() - t, time.process_time() - c


def _triangles(out) -> int:
    return out.n_triangles if isinstance(out, aftmesh.Mesh) else sum(m.n_triangles for m in out)


def _rounds(case: str, backends: dict, repeats: int) -> list:
    """Each backend once per round, in the same order every round, `repeats` rounds:
    one row per backend with the median wall and CPU time, and the median and range of
    its speed-up over the serial run of the same round (a ratio taken within a round
    cancels most of a shared machine's slow spells; one round alone does not).  The
    mean radius ratio is reported for a single mesh (a partitioned run against the
    serial one)."""
    times: dict = {name: [] for name in backends}
    last: dict = {}
    for _ in range(repeats):
        for name, fn in backends.items():
            last.pop(name, None)  # the previous round's result is not kept alive
            last[name], wall, cpu = _timed(fn)
            times[name].append((wall, cpu))
    base = [w for w, _ in times["serial"]]
    rr = {
        name: float(out.quality()["radius_ratio_mean"])
        for name, out in last.items()
        if isinstance(out, aftmesh.Mesh)
    }
    rows = []
    for name, runs in times.items():
        walls = [w for w, _ in runs]
        speedups = None if name == "serial" else [s / w for s, w in zip(base, walls)]
        rows.append(
            {
                "case": case,
                "backend": name,
                "triangles": _triangles(last[name]),
                "rounds": len(runs),
                "wall": float(np.median(walls)),
                "cpu": float(np.median([c for _, c in runs])),
                "speedup": None if speedups is None else float(np.median(speedups)),
                "range": None if speedups is None else (min(speedups), max(speedups)),
                "rr": rr.get(name),
                "drr": rr[name] - rr["serial"] if name in rr and name != "serial" else None,
            }
        )
    return rows


def _with_and_without(case: str, serial, threads: dict, dask: dict, cluster, repeats) -> list:
    """The thread backends against serial runs while no Dask cluster exists (an idle
    2-worker LocalCluster, its scheduler in this process, took about 17 % of a core
    on this machine: that comes out of a 2-thread run, not out of a serial one); then
    a cluster of `cluster()` and the Dask backends (`dask`: a backend for a client)
    against serial runs beside it."""
    rows = _rounds(case, {"serial": serial, **threads}, repeats)
    with cluster() as client:
        on_dask = {name: make(client) for name, make in dask.items()}
        dask_rows = _rounds(case, {"serial": serial, **on_dask}, repeats)
    dask_rows[0]["backend"] = "serial, cluster up"
    return rows + dask_rows


def bench_many(n, cluster, repeats: int) -> list:
    doms = small_polygons(n)
    return _with_and_without(
        f"{n} polygons",
        lambda: [aftmesh.generate(d, SMALL_SIZE) for d in doms],
        {"2 threads": lambda: aftmesh.generate_many(doms, SMALL_SIZE, workers=2)},
        # the automatic batches, as a user gets them
        {"Dask 2 procs": lambda c: lambda: aftmesh.generate_many(doms, SMALL_SIZE, client=c)},
        cluster,
        repeats,
    )


def bench_square(label, h, cluster, repeats: int) -> list:
    d = box(0, 0, 1, 1)
    return _with_and_without(
        f"square ~{label}",
        lambda: aftmesh.generate(d, h),
        {"partitions=2, 2 threads": lambda: aftmesh.generate(d, h, partitions=2)},
        {
            "partitions=2, Dask 2 procs": lambda c: (
                lambda: aftmesh.generate(d, h, partitions=2, client=c)
            )
        },
        cluster,
        repeats,
    )


def _peak_mib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def _serial_peak_mib(h: float) -> float:
    """Peak resident memory of a fresh process meshing the whole square serially."""
    code = (
        "import resource, aftmesh; from shapely.geometry import box; "
        f"aftmesh.generate(box(0, 0, 1, 1), {h!r}); "
        "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return int(out.stdout.split()[-1]) / 1024


def bench_out(label, h, cluster_factory) -> dict:
    """Parts written by 2 fresh Dask worker processes: their peaks and the driver's."""
    with cluster_factory() as client, tempfile.TemporaryDirectory() as tmp:
        index, wall, _ = _timed(
            lambda: aftmesh.generate(
                box(0, 0, 1, 1), h, partitions=2, client=client, out=Path(tmp) / "parts"
            )
        )
        driver_peak = _peak_mib()
        worker_peak = max(client.run(_peak_mib).values())
        files = sum(f.stat().st_size for f in (Path(tmp) / "parts").iterdir()) / 2**20
        back = aftmesh.read_partitioned(index)
        n_t, n_p = back.n_triangles, back.n_points
        # what one process holding the mesh needs: points, triangles, neighbors, regions
        whole = (16 * n_p + (12 + 12 + 4) * n_t) / 2**20
        del back
    return {
        "case": f"square ~{label}, out=",
        "triangles": n_t,
        "wall": wall,
        "serial_peak": _serial_peak_mib(h),
        "driver_peak": driver_peak,
        "worker_peak": worker_peak,
        "whole_mesh": whole,
        "files": files,
    }


def _table(rows) -> str:
    lines = [
        (
            "| case | backend | triangles | rounds | wall (median) | CPU, this process "
            "(median) | speed-up (wall, median) | speed-up range | RR mean | RR - serial |"
        ),
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        f = lambda v, fmt: "-" if v is None else fmt.format(v)
        spread = "-" if r["range"] is None else "{:.2f}-{:.2f}x".format(*r["range"])
        lines.append(
            f"| {r['case']} | {r['backend']} | {r['triangles']} | {r['rounds']} | "
            f"{r['wall']:.2f} s | {r['cpu']:.2f} s | {f(r['speedup'], '{:.2f}x')} | {spread} | "
            f"{f(r['rr'], '{:.4f}')} | {f(r['drr'], '{:+.4f}')} |"
        )
    return "\n".join(lines)


def main(quick: bool, out_dir: Path) -> int:
    import distributed

    def cluster():
        lc = distributed.LocalCluster(
            n_workers=2,
            processes=True,
            threads_per_worker=1,
            dashboard_address=":0",
            silence_logs=40,
        )
        client = distributed.Client(lc, set_as_default=False)

        class Both:
            def __enter__(self):
                return client

            def __exit__(self, *exc):
                client.close()
                lc.close()

        return Both()

    sizes = QUICK_SIZES if quick else SQUARE_SIZES
    load = [os.getloadavg()[0]]
    largest = list(sizes.items())[-1]
    mem = bench_out(*largest, cluster)  # first: the driver's peak is still its own
    rounds = QUICK_ROUNDS if quick else MANY_ROUNDS
    rows = bench_many(200 if quick else 1000, cluster, rounds)
    for label, h in sizes.items():
        rows += bench_square(label, h, cluster, QUICK_ROUNDS if quick else SQUARE_ROUNDS)
    load.append(os.getloadavg()[0])
    text = [
        (
            f"Parallel meshing, {time.strftime('%Y-%m-%d %H:%M')}, {os.cpu_count()} cores, "
            f"load average {load[0]:.1f} at the start, {load[1]:.1f} at the end (a shared "
            "machine: wall times and speed-ups are only as good as the free cores)."
        ),
        "",
        _table(rows),
        "",
        (
            f"{mem['case']}: {mem['triangles']} triangles written by 2 Dask workers in "
            f"{mem['wall']:.1f} s ({mem['files']:.0f} MiB of .vtu); peak resident memory: "
            f"largest worker {mem['worker_peak']:.0f} MiB, driver {mem['driver_peak']:.0f} MiB; "
            f"one process meshing it whole peaks at {mem['serial_peak']:.0f} MiB "
            f"(the final arrays alone: {mem['whole_mesh']:.0f} MiB)."
        ),
    ]
    report = "\n".join(text)
    print(report)
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "parallel.md").write_text(report + "\n")
    return 0
