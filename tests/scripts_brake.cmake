# Tests of scripts/plot_brake.py (label "scripts"), in the manner of
# scripts.cmake:
#   scripts.brake_run               friction computes a short brake run (fixture)
#   scripts.plot_brake.*            phase plane and x(tau) PNGs, --help, errors
# Included from tests/CMakeLists.txt after scripts.cmake (which checks for
# h5py and matplotlib and defines the helpers used here).

set(_fb_work "${CMAKE_CURRENT_BINARY_DIR}/scripts_brake")
file(MAKE_DIRECTORY "${_fb_work}")
set(_fb_run "${_fb_work}/brake_short.h5")
set(_fb_plot ${Python3_EXECUTABLE} "${_fs_scripts}/plot_brake.py")
set(_fb_check ${Python3_EXECUTABLE} "${_fs_tests}/check_png.py" --newer-than "${_fb_run}")

add_test(NAME scripts.brake_run
  COMMAND $<TARGET_FILE:friction_app> --quiet --force -o "${_fb_run}"
          "${_fs_inputs}/brake.nml" "${_fs_tests}/data/brake_short.nml"
  WORKING_DIRECTORY "${_fb_work}")
set_tests_properties(scripts.brake_run PROPERTIES FIXTURES_SETUP scripts_brake_run)

add_test(NAME scripts.plot_brake.run
  COMMAND ${_fb_plot} "${_fb_run}" --window 100 300 -o "${_fb_work}/plots"
  WORKING_DIRECTORY "${_fb_work}")
set_tests_properties(scripts.plot_brake.run PROPERTIES
  FIXTURES_REQUIRED scripts_brake_run FIXTURES_SETUP scripts_plot_brake)

add_test(NAME scripts.plot_brake.png
  COMMAND ${_fb_check} "${_fb_work}/plots/brake_short_phase.png" "${_fb_work}/plots/brake_short_x.png")
set_tests_properties(scripts.plot_brake.png PROPERTIES
  FIXTURES_REQUIRED "scripts_brake_run;scripts_plot_brake")

add_test(NAME scripts.plot_brake.help COMMAND ${_fb_plot} --help)
set_tests_properties(scripts.plot_brake.help PROPERTIES
  PASS_REGULAR_EXPRESSION "usage: plot_brake.py.*--window.*--output-dir")

add_test(NAME scripts.plot_brake.missing_file
  COMMAND ${_fs_expect} 2 --stderr "no_such_run\\.h5: no such file"
          -- ${_fb_plot} no_such_run.h5
  WORKING_DIRECTORY "${_fb_work}")

# An AFM map is a friction file, but not a brake run.
add_test(NAME scripts.plot_brake.not_a_brake_file
  COMMAND ${_fs_expect} 2 --stderr "small\\.h5: not a friction brake file"
          -- ${_fb_plot} "${_fs_map}" -o "${_fb_work}/not_brake"
  WORKING_DIRECTORY "${_fb_work}")
set_tests_properties(scripts.plot_brake.not_a_brake_file PROPERTIES
  FIXTURES_REQUIRED scripts_small_map)

add_test(NAME scripts.plot_brake.window_outside
  COMMAND ${_fs_expect} 2 --stderr "brake_short\\.h5: --window 5000 6000 is outside the run"
          -- ${_fb_plot} "${_fb_run}" --window 5000 6000 -o "${_fb_work}/bad_window"
  WORKING_DIRECTORY "${_fb_work}")
set_tests_properties(scripts.plot_brake.window_outside PROPERTIES
  FIXTURES_REQUIRED scripts_brake_run)

# plot_chaos.py on the same run (tests/data/brake_short.nml keeps the
# diagnostics of inputs/brake.nml on, over its 300 tau).
set(_fc_plot ${Python3_EXECUTABLE} "${_fs_scripts}/plot_chaos.py")
add_test(NAME scripts.plot_chaos.run
  COMMAND ${_fc_plot} "${_fb_run}" -o "${_fb_work}/chaos"
  WORKING_DIRECTORY "${_fb_work}")
