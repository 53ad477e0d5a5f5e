"""Run the measurements: one subprocess per (mesher, case), per CDT memory probe and
one for the CDT speed comparison; collect what they print."""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

from .cases import build_case
from .meshers import MESHERS, REFERENCE, mesher_available

ROOT = Path(__file__).resolve().parent.parent
SRC = ROOT / "src"
MARK = "@@RESULT "
HOW_TO_BUILD = (
    "Either install aftmesh (pip install .) or build its kernel in place in this "
    "checkout (python setup.py build_ext --inplace); src/ is used only when the "
    "kernel is built there."
)


class SetupError(RuntimeError):
    """The workers cannot import aftmesh: the run stops at once."""


def kernel_in_place() -> bool:
    """Whether ``src/aftmesh`` holds a compiled kernel (an in-place build)."""
    pkg = SRC / "aftmesh"
    return any(pkg.glob("_kernel*.so")) or any(pkg.glob("_kernel*.pyd"))


_AFTMESH: dict = {}


def _env_with(parts: list[str]) -> dict:
    env = dict(os.environ)
    if env.get("PYTHONPATH"):
        parts = parts + [env["PYTHONPATH"]]
    env["PYTHONPATH"] = os.pathsep.join(parts)
    env.setdefault("OMP_NUM_THREADS", "1")
    return env


def locate_aftmesh() -> str:
    """Decide once which aftmesh the workers import, check it in a worker-like process
    and return its location: ``src/`` when the kernel is built in place there,
    otherwise the installed package.  Raises `SetupError` saying how to fix it."""
    if "file" not in _AFTMESH:
        parts = [str(ROOT)] + ([str(SRC)] if kernel_in_place() else [])
        code = "import aftmesh, aftmesh._kernel as k; print(aftmesh.__file__); print(k.__file__)"
        try:
            probe = subprocess.run(
                [sys.executable, "-c", code],
                cwd=ROOT,
                env=_env_with(parts),
                capture_output=True,
                text=True,
                timeout=120,
            )
        except subprocess.TimeoutExpired:
            raise SetupError("importing aftmesh took over 120 s") from None
        if probe.returncode != 0:
            tail = (probe.stderr.strip().splitlines() or ["no output"])[-1]
            where = "src/ (kernel built in place)" if len(parts) > 1 else "the installed packages"
            raise SetupError(f"cannot import aftmesh from {where}: {tail}\n{HOW_TO_BUILD}")
        package, kernel = probe.stdout.strip().splitlines()[-2:]
        _AFTMESH.update(parts=parts, file=package, kernel=kernel, build=_build_of(kernel))
        if len(parts) > 1 and str(SRC) not in sys.path:
            sys.path.insert(0, str(SRC))  # this process checks availability the same way
    return _AFTMESH["file"]


def worker_env() -> dict:
    """The environment of a worker process: it imports the aftmesh `locate_aftmesh`
    chose."""
    locate_aftmesh()
    return _env_with(list(_AFTMESH["parts"]))


def import_located() -> str:
    """For a benchmark that imports aftmesh in this process and starts processes of
    its own (Dask workers, a memory probe): `locate_aftmesh`, and the same aftmesh
    for those children too, through this process's PYTHONPATH."""
    where = locate_aftmesh()
    if not _AFTMESH.get("exported"):
        os.environ["PYTHONPATH"] = worker_env()["PYTHONPATH"]
        _AFTMESH["exported"] = True
    return where


def _import_failed(err: str) -> bool:
    return err.startswith(("ImportError", "ModuleNotFoundError")) and "aftmesh" in err


def _build_of(kernel: str) -> tuple[int, int] | None:
    """The compiled kernel file's size and modification time: they change when it is
    rebuilt (None: it is gone)."""
    try:
        st = os.stat(kernel)
    except OSError:
        return None
    return st.st_size, st.st_mtime_ns


