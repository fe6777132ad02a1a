# Tests of scripts/plot_graphite.py, the plots of the lattice-sum (graphite)
# scene (label "scripts"):
#   scripts.graphite_map               friction computes a tiny graphite map (fixture):
#                                      inputs/graphite.nml + tests/data/graphite_small.nml
#   scripts.graphite_naf_map           friction computes a small NaF map (fixture), the
#                                      file without a crystal net the script must refuse
#   scripts.plot_graphite.run/.png     net and stacked-lines PNGs with the defaults
#   scripts.plot_graphite.options.*    the same with --whole, --component, --offset, --no-tip
#   scripts.plot_graphite.help         --help names the options
#   scripts.plot_graphite.<error>      bad input: exit code 2, a message naming the file,
#                                      no traceback (through expect_exit.py)
# A *.run test writes the PNGs, the matching *.png test checks them with
# check_png.py (complete PNG, more than 100 px each way, newer than the map).
#
# Included from tests/CMakeLists.txt, which must have run
#   find_package(Python3 COMPONENTS Interpreter REQUIRED)
# Needs h5py, matplotlib and numpy in that Python; without them configuration
# stops (a skipped test could hide a broken install).
#   ctest -L scripts            # run them all (with those of scripts.cmake)
#   ctest -R plot_graphite      # only these

set(_fg_scripts "${CMAKE_CURRENT_LIST_DIR}/../scripts")
set(_fg_inputs "${CMAKE_CURRENT_LIST_DIR}/../inputs")
set(_fg_tests "${CMAKE_CURRENT_LIST_DIR}")
set(_fg_work "${CMAKE_CURRENT_BINARY_DIR}/graphite_scripts")
file(MAKE_DIRECTORY "${_fg_work}")
set(_fg_map "${_fg_work}/graphite_small.h5")
set(_fg_naf "${_fg_work}/naf_small.h5")
set(_fg_check ${Python3_EXECUTABLE} "${_fg_tests}/check_png.py" --newer-than "${_fg_map}")
set(_fg_expect ${Python3_EXECUTABLE} "${_fg_tests}/expect_exit.py")
set(_fg_plot ${Python3_EXECUTABLE} "${_fg_scripts}/plot_graphite.py")

# (h5py, matplotlib, numpy: checked by cmake/FrictionTestTools.cmake.)

# ---- fixtures: the maps the plotting tests read ----
# Graphite: 3 lines x 24 points, trace only, 150-atom flake; about a second.
add_test(NAME scripts.graphite_map
  COMMAND $<TARGET_FILE:friction_app> --quiet --force -o "${_fg_map}"
          "${_fg_inputs}/graphite.nml" "${_fg_tests}/data/graphite_small.nml"
  WORKING_DIRECTORY "${_fg_work}")
set_tests_properties(scripts.graphite_map PROPERTIES FIXTURES_SETUP scripts_graphite_map)

# NaF: an AFM map without /surface, which plot_graphite.py must refuse.
add_test(NAME scripts.graphite_naf_map
  COMMAND $<TARGET_FILE:friction_app> --quiet --force -o "${_fg_naf}"
          "${_fg_inputs}/naf.nml" "${_fg_tests}/data/small.nml"
  WORKING_DIRECTORY "${_fg_work}")
set_tests_properties(scripts.graphite_naf_map PROPERTIES
  FIXTURES_SETUP scripts_graphite_naf_map)

# ---- the PNGs ----
add_test(NAME scripts.plot_graphite.run
  COMMAND ${_fg_plot} "${_fg_map}" -o "${_fg_work}/default"
  WORKING_DIRECTORY "${_fg_work}")
set_tests_properties(scripts.plot_graphite.run PROPERTIES
  FIXTURES_REQUIRED scripts_graphite_map FIXTURES_SETUP scripts_plot_graphite
  PASS_REGULAR_EXPRESSION "wrote .*graphite_small_net\\.png.*wrote .*graphite_small_lines\\.png")

