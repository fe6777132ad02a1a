#!/usr/bin/env python3
"""The packaging recipes name what CMake looks for (CTest: packaging-recipes).

Neither Spack nor Apptainer runs here, so the recipes are checked against the
build's own statement of its dependencies:
- scripts/spack/packages/friction/package.py: every find_package and
  pkg_check_modules of cmake/FrictionDependencies.cmake (the library and the
  program), of cmake/FrictionTestTools.cmake and tests/CMakeLists.txt (the
  tests) is a depends_on of the recipe (tests' under `when("+tests")` with
  type "test"), with the versions CMake asks for (CMake's minimum version,
  pFUnit's) and HDF5's Fortran and MPI; a dependency CMake adds that the
  table below does not know fails the test, so the recipe is updated with it.
- scripts/container/friction.def: builds from Debian with scripts/install-deps,
  whose package list holds every Debian package CMake's messages name, and
  configures without the tests, builds, installs and tests the program.

    packaging_test.py SOURCE_DIR
"""
import ast
import re
import shlex
import sys
from pathlib import Path

# CMake's name of a dependency -> Spack's package, for the library and program.
LIBRARY = {"MPI": "mpi", "GSL": "gsl", "PkgConfig": "pkgconfig", "HDF5": "hdf5", "fftw3": "fftw-api", "LAPACK": "lapack"}
# The tests' tools (find_package / find_program) -> Spack's package.
TESTS = {"PFUNIT": "pfunit", "Python3": "python", "ngspice": "ngspice", "gnuplot": "gnuplot"}
# The tests' tools a library dependency provides: h5dump comes with HDF5.
PROVIDED = {"h5dump": "hdf5"}
# Found by CMake but not a package of their own: the compiler's threads, git for the revision.
NOT_PACKAGES = {"Threads", "Git"}


def cmake_finds(path):
    text = path.read_text()
    found = {m.group(1): m.group(2) for m in re.finditer(r"find_package\((\w+)\s*([^)]*)\)", text)}
    found.update({m.group(1): "" for m in re.finditer(r"pkg_check_modules\(\w+[^)]*?\s(\w+)\)", text)})
    found.update({m.group(1): "" for m in re.finditer(r"find_program\(\w+\s+(\w+)", text)})
    return found


def recipe_depends(path):
    """[(spec, type, under +tests)] of the recipe's depends_on calls."""
    tree = ast.parse(path.read_text())
    out = []

    def visit(node, tests):
        for child in ast.iter_child_nodes(node):
            inside = tests
            if isinstance(child, ast.With):
                for item in child.items:
                    call = item.context_expr
                    if (isinstance(call, ast.Call) and getattr(call.func, "id", "") == "when"
                            and call.args and ast.literal_eval(call.args[0]) == "+tests"):
                        inside = True
            if (isinstance(child, ast.Call) and getattr(child.func, "id", "") == "depends_on"):
                kind = next((ast.literal_eval(k.value) for k in child.keywords if k.arg == "type"), "build,link,run")
                out.append((ast.literal_eval(child.args[0]), kind, tests))
            visit(child, inside)
    visit(tree, False)
    return out


def main(source):
    source = Path(source)
    failures = []
    library = cmake_finds(source / "cmake" / "FrictionDependencies.cmake")
    tests = cmake_finds(source / "cmake" / "FrictionTestTools.cmake")
    tests.update(cmake_finds(source / "tests" / "CMakeLists.txt"))
    depends = recipe_depends(source / "scripts" / "spack" / "packages" / "friction" / "package.py")
    by_name = {}
    for spec, kind, under_tests in depends:
        by_name.setdefault(re.match(r"[\w-]+", spec).group(0), []).append((spec, kind, under_tests))

    for name in library:
        if name in NOT_PACKAGES:
            continue
        if name not in LIBRARY:
            failures.append(f"cmake/FrictionDependencies.cmake finds {name}: add it to the Spack recipe "
                            f"and to this test's table")
        elif LIBRARY[name] not in by_name or any(t for _, _, t in by_name[LIBRARY[name]]):
            failures.append(f"the Spack recipe lacks depends_on('{LIBRARY[name]}') (CMake: {name})")
    for name in tests:
        if name in NOT_PACKAGES or name in library:
            continue
        if name in PROVIDED:
            if PROVIDED[name] not in by_name:
                failures.append(f"the Spack recipe lacks {PROVIDED[name]}, which provides {name} for the tests")
            continue
        if name not in TESTS:
            failures.append(f"the tests' CMake finds {name}: add it to the Spack recipe's +tests and this test's table")
        elif not any(t and "test" in k for _, k, t in by_name.get(TESTS[name], [])):
            failures.append(f"the Spack recipe lacks depends_on('{TESTS[name]}', type='test') under +tests "
                            f"(CMake: {name})")

    hdf5 = " ".join(spec for spec, _, _ in by_name.get("hdf5", []))
    for variant in ("+fortran", "+mpi"):
        if variant not in hdf5:
            failures.append(f"the Spack recipe's hdf5 lacks {variant} (CMake asks for Fortran and a parallel HDF5)")
    minimum = re.search(r"cmake_minimum_required\(VERSION ([\d.]+)\)", (source / "CMakeLists.txt").read_text()).group(1)
    if not any(spec == f"cmake@{minimum}:" for spec, _, _ in by_name.get("cmake", [])):
        failures.append(f"the Spack recipe should depend on cmake@{minimum}: (CMakeLists.txt's minimum)")
    pfunit = re.match(r"([\d.]+)", tests.get("PFUNIT", "")).group(1)
    if not any(spec.startswith(f"pfunit@{pfunit}:") for spec, _, _ in by_name.get("pfunit", [])):
        failures.append(f"the Spack recipe should depend on pfunit@{pfunit}: (the version CMake asks for)")
    recipe = (source / "scripts" / "spack" / "packages" / "friction" / "package.py").read_text()
    for option in re.findall(r'option\((FRICTION_\w+)', (source / "CMakeLists.txt").read_text()):
        if option == "FRICTION_BUILD_TESTS" and '"FRICTION_BUILD_TESTS"' not in recipe:
            failures.append("the Spack recipe does not set FRICTION_BUILD_TESTS from its tests variant")

    # The container: Debian, install-deps (holding every package CMake's messages name), no tests.
    definition = (source / "scripts" / "container" / "friction.def").read_text()
    deps_script = (source / "scripts" / "install-deps").read_text()
    packages = set(shlex.split(re.search(r"^packages=\((.*?)\)", deps_script, re.S | re.M).group(1),
                               comments=True))
    named = set()
    for match in re.finditer(r'friction_require\([^"]*"[^"]*"\s+"([^"]+)"\)',
                             (source / "cmake" / "FrictionDependencies.cmake").read_text()):
        named.update(match.group(1).split())
    for package in sorted(named - packages):
        failures.append(f"scripts/install-deps does not install {package}, which CMake's message names")
    for needed, why in (("From: debian:", "a Debian base (install-deps uses apt)"),
                        ("scripts/install-deps", "the project's own dependency script"),
                        ("-DFRICTION_BUILD_TESTS=OFF", "the program and library without the tests"),
                        ("cmake --install", "an installed program"),
                        ("friction --version", "a %test that runs the program")):
        if needed not in definition:
            failures.append(f"scripts/container/friction.def lacks {needed!r}: {why}")

    for failure in failures:
        print("FAIL:", failure)
    print(f"{len(library)} library and {len(tests)} test dependencies of CMake; "
          f"{len(depends)} depends_on in the Spack recipe; {len(failures)} failures")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
