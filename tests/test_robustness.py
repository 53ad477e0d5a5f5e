"""Robustness of ``aftmesh.generate`` / ``aftmesh.cdt`` (issue "Robustness: every
valid domain meshes, every invalid one gets a clear error, nothing crashes, hangs or
leaks").

1. Property-based: random valid domains of every awkward kind (``fuzz_domains``) are
   meshed and every mesh passes check_mesh with the exact area, keeps the boundary,
   and is the CDT of its points and segments (Triangle as the oracle).  Each call runs
   in a forked child with a time limit, so a hang or a segfault fails one test.
2. Invalid input: each malformed input class raises the aftmesh ``ValueError``
   subclass naming the problem; random garbage in every argument gives a checked mesh
   or an ``InvalidInputError``, nothing else.
3. Termination: adversarial sizes raise or complete, ``max_triangles`` caps the mesh,
   Ctrl-C (a progress callback raising KeyboardInterrupt, SIGINT from a timer thread)
   stops a large mesh quickly and the process keeps working.
4. Determinism: bit-identical output across runs and processes.
5. Memory: resident memory stays flat over hundreds of calls (also on error paths).
6. Threads: meshing from a thread pool gives the same meshes as one by one.

Failures found here are pinned as named tests in ``test_regressions.py``.
"""

from __future__ import annotations

import hashlib
import json
import os
import signal
import subprocess
import sys
import threading
import time
import warnings
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import fuzz_domains as fd  # noqa: E402  (tests/ is on the path; after aftmesh on purpose)
import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from shapely.geometry import GeometryCollection, LineString, MultiPolygon, Point, Polygon, box

import aftmesh
from aftmesh import (  # noqa: E402
    CrossingSegmentsError,
    InvalidDomainError,
    InvalidInputError,
    InvalidOptionError,
    InvalidSizeError,
)
from aftmesh.aft import Strategy  # noqa: E402

# child processes import the same aftmesh as this one (installed, or src/ in a
# development checkout)
PACKAGE_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(aftmesh.__file__)))

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent

# Seconds one generate() call may take in the property tests (they take well under
# one); beyond it the call counts as a hang.
GEN_TIMEOUT = 20.0

_SUPPRESS = [
    HealthCheck.function_scoped_fixture,
    HealthCheck.too_slow,
    HealthCheck.data_too_large,
    HealthCheck.filter_too_much,
]


def budget(fraction: float, minimum: int = 5) -> settings:
    """A share of the active profile's max_examples (ci: 60, long: 2000)."""
    return settings(
        max_examples=max(minimum, int(settings.default.max_examples * fraction)),
        suppress_health_check=_SUPPRESS,
    )


def same_arrays(a, b) -> bool:
    return all(
        np.array_equal(getattr(a, k), getattr(b, k)) and getattr(a, k).dtype == getattr(b, k).dtype
        for k in ("points", "triangles", "neighbors", "segments", "regions", "segment_markers")
    )


def digest(mesh) -> str:
    h = hashlib.sha256()
    for k in ("points", "triangles", "neighbors", "segments", "regions", "segment_markers"):
        a = np.ascontiguousarray(getattr(mesh, k))
        h.update(k.encode() + str(a.dtype).encode() + str(a.shape).encode() + a.tobytes())
    return h.hexdigest()


# ============================================= 1. every valid domain meshes, correctly
@pytest.mark.parametrize("kind", sorted(fd.GENERATORS))
@budget(1.0)
@given(data=st.data())
def test_valid_domains_mesh(kind, data, checked):
    """Each generator's domains (half of them moved by 1e7 or scaled by 1e-6, in all
    input forms, with constant, absent or graded sizes) mesh, and correctly."""
    case = data.draw(fd.fuzz_cases(kinds=[kind]), label="case")
    fd.run_case(case, check=checked, timeout=GEN_TIMEOUT)


@budget(3.0)
@given(case=fd.fuzz_cases(rich_options=True))
def test_valid_domains_mesh_with_any_options(case, checked):
    """The same with every option drawn (order, swaps, split_boundary, greedy, smooth,
    close_factor, gradation, max_triangles): a correct mesh, max_triangles respected,
    or the refusal of a max_triangles below what the boundary alone needs."""
    fd.run_case(case, check=checked, timeout=GEN_TIMEOUT)


@budget(0.2)
@given(
    case=fd.fuzz_cases(
        kinds=["star", "holes", "touching", "cocircular"], transform=False, forms=False
    )
)
def test_far_from_origin_and_tiny_same_topology(case, checked):
    """The same domain at scale 1, scaled by 2**-20 and moved by 2**24 (exactly, or
    nearly: rounding at 2**24) gives a valid mesh each time."""
    mesh = fd.run_case(case, check=checked, timeout=GEN_TIMEOUT)
    s = 2.0**-20
    small = fd.FuzzCase(
        case.kind + "*2^-20",
        shapely.transform(case.domain, lambda c: c * s)
        if isinstance(case.domain, shapely.Geometry)
        else [shapely.transform(p, lambda c: c * s) for p in case.domain],
        _scaled_size(case.size, s),
        dict(case.options),
        [shapely.transform(p, lambda c: c * s) for p in case.polygons],
    )
    small_mesh = fd.run_case(small, check=checked, timeout=GEN_TIMEOUT)
    # (not asserted: the same mesh, scaled.  The boundary's split points differ in the
    # last bits between scales (log / exp in the integration of 1/h), and Basic_aft's
    # choices follow such differences, so the meshes may differ.)
    assert (mesh is None) == (small_mesh is None)
    far = fd.FuzzCase(
        case.kind + "+2^24",
        shapely.transform(case.domain, lambda c: c + 2.0**24)
        if isinstance(case.domain, shapely.Geometry)
        else [shapely.transform(p, lambda c: c + 2.0**24) for p in case.domain],
        _shifted_size(case.size, 2.0**24),
        dict(case.options),
        [shapely.transform(p, lambda c: c + 2.0**24) for p in case.polygons],
    )
    fd.run_case(far, check=checked, timeout=GEN_TIMEOUT)


def _scaled_size(spec, s):
    if spec is None or isinstance(spec, (int, float)):
        return None if spec is None else spec * s
    out = dict(spec)
    for k in ("lo", "hi", "reach", "x0", "width"):
        if k in out:
            out[k] = out[k] * s
    if "center" in out:
        out["center"] = [c * s for c in out["center"]]
    return out