set_tests_properties(scripts.plot_chaos.run PROPERTIES
  FIXTURES_REQUIRED scripts_brake_run FIXTURES_SETUP scripts_plot_chaos)
add_test(NAME scripts.plot_chaos.png
  COMMAND ${_fb_check} "${_fb_work}/chaos/brake_short_spectrum.png"
          "${_fb_work}/chaos/brake_short_poincare.png" "${_fb_work}/chaos/brake_short_lyapunov.png"
          "${_fb_work}/chaos/brake_short_floquet.png")
set_tests_properties(scripts.plot_chaos.png PROPERTIES
  FIXTURES_REQUIRED "scripts_brake_run;scripts_plot_chaos")
# The orbit followed along mu (inputs/brake_continuation.nml, shortened):
# the bifurcation diagram.
set(_fc_branch "${_fb_work}/brake_continuation_short.h5")
add_test(NAME scripts.plot_chaos.continuation_run
  COMMAND $<TARGET_FILE:friction_app> --quiet --force -o "${_fc_branch}" "${_fs_inputs}/brake.nml"
          "${_fs_inputs}/brake_continuation.nml" "${_fs_tests}/data/brake_continuation_short.nml"
  WORKING_DIRECTORY "${_fb_work}")
set_tests_properties(scripts.plot_chaos.continuation_run PROPERTIES FIXTURES_SETUP scripts_continuation_run)
add_test(NAME scripts.plot_chaos.bifurcation
  COMMAND ${_fc_plot} "${_fc_branch}" -o "${_fb_work}/branch"
  WORKING_DIRECTORY "${_fb_work}")
set_tests_properties(scripts.plot_chaos.bifurcation PROPERTIES
  FIXTURES_REQUIRED scripts_continuation_run FIXTURES_SETUP scripts_plot_bifurcation)
add_test(NAME scripts.plot_chaos.bifurcation_png
  COMMAND ${Python3_EXECUTABLE} "${_fs_tests}/check_png.py" --newer-than "${_fc_branch}"
          "${_fb_work}/branch/brake_continuation_short_bifurcation.png"
          "${_fb_work}/branch/brake_continuation_short_floquet.png")
set_tests_properties(scripts.plot_chaos.bifurcation_png PROPERTIES
  FIXTURES_REQUIRED "scripts_continuation_run;scripts_plot_bifurcation")
add_test(NAME scripts.plot_chaos.help COMMAND ${_fc_plot} --help)
set_tests_properties(scripts.plot_chaos.help PROPERTIES
  PASS_REGULAR_EXPRESSION "usage: plot_chaos.py.*--output-dir")
add_test(NAME scripts.plot_chaos.missing_file
  COMMAND ${_fs_expect} 2 --stderr "no_such_run\\.h5: no such file"
          -- ${_fc_plot} no_such_run.h5
  WORKING_DIRECTORY "${_fb_work}")
add_test(NAME scripts.plot_chaos.not_a_brake_file
  COMMAND ${_fs_expect} 2 --stderr "small\\.h5: not a friction brake file"
          -- ${_fc_plot} "${_fs_map}" -o "${_fb_work}/not_chaos"
  WORKING_DIRECTORY "${_fb_work}")
set_tests_properties(scripts.plot_chaos.not_a_brake_file PROPERTIES
  FIXTURES_REQUIRED scripts_small_map)

set(_fb_all scripts.plot_chaos.run scripts.plot_chaos.png scripts.plot_chaos.help
  scripts.plot_chaos.continuation_run scripts.plot_chaos.bifurcation scripts.plot_chaos.bifurcation_png
  scripts.plot_chaos.missing_file scripts.plot_chaos.not_a_brake_file
  scripts.brake_run scripts.plot_brake.run scripts.plot_brake.png scripts.plot_brake.help
  scripts.plot_brake.missing_file scripts.plot_brake.not_a_brake_file scripts.plot_brake.window_outside)
set_property(TEST ${_fb_all} APPEND PROPERTY LABELS scripts)
set_tests_properties(${_fb_all} PROPERTIES TIMEOUT 120)
