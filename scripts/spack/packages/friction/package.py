# Spack recipe for friction, from a clone of the repository:
#   spack repo add scripts/spack
#   spack dev-build -d . friction@main          # builds this clone, no download
#   spack dev-build -d . --test=root friction@main +tests   # and runs the test suite
# Its dependencies are those CMake looks for (cmake/FrictionDependencies.cmake,
# cmake/FrictionTestTools.cmake); the test `packaging-recipes` checks that they agree.
from spack.package import *


class Friction(CMakePackage):
    """Dry friction from the atomic scale to the machine scale: AFM friction
    maps over NaF, HOPG and graphite, machine-scale friction laws and
    mechanisms, the Girling brake's stick-slip and chaos diagnostics."""

    maintainers("friction-developers")
    license("BSD-3-Clause")

    version("main")

    variant("tests", default=False, description="Build the test suite (pFUnit, Python tests)")
    variant("cpu_target", default="x86-64-v2",
            description="Processor of the Fortran code (-march=VALUE; 'none' for the compiler's default)")

    depends_on("c", type="build")
    depends_on("fortran", type="build")
    depends_on("cmake@3.20:", type="build")
    depends_on("pkgconfig", type="build")

    depends_on("mpi")
    depends_on("hdf5@1.10:+fortran+mpi")
    depends_on("gsl")
    depends_on("fftw-api@3")
    depends_on("lapack")

    with when("+tests"):
        depends_on("pfunit@4.14:+mpi", type="test")
        depends_on("ngspice", type="test")
        depends_on("gnuplot", type="test")
        depends_on("python@3.9:", type="test")
        depends_on("py-numpy", type="test")
        depends_on("py-h5py", type="test")
        depends_on("py-matplotlib", type="test")
        depends_on("py-scipy", type="test")
        depends_on("py-xarray", type="test")
        depends_on("py-pytest", type="test")

    def cmake_args(self):
        target = self.spec.variants["cpu_target"].value
        return [
            self.define_from_variant("FRICTION_BUILD_TESTS", "tests"),
            self.define("FRICTION_CPU_TARGET", "" if target == "none" else target),
            # Spack's HDF5 may come without the static archives Debian ships.
            self.define("FRICTION_STATIC_HDF5", False),
        ]

    def check(self):
        with working_dir(self.build_directory):
            ctest("--output-on-failure")
