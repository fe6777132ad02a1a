# Finds GSL, FFTW3, LAPACK, parallel HDF5 with Fortran and the serial build of
# the same HDF5 (for the serial program), and MPI with mpi_f08.  A
# missing dependency stops configuration with the Debian package to install
# (scripts/install-deps installs them all).

macro(friction_require found what package)
  if(NOT ${found})
    message(FATAL_ERROR
      "friction needs ${what}, which was not found.\n"
      "On Debian/Ubuntu: sudo apt-get install ${package}\n"
      "(or run scripts/install-deps, which installs every dependency)")
  endif()
endmacro()

find_package(MPI COMPONENTS Fortran C QUIET)
friction_require(MPI_Fortran_FOUND "MPI for Fortran" "libopenmpi-dev openmpi-bin")
if(NOT MPI_Fortran_HAVE_F08_MODULE)
  message(FATAL_ERROR "friction needs the MPI Fortran 2008 bindings (mpi_f08).\n"
    "On Debian/Ubuntu: sudo apt-get install libopenmpi-dev")
endif()

find_package(GSL QUIET)
friction_require(GSL_FOUND "the GNU Scientific Library" "libgsl-dev")

find_package(PkgConfig QUIET)
friction_require(PKG_CONFIG_FOUND "pkg-config" "pkg-config")
pkg_check_modules(FFTW3 QUIET IMPORTED_TARGET fftw3)
friction_require(FFTW3_FOUND "FFTW3" "libfftw3-dev")

# LAPACK's dgeev: the multipliers of a periodic orbit whose section has more
# than 3 coordinates (a law with several internal states).
find_package(LAPACK QUIET)
friction_require(LAPACK_FOUND "LAPACK" "liblapack-dev")
# The program links the reference LAPACK and BLAS's static archives where
# Debian ships them (liblapack-dev, libblas-dev), as it does HDF5's: the
# shared liblapack.so may be OpenBLAS behind Debian's alternatives, whose
# thread pool starts whenever it is loaded and tripled the program's start-up
# (docs/speed.md) for eigenvalues of a few rows.  Without the archives, or
# with -DFRICTION_STATIC_LAPACK=OFF, the LAPACK that FindLAPACK found; the
# shared library always links that one (Debian's libblas.a is not
# position-independent).
option(FRICTION_STATIC_LAPACK "Link the program with the reference LAPACK and BLAS's static archives" ON)
find_library(FRICTION_LAPACK_ARCHIVE NAMES liblapack.a
  PATHS /usr/lib/${CMAKE_LIBRARY_ARCHITECTURE}/lapack NO_DEFAULT_PATH)
find_library(FRICTION_BLAS_ARCHIVE NAMES libblas.a
  PATHS /usr/lib/${CMAKE_LIBRARY_ARCHITECTURE}/blas NO_DEFAULT_PATH)
add_library(friction::lapack_program INTERFACE IMPORTED)
if(FRICTION_STATIC_LAPACK AND FRICTION_LAPACK_ARCHIVE AND FRICTION_BLAS_ARCHIVE)
  target_link_libraries(friction::lapack_program INTERFACE ${FRICTION_LAPACK_ARCHIVE} ${FRICTION_BLAS_ARCHIVE})
  set(friction_static_lapack ON)
else()
  target_link_libraries(friction::lapack_program INTERFACE LAPACK::LAPACK)
  set(friction_static_lapack OFF)
endif()
message(STATUS "friction: the program links the reference LAPACK's static archives: ${friction_static_lapack}")

# The program links GSL's and FFTW's static archives where Debian ships them
# (libgsl-dev, libfftw3-dev), as it does HDF5's: the shared libfftw3 is
# bound at load (BIND_NOW) with some 950 symbol lookups for its codelet
# tables, a quarter of the loader's work at every start (docs/speed.md, The
# friction laws), for a spectrum most runs never take.  Without the
# archives, or with -DFRICTION_STATIC_NUMERICS=OFF, the shared libraries;
# the shared library always links those.
option(FRICTION_STATIC_NUMERICS "Link the program with GSL's and FFTW's static archives" ON)
find_library(FRICTION_GSL_ARCHIVE NAMES libgsl.a)
find_library(FRICTION_GSLCBLAS_ARCHIVE NAMES libgslcblas.a)
find_library(FRICTION_FFTW_ARCHIVE NAMES libfftw3.a)
add_library(friction::numerics_program INTERFACE IMPORTED)
set(FRICTION_PROGRAM_STATIC_NUMERICS OFF)
if(FRICTION_STATIC_NUMERICS AND FRICTION_GSL_ARCHIVE AND FRICTION_GSLCBLAS_ARCHIVE AND FRICTION_FFTW_ARCHIVE)
  # Archives without position-independent code cannot go into the program
  # (position-independent): a small program linked the same way tells.
  include(CheckCSourceCompiles)
  set(CMAKE_REQUIRED_LIBRARIES ${FRICTION_GSL_ARCHIVE} ${FRICTION_GSLCBLAS_ARCHIVE} ${FRICTION_FFTW_ARCHIVE} m)
  set(CMAKE_REQUIRED_QUIET ON)
  check_c_source_compiles("#include <stddef.h>
double gsl_sf_bessel_J0(double);
void *fftw_malloc(size_t);
void fftw_free(void *);
int main(void) { void *p = fftw_malloc(8); fftw_free(p); return gsl_sf_bessel_J0(0.0) > 2.0; }"
    FRICTION_NUMERICS_ARCHIVES_LINK)
  unset(CMAKE_REQUIRED_LIBRARIES)
  unset(CMAKE_REQUIRED_QUIET)
  if(FRICTION_NUMERICS_ARCHIVES_LINK)
    target_link_libraries(friction::numerics_program INTERFACE
      ${FRICTION_GSL_ARCHIVE} ${FRICTION_GSLCBLAS_ARCHIVE} ${FRICTION_FFTW_ARCHIVE} m)
    set(FRICTION_PROGRAM_STATIC_NUMERICS ON)
  endif()
