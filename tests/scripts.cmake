# Tests of the plotting scripts in scripts/ (label "scripts"):
#   scripts.small_map         friction computes a small NaF map (fixture)
#   scripts.plot_afm.*        plot_afm.py: maps and loop PNGs, --help, errors
#   scripts.gnuplot.*         afm_maps_gnuplot.sh + afm_maps.gp: maps PNG, errors
# A *.run test writes the PNGs, the matching *.png test checks them with
# check_png.py (complete PNG, more than 100 px each way, newer than the map).
# Error paths go through expect_exit.py, which wants exit code 2 exactly, a
# message naming the file and no traceback.
#
# Included from tests/CMakeLists.txt, which must have run
#   find_package(Python3 COMPONENTS Interpreter REQUIRED)
# The plot_afm.py tests need h5py and matplotlib in that Python, the gnuplot
# ones h5dump and gnuplot; without them configuration stops (a test that is
# skipped could hide a broken install).
#   ctest -L scripts            # run them all

set(_fs_scripts "${CMAKE_CURRENT_LIST_DIR}/../scripts")
set(_fs_inputs "${CMAKE_CURRENT_LIST_DIR}/../inputs")
set(_fs_tests "${CMAKE_CURRENT_LIST_DIR}")
set(_fs_work "${CMAKE_CURRENT_BINARY_DIR}/scripts")
file(MAKE_DIRECTORY "${_fs_work}")
set(_fs_map "${_fs_work}/small.h5")
set(_fs_check ${Python3_EXECUTABLE} "${_fs_tests}/check_png.py" --newer-than "${_fs_map}")
set(_fs_expect ${Python3_EXECUTABLE} "${_fs_tests}/expect_exit.py")
set(_fs_plot ${Python3_EXECUTABLE} "${_fs_scripts}/plot_afm.py")
set(_fs_gnuplot sh "${_fs_scripts}/afm_maps_gnuplot.sh")

# What the plotting routes need besides Python itself.
# (Found, or configuration stopped naming what is missing, by cmake/FrictionTestTools.cmake.)
set(_fs_no_python_modules OFF)
set(_fs_no_gnuplot OFF)
set(_fs_gnuplot_env "GNUPLOT=${FRICTION_GNUPLOT_EXECUTABLE}" "H5DUMP=${FRICTION_H5DUMP_EXECUTABLE}")

# The map every plotting test reads: 40 x 10 samples, trace and retrace.
add_test(NAME scripts.small_map
  COMMAND $<TARGET_FILE:friction_app> --quiet --force -o "${_fs_map}"
          "${_fs_inputs}/naf.nml" "${_fs_tests}/data/small.nml"
  WORKING_DIRECTORY "${_fs_work}")
set_tests_properties(scripts.small_map PROPERTIES FIXTURES_SETUP scripts_small_map)

# ---- matplotlib route: scripts/plot_afm.py ----
add_test(NAME scripts.plot_afm.run
  COMMAND ${_fs_plot} "${_fs_map}" -o "${_fs_work}/plot_afm"
  WORKING_DIRECTORY "${_fs_work}")
set_tests_properties(scripts.plot_afm.run PROPERTIES
  FIXTURES_REQUIRED scripts_small_map FIXTURES_SETUP scripts_plot_afm
  DISABLED ${_fs_no_python_modules})

add_test(NAME scripts.plot_afm.png
  COMMAND ${_fs_check} "${_fs_work}/plot_afm/small_maps.png" "${_fs_work}/plot_afm/small_loop.png")
set_tests_properties(scripts.plot_afm.png PROPERTIES
  FIXTURES_REQUIRED "scripts_small_map;scripts_plot_afm"
  DISABLED ${_fs_no_python_modules})

add_test(NAME scripts.plot_afm.help COMMAND ${_fs_plot} --help)
set_tests_properties(scripts.plot_afm.help PROPERTIES
  PASS_REGULAR_EXPRESSION "usage: plot_afm.py.*--output-dir.*--dpi"
  DISABLED ${_fs_no_python_modules})

add_test(NAME scripts.plot_afm.missing_file
  COMMAND ${_fs_expect} 2 --stderr "no_such_map\\.h5: no such file"
          -- ${_fs_plot} no_such_map.h5
  WORKING_DIRECTORY "${_fs_work}")

add_test(NAME scripts.plot_afm.not_a_map
  COMMAND ${_fs_expect} 2 --stderr "small\\.nml: .*HDF5"
          -- ${_fs_plot} "${_fs_tests}/data/small.nml" -o "${_fs_work}/not_a_map"
  WORKING_DIRECTORY "${_fs_work}")

add_test(NAME scripts.plot_afm.line_out_of_range
  COMMAND ${_fs_expect} 2 --stderr "small\\.h5: --line 10 out of range"
          -- ${_fs_plot} "${_fs_map}" --line 10 -o "${_fs_work}/bad_line"
  WORKING_DIRECTORY "${_fs_work}")
set_tests_properties(scripts.plot_afm.line_out_of_range PROPERTIES
  FIXTURES_REQUIRED scripts_small_map)
set_tests_properties(scripts.plot_afm.missing_file scripts.plot_afm.not_a_map
  scripts.plot_afm.line_out_of_range PROPERTIES DISABLED ${_fs_no_python_modules})

# ---- gnuplot route: scripts/afm_maps_gnuplot.sh + scripts/afm_maps.gp ----
add_test(NAME scripts.gnuplot.run
  COMMAND ${_fs_gnuplot} "${_fs_map}"
  WORKING_DIRECTORY "${_fs_work}")
set_tests_properties(scripts.gnuplot.run PROPERTIES
  FIXTURES_REQUIRED scripts_small_map FIXTURES_SETUP scripts_gnuplot)

add_test(NAME scripts.gnuplot.png
  COMMAND ${_fs_check} "${_fs_work}/small_maps_gnuplot.png")
set_tests_properties(scripts.gnuplot.png PROPERTIES
  FIXTURES_REQUIRED "scripts_small_map;scripts_gnuplot")

add_test(NAME scripts.gnuplot.missing_file
  COMMAND ${_fs_expect} 2 --stderr "no_such_map\\.h5: no such file"
          -- ${_fs_gnuplot} no_such_map.h5
  WORKING_DIRECTORY "${_fs_work}")
set_tests_properties(scripts.gnuplot.run scripts.gnuplot.png scripts.gnuplot.missing_file
  PROPERTIES ENVIRONMENT "${_fs_gnuplot_env}" DISABLED ${_fs_no_gnuplot})

# All of them: label, and a bound on a hung plot.
set(_fs_all scripts.small_map
  scripts.plot_afm.run scripts.plot_afm.png scripts.plot_afm.help scripts.plot_afm.missing_file
  scripts.plot_afm.not_a_map scripts.plot_afm.line_out_of_range
  scripts.gnuplot.run scripts.gnuplot.png scripts.gnuplot.missing_file)
set_property(TEST ${_fs_all} APPEND PROPERTY LABELS scripts)
set_tests_properties(${_fs_all} PROPERTIES TIMEOUT 120)
