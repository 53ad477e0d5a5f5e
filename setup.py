"""Build the compiled kernel ``aftmesh._kernel`` from ``cython_ext/``.

Set ``AFTMESH_DEBUG=1`` to build with bounds checks, wraparound checks and
``-O0 -g`` (used once in CI); the default is an optimised build.  The
floating-point flags matter for the exact predicates: ``-ffp-contract=off``
forbids the compiler from fusing a*b+c into an FMA, which would change the
rounding the error bounds rely on, and ``-ffast-math`` is never used.

Cython writes the generated C file under ``build/cython/``, never next to the
sources, so the source tree (and the sdist made from it) holds only ``.pyx``,
``.pxi``, ``.pxd`` and ``.h`` files.
"""

import os

from Cython.Build import cythonize
from setuptools import Extension, setup

DEBUG = os.environ.get("AFTMESH_DEBUG", "0") not in ("", "0")

# Where the generated C code goes: inside the build tree, so it is never committed or
# shipped; the debug build has its own directory so an optimised build never reuses
# C code generated with the checks on.
CYTHON_BUILD_DIR = os.path.join("build", "cython-debug" if DEBUG else "cython")

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
        build_dir=CYTHON_BUILD_DIR,
        compiler_directives=directives,
        compile_time_env={"AFTMESH_DEBUG": DEBUG},
        force=DEBUG,
    )
)
