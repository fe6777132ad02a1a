# Tests of scripts/work_precision.py and of method = 'auto' (labels "scripts", "cli"):
#   work_precision.quick   the --quick ladder (naf, brake_switched; rkf45, rk8pd,
#                          rk4imp; rtol 1e-4, 1e-6, 1e-8) and a small failure map,
#                          with the --extra hook (fixture, about 20 s)
#   work_precision.data    the HDF5 files: errors fall as the tolerance tightens
#                          (rkf45, rk8pd), the reference passes its own check,
#                          the failure map's categories (tests/check_work_precision.py)
#   work_precision.png     the three PNGs are complete images
#   work_precision.add     --add-to adds rodas4 to a copy of those files: nothing
#                          measured before changes, the failure map's categories
#                          follow its rule (tests/check_work_precision_add.py)
#   auto-method            method = 'auto' resolves to docs/speed.md's table and
#                          runs as the named method (CLI and C API)
# Included from tests/CMakeLists.txt after scripts.cmake (which checks for
# h5py and matplotlib and defines the helpers used here).

set(_wp_work "${CMAKE_CURRENT_BINARY_DIR}/work_precision")
file(MAKE_DIRECTORY "${_wp_work}")

add_test(NAME work_precision.quick
  COMMAND ${Python3_EXECUTABLE} "${_fs_scripts}/work_precision.py" --quick
          --binary $<TARGET_FILE:friction_app> --out "${_wp_work}"
          --extra "${_fs_tests}/data/extra_series.json"
  WORKING_DIRECTORY "${_wp_work}")
set_tests_properties(work_precision.quick PROPERTIES FIXTURES_SETUP work_precision_quick
  LABELS scripts TIMEOUT 300)

add_test(NAME work_precision.data
  COMMAND ${Python3_EXECUTABLE} "${_fs_tests}/check_work_precision.py" "${_wp_work}")
set_tests_properties(work_precision.data PROPERTIES FIXTURES_REQUIRED work_precision_quick
  LABELS scripts)

add_test(NAME work_precision.png
  COMMAND ${Python3_EXECUTABLE} "${_fs_tests}/check_png.py" --newer-than "${_wp_work}/work_precision.h5"
          "${_wp_work}/work_precision_naf.png" "${_wp_work}/work_precision_brake_switched.png"
          "${_wp_work}/failure_map.png")
set_tests_properties(work_precision.png PROPERTIES FIXTURES_REQUIRED work_precision_quick
  LABELS scripts)

add_test(NAME work_precision.add
  COMMAND ${Python3_EXECUTABLE} "${_fs_tests}/check_work_precision_add.py" --script "${_fs_scripts}/work_precision.py"
          --binary $<TARGET_FILE:friction_app> --from "${_wp_work}" --workdir "${_wp_work}/add")
set_tests_properties(work_precision.add PROPERTIES FIXTURES_REQUIRED work_precision_quick
  LABELS scripts TIMEOUT 300)

add_test(NAME auto-method
  COMMAND ${Python3_EXECUTABLE} "${_fs_tests}/auto_method_test.py"
          --binary $<TARGET_FILE:friction_app> --inputs "${_fs_inputs}"
          --workdir "${CMAKE_CURRENT_BINARY_DIR}/auto_method" --library $<TARGET_FILE:friction>)
set_tests_properties(auto-method PROPERTIES LABELS "cli;capi" TIMEOUT 300)

# The paper's network model in ngspice on the chart of the line it models.
add_test(NAME work_precision.ngspice
  COMMAND ${Python3_EXECUTABLE} "${_fs_scripts}/work_precision.py" --quick --ngspice --scenes naf_trace
          --methods rkf45 --no-failure-map --binary $<TARGET_FILE:friction_app> --out "${_wp_work}/ngspice"
  WORKING_DIRECTORY "${_wp_work}")
set_tests_properties(work_precision.ngspice PROPERTIES FIXTURES_SETUP work_precision_ngspice
  LABELS "scripts;netlist" TIMEOUT 300)
add_test(NAME work_precision.ngspice_data
  COMMAND ${Python3_EXECUTABLE} "${_fs_tests}/check_ngspice_series.py" "${_wp_work}/ngspice")
set_tests_properties(work_precision.ngspice_data PROPERTIES FIXTURES_REQUIRED work_precision_ngspice
  LABELS "scripts;netlist")
