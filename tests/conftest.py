"""Shared test set-up: hypothesis profiles and the invariant checker fixture.

Profiles (select with AFTMESH_TEST_PROFILE): ``ci`` (default: bounded, derandomized so
every run tries the same examples), ``long`` (many more examples, for fuzzing
sessions; failures found there are pinned as named regression tests).

Wall-clock thresholds depend on the machine and its load, so the default run does not
assert them: tests marked ``timing`` are skipped, and the ``time_limit`` fixture only
records the time, unless ``AFTMESH_TIMING_TESTS=1`` is set or ``-m timing`` is given.
"""

import os
import signal

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

import aftmesh
from aftmesh.checks import check_mesh

settings.register_profile(
    "ci",
    max_examples=60,
    derandomize=True,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
settings.register_profile(
    "long",
    max_examples=2000,
    derandomize=False,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
settings.load_profile(os.environ.get("AFTMESH_TEST_PROFILE", "ci"))

TIMING_ENV = "AFTMESH_TIMING_TESTS"


def _timing_on(config) -> bool:
    """Whether this run asserts wall-clock thresholds."""
    if os.environ.get(TIMING_ENV, "") not in ("", "0"):
        return True
    expr = config.getoption("markexpr", "") or ""
    return "timing" in expr and "not timing" not in expr


def pytest_collection_modifyitems(config, items):
    """Tests marked ``timing`` are skipped by default; tests using ``time_limit`` run
    by default (their thresholds unchecked) and get the marker, so ``-m timing``
    selects them with the thresholds checked."""
    skip = pytest.mark.skip(reason=f"wall-clock test: set {TIMING_ENV}=1 or use -m timing")
    timing_on = _timing_on(config)
    for item in items:
        if item.get_closest_marker("timing") is not None and not timing_on:
            item.add_marker(skip)
        elif "time_limit" in getattr(item, "fixturenames", ()):
            item.add_marker(pytest.mark.timing)


@pytest.fixture
def time_limit(request, record_property):
    """``time_limit(seconds, limit, what)``: records the time and, in a timing run
    only, asserts ``seconds < limit``.  The test's other assertions always run."""
    enforce = _timing_on(request.config)

    def check(seconds, limit, what="elapsed"):
        record_property(what, round(seconds, 3))
        if enforce:
            assert seconds < limit, f"{what}: {seconds:.2f} s, limit {limit} s"

    return check


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


@pytest.fixture
def checked():
    """``checked(mesh, **kw)`` runs the invariant checker and returns the mesh."""

    def run(mesh, **kw):
        check_mesh(mesh, **kw)
        return mesh

    return run


@pytest.fixture
def default_sigint():
    """Python's own SIGINT handler (KeyboardInterrupt) for the test's duration: a test
    run started as a background job of a non-interactive shell inherits SIGINT
    ignored, and Python then never installs that handler."""
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)


@pytest.fixture(scope="module")
def dask_client():
    """A real Dask cluster of 2 worker processes (one thread each), per test module."""
    distributed = pytest.importorskip(
        "distributed", reason="dask.distributed is not installed (pip install aftmesh[dask])"
    )
    # worker processes import aftmesh: hand them the path it was imported from
    src = os.path.dirname(os.path.dirname(aftmesh.__file__))
    old = os.environ.get("PYTHONPATH")
    os.environ["PYTHONPATH"] = os.pathsep.join(p for p in (src, old) if p)
    cluster = distributed.LocalCluster(
        n_workers=2, processes=True, threads_per_worker=1, dashboard_address=":0", silence_logs=40
    )
    client = distributed.Client(cluster, set_as_default=False)
    try:
        yield client
    finally:
        client.close()
        cluster.close()
        if old is None:
            os.environ.pop("PYTHONPATH", None)
        else:
            os.environ["PYTHONPATH"] = old