def _shifted_size(spec, d):
    if spec is None or isinstance(spec, (int, float)):
        return spec
    out = dict(spec)
    if "x0" in out:
        out["x0"] = out["x0"] + d
    if "center" in out:
        out["center"] = [c + d for c in out["center"]]
    return out


def test_hundreds_of_exactly_cocircular_vertices(checked):
    """All 324 integer points of the circle of radius 32045: every CDT of them is
    legal; check_mesh's exact test and the cocircular fallback must both accept."""
    P = fd.lattice_circle(32045)
    case = fd.FuzzCase("lattice324", Polygon(P), 2000.0, {}, [Polygon(P)])
    mesh = fd.run_case(case, check=checked, timeout=60)
    assert mesh.n_triangles > len(P)
    greedy = fd.FuzzCase(
        "lattice324-greedy",
        Polygon(P),
        None,
        {"greedy": True, "split_boundary": False},
        [Polygon(P)],
    )
    mesh = fd.run_case(greedy, check=checked, timeout=60)
    assert mesh.n_triangles == len(P) - 2


def test_regular_polygon_800_with_center_hole(checked):
    t = 2 * np.pi * np.arange(800) / 800
    hole = 0.5 * np.c_[np.cos(t[::2]), np.sin(t[::2])]
    poly = Polygon(np.c_[np.cos(t), np.sin(t)], [hole])
    for opts in ({}, {"greedy": True, "split_boundary": False}, {"order": "oldest"}):
        fd.run_case(fd.FuzzCase("ngon800", poly, 0.05, opts, [poly]), check=checked, timeout=60)


@pytest.mark.parametrize("gap", [1e-7, 1e-9])
@pytest.mark.parametrize("scale", [1.0, 1e-6])
def test_hole_nearly_touching_outer_ring(gap, scale, checked):
    """A diamond hole whose tip is gap * size away from the outer ring."""
    hole = np.array([(gap, 1.0), (0.5, 0.7), (1.0, 1.0), (0.5, 1.3)]) * scale
    poly = Polygon(np.array([(0, 0), (2, 0), (2, 2), (0, 2)]) * scale, [hole])
    fd.run_case(
        fd.FuzzCase("near", poly, 0.2 * scale, {}, [poly]), check=checked, timeout=GEN_TIMEOUT
    )


# =========================================================== 2. invalid input is named
SQ = box(0, 0, 1, 1)
TRI = {"vertices": [(0, 0), (1, 0), (0, 1)], "segments": [(0, 1), (1, 2), (2, 0)]}


def _dict(**kw):
    d = {k: v for k, v in TRI.items()}
    d.update(kw)
    return d


