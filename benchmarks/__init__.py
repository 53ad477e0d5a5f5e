"""Benchmark suite of aftmesh: speed, memory and mesh quality against Triangle and Gmsh.

Run ``python -m benchmarks --help``; see benchmarks/README.md.  Performance is
measured here and never asserted in the tests.
"""
