"""One measurement in a fresh process: ``python -m benchmarks.worker '<json job>'``.

Prints one line ``@@RESULT <json>`` at the end.  Jobs:

* ``{"kind": "mesh", "case", "mesher", "repeat", "min_repeat", "budget", "edges"}``,
  with ``"own_cdt": true`` (aftmesh) also timing ``aftmesh.cdt`` of its own output,
  or with ``"timing_only": true`` only the timed runs, after an untimed one (a later
  pass of runner.py's, which takes turns with the other meshers)
* ``{"kind": "cdt-speed", "sizes", "repeat", "constrained", "tools"}``
* ``{"kind": "cdt-mem", "tool", "n"}``
"""

from __future__ import annotations

import gc
import json
import sys
import time
import traceback

import numpy as np

MARK = "@@RESULT "


def _emit(obj) -> None:
    sys.stdout.write(MARK + json.dumps(obj) + "\n")
    sys.stdout.flush()


# ----------------------------------------------------------------------- meshing


def _prepared(job: dict):
    """The job's case and its mesher, warmed up on a tiny square (which loads lazily
    imported code and initialises Gmsh)."""
    from .cases import build_case, square
    from .meshers import prepare

    case = build_case(job["case"])
    tiny = prepare(job["mesher"], square(0.1))
    tiny.result(tiny.run())
    del tiny
    return case, prepare(job["mesher"], case)


def _timed_runs(runner, job: dict, times: list, cpu: list, timings: list) -> None:
    """More timed runs, until ``repeat`` in all, or ``budget`` seconds once there
    are ``min_repeat``."""
    started = time.perf_counter()
    while len(times) < job["repeat"]:
        if len(times) >= job["min_repeat"] and time.perf_counter() - started > job["budget"]:
            break
        runner.reset()
        gc.collect()
        c0 = time.process_time()
        t0 = time.perf_counter()
        raw = runner.run()
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
        timings.append(_internal_timing(raw))
        del raw


def timing_job(job: dict) -> dict:
    """Only timed runs (see the module's docstring), after one untimed run of the
    case: every run timed here is a repeat, like all but the first of mesh_job's."""
    _, runner = _prepared(job)
    runner.run()
    times: list = []
    cpu: list = []
    timings: list = []
    _timed_runs(runner, job, times, cpu, timings)
    runner.close()
    return {"times": times, "cpu": cpu, "internal_timings": timings}


def mesh_job(job: dict) -> dict:
    from .measure import MemoryProbe, quality_stats

    if job.get("timing_only"):
        return timing_job(job)
    case, runner = _prepared(job)
    probe = MemoryProbe()
    probe.start()
    c0 = time.process_time()
    t0 = time.perf_counter()
    raw = runner.run()
    times = [time.perf_counter() - t0]
    cpu = [time.process_time() - c0]
    mem = probe.stop_mib()
    timings = [_internal_timing(raw)]
    out = runner.result(raw)
    target = case.target if job.get("edges", True) else None
    stats = quality_stats(out.points, out.triangles, target)
    stats["segments_out"] = out.n_segments
    stats["segments_in"] = int(len(case.segments))
    passes = runner.passes
    # the first run's vertices and boundary, kept (copied, so that the rest of the
    # mesh is freed before the timed runs) for the own-output CDT below
    own_input = _own_cdt_input(raw) if job.get("own_cdt") else None
    del raw, out
    _timed_runs(runner, job, times, cpu, timings)
    own = own_cdt_times(*own_input, len(times)) if own_input is not None else None
    runner.close()
    result = {
        "times": times,
        "cpu": cpu,
        "mem_mib": mem,
        "mem_method": probe.method,
        "stats": stats,
        "passes": passes,
        "internal_timings": timings,
    }
    if own is not None:
        result["own_cdt"] = own
    return result


def _own_cdt_input(mesh) -> tuple[np.ndarray, np.ndarray]:
    """A generate call's own output as ``aftmesh.cdt`` input: copies of its vertices
    and boundary segments."""
    return np.array(mesh.points, order="C"), np.array(mesh.segments, order="C")


def own_cdt_times(points: np.ndarray, segments: np.ndarray, repeat: int) -> dict:
    """Wall and CPU times of ``aftmesh.cdt`` of a generate call's own output (see
    _own_cdt_input), the least any mesher of that mesh must do."""
    import aftmesh

    times, cpu = [], []
    for _ in range(repeat):
        gc.collect()
        c0 = time.process_time()
        t0 = time.perf_counter()
        aftmesh.cdt(points, segments)
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return {"times": times, "cpu": cpu}


def _internal_timing(raw):
    """aftmesh's own split of the time (``Mesh.info['timing']``), else None."""
    info = getattr(raw, "info", None)
    if isinstance(info, dict) and isinstance(info.get("timing"), dict):
        t = {k: float(v) for k, v in info["timing"].items()}
        if all(k in t for k in ("boundary", "cdt", "basic_aft", "total")):
            t["after"] = t["total"] - t["boundary"] - t["cdt"] - t["basic_aft"]
        return t
    return None


# ----------------------------------------------------------------------- CDT


def random_points(n: int, seed: int = 12345) -> np.ndarray:
    return np.random.default_rng(seed).random((n, 2))