# (name, call, error class, words the message must contain (lower case))
INVALID = [
    # domains that are not domains
    ("domain-none", lambda: aftmesh.generate(None, 0.1), InvalidDomainError, ["nonetype"]),
    ("domain-int", lambda: aftmesh.generate(7, 0.1), InvalidDomainError, ["int"]),
    ("domain-object", lambda: aftmesh.generate(object(), 0.1), InvalidDomainError, ["object"]),
    ("domain-empty-list", lambda: aftmesh.generate([], 0.1), InvalidDomainError, ["empty"]),
    (
        "domain-empty-polygon",
        lambda: aftmesh.generate(Polygon(), 0.1),
        InvalidDomainError,
        ["empty"],
    ),
    (
        "domain-line",
        lambda: aftmesh.generate(LineString([(0, 0), (1, 1)]), 0.1),
        InvalidDomainError,
        ["polygon"],
    ),
    ("domain-point", lambda: aftmesh.generate(Point(0, 0), 0.1), InvalidDomainError, ["polygon"]),
    (
        "ring-two-vertices",
        lambda: aftmesh.generate([(0, 0), (1, 0)], 0.1),
        InvalidDomainError,
        ["3 vertices"],
    ),
    (
        "ring-collinear",
        lambda: aftmesh.generate([(0, 0), (1, 0), (2, 0)], 0.1),
        InvalidDomainError,
        [],
    ),
    ("ring-all-same", lambda: aftmesh.generate([(1, 1)] * 5, 0.1), InvalidDomainError, []),
    (
        "ring-nan",
        lambda: aftmesh.generate([(0, 0), (1, np.nan), (0, 1)], 0.1),
        InvalidDomainError,
        ["vertex 1", "not finite"],
    ),
    (
        "ring-inf",
        lambda: aftmesh.generate([(0, 0), (np.inf, 0), (0, 1)], 0.1),
        InvalidDomainError,
        ["vertex 1", "not finite"],
    ),
    ("ring-3d", lambda: aftmesh.generate(np.zeros((4, 3)), 0.1), InvalidDomainError, []),
    (
        "bowtie",
        lambda: aftmesh.generate([(0, 0), (1, 1), (1, 0), (0, 1)], 0.1),
        InvalidDomainError,
        ["self-intersection"],
    ),
    (
        "hole-self-intersecting",
        lambda: aftmesh.generate(
            Polygon(SQ.exterior.coords, [[(0.2, 0.2), (0.8, 0.8), (0.8, 0.2), (0.2, 0.8)]]), 0.1
        ),
        InvalidDomainError,
        ["hole 0"],
    ),
    (
        "hole-outside",
        lambda: aftmesh.generate(Polygon(SQ.exterior.coords, [[(2, 2), (3, 2), (3, 3)]]), 0.1),
        InvalidDomainError,
        ["hole 0"],
    ),
    (
        "regions-overlap",
        lambda: aftmesh.generate([box(0, 0, 2, 2), box(1, 1, 3, 3)], 0.1),
        InvalidDomainError,
        ["regions 0 and 1", "overlap"],
    ),
    (
        "region-not-polygon",
        lambda: aftmesh.generate([SQ, "square"], 0.1),
        InvalidDomainError,
        ["region 1"],
    ),
    (
        "region-ring-too-short",
        lambda: aftmesh.generate([SQ, [(2, 0), (3, 0)]], 0.1),
        InvalidInputError,
        ["region 1"],
    ),
    (
        "constraint-outside",
        lambda: aftmesh.generate(GeometryCollection([SQ, LineString([(0.5, 0.5), (2, 2)])]), 0.1),
        InvalidDomainError,
        ["constraint line 0"],
    ),
    (
        "fixed-point-outside",
        lambda: aftmesh.generate(GeometryCollection([SQ, Point(3, 3)]), 0.1),
        InvalidDomainError,
        ["fixed point 0"],
    ),
    (
        "huge-coordinates",
        lambda: aftmesh.generate([(0, 0), (1e300, 0), (0, 1e300)], 1e299),
        InvalidInputError,
        [],
    ),
    (
        "missing-file",
        lambda: aftmesh.generate("/nonexistent/x.poly", 0.1),
        InvalidInputError,
        ["/nonexistent/x.poly"],
    ),
    # the dict form
    (
        "dict-no-vertices",
        lambda: aftmesh.generate({"segments": [(0, 1)]}, 0.1),
        InvalidInputError,
        ["vertices"],
    ),
    (
        "dict-vertices-shape",
        lambda: aftmesh.generate(_dict(vertices=[(0, 0, 0)] * 3), 0.1),
        InvalidInputError,
        ["vertices", "shape"],
    ),
    (
        "dict-vertices-text",
        lambda: aftmesh.generate(_dict(vertices="abc"), 0.1),
        InvalidInputError,
        ["vertices"],
    ),
    (
        "dict-vertex-nan",
        lambda: aftmesh.generate(_dict(vertices=[(0, 0), (1, 0), (0, np.nan)]), 0.1),
        InvalidInputError,
        ["vertices[2]", "not finite"],
    ),
    (
        "dict-segment-out-of-range",
        lambda: aftmesh.generate(_dict(segments=[(0, 1), (1, 3), (2, 0)]), 0.1),
        InvalidInputError,
        ["segments[1]", "outside"],
    ),
    (
        "dict-segment-negative",
        lambda: aftmesh.generate(_dict(segments=[(0, 1), (1, 2), (2, -1)]), 0.1),
        InvalidInputError,
        ["segments[2]"],
    ),
    (
        "dict-segment-float",
        lambda: aftmesh.generate(_dict(segments=[(0, 1.5)]), 0.1),
        InvalidInputError,
        ["integer"],
    ),
    (
        "dict-segment-zero-length",
        lambda: aftmesh.generate(_dict(segments=[(0, 1), (1, 1), (2, 0)]), 0.1),
        InvalidInputError,
        ["segments[1]", "zero length"],
    ),
    (
        "dict-segment-shape",
        lambda: aftmesh.generate(_dict(segments=[0, 1, 2]), 0.1),
        InvalidInputError,
        ["segments", "shape"],
    ),
    (
        "dict-crossing",
        lambda: aftmesh.generate(
            {
                "vertices": [(0, 0), (1, 0), (1, 1), (0, 1)],
                "segments": [(0, 2), (1, 3), (0, 1), (1, 2), (2, 3), (3, 0)],
            }
        ),
        CrossingSegmentsError,
        ["cross"],
    ),
    (
        "dict-open",
        lambda: aftmesh.generate(_dict(segments=[(0, 1)]), 0.1),
        InvalidDomainError,
        ["encloses no area"],
    ),
    (
        "dict-hole-outside",
        lambda: aftmesh.generate(_dict(holes=[(5, 5)]), 0.1),
        InvalidDomainError,
        ["holes[0]", "not inside"],
    ),
    (
        "dict-hole-nan",
        lambda: aftmesh.generate(_dict(holes=[(np.nan, 0)]), 0.1),
        InvalidInputError,
        ["holes[0]"],
    ),
    (
        "dict-all-hole",
        lambda: aftmesh.generate(_dict(holes=[(0.2, 0.2)]), 0.1),
        InvalidDomainError,
        [],
    ),
    (
        "dict-regions-shape",
        lambda: aftmesh.generate(_dict(regions=[(0.1, 0.1)]), 0.1),
        InvalidInputError,
        ["regions"],
    ),
    (
        "dict-region-marker-fraction",
        lambda: aftmesh.generate(_dict(regions=[(0.1, 0.1, 1.5)]), 0.1),
        InvalidInputError,
        ["marker", "integer"],
    ),
    (
        "dict-segment-markers-length",
        lambda: aftmesh.generate(_dict(segment_markers=[1, 2]), 0.1),
        InvalidInputError,
        ["segment_markers"],
    ),
    (
        "dict-segment-markers-float",
        lambda: aftmesh.generate(_dict(segment_markers=[1.5, 2, 3]), 0.1),
        InvalidInputError,
        ["segment_markers", "integer"],
    ),
    # sizes
    ("size-negative", lambda: aftmesh.generate(SQ, -0.1), InvalidSizeError, ["positive"]),
    ("size-zero", lambda: aftmesh.generate(SQ, 0.0), InvalidSizeError, ["positive"]),
    ("size-nan", lambda: aftmesh.generate(SQ, np.nan), InvalidSizeError, []),
    ("size-inf", lambda: aftmesh.generate(SQ, np.inf), InvalidSizeError, []),
    ("size-text", lambda: aftmesh.generate(SQ, "fine"), InvalidSizeError, ["size"]),
    ("size-complex", lambda: aftmesh.generate(SQ, 0.1 + 1j), InvalidSizeError, ["size"]),
    ("size-numeric-text", lambda: aftmesh.generate(SQ, "0.1"), InvalidSizeError, ["'0.1'"]),
    ("size-bool", lambda: aftmesh.generate(SQ, True), InvalidSizeError, ["true"]),
    (
        "size-per-region-bool",
        lambda: aftmesh.generate([SQ, box(1, 0, 2, 1)], [0.1, True]),
        InvalidSizeError,
        ["size[1]"],
    ),
    (
        "size-below-resolution",
        lambda: aftmesh.generate(box(1e6, 0, 1e6 + 1, 1), 1e-9),
        InvalidSizeError,
        ["resolve", "1e-09"],
    ),
    (
        "size-callable-below-resolution",
        lambda: aftmesh.generate(box(1e6, 0, 1e6 + 1, 1), lambda x, y: 1e-9 + 0 * x),
        InvalidSizeError,
        ["resolve", "callable"],
    ),
    (
        "size-wrong-count",
        lambda: aftmesh.generate([SQ, box(1, 0, 2, 1)], [0.1]),
        InvalidSizeError,
        ["1 sizes", "2 regions"],
    ),
    (
        "size-per-region-nan",
        lambda: aftmesh.generate([SQ, box(1, 0, 2, 1)], [0.1, np.nan]),
        InvalidSizeError,
        ["size[1]"],
    ),
    ("size-list-for-dict", lambda: aftmesh.generate(TRI, [0.1]), InvalidSizeError, ["region"]),
    (
        "size-callable-raises",
        lambda: aftmesh.generate(SQ, lambda x, y: 1 / 0),
        InvalidSizeError,
        ["zerodivisionerror"],
    ),
    (
        "size-callable-wrong-shape",
        lambda: aftmesh.generate(SQ, lambda x, y: np.ones(3)),
        InvalidSizeError,
        ["shape"],
    ),
    ("size-callable-text", lambda: aftmesh.generate(SQ, lambda x, y: "big"), InvalidSizeError, []),
    (
        "size-callable-negative",
        lambda: aftmesh.generate(SQ, lambda x, y: x - 2),
        InvalidSizeError,
        ["finite and positive"],
    ),
    (
        "size-callable-nan-spot",
        lambda: aftmesh.generate(
            SQ, lambda x, y: np.where(np.hypot(x - 0.5, y - 0.5) < 0.3, np.nan, 0.1)
        ),
        InvalidSizeError,
        ["nan"],
    ),
    (
        "size-none-no-edges",
        lambda: aftmesh.generate({"vertices": [(0, 0), (1, 0), (0, 1)]}),
        InvalidInputError,
        [],
    ),
    # options
    ("order", lambda: aftmesh.generate(SQ, 0.1, order="random"), InvalidOptionError, ["order"]),
    (
        "order-unhashable",
        lambda: aftmesh.generate(SQ, 0.1, order=[]),
        InvalidOptionError,
        ["order"],
    ),
    (
        "max-triangles-zero",
        lambda: aftmesh.generate(SQ, 0.1, max_triangles=0),
        InvalidOptionError,
        ["max_triangles"],
    ),
    (
        "max-triangles-float",
        lambda: aftmesh.generate(SQ, 0.1, max_triangles=10.0),
        InvalidOptionError,
        ["max_triangles"],
    ),
    (
        "max-triangles-bool",
        lambda: aftmesh.generate(SQ, 0.1, max_triangles=True),
        InvalidOptionError,
        ["max_triangles"],
    ),
    (
        "max-triangles-below-boundary",
        lambda: aftmesh.generate(SQ, 0.1, max_triangles=3),
        InvalidSizeError,
        ["triangles", "3"],
    ),
    (
        "min-area-negative",
        lambda: aftmesh.generate(SQ, 0.1, min_area=-1.0),
        InvalidOptionError,
        ["min_area"],
    ),
    (
        "min-area-empty-list",
        lambda: aftmesh.generate(SQ, 0.1, min_area=[]),
        InvalidOptionError,
        ["min_area"],
    ),
    (
        "min-area-text",
        lambda: aftmesh.generate(SQ, 0.1, min_area="small"),
        InvalidOptionError,
        ["min_area"],
    ),
    (
        "close-factor-2",
        lambda: aftmesh.generate(SQ, 0.1, close_factor=2.0),
        InvalidOptionError,
        ["close_factor"],
    ),
    (
        "close-factor-none",
        lambda: aftmesh.generate(SQ, 0.1, close_factor=None),
        InvalidOptionError,
        ["close_factor"],
    ),
    (
        "gradation-below-1",
        lambda: aftmesh.generate(SQ, 0.1, gradation=0.5),
        InvalidSizeError,
        ["gradation"],
    ),
    (
        "gradation-text",
        lambda: aftmesh.generate(SQ, 0.1, gradation="fast"),
        InvalidInputError,
        ["gradation"],
    ),
    (
        "smooth-negative",
        lambda: aftmesh.generate(SQ, 0.1, smooth=-1),
        InvalidOptionError,
        ["smooth"],
    ),
    ("smooth-float", lambda: aftmesh.generate(SQ, 0.1, smooth=1.5), InvalidOptionError, ["smooth"]),
    (
        "greedy-text",
        lambda: aftmesh.generate(SQ, 0.1, greedy="yes"),
        InvalidOptionError,
        ["greedy"],
    ),
    ("swaps-int", lambda: aftmesh.generate(SQ, 0.1, swaps=1), InvalidOptionError, ["swaps"]),
    (
        "split-none",
        lambda: aftmesh.generate(SQ, 0.1, split_boundary=None),
        InvalidOptionError,
        ["split_boundary"],
    ),
    (
        "strategy-int",
        lambda: aftmesh.generate(SQ, 0.1, strategy=1),
        InvalidOptionError,
        ["strategy"],
    ),
    # cdt()
    ("cdt-one-point", lambda: aftmesh.cdt([(0, 0)]), InvalidDomainError, ["3 vertices"]),
    (
        "cdt-collinear",
        lambda: aftmesh.cdt([(0, 0), (1, 1), (2, 2), (3, 3)]),
        InvalidDomainError,
        ["collinear"],
    ),
    ("cdt-text", lambda: aftmesh.cdt("points"), InvalidInputError, ["vertices"]),
    (
        "cdt-segments-3d",
        lambda: aftmesh.cdt([(0, 0), (1, 0), (0, 1)], np.zeros((1, 2, 2), int)),
        InvalidInputError,
        ["segments", "shape"],
    ),
    (
        "cdt-segments-uint64",
        lambda: aftmesh.cdt([(0, 0), (1, 0), (0, 1)], np.array([[2**63, 1]], dtype=np.uint64)),
        InvalidInputError,
        ["segments[0]"],
    ),
    (
        "cdt-crossing",
        lambda: aftmesh.cdt([(0, 0), (1, 0), (1, 1), (0, 1)], [(0, 2), (1, 3)]),
        CrossingSegmentsError,
        ["segments[1]", "segments[0]"],
    ),
    (
        "cdt-regions-text",
        lambda: aftmesh.cdt([(0, 0), (1, 0), (0, 1)], regions="abc"),
        InvalidInputError,
        ["regions"],
    ),
    (
        "cdt-holes-shape",
        lambda: aftmesh.cdt([(0, 0), (1, 0), (0, 1)], holes=[1, 2, 3]),
        InvalidInputError,
        ["holes"],
    ),
]


