"""Build the compiled kernel ``aftmesh._kernel`` from ``cython_ext/``.

Set ``AFTMESH_DEBUG=1`` to build with bounds checks, wraparound checks and
``-O0 -g`` (used once in CI); the default is an optimised build.  The
floating-point flags matter for the exact predicates: ``-ffp-contract=off``
forbids the compiler from fusing a*b+c into an FMA, which would change the
rounding the error bounds rely on, and ``-ffast-math`` is never used.
"""
import os

from Cython.Build import cythonize
from setuptools import Extension, setup

DEBUG = os.environ.get("AFTMESH_DEBUG", "0") not in ("", "0")

compile_args = ["-ffp-contract=off", "-fno-fast-math"]
compile_args += ["-O0", "-g"] if DEBUG else ["-O3"]

directives = {
    "language_level": 3,
    "boundscheck": DEBUG,
    "wraparound": False,
    "initializedcheck": DEBUG,
    "cdivision": True,
    "embedsignature": True,
}

extensions = [
    Extension(
        "aftmesh._kernel",
        ["cython_ext/_kernel.pyx"],
        extra_compile_args=compile_args,
        define_macros=[("AFTMESH_DEBUG", "1" if DEBUG else "0")],
    )
]

setup(
    ext_modules=cythonize(
        extensions,
        include_path=["cython_ext"],
        compiler_directives=directives,
        compile_time_env={"AFTMESH_DEBUG": DEBUG},
        force=DEBUG,
    )
)
