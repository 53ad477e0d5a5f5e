"""Run the doctests of every module of the aftmesh package that is imported (the
installed wheel in CI, ``src/`` with ``PYTHONPATH=src``): one test per module, so a
failing example names its module.  Each runs in a fresh temporary directory, since
some examples write files."""

import doctest
import importlib
import pkgutil

import pytest

import aftmesh

# ``python -m aftmesh`` runs the command line when imported: not a library module.
NOT_IMPORTABLE = {"aftmesh.__main__"}
# Modules whose examples need an optional dependency.
NEEDS = {"aftmesh.plotting": "matplotlib", "aftmesh.io": "meshio"}


def _module_names() -> list[str]:
    names = ["aftmesh"]
    for info in pkgutil.walk_packages(aftmesh.__path__, prefix="aftmesh."):
        if info.name not in NOT_IMPORTABLE:
            names.append(info.name)
    return sorted(names)


def test_every_module_is_found():
    """The walk sees the package's modules (an empty list would test nothing)."""
    names = _module_names()
    assert {"aftmesh.generate", "aftmesh.cdt", "aftmesh.mesh"} <= set(names)


@pytest.mark.parametrize("name", _module_names())
def test_module_doctests(name, tmp_path, monkeypatch):
    if name in NEEDS:
        pytest.importorskip(NEEDS[name], reason=f"{name}'s examples need {NEEDS[name]}")
    try:
        import matplotlib

        matplotlib.use("Agg")
    except ImportError:
        pass
    monkeypatch.chdir(tmp_path)
    module = importlib.import_module(name)
    flags = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE
    finder = doctest.DocTestFinder(exclude_empty=True)
    runner = doctest.DocTestRunner(optionflags=flags)
    for test in finder.find(module, name):  # globals: a copy of the module's
        runner.run(test)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples failed in {name}"
