# The tools the test suite needs and the library does not: pFUnit, ngspice,
# gnuplot, h5dump, and h5py, matplotlib, numpy and pytest in the Python that
# runs the tests.  Included from tests/CMakeLists.txt only, so a build with
# -DFRICTION_BUILD_TESTS=OFF needs none of them.  Every missing one is named
# in one message, with its Debian package.

set(friction_missing_tools "")
macro(friction_test_tool found what remedy)
  if(NOT ${found})
    string(APPEND friction_missing_tools "\n  ${what}: ${remedy}")
  endif()
endmacro()

# Besides CMAKE_PREFIX_PATH, where scripts/install-deps --tests puts pFUnit
# (scripts/pfunit-prefix): FRICTION_PFUNIT_PREFIX, this clone's .deps/ of
# older versions, and the per-user cache every clone shares, so that a plain
# `cmake -S . -B build` finds it.
if(DEFINED ENV{XDG_CACHE_HOME} AND NOT "$ENV{XDG_CACHE_HOME}" STREQUAL "")
  set(friction_user_cache "$ENV{XDG_CACHE_HOME}")
else()
  set(friction_user_cache "$ENV{HOME}/.cache")
endif()
find_package(PFUNIT 4.14 QUIET HINTS $ENV{FRICTION_PFUNIT_PREFIX} ${PROJECT_SOURCE_DIR}/.deps/pfunit-4.14.0/install
  "${friction_user_cache}/friction/pfunit-4.14.0-${CMAKE_Fortran_COMPILER_ID}-${CMAKE_Fortran_COMPILER_VERSION}")
friction_test_tool(PFUNIT_FOUND "pFUnit 4.14" "not packaged by Debian: scripts/install-deps builds it \
with --tests into a per-user prefix outside the repository (scripts/pfunit-prefix prints it), where this \
configuration looks; or configure with -DFRICTION_BUILD_TESTS=OFF for the program and the library alone")
find_program(FRICTION_NGSPICE_EXECUTABLE ngspice DOC "ngspice, for the netlist tests")
friction_test_tool(FRICTION_NGSPICE_EXECUTABLE "ngspice" "Debian package ngspice")
find_program(FRICTION_GNUPLOT_EXECUTABLE gnuplot DOC "gnuplot, for the scripts tests")
friction_test_tool(FRICTION_GNUPLOT_EXECUTABLE "gnuplot" "Debian package gnuplot-nox")
find_program(FRICTION_H5DUMP_EXECUTABLE h5dump DOC "h5dump (hdf5-tools), for the scripts tests")
friction_test_tool(FRICTION_H5DUMP_EXECUTABLE "h5dump" "Debian package hdf5-tools")
foreach(module h5py matplotlib numpy pytest)
  execute_process(COMMAND ${Python3_EXECUTABLE} -c "import ${module}"
                  RESULT_VARIABLE friction_module_status OUTPUT_QUIET ERROR_QUIET)
  if(friction_module_status EQUAL 0)
    set(friction_module_found ON)
  else()
    set(friction_module_found OFF)
  endif()
  friction_test_tool(friction_module_found "the Python module ${module} in ${Python3_EXECUTABLE}"
                     "Debian package python3-${module}, or python3 -m pip install ${module}")
endforeach()
if(friction_missing_tools)
  message(FATAL_ERROR "The tests need tools that were not found:${friction_missing_tools}\n"
    "scripts/install-deps installs them all; or configure with -DFRICTION_BUILD_TESTS=OFF to build "
    "the library and the program only.")
endif()
