"""GIL-held CPU time per ``aftmesh.generate`` call (issues 12 and 13).

``python -m benchmarks.gil`` meshes the small polygons of ``benchmarks.parallel`` (or
``--strip``: the fixed-cost polygon of ``benchmarks.overhead``) one after the other
and prints, per call, the CPU time of the calling thread, the part of it spent with
the GIL released (the kernel's ``nogil`` sections, numpy's and shapely's releases),
the rest (held: what caps the speed-up of ``generate_many`` on threads), and how many
times the GIL was released.  CPU time, not wall time: it means the same on a busy
machine.  Then it meshes them again with ``generate_many`` on ``--threads`` threads
and prints the wall time the threads spent waiting to take the GIL back, per call:
that is where the speed-up goes (a thread waits at the end of a ``nogil`` section
while another thread runs Python).

It works by interposing ``PyEval_SaveThread`` / ``PyEval_RestoreThread`` (through
which Cython's ``with nogil``, numpy and shapely release the GIL) with a small shared
library, compiled here with the C compiler (``cc``) and preloaded into a child
process.  Linux only; nothing here is asserted.
"""

from __future__ import annotations

import argparse
import ctypes
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from . import runner

# Calls timed per round, and rounds (the minimum is printed: the least disturbed).
CALLS = 600
ROUNDS = 3
# Calls before timing: imports, caches and the kernel's first allocations.
WARM_UP = 30
# Threads of the generate_many measurement: the 2 cores of the project's machine.
THREADS = 2
_ENV = "AFTMESH_GIL_SHIM"

_SHIM = r"""
#define _GNU_SOURCE
#include <dlfcn.h>
#include <time.h>
static void *(*save)(void);
static void (*restore)(void *);
static long long released_ns, releases, waited_ns;
static __thread long long since;
static long long cpu(void) {
    struct timespec t; clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return t.tv_sec * 1000000000LL + t.tv_nsec;
}
void *PyEval_SaveThread(void) {
    if (!save) save = (void *(*)(void))dlsym(RTLD_NEXT, "PyEval_SaveThread");
    releases++;
    void *state = save();
    since = cpu();
    return state;
}
static long long wall(void) {
    struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1000000000LL + t.tv_nsec;
}
void PyEval_RestoreThread(void *state) {
    if (!restore) restore = (void (*)(void *))dlsym(RTLD_NEXT, "PyEval_RestoreThread");
    if (since) released_ns += cpu() - since;
    since = 0;
    long long t = wall();
    restore(state);
    __atomic_add_fetch(&waited_ns, wall() - t, __ATOMIC_RELAXED);
}
void gil_read(long long *out) { out[0] = released_ns; out[1] = releases; out[2] = waited_ns; }
"""


def _build_shim(folder: Path) -> Path:
    src, lib = folder / "gilshim.c", folder / "gilshim.so"
    src.write_text(_SHIM)
    subprocess.run(["cc", "-O2", "-shared", "-fPIC", "-o", str(lib), str(src), "-ldl"], check=True)
    return lib


def _cases(strip: bool, n: int) -> list:
    if strip:
        from .overhead import overhead_outline

        case = overhead_outline()
        return [(case.polygon, case.size)] * n
    from .parallel import SMALL_SIZE, small_polygons

    return [(d, SMALL_SIZE) for d in small_polygons(n)]


def _measure(strip: bool, calls: int, rounds: int) -> None:
    import aftmesh

    lib = ctypes.CDLL(None)
    out = (ctypes.c_longlong * 3)()
    cases = _cases(strip, calls)
    for domain, size in cases[:WARM_UP]:
        aftmesh.generate(domain, size)
    best = None
    for _ in range(rounds):
        lib.gil_read(out)
        released0, releases0 = out[0], out[1]
        c0 = time.thread_time_ns()
        for domain, size in cases:
            aftmesh.generate(domain, size)
        cpu = time.thread_time_ns() - c0
        lib.gil_read(out)
        row = (cpu, out[0] - released0, out[1] - releases0)
        best = row if best is None or row[0] < best[0] else best
    cpu, released, releases = best
    # each gil_read call releases the GIL once itself (ctypes): not counted
    per = 1e6 * calls  # ns -> ms per call
    print(
        f"{'strip-100' if strip else 'small polygons'}: {calls} calls, least CPU of {rounds} "
        f"rounds: cpu {cpu / per:.3f} ms/call, GIL released {released / per:.3f}, "
        f"GIL held {(cpu - released) / per:.3f} ms/call, {(releases - 1) / calls:.1f} "
        "releases/call"
    )


def _measure_threads(strip: bool, calls: int, rounds: int, threads: int) -> None:
    """generate_many on `threads` threads: the wall time its threads waited to take
    the GIL back, per call (the least of `rounds`), and the cores they kept busy."""
    import aftmesh

    lib = ctypes.CDLL(None)
    out = (ctypes.c_longlong * 3)()
    cases = _cases(strip, calls)
    domains, size = [d for d, _ in cases], cases[0][1]
    aftmesh.generate_many(domains[:WARM_UP], size, workers=threads)
    best = None
    for _ in range(rounds):
        lib.gil_read(out)
        waited0 = out[2]
        t0, c0 = time.perf_counter(), time.process_time()
        aftmesh.generate_many(domains, size, workers=threads)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        lib.gil_read(out)
        row = ((out[2] - waited0) / 1e3 / calls, cpu / wall)
        best = row if best is None or row[0] < best[0] else best
    waited, busy = best
    print(
        f"  generate_many on {threads} threads: waited for the GIL {waited:.0f} us/call "
        f"(least of {rounds} rounds), {busy:.2f} cores busy"
    )


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.gil", description=__doc__)
    parser.add_argument("--strip", action="store_true", help="the fixed-cost polygon")
    parser.add_argument("--calls", type=int, default=CALLS)
    parser.add_argument("--rounds", type=int, default=ROUNDS)
    parser.add_argument("--threads", type=int, default=THREADS)
    args = parser.parse_args(argv)
    if os.environ.get(_ENV):
        _measure(args.strip, args.calls, args.rounds)
        _measure_threads(args.strip, args.calls, args.rounds, args.threads)
        return
    with tempfile.TemporaryDirectory() as tmp:
        lib = _build_shim(Path(tmp))
        env = dict(runner.worker_env(), LD_PRELOAD=str(lib), **{_ENV: "1"})
        args_given = sys.argv[1:] if argv is None else list(argv)
        cmd = [sys.executable, "-m", "benchmarks.gil", *args_given]
        subprocess.run(cmd, env=env, check=True)


if __name__ == "__main__":
    main()