endif()
message(STATUS "friction: the program links GSL's and FFTW's static archives: ${FRICTION_PROGRAM_STATIC_NUMERICS}")

# Parallel HDF5 with its Fortran interface, and its high-level library (the
# dimension scales).  FindHDF5 asks the h5pfc wrapper.
set(HDF5_PREFER_PARALLEL TRUE)
find_package(HDF5 QUIET COMPONENTS Fortran HL)
friction_require(HDF5_FOUND "HDF5 with Fortran support and its high-level library" "libhdf5-openmpi-dev")
if(NOT HDF5_IS_PARALLEL)
  message(FATAL_ERROR "friction needs the parallel (MPI) build of HDF5, found a serial one.\n"
    "On Debian/Ubuntu: sudo apt-get install libhdf5-openmpi-dev")
endif()
add_library(friction::hdf5_headers INTERFACE IMPORTED)
target_include_directories(friction::hdf5_headers INTERFACE ${HDF5_Fortran_INCLUDE_DIRS} ${HDF5_INCLUDE_DIRS})
target_compile_definitions(friction::hdf5_headers INTERFACE ${HDF5_Fortran_DEFINITIONS})
add_library(friction::hdf5 INTERFACE IMPORTED)
target_link_libraries(friction::hdf5 INTERFACE friction::hdf5_headers
  ${HDF5_HL_LIBRARIES} ${HDF5_Fortran_LIBRARIES} ${HDF5_LIBRARIES})

# The program's HDF5: each of HDF5's own shared libraries replaced by the
# static archive beside it, when there is one (Debian's libhdf5-*-dev ship
# them); the other libraries HDF5 names stay as they are.  Without the
# archives, or with -DFRICTION_STATIC_HDF5=OFF, the shared ones.
option(FRICTION_STATIC_HDF5 "Link the friction program with HDF5's static archives" ON)
set(friction_hdf5_program_libraries)
foreach(library IN LISTS HDF5_HL_LIBRARIES HDF5_Fortran_LIBRARIES HDF5_LIBRARIES)
  get_filename_component(library_name "${library}" NAME)
  string(REGEX REPLACE "\\.so$" ".a" archive "${library}")
  if(FRICTION_STATIC_HDF5 AND library_name MATCHES "^libhdf5.*\\.so$" AND EXISTS "${archive}")
    list(APPEND friction_hdf5_program_libraries "${archive}")
  else()
    list(APPEND friction_hdf5_program_libraries "${library}")
  endif()
endforeach()
list(REMOVE_DUPLICATES friction_hdf5_program_libraries)
set(FRICTION_PROGRAM_STATIC_HDF5 OFF)
if(friction_hdf5_program_libraries MATCHES "libhdf5[^;]*\\.a(;|$)")
  # Archives built without position-independent code (some sites' own
  # HDF5) cannot go into the program, which the compiler makes
  # position-independent: a small program linked the same way tells, and
  # without it the shared libraries serve.
  include(CheckFortranSourceCompiles)
  set(CMAKE_REQUIRED_INCLUDES ${HDF5_Fortran_INCLUDE_DIRS} ${HDF5_INCLUDE_DIRS})
  set(CMAKE_REQUIRED_LIBRARIES ${friction_hdf5_program_libraries} MPI::MPI_C)
  set(CMAKE_REQUIRED_LINK_OPTIONS "LINKER:--as-needed")
  set(CMAKE_REQUIRED_QUIET ON)
  check_fortran_source_compiles("program probe\n  use hdf5\n  integer :: status\n  call h5open_f(status)\nend program probe\n"
    FRICTION_HDF5_ARCHIVES_LINK SRC_EXT F90)
  unset(CMAKE_REQUIRED_INCLUDES)
  unset(CMAKE_REQUIRED_LIBRARIES)
  unset(CMAKE_REQUIRED_LINK_OPTIONS)
  unset(CMAKE_REQUIRED_QUIET)
  if(FRICTION_HDF5_ARCHIVES_LINK)
    set(FRICTION_PROGRAM_STATIC_HDF5 ON)
  else()
    set(friction_hdf5_program_libraries ${HDF5_HL_LIBRARIES} ${HDF5_Fortran_LIBRARIES} ${HDF5_LIBRARIES})
  endif()
