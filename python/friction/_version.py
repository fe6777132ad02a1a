"""The package's version, written here and nowhere else in the package.

pyproject.toml reads it (setuptools' dynamic version), CMake refuses to
configure when it differs from project(friction VERSION ...), and the tests
compare it with the library's friction_version() and the `version`
attribute of the program's output files.
"""

__version__ = "0.1.0"