@pytest.mark.parametrize("name,call,error,words", INVALID, ids=[c[0] for c in INVALID])
def test_invalid_input_named(name, call, error, words):
    """Each malformed input class: the specific ValueError subclass, with a message
    that names the problem; never an IndexError, TypeError, crash or hang."""
    with pytest.raises(error) as info:
        fd.isolated(call, timeout=GEN_TIMEOUT)
    msg = str(info.value).lower()
    assert msg, "empty error message"
    for w in words:
        assert w in msg, f"{w!r} not in the message {str(info.value)!r}"


# ------------------------------------------------------------------ random garbage
_FLOATS = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, -0.0, 1e300, -1e300, 5e-324, 1e-300, 1e100, 1.0]),
)
_SCALARS = st.one_of(
    st.none(),
    st.booleans(),
    _FLOATS,
    st.integers(-(2**70), 2**70),
    st.integers(-3, 5),
    st.text(max_size=6),
    st.binary(max_size=6),
    st.complex_numbers(allow_nan=True, allow_infinity=True),
)


@st.composite
def _arrays(draw):
    shape = draw(
        st.sampled_from([(), (0,), (0, 2), (3,), (3, 2), (4, 2), (2, 3), (3, 2, 2), (1, 1), (5, 2)])
    )
    dtype = draw(st.sampled_from(["f8", "f4", "i8", "i4", "u8", "bool", "c16", "O", "U3"]))
    n = int(np.prod(shape)) if shape else 1
    vals = draw(st.lists(st.one_of(_FLOATS, st.integers(-3, 10)), min_size=n, max_size=n))
    try:
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return np.array(vals, dtype=object).astype(dtype).reshape(shape)
    except (ValueError, TypeError, OverflowError):
        return np.array(vals, dtype=object).reshape(shape)