add_test(NAME scripts.plot_graphite.png
  COMMAND ${_fg_check} "${_fg_work}/default/graphite_small_net.png"
                       "${_fg_work}/default/graphite_small_lines.png")
set_tests_properties(scripts.plot_graphite.png PROPERTIES
  FIXTURES_REQUIRED "scripts_graphite_map;scripts_plot_graphite")

add_test(NAME scripts.plot_graphite.options.run
  COMMAND ${_fg_plot} "${_fg_map}" --whole --no-tip --component f_along --offset 0.5
          --dpi 80 -o "${_fg_work}/options"
  WORKING_DIRECTORY "${_fg_work}")
set_tests_properties(scripts.plot_graphite.options.run PROPERTIES
  FIXTURES_REQUIRED scripts_graphite_map FIXTURES_SETUP scripts_plot_graphite_options)

add_test(NAME scripts.plot_graphite.options.png
  COMMAND ${_fg_check} "${_fg_work}/options/graphite_small_net.png"
                       "${_fg_work}/options/graphite_small_lines.png")
set_tests_properties(scripts.plot_graphite.options.png PROPERTIES
  FIXTURES_REQUIRED "scripts_graphite_map;scripts_plot_graphite_options")

add_test(NAME scripts.plot_graphite.help COMMAND ${_fg_plot} --help)
set_tests_properties(scripts.plot_graphite.help PROPERTIES
  PASS_REGULAR_EXPRESSION "usage: plot_graphite.py.*--component.*--output-dir.*--dpi")

# ---- bad input: exit 2, the file named, no traceback ----
add_test(NAME scripts.plot_graphite.not_lattice_sum
  COMMAND ${_fg_expect} 2 --stderr "naf_small\\.h5: not a lattice-sum scene: no /surface/atoms"
          -- ${_fg_plot} "${_fg_naf}" -o "${_fg_work}/not_lattice_sum"
  WORKING_DIRECTORY "${_fg_work}")
set_tests_properties(scripts.plot_graphite.not_lattice_sum PROPERTIES
  FIXTURES_REQUIRED scripts_graphite_naf_map)

add_test(NAME scripts.plot_graphite.missing_file
  COMMAND ${_fg_expect} 2 --stderr "no_such_map\\.h5: no such file"
          -- ${_fg_plot} no_such_map.h5 -o "${_fg_work}/missing_file"
  WORKING_DIRECTORY "${_fg_work}")

add_test(NAME scripts.plot_graphite.not_hdf5
  COMMAND ${_fg_expect} 2 --stderr "graphite_small\\.nml: .*HDF5"
          -- ${_fg_plot} "${_fg_tests}/data/graphite_small.nml" -o "${_fg_work}/not_hdf5"
  WORKING_DIRECTORY "${_fg_work}")

add_test(NAME scripts.plot_graphite.no_retrace
  COMMAND ${_fg_expect} 2 --stderr "graphite_small\\.h5: no /afm/retrace"
          -- ${_fg_plot} "${_fg_map}" --trip retrace -o "${_fg_work}/no_retrace"
  WORKING_DIRECTORY "${_fg_work}")
set_tests_properties(scripts.plot_graphite.no_retrace PROPERTIES
  FIXTURES_REQUIRED scripts_graphite_map)

# All of them: label, and a bound on a hung run.
set(_fg_all scripts.graphite_map scripts.graphite_naf_map
  scripts.plot_graphite.run scripts.plot_graphite.png
  scripts.plot_graphite.options.run scripts.plot_graphite.options.png
  scripts.plot_graphite.help scripts.plot_graphite.not_lattice_sum
  scripts.plot_graphite.missing_file scripts.plot_graphite.not_hdf5
  scripts.plot_graphite.no_retrace)
set_property(TEST ${_fg_all} APPEND PROPERTY LABELS scripts)
set_tests_properties(${_fg_all} PROPERTIES TIMEOUT 120)
