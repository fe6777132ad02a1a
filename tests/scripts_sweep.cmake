# Tests of scripts/plot_sweep.py (label "scripts"), in the manner of
# scripts_brake.cmake:
#   scripts.sweep_run               friction computes a small sweep (fixture)
#   scripts.plot_sweep.*            bifurcation and exponent PNGs, --help, errors; AFM and machine sweeps
# Included from tests/CMakeLists.txt after scripts.cmake (helpers, h5py and
# matplotlib checks).

set(_fw_work "${CMAKE_CURRENT_BINARY_DIR}/scripts_sweep")
file(MAKE_DIRECTORY "${_fw_work}")
set(_fw_run "${_fw_work}/sweep_small.h5")
set(_fw_plot ${Python3_EXECUTABLE} "${_fs_scripts}/plot_sweep.py")

add_test(NAME scripts.sweep_run
  COMMAND $<TARGET_FILE:friction_app> --quiet --force -o "${_fw_run}"
          "${_fs_inputs}/brake_sweep.nml" "${_fs_tests}/data/sweep_small.nml"
  WORKING_DIRECTORY "${_fw_work}")
set_tests_properties(scripts.sweep_run PROPERTIES FIXTURES_SETUP scripts_sweep_run LABELS scripts)

add_test(NAME scripts.plot_sweep.run
  COMMAND ${_fw_plot} "${_fw_run}" -o "${_fw_work}/plots"
  WORKING_DIRECTORY "${_fw_work}")
set_tests_properties(scripts.plot_sweep.run PROPERTIES
  FIXTURES_REQUIRED scripts_sweep_run FIXTURES_SETUP scripts_plot_sweep LABELS scripts)

add_test(NAME scripts.plot_sweep.png
  COMMAND ${Python3_EXECUTABLE} "${_fs_tests}/check_png.py" --newer-than "${_fw_run}"
          "${_fw_work}/plots/sweep_small_bifurcation.png" "${_fw_work}/plots/sweep_small_lyapunov.png")
set_tests_properties(scripts.plot_sweep.png PROPERTIES
  FIXTURES_REQUIRED "scripts_sweep_run;scripts_plot_sweep" LABELS scripts)

add_test(NAME scripts.plot_sweep.help COMMAND ${_fw_plot} --help)
set_tests_properties(scripts.plot_sweep.help PROPERTIES
  PASS_REGULAR_EXPRESSION "usage: plot_sweep.py.*--output-dir" LABELS scripts)

add_test(NAME scripts.plot_sweep.missing_file
  COMMAND ${_fs_expect} 2 --stderr "no_such_sweep\\.h5: no such file"
          -- ${_fw_plot} no_such_sweep.h5
  WORKING_DIRECTORY "${_fw_work}")
set_tests_properties(scripts.plot_sweep.missing_file PROPERTIES LABELS scripts)

# A brake run is a friction file, but not a sweep.
add_test(NAME scripts.plot_sweep.not_a_sweep
  COMMAND ${_fs_expect} 2 --stderr "not a friction sweep file"
          -- ${_fw_plot} "${CMAKE_CURRENT_BINARY_DIR}/scripts_brake/brake_short.h5")
set_tests_properties(scripts.plot_sweep.not_a_sweep PROPERTIES
  FIXTURES_REQUIRED scripts_brake_run LABELS scripts)

# An AFM sweep over two variables (inputs/afm_sweep.nml made small): friction plot.
set(_fw_afm "${_fw_work}/afm_sweep_small.h5")
add_test(NAME scripts.afm_sweep_run
  COMMAND $<TARGET_FILE:friction_app> --quiet --force -o "${_fw_afm}"
          "${_fs_inputs}/afm_sweep.nml" "${_fs_tests}/data/afm_sweep_small.nml"
  WORKING_DIRECTORY "${_fw_work}")
set_tests_properties(scripts.afm_sweep_run PROPERTIES FIXTURES_SETUP scripts_afm_sweep_run LABELS scripts)

add_test(NAME scripts.plot_sweep.afm.run
  COMMAND ${_fw_plot} "${_fw_afm}" -o "${_fw_work}/plots"
  WORKING_DIRECTORY "${_fw_work}")
set_tests_properties(scripts.plot_sweep.afm.run PROPERTIES
  FIXTURES_REQUIRED scripts_afm_sweep_run FIXTURES_SETUP scripts_plot_afm_sweep LABELS scripts)

add_test(NAME scripts.plot_sweep.afm.png
  COMMAND ${Python3_EXECUTABLE} "${_fs_tests}/check_png.py" --newer-than "${_fw_afm}"
          "${_fw_work}/plots/afm_sweep_small_friction.png")
set_tests_properties(scripts.plot_sweep.afm.png PROPERTIES
  FIXTURES_REQUIRED "scripts_afm_sweep_run;scripts_plot_afm_sweep" LABELS scripts)

# A machine sweep (inputs/machine_stribeck_orbit.nml over 4 belt velocities): maxima and results PNGs.
set(_fw_machine "${_fw_work}/machine_sweep_small.h5")
add_test(NAME scripts.machine_sweep_run
  COMMAND $<TARGET_FILE:friction_app> --quiet --force -o "${_fw_machine}"
          "${_fs_inputs}/machine_stribeck_orbit.nml" "${_fs_tests}/data/machine_sweep_small.nml"
  WORKING_DIRECTORY "${_fw_work}")
set_tests_properties(scripts.machine_sweep_run PROPERTIES FIXTURES_SETUP scripts_machine_sweep_run LABELS scripts)

add_test(NAME scripts.plot_sweep.machine.run
  COMMAND ${_fw_plot} "${_fw_machine}" -o "${_fw_work}/plots"
  WORKING_DIRECTORY "${_fw_work}")
set_tests_properties(scripts.plot_sweep.machine.run PROPERTIES
  FIXTURES_REQUIRED scripts_machine_sweep_run FIXTURES_SETUP scripts_plot_machine_sweep LABELS scripts)

add_test(NAME scripts.plot_sweep.machine.png
  COMMAND ${Python3_EXECUTABLE} "${_fs_tests}/check_png.py" --newer-than "${_fw_machine}"
          "${_fw_work}/plots/machine_sweep_small_bifurcation.png" "${_fw_work}/plots/machine_sweep_small_machine.png")
set_tests_properties(scripts.plot_sweep.machine.png PROPERTIES
  FIXTURES_REQUIRED "scripts_machine_sweep_run;scripts_plot_machine_sweep" LABELS scripts)