def _nan_polygon() -> Polygon:
    """A polygon with a NaN coordinate, made quietly: shapely warns on the NaN while
    building it, and the warning is about the test's input, not about aftmesh."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return Polygon([(0, 0), (1, 0), (np.nan, 1)])


_SENTINELS = st.sampled_from(
    [
        object(),
        print,
        Polygon(),
        Point(0, 0),
        LineString([(0, 0), (1, 1)]),
        GeometryCollection(),
        _nan_polygon(),
        MultiPolygon(),
        range(3),
        b"\x00\x01",
        "",
        "POLYGON ((0 0, 1 0, 0 1, 0 0))",
    ]
)

garbage = st.recursive(
    st.one_of(_SCALARS, _arrays(), _SENTINELS),
    lambda inner: st.one_of(
        st.lists(inner, max_size=5),
        st.lists(inner, max_size=5).map(tuple),
        st.dictionaries(
            st.sampled_from(["vertices", "segments", "holes", "regions", "segment_markers", "x"]),
            inner,
            max_size=4,
        ),
    ),
    max_leaves=12,
)


@st.composite
def _near_valid_rings(draw):
    """A valid ring with one coordinate, vertex or the container replaced by garbage."""
    ring = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
    how = draw(st.sampled_from(["coord", "vertex", "extra", "wrap"]))
    i = draw(st.integers(0, 3))
    g = draw(garbage)
    if how == "coord":
        ring[i][draw(st.integers(0, 1))] = g
    elif how == "vertex":
        ring[i] = g
    elif how == "extra":
        ring.insert(i, g)
    else:
        ring = [ring, g]
    return ring


def _outcome(call, checked):
    """A checked mesh or an InvalidInputError; anything else fails with its type."""
    try:
        mesh = fd.isolated(call, timeout=GEN_TIMEOUT)
    except InvalidInputError as exc:
        assert str(exc), "empty error message"
        return exc
    except (fd.Hang, fd.Crash):
        raise
    except BaseException as exc:  # noqa: BLE001
        raise AssertionError(
            f"{type(exc).__name__} escaped: {exc}\n{getattr(exc, 'child_traceback', '')}"
        ) from exc
    if isinstance(mesh, aftmesh.Mesh):
        checked(mesh)
    return mesh


@budget(1.0)
@given(domain=st.one_of(garbage, _near_valid_rings()))
def test_garbage_domain(domain, checked):
    _outcome(lambda: aftmesh.generate(domain, None, max_triangles=20000), checked)


@budget(0.5)
@given(size=st.one_of(garbage, st.lists(_FLOATS, min_size=1, max_size=1)))
def test_garbage_size(size, checked):
    _outcome(lambda: aftmesh.generate(SQ, size, max_triangles=20000), checked)


OPTIONS = [
    "max_triangles",
    "min_area",
    "order",
    "greedy",
    "swaps",
    "split_boundary",
    "gradation",
    "close_factor",
    "smooth",
    "strategy",
    "progress",
]


@budget(1.0)
@given(name=st.sampled_from(OPTIONS), value=garbage)
def test_garbage_option(name, value, checked):
    kw = {name: value}
    if name != "max_triangles":
        kw["max_triangles"] = 20000
    _outcome(lambda: aftmesh.generate(SQ, 0.1, **kw), checked)


@budget(1.0)
@given(
    entries=st.dictionaries(
        st.sampled_from(["vertices", "segments", "holes", "regions", "segment_markers"]),
        st.one_of(
            garbage,
            st.just(TRI["vertices"]),
            st.just(TRI["segments"]),
            st.just([(0.2, 0.2, 1)]),
            st.just([(0.2, 0.2)]),
            st.just([1, 2, 3]),
        ),
        min_size=1,
    )
)
def test_garbage_dict_domain(entries, checked):
    _outcome(lambda: aftmesh.generate(entries, None, max_triangles=20000), checked)


@budget(1.0)
@given(
    vertices=st.one_of(garbage, st.just([(0, 0), (1, 0), (1, 1), (0, 1)])),
    segments=st.one_of(st.none(), garbage, st.just([(0, 1), (1, 2), (2, 3), (3, 0)])),
    holes=st.one_of(st.none(), garbage),
    regions=st.one_of(st.none(), garbage),
)
def test_garbage_cdt(vertices, segments, holes, regions, checked):
    _outcome(lambda: aftmesh.cdt(vertices, segments, holes=holes, regions=regions), checked)


# ====================================================== 3. termination, caps, Ctrl-C
def _spot(h0, cx=0.3, cy=0.4, base=0.1):
    """The size: base everywhere except a point-like spot of size h0."""

    def size(x, y):
        return np.maximum(h0, np.minimum(base, 0.5 * np.hypot(x - cx, y - cy)))

    return size


@pytest.mark.parametrize("h0", [1e-3, 1e-6, 1e-12, 1e-100, 1e-300, 5e-324])
def test_size_tiny_in_one_spot(h0, checked):
    """A size that is tiny at one point completes (the grid and the gradation keep the
    mesh small) or is refused; it never hangs."""
    res = _outcome(lambda: aftmesh.generate(SQ, _spot(h0)), checked)
    if isinstance(res, aftmesh.Mesh):
        fd.verify(res, fd.FuzzCase("spot", SQ, None, {}, [SQ]), checked)


@pytest.mark.parametrize("bad", [np.nan, -1.0, 0.0, np.inf, -np.inf])
def test_size_bad_in_one_spot(bad):
    """A bad value over a spot a few sizes wide is seen: the callable is sampled at
    least every RESOLVE_COARSEST sizes (narrower spots are the next test's case)."""

    def size(x, y):
        return np.where(np.hypot(x - 0.4, y - 0.5) < 0.3, bad, 0.1)

    with pytest.raises(InvalidSizeError):
        fd.isolated(aftmesh.generate, SQ, size, timeout=GEN_TIMEOUT)


@pytest.mark.parametrize("bad", [np.nan, -1.0])
def test_size_bad_at_one_point_between_samples(bad, checked):
    """Bad only exactly at one point the sampling may miss: refused, or unseen and
    the mesh is fine (the kernel never reads the callable itself)."""

    def size(x, y):
        x = np.asarray(x, dtype=float)
        return np.where((x == 0.123456789) & (np.asarray(y) == 0.5), bad, 0.1 + 0 * x)

    _outcome(lambda: aftmesh.generate(SQ, size), checked)


@budget(0.3)
@given(case=fd.fuzz_cases(kinds=["star", "holes", "cells", "touching"]), cap=st.integers(1, 400))
def test_max_triangles_caps_the_mesh(case, cap, checked):
    case.options["max_triangles"] = cap
    mesh = fd.run_case(case, check=checked, timeout=GEN_TIMEOUT)
    if mesh is not None:
        assert mesh.n_triangles <= cap


def test_max_triangles_caps_a_huge_request(checked, time_limit):
    """Size 1e-4 on the unit square asks for ~2e8 triangles; max_triangles=50000 must
    stop it early (the boundary alone needs 4e4)."""
    t = time.perf_counter()
    mesh = fd.isolated(aftmesh.generate, SQ, 1e-4, max_triangles=50000, timeout=GEN_TIMEOUT)
    checked(mesh, domain_area=1.0)
    assert mesh.n_triangles <= 50000
    time_limit(time.perf_counter() - t, 10, "capped_s")


def _big(progress=None, smooth=0):
    """A mesh of a few million triangles: several seconds of work."""
    return aftmesh.generate(SQ, 0.0008, progress=progress, smooth=smooth)


def test_ctrl_c_from_progress_callback(checked, time_limit):
    """A progress callback raising KeyboardInterrupt stops the compiled loop at once;
    the next call works."""
    calls = []

    def progress(f):
        calls.append((time.perf_counter(), f))
        if len(calls) == 3:
            raise KeyboardInterrupt

    t0 = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        _big(progress)
    stopped = time.perf_counter()
    assert len(calls) == 3
    assert calls[-1][1] < 0.5, "the interrupt came late"
    time_limit(stopped - calls[-1][0], 0.5, "after_callback_raised_s")
    mesh = aftmesh.generate(SQ, 0.1)
    checked(mesh, domain_area=1.0)
    time_limit(stopped - t0, 5, "until_stopped_s")


def test_progress_callback_other_errors_ignored(checked):
    """A broken progress display (any other exception) does not stop meshing."""

    def progress(f):
        raise RuntimeError("display broke")

    mesh = aftmesh.generate(SQ, 0.005, progress=progress)
    checked(mesh, domain_area=1.0)


def _interrupt_after(delay: float, sig=signal.SIGINT):
    """Send `sig` to this process from a timer thread after `delay` seconds; returns
    (thread, record) with record['sent'] the time it was sent."""
    record = {}

    def fire():
        time.sleep(delay)
        record["sent"] = time.perf_counter()
        os.kill(os.getpid(), sig)

    th = threading.Thread(target=fire, daemon=True)
    th.start()
    return th, record


def test_sigint_during_large_mesh(checked, default_sigint, time_limit):
    """SIGINT (os.kill from a timer thread) while the compiled loop runs: the
    KeyboardInterrupt arrives within a fraction of a second and the process keeps
    working."""
    got = None
    record = {}
    th = None
    try:
        try:
            th, record = _interrupt_after(0.7)
            _big()
            got = "finished"
        finally:
            if th is not None:
                th.join()
            time.sleep(0.05)  # a late signal would land here, inside the try
    except KeyboardInterrupt:
        got = time.perf_counter()
    assert got != "finished", "the large mesh finished before the signal: make it bigger"
    assert got is not None
    time_limit(got - record["sent"], 0.5, "interrupt_latency_s")
    mesh = aftmesh.generate(SQ, 0.1)
    checked(mesh, domain_area=1.0)
    assert same_arrays(mesh, aftmesh.generate(SQ, 0.1))


def test_sigint_in_subprocess_exits_cleanly(time_limit):
    """The same from outside: SIGINT to a process in the middle of a large mesh gives
    a KeyboardInterrupt there (caught, then a small mesh is made), not a hang or a
    crash."""
    code = (
        "import signal, time, aftmesh\n"
        # Python installs its Ctrl-C handler only if SIGINT was not inherited ignored
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        "from shapely.geometry import box\n"
        "print('ready', flush=True)\n"
        "try:\n"
        "    aftmesh.generate(box(0, 0, 1, 1), 0.0006)\n"
        "    print('finished', flush=True)\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted', time.perf_counter(), flush=True)\n"
        "m = aftmesh.generate(box(0, 0, 1, 1), 0.1)\n"
        "print('after', m.n_triangles, flush=True)\n"
    )
    env = dict(
        os.environ, PYTHONPATH=os.pathsep.join([PACKAGE_ROOT, os.environ.get("PYTHONPATH", "")])
    )
    proc = subprocess.Popen(
        [sys.executable, "-c", code],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    try:
        assert proc.stdout.readline().strip() == "ready"
        time.sleep(1.5)  # past the imports and well into the mesh
        proc.send_signal(signal.SIGINT)
        sent = time.perf_counter()
        out, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 0, err
    lines = out.split("\n")
    assert lines[0].startswith("interrupted"), out
    time_limit(float(lines[0].split()[1]) - sent, 1.0, "interrupt_latency_s")
    assert lines[1].startswith("after") and int(lines[1].split()[1]) > 0


# ============================================================== 4. determinism
@budget(0.2)
@given(case=fd.fuzz_cases(rich_options=True))
def test_same_input_same_output(case):
    def twice():
        out = []
        for _ in range(2):
            try:
                out.append(case.call())
            except InvalidInputError as exc:
                # a refusal (max_triangles, coordinates out of range...) must repeat too
                if not (isinstance(exc, InvalidSizeError) or fd.acceptable_refusal(case, exc)):
                    raise
                out.append(None)
        return out

    a, b = fd.isolated(twice, timeout=2 * GEN_TIMEOUT)
    assert (a is None) == (b is None)
    if a is not None:
        assert same_arrays(a, b)


DETERMINISM_SCRIPT = r"""
import json, sys
sys.path.insert(0, sys.argv[1])
import fuzz_domains as fd
cases = [fd.case_from_json(c) for c in json.load(open(sys.argv[2]))]
from test_robustness import digest
print(json.dumps([digest(c.call()) for c in cases]))
"""


def _determinism_cases():
    t = 2 * np.pi * np.arange(200) / 200
    ring = Polygon(np.c_[np.cos(t), np.sin(t)], [0.4 * np.c_[np.cos(t[::4]), np.sin(t[::4])]])
    holes = Polygon(
        box(0, 0, 4, 3).exterior.coords,
        [fd._ngon(0.5 + i, 0.5 + j, 0.3, 3 + i + j, 0.1 * i) for i in range(4) for j in range(3)],
    )
    lat = Polygon(fd.lattice_circle(5525))
    far = shapely.transform(holes, lambda c: c + 1e7)
    cells = shapely.union_all(
        [box(i, j, i + 1, j + 1) for i in range(4) for j in range(4) if (i + j) % 2 == 0 or i == j]
    )
    # the lines cross at (1, 0.5), exactly on both (dyadic coordinates)
    gc = GeometryCollection(
        [
            box(0, 0, 2, 1),
            LineString([(0.25, 0.25), (1.75, 0.75)]),
            LineString([(0.25, 0.75), (1.75, 0.25)]),
            Point(1.5, 0.5),
        ]
    )
    regions = [box(0, 0, 1, 1), box(1, 0, 2, 1), box(0, 1, 2, 2)]
    graded = {"kind": "point", "lo": 1e-3, "hi": 0.3, "center": [0.3, 0.3], "slope": 0.3}
    return [
        fd.FuzzCase("ring", ring, 0.08, {}, [ring]),
        fd.FuzzCase("holes", holes, graded, {}, [holes]),
        fd.FuzzCase("holes-oldest", holes, 0.2, {"order": "oldest", "smooth": 5}, [holes]),
        fd.FuzzCase("lattice", lat, 800.0, {}, [lat]),
        fd.FuzzCase("far", far, 0.15, {"close_factor": 1.0}, [far]),
        fd.FuzzCase("cells", cells, None, {}, [cells]),
        fd.FuzzCase("cracks", gc, 0.1, {}, [box(0, 0, 2, 1)]),
        fd.FuzzCase("regions", regions, 0.12, {"max_triangles": 300}, regions),
    ]


def test_same_output_across_processes(tmp_path):
    """Bit-identical meshes in this process and in two others with different
    PYTHONHASHSEED (no set / dict ordering or address leaks into the output)."""
    cases = _determinism_cases()
    here = [digest(c.call()) for c in cases]
    path = tmp_path / "cases.json"
    path.write_text(json.dumps([fd.case_to_json(c) for c in cases]))
    for seed in ("0", "4242"):
        env = dict(
            os.environ,
            PYTHONHASHSEED=seed,
            PYTHONPATH=os.pathsep.join([PACKAGE_ROOT, str(HERE), os.environ.get("PYTHONPATH", "")]),
        )
        out = subprocess.run(
            [sys.executable, "-c", DETERMINISM_SCRIPT, str(HERE), str(path)],
            env=env,
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert out.returncode == 0, out.stderr
        there = json.loads(out.stdout.strip().splitlines()[-1])
        diff = [c.kind for c, a, b in zip(cases, here, there) if a != b]
        assert not diff, f"PYTHONHASHSEED={seed}: different meshes for {diff}"


# ================================================================== 5. memory
def _rss_mb() -> float:
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    raise RuntimeError("no VmRSS")


def _rss_growth(call, n: int = 200, warmup: int = 20) -> float:
    """RSS growth (MB) over n calls after a warm-up (run in a forked child so the
    test process's own heap does not blur it)."""

    def measure():
        for _ in range(warmup):
            call()
        before = _rss_mb()
        for _ in range(n):
            call()
        return _rss_mb() - before

    return fd.isolated(measure, timeout=300)


MEMORY_DOMAIN = Polygon(
    box(0, 0, 3, 2).exterior.coords,
    [fd._ngon(1.0, 1.0, 0.4, 7, 0.0), fd._ngon(2.1, 0.9, 0.5, 5, 0.3)],
)


def test_memory_flat_repeated_generate():
    """200 meshes of ~10^4 triangles: no growth beyond 20 MB (a leak of the kernel's
    arrays would be ~0.5 MB a call)."""
    n_tri = aftmesh.generate(MEMORY_DOMAIN, 0.03).n_triangles
    assert n_tri > 8000
    growth = _rss_growth(lambda: aftmesh.generate(MEMORY_DOMAIN, 0.03))
    assert growth < 20, f"RSS grew by {growth:.1f} MB over 200 calls"


def _raises(call, exc_type):
    def run():
        try:
            call()
        except exc_type:
            return
        raise AssertionError("no error")

    return run


@pytest.mark.parametrize("what", ["crossing", "max_triangles", "interrupt", "cdt", "python-loop"])
def test_memory_flat_error_paths(what):
    """The same on paths that leave early with a kernel already built."""
    crossing = {
        "vertices": np.r_[
            MEMORY_DOMAIN.exterior.coords[:-1], [(0.5, 0.5), (2.5, 1.5)], [(0.7, 1.6), (2.2, 0.3)]
        ],
        "segments": [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (6, 7)],
    }

    def interrupt(f):
        raise KeyboardInterrupt

    calls = {
        "crossing": _raises(lambda: aftmesh.generate(crossing, 0.01), CrossingSegmentsError),
        "max_triangles": _raises(
            lambda: aftmesh.generate(MEMORY_DOMAIN, 0.003, max_triangles=100), InvalidSizeError
        ),
        "interrupt": _raises(
            lambda: aftmesh.generate(MEMORY_DOMAIN, 0.004, progress=interrupt), KeyboardInterrupt
        ),
        "cdt": lambda: aftmesh.cdt(np.random.default_rng(0).random((3000, 2))),
        "python-loop": lambda: aftmesh.generate(MEMORY_DOMAIN, 0.2, strategy=_PyStrategy()),
    }
    growth = _rss_growth(calls[what], n=200 if what != "python-loop" else 100)
    assert growth < 20, f"{what}: RSS grew by {growth:.1f} MB"


class _PyStrategy(Strategy):
    """Overrides Get_next_edge, so the Python loop runs."""

    def get_next_edge(self, kernel):
        return kernel.get_next_edge()


# ================================================================ 6. threads
def _thread_cases():
    return _determinism_cases() + [fd.FuzzCase("square", SQ, 0.004, {}, [SQ])]


def test_thread_pool_same_meshes(record_property):
    """Meshing from a thread pool gives the same meshes as one by one (the compiled
    loop and bulk insertion run without the GIL).  Wall times are recorded (and
    printed with -s), not asserted."""
    cases = _thread_cases() * 2
    t = time.perf_counter()
    serial = [c.call() for c in cases]
    t_serial = time.perf_counter() - t
    with ThreadPoolExecutor(max_workers=4) as pool:
        t = time.perf_counter()
        threaded = list(pool.map(lambda c: c.call(), cases))
        t_threads = time.perf_counter() - t
    for c, a, b in zip(cases, serial, threaded):
        assert same_arrays(a, b), c.kind
    record_property("serial_s", round(t_serial, 3))
    record_property("threads_s", round(t_threads, 3))
    print(
        f"\n[threads] {len(cases)} meshes: serial {t_serial:.2f} s, 4 threads "
        f"{t_threads:.2f} s (cpu count {os.cpu_count()})"
    )


def test_threads_with_progress_callbacks():
    """Progress callbacks called from several meshing threads at once (the compiled
    loop takes the GIL back for them) are all called, and the meshes are right."""
    seen = {k: [] for k in range(4)}

    def run(k):
        return aftmesh.generate(SQ, 0.003 + 0.0005 * k, progress=seen[k].append)

    with ThreadPoolExecutor(max_workers=4) as pool:
        meshes = list(pool.map(run, range(4)))
    for k, m in enumerate(meshes):
        assert seen[k], f"thread {k}: no progress call"
        assert all(0 <= f <= 1 for f in seen[k])
        assert same_arrays(m, aftmesh.generate(SQ, 0.003 + 0.0005 * k))


def test_interrupting_one_thread_leaves_the_others():
    """A KeyboardInterrupt raised by one thread's progress callback stops only that
    mesh."""

    def stop(f):
        raise KeyboardInterrupt

    def run(k):
        try:
            return aftmesh.generate(SQ, 0.003, progress=stop if k == 0 else None)
        except KeyboardInterrupt:
            return "interrupted"

    with ThreadPoolExecutor(max_workers=3) as pool:
        out = list(pool.map(run, range(3)))
    assert out[0] == "interrupted"
    ref = aftmesh.generate(SQ, 0.003)
    assert same_arrays(out[1], ref) and same_arrays(out[2], ref)


# ====================================================== the oracle itself can fail
def test_oracle_detects_broken_meshes(checked):
    """The checks used above reject a mesh with a hole in it, a boundary point off the
    boundary, and a triangulation that is not the CDT."""
    case = fd.FuzzCase("square", SQ, 0.25, {}, [SQ])
    good = aftmesh.generate(SQ, 0.25)
    fd.verify(good, case, checked)

    def mesh(points=None, triangles=None):
        T = np.asarray(good.triangles if triangles is None else triangles)
        return aftmesh.Mesh(
            points=good.points if points is None else points,
            triangles=T,
            neighbors=_neighbors(T),
            segments=good.segments,
            regions=np.zeros(len(T), dtype=np.int32),
        )

    with pytest.raises(AssertionError):
        fd.verify(mesh(triangles=good.triangles[1:]), case, checked)
    seg_pt = int(good.segments[0, 0])
    moved = np.array(good.points)
    moved[seg_pt] += 1e-3 * np.array([1.0, 0.7])
    with pytest.raises(AssertionError):
        fd.verify(mesh(points=moved), case, checked)
    # the square (0,0) (2,0) (2,1.5) (0,1.2): the diagonal (0,0)-(2,1.5) is not Delaunay
    P = np.array([(0, 0), (2, 0), (2, 1.5), (0, 1.2)], dtype=float)
    bad = aftmesh.Mesh(
        points=P,
        triangles=[(0, 1, 2), (0, 2, 3)],
        neighbors=[(-1, 1, -1), (-1, -1, 0)],
        segments=[(0, 1), (1, 2), (2, 3), (3, 0)],
        regions=[0, 0],
    )
    with pytest.raises(AssertionError):
        fd.check_cdt_with_triangle(bad, np.zeros((0, 2)))


def _neighbors(T: np.ndarray) -> np.ndarray:
    """neighbors[i, k]: the triangle across the edge opposite vertex k (-1: none)."""
    where = {}
    for i, t in enumerate(T.tolist()):
        for k in range(3):
            where[(t[(k + 1) % 3], t[(k + 2) % 3])] = (i, k)
    N = np.full(T.shape, -1, dtype=np.int32)
    for (u, v), (i, k) in where.items():
        if (v, u) in where:
            N[i, k] = where[(v, u)][0]
    return N