def _same_build() -> None:
    """Stop the run if the kernel the workers import is no longer the one it started
    with: each worker imports it afresh, so a rebuild in the middle of a run would
    put two builds' figures in one table."""
    locate_aftmesh()
    if _build_of(_AFTMESH["kernel"]) != _AFTMESH["build"]:
        raise SetupError(
            f"the kernel {_AFTMESH['kernel']} changed since the run started (rebuilt?): "
            "its figures would mix two builds; run again once the build is final"
        )


def run_job(job: dict, timeout: float) -> dict:
    """Run one job in a fresh interpreter; a failure becomes ``{"error": ...}``, except
    a worker that cannot import aftmesh, or a kernel rebuilt before or during the job,
    which stops the run (`SetupError`)."""
    _same_build()
    t0 = time.perf_counter()
    try:
        proc = subprocess.run(
            [sys.executable, "-m", "benchmarks.worker", json.dumps(job)],
            cwd=ROOT,
            env=worker_env(),
            capture_output=True,
            text=True,
            timeout=timeout,
        )
    except subprocess.TimeoutExpired:
        return {"error": f"timeout after {timeout:.0f} s"}
    wall = time.perf_counter() - t0
    _same_build()
    lines = [ln for ln in proc.stdout.splitlines() if ln.startswith(MARK)]
    if lines:
        res = json.loads(lines[-1][len(MARK) :])
    else:
        tail = (proc.stderr.strip().splitlines() or ["no output"])[-1]
        res = {"error": f"worker exit {proc.returncode}: {tail}"}
    res["wall"] = wall
    err = res.get("error", "")
    if _import_failed(err):
        raise SetupError(f"a worker cannot import aftmesh: {err}\n{HOW_TO_BUILD}")
    return res


def _median(xs):
    return statistics.median(xs) if xs else None


# ----------------------------------------------------------------------- meshing


def reference_area(case) -> float | None:
    """Area of the faces that are not holes (what every mesher should cover)."""
    try:
        from .meshers import _faces

        faces, _, _ = _faces(case)
        return float(sum(poly.area for poly, _, _ in faces))
    except Exception:
        return None


# Each mesher's timed runs of a case are split over this many workers (at most one a
# run), which take turns with the other meshers' in rotating order: a burst of load
# on a shared machine then weighs on a few runs of each mesher, where one worker
# running all of one mesher's repeats back to back could slow every one of them.
TIMING_PASSES = 3


