"""Shared test set-up: hypothesis profiles and the invariant checker fixture.

Profiles (select with AFTMESH_TEST_PROFILE): ``ci`` (default: bounded, derandomized so
every run tries the same examples), ``long`` (many more examples, for fuzzing
sessions; failures found there are pinned as named regression tests).
"""
import os
import signal

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

import aftmesh
from aftmesh.checks import check_mesh

settings.register_profile(
    "ci", max_examples=60, derandomize=True, deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
settings.register_profile(
    "long", max_examples=2000, derandomize=False, deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
settings.load_profile(os.environ.get("AFTMESH_TEST_PROFILE", "ci"))


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
        "distributed", reason="dask.distributed is not installed (pip install aftmesh[dask])")
    # worker processes import aftmesh: hand them the path it was imported from
    src = os.path.dirname(os.path.dirname(aftmesh.__file__))
    old = os.environ.get("PYTHONPATH")
    os.environ["PYTHONPATH"] = os.pathsep.join(p for p in (src, old) if p)
    cluster = distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1,
                                       dashboard_address=":0", silence_logs=40)
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