endif()
message(STATUS "friction: the program links HDF5's static archives: ${FRICTION_PROGRAM_STATIC_HDF5}")
add_library(friction::hdf5_program INTERFACE IMPORTED)
# (MPI after the archives: they call it, and a static archive's needs are
# met only by libraries that follow it.)
target_link_libraries(friction::hdf5_program INTERFACE friction::hdf5_headers
  ${friction_hdf5_program_libraries} MPI::MPI_C)

# The serial program's HDF5 (docs/layout.md, The two programs): Debian's
# serial build of the same HDF5 (libhdf5-dev), whose libraries link no MPI,
# in place of each of the parallel build's own libraries, archives or
# shared as above.  The code is compiled once, against the parallel
# build's Fortran modules: the two builds are of one HDF5 source, the
# serial one without the MPI-IO driver, which only the MPI side of
# src/friction/core/parallel.f90 calls; so the versions must be the same.
# Without a serial HDF5 of that version (a cluster's modules, say) the
# program friction is the parallel one, as friction-mpi is, and says so.
find_path(FRICTION_SERIAL_HDF5_DIR NAMES libhdf5_fortran.so libhdf5_fortran.a
  PATHS /usr/lib/${CMAKE_LIBRARY_ARCHITECTURE}/hdf5/serial NO_DEFAULT_PATH
  DOC "The folder of the serial HDF5's libraries (libhdf5_fortran), for the serial program")
set(FRICTION_SERIAL_PROGRAM OFF)
set(friction_serial_why "no serial HDF5 (on Debian/Ubuntu: sudo apt-get install libhdf5-dev)")
if(FRICTION_SERIAL_HDF5_DIR)
  set(FRICTION_SERIAL_PROGRAM ON)
  set(friction_hdf5_serial_program_libraries)
  set(friction_parallel_hdf5_dir "")
  foreach(library IN LISTS friction_hdf5_program_libraries)
    get_filename_component(library_name "${library}" NAME)
    if(library_name MATCHES "^libhdf5.*\\.(a|so)$")
      get_filename_component(friction_parallel_hdf5_dir "${library}" DIRECTORY)
      set(serial_library "${FRICTION_SERIAL_HDF5_DIR}/${library_name}")
      if(NOT EXISTS "${serial_library}")
        set(FRICTION_SERIAL_PROGRAM OFF)
        set(friction_serial_why "the serial HDF5 in ${FRICTION_SERIAL_HDF5_DIR} has no ${library_name}")
      endif()
      list(APPEND friction_hdf5_serial_program_libraries "${serial_library}")
    elseif(NOT library_name MATCHES "mpi")
      list(APPEND friction_hdf5_serial_program_libraries "${library}")
    endif()
  endforeach()
  # The same version: each build's libhdf5.settings says which.
  foreach(build parallel serial)
    if(build STREQUAL "parallel")
      set(settings "${friction_parallel_hdf5_dir}/libhdf5.settings")
    else()
      set(settings "${FRICTION_SERIAL_HDF5_DIR}/libhdf5.settings")
    endif()
    set(friction_hdf5_${build}_version "unknown")
    if(EXISTS "${settings}")
      file(STRINGS "${settings}" version_line REGEX "HDF5 Version:")
      string(REGEX REPLACE ".*HDF5 Version: *([^ ]+).*" "\\1" friction_hdf5_${build}_version "${version_line}")
    endif()
  endforeach()
  if(FRICTION_SERIAL_PROGRAM AND (NOT friction_hdf5_parallel_version STREQUAL friction_hdf5_serial_version
     OR friction_hdf5_serial_version STREQUAL "unknown"))
    set(FRICTION_SERIAL_PROGRAM OFF)
    set(friction_serial_why "the serial HDF5 (${FRICTION_SERIAL_HDF5_DIR}) is version "
      "${friction_hdf5_serial_version}, the parallel one ${friction_hdf5_parallel_version}")
  endif()
endif()
add_library(friction::hdf5_serial_program INTERFACE IMPORTED)
if(FRICTION_SERIAL_PROGRAM)
  message(STATUS "friction: the program friction is serial (loads no MPI), with the HDF5 in ${FRICTION_SERIAL_HDF5_DIR}")
  target_link_libraries(friction::hdf5_serial_program INTERFACE friction::hdf5_headers
    ${friction_hdf5_serial_program_libraries})
else()
  string(CONCAT friction_serial_why ${friction_serial_why})
  message(STATUS "friction: the program friction is the parallel one, as friction-mpi: ${friction_serial_why}")
endif()