def split_repeats(repeat: int, passes: int) -> list[int]:
    """``repeat`` runs over at most ``passes`` workers, the earlier ones taking the
    remainder: ``split_repeats(5, 3) == [2, 2, 1]``."""
    passes = max(1, min(passes, repeat))
    return [repeat // passes + (k < repeat % passes) for k in range(passes)]


def _mesh_job(cname: str, mname: str, repeat: int, quick: bool, timing_only: bool) -> dict:
    job = {
        "kind": "mesh",
        "case": cname,
        "mesher": mname,
        "repeat": repeat,
        "min_repeat": 1 if quick else min(repeat, 5),
        "budget": 0.25 if quick else 60.0,
        "edges": True,
        "timing_only": timing_only,
    }
    return run_job(job, timeout=120 if quick else 1200)


def _case_meta(case) -> dict:
    return {
        "description": case.description,
        "vertices": len(case.vertices),
        "segments": len(case.segments),
        "holes": len(case.holes),
        "notes": case.notes,
        "area": reference_area(case),
    }


def _first_pass(cname, mesher_names, repeat, quick, gmsh_limit, log) -> list[dict]:
    """Every mesher's full job on the case (result, memory, quality, first runs)."""
    rows: list[dict] = []
    aft_triangles = None
    for mname in mesher_names:
        row = {"case": cname, "mesher": mname}
        rows.append(row)
        why = mesher_available(mname)
        if why:
            row["error"] = f"not available ({why})"
            continue
        if mname.startswith("gmsh") and aft_triangles is not None and aft_triangles > gmsh_limit:
            row["skipped"] = (
                f"skipped: about {aft_triangles:.2g} triangles > gmsh limit "
                f"{gmsh_limit:.2g} (--gmsh-limit)"
            )
            log(f"  {cname:18s} {mname:14s} {row['skipped']}")
            continue
        row.update(_mesh_job(cname, mname, repeat, quick, timing_only=False))
        if "times" not in row:
            log(f"  {cname:18s} {mname:14s} ERROR {row.get('error')}")
        elif mname == "aft":
            aft_triangles = row["stats"]["triangles"]
    return rows


def _later_passes(cname, rows: list[dict], counts: list[int], quick, log) -> None:
    """The other passes' timed runs, appended to the rows that have a result; the
    meshers' order rotates by one each pass."""
    live = [r for r in rows if "times" in r]
    for k, repeat in enumerate(counts[1:], start=1):
        turn = k % len(live) if live else 0
        for row in live[turn:] + live[:turn]:
            res = _mesh_job(cname, row["mesher"], repeat, quick, timing_only=True)
            if "times" not in res:
                log(f"  {cname:18s} {row['mesher']:14s} pass {k + 1}: ERROR {res.get('error')}")
                continue
            for key in ("times", "cpu", "internal_timings"):
                row[key] = row.get(key, []) + res[key]
            row["wall"] = row.get("wall", 0.0) + res["wall"]


def median_timing(timings: list) -> dict | None:
    """Per stage, the median of the runs' internal timings (the workers'
    ``internal_timings``; None unless every run has them)."""
    if not timings or not all(timings):
        return None
    return {k: statistics.median(t[k] for t in timings) for k in timings[0]}


def _finish_rows(cname: str, rows: list[dict], log) -> None:
    """Medians, triangle counts and the ratios to the reference mesher."""
    for row in rows:
        if "times" not in row:
            continue
        row["median"] = _median(row["times"])
        row["cpu_median"] = _median(row["cpu"])
        row["triangles"] = row["stats"]["triangles"]
        row["internal_timing"] = median_timing(row.get("internal_timings", []))
        row["tri_per_s"] = row["triangles"] / row["median"]
        log(
            f"  {cname:18s} {row['mesher']:14s} {row['triangles']:>9d} tri  "
            f"{row['median']:.4f} s  ({len(row['times'])} runs)"
        )
    ref = next((r for r in rows if r["mesher"] == REFERENCE and r.get("median")), None)
    for row in rows:
        if ref and row.get("median"):
            row["time_ratio"] = row["median"] / ref["median"]
            row["rate_ratio"] = row["tri_per_s"] / ref["tri_per_s"]
            row["cpu_ratio"] = row["cpu_median"] / ref["cpu_median"]


def run_mesh_suite(
    case_names, mesher_names, *, quick: bool, repeat: int, gmsh_limit: float, log=print
) -> dict:
    """Mesh every case with every mesher: a first pass of full jobs, then (unless
    quick) TIMING_PASSES - 1 passes of timed runs only, taking turns."""
    rows = []
    cases_meta = {}
    counts = split_repeats(repeat, 1 if quick else TIMING_PASSES)
    for cname in case_names:
        try:
            case = build_case(cname)
        except Exception as exc:
            log(f"  {cname}: cannot build: {exc}")
            rows.append({"case": cname, "mesher": "-", "error": f"case: {exc}"})
            continue
        cases_meta[cname] = _case_meta(case)
        case_rows = _first_pass(cname, mesher_names, counts[0], quick, gmsh_limit, log)
        _later_passes(cname, case_rows, counts, quick, log)
        _finish_rows(cname, case_rows, log)
        rows += case_rows
    return {
        "rows": rows,
        "cases": cases_meta,
        "meshers": {m: MESHERS[m] for m in mesher_names},
        "reference": REFERENCE,
    }


# ----------------------------------------------------------------------- CDT


def run_cdt_suite(*, quick: bool, repeat: int, log=print) -> dict:
    tools = ["aft", "tri", "scipy"]
    sizes = [1e4, 1e5, 1e6]
    job = {
        "kind": "cdt-speed",
        "sizes": sizes,
        "repeat": repeat,
        "repeat_big": 1 if quick else max(3, min(repeat, 5)),
        "constrained": True,
        "tools": tools,
    }
    log("  CDT speed (one process) ...")
    res = run_job(job, timeout=300 if quick else 1800)
    rows = res.get("rows", [])
    if "error" in res:
        rows = [{"input": "all", "tool": "-", "error": res["error"]}]
    for r in rows:
        if "times" in r:
            r["median"] = _median(r["times"])
            r["cpu_median"] = _median(r["cpu"])
    for r in rows:
        ref = next(
            (
                x
                for x in rows
                if x["input"] == r["input"] and x["tool"] == "tri" and x.get("median")
            ),
            None,
        )
        if r.get("median") and ref:
            r["time_ratio"] = r["median"] / ref["median"]
            r["cpu_ratio"] = r["cpu_median"] / ref["cpu_median"]
        if r.get("median"):
            log(f"  {r['input']:32s} {r['tool']:6s} {r['median']:.4f} s  {r['triangles']} tri")
    mem = []
    for tool in ["aft", "tri"]:
        log(f"  CDT memory, {tool}, 1e6 points ...")
        m = run_job({"kind": "cdt-mem", "tool": tool, "n": 1_000_000}, timeout=600)
        m.setdefault("tool", tool)
        mem.append(m)
    return {"rows": rows, "memory": mem}


# ----------------------------------------------------------------------- scaling

SCALING_H_FULL = [0.015, 0.008, 0.0045, 0.0025, 0.0015, 0.001, 0.0007, 0.0005]
SCALING_H_QUICK = [0.015, 0.008, 0.0045, 0.0025, 0.0015]
SCALING_MESHERS = ["aft", REFERENCE]


def fit_exponent(n, t):
    """Least-squares slope of log t against log n."""
    import numpy as np

    n = np.log(np.asarray(n, dtype=float))
    t = np.log(np.asarray(t, dtype=float))
    if len(n) < 2:
        return None
    return float(np.polyfit(n, t, 1)[0])


def run_scaling(*, quick: bool, repeat: int, log=print) -> dict:
    hs = SCALING_H_QUICK if quick else SCALING_H_FULL
    rows = []
    for h in hs:
        for mname in SCALING_MESHERS:
            job = {
                "kind": "mesh",
                "case": f"square-{h:g}",
                "mesher": mname,
                "repeat": repeat if h > 0.002 else 3,
                "min_repeat": 1,
                "budget": 1.0 if quick else 20.0,
                "edges": False,
                "own_cdt": mname == "aft",
            }
            res = run_job(job, timeout=300 if quick else 1800)
            row = {"h": h, "mesher": mname, **res}
            if "times" in res:
                row["median"] = _median(res["times"])
                row["cpu_median"] = _median(res["cpu"])
                row["triangles"] = res["stats"]["triangles"]
                if "own_cdt" in res:
                    row["own_cdt_cpu_median"] = _median(res["own_cdt"]["cpu"])
                log(
                    f"  h={h:<8g} {mname:10s} {row['triangles']:>9d} tri  {row['median']:.4f} s"
                    f"  {res['mem_mib']:.0f} MiB"
                )
            else:
                log(f"  h={h:<8g} {mname:10s} ERROR {res.get('error')}")
            rows.append(row)
    fits = {}
    for mname in SCALING_MESHERS:
        ok = [r for r in rows if r["mesher"] == mname and r.get("median")]
        big = [r for r in ok if r["triangles"] >= 1e5]
        fits[mname] = {
            "all": fit_exponent([r["triangles"] for r in ok], [r["median"] for r in ok]),
            "from_1e5": fit_exponent([r["triangles"] for r in big], [r["median"] for r in big]),
            "cpu_all": fit_exponent([r["triangles"] for r in ok], [r["cpu_median"] for r in ok]),
            "cpu_from_1e5": fit_exponent(
                [r["triangles"] for r in big], [r["cpu_median"] for r in big]
            ),
        }
    return {"rows": rows, "fits": fits}