def constrained_input(n_points: int = 100_000, n_segments: int = 10_000, seed: int = 7):
    """Points on a jittered grid (jitter < 1/4 of the spacing) and random segments
    between grid neighbours: two such segments either share an end or are apart, so
    none cross (checked anyway).  A square ring of 4 segments encloses everything."""
    import shapely

    rng = np.random.default_rng(seed)
    m = int(round(np.sqrt(n_points)))
    i, j = np.meshgrid(np.arange(m), np.arange(m), indexing="ij")
    pts = np.column_stack([(i.ravel() + 0.5) / m, (j.ravel() + 0.5) / m])
    pts += rng.uniform(-0.2 / m, 0.2 / m, pts.shape)
    idx = (i * m + j).ravel()
    right = np.column_stack([idx[i.ravel() < m - 1], idx[i.ravel() < m - 1] + m])
    up = np.column_stack([idx[j.ravel() < m - 1], idx[j.ravel() < m - 1] + 1])
    cand = np.concatenate([right, up])
    segs = cand[rng.choice(len(cand), n_segments, replace=False)]
    lines = shapely.linestrings(np.stack([pts[segs[:, 0]], pts[segs[:, 1]]], axis=1))
    tree = shapely.STRtree(lines)
    a, b = tree.query(lines, predicate="crosses")
    if len(a):
        raise RuntimeError(f"{len(a) // 2} constraint segments cross")
    corners = np.array([[-0.01, -0.01], [1.01, -0.01], [1.01, 1.01], [-0.01, 1.01]])
    n = len(pts)
    box = np.array([[n, n + 1], [n + 1, n + 2], [n + 2, n + 3], [n + 3, n]])
    return np.concatenate([pts, corners]), np.concatenate([segs, box]).astype(np.int32)


def _cdt_call(tool: str, pts, segs=None):
    """A callable doing one triangulation and returning its triangle count."""
    if tool == "aft":
        import aftmesh

        if segs is None:
            return lambda: aftmesh.cdt(pts).n_triangles
        return lambda: aftmesh.cdt(pts, segs).n_triangles
    if tool == "tri":
        import triangle

        if segs is None:
            d = {"vertices": pts}
            return lambda: len(triangle.triangulate(d, "")["triangles"])
        d = {"vertices": pts, "segments": segs}
        return lambda: len(triangle.triangulate(d, "p")["triangles"])
    if tool == "scipy":
        from scipy.spatial import Delaunay

        return lambda: len(Delaunay(pts).simplices)  # unconstrained, even with segments
    raise KeyError(tool)


def _count(n) -> str:
    n = float(n)
    if n >= 1e6:
        return f"{n / 1e6:.3g}M"
    if n >= 1e3:
        return f"{n / 1e3:.3g}k"
    return f"{n:.0f}"


def cdt_speed_job(job: dict) -> dict:
    tools = job["tools"]
    warm = random_points(1000, seed=1)
    for tool in tools:
        _cdt_call(tool, warm)()
    rows = []
    inputs = [(f"{_count(n)} random points", random_points(int(n)), None) for n in job["sizes"]]
    if job.get("constrained"):
        p, s = constrained_input()
        inputs.append((f"{_count(len(p))} grid points + {_count(len(s) - 4)} segments", p, s))
    for label, pts, segs in inputs:
        for tool in tools:
            row = {
                "input": label,
                "tool": tool,
                "n_points": int(len(pts)),
                "n_segments": 0 if segs is None else int(len(segs)),
            }
            try:
                call = _cdt_call(tool, pts, segs)
                times, cpu, ntri = [], [], None
                for _ in range(job["repeat"] if len(pts) < 500_000 else job["repeat_big"]):
                    gc.collect()
                    c0 = time.process_time()
                    t0 = time.perf_counter()
                    ntri = call()
                    times.append(time.perf_counter() - t0)
                    cpu.append(time.process_time() - c0)
                row.update(times=times, cpu=cpu, triangles=int(ntri))
            except Exception as exc:
                row["error"] = f"{type(exc).__name__}: {exc}"
            rows.append(row)
    return {"rows": rows}


def cdt_mem_job(job: dict) -> dict:
    from .measure import MemoryProbe

    tool = job["tool"]
    _cdt_call(tool, random_points(1000, seed=1))()
    pts = random_points(int(job["n"]))
    call = _cdt_call(tool, pts)
    probe = MemoryProbe()
    probe.start()
    t0 = time.perf_counter()
    ntri = call()
    t = time.perf_counter() - t0
    mem = probe.stop_mib()
    return {
        "tool": tool,
        "n": int(job["n"]),
        "triangles": int(ntri),
        "mem_mib": mem,
        "time": t,
        "bytes_per_triangle": mem * 1024 * 1024 / max(ntri, 1),
        "mem_method": probe.method,
    }


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    job = json.loads(argv[0])
    try:
        kind = job["kind"]
        if kind == "mesh":
            res = mesh_job(job)
        elif kind == "cdt-speed":
            res = cdt_speed_job(job)
        elif kind == "cdt-mem":
            res = cdt_mem_job(job)
        else:
            raise KeyError(f"unknown job kind {kind!r}")
    except Exception as exc:
        tb = traceback.format_exc(limit=4)
        _emit({"error": f"{type(exc).__name__}: {exc}".strip(), "traceback": tb})
        return 0
    _emit(res)
    return 0


if __name__ == "__main__":
    sys.exit(main())
