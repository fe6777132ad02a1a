# Tests of scripts/thermal_velocity.py and the fit it draws (label "scripts"):
#   scripts.thermal_velocity   tests/thermal_scripts_test.py under pytest: Sang et al.'s
#                              law fitted (friction.plot.sang_fit) recovers F_c, beta and
#                              v_c from synthetic points; the overlap of the two models;
#                              the curve's points; the command line
# Included from tests/CMakeLists.txt after scripts.cmake (pytest, numpy and
# matplotlib checked by cmake/FrictionTestTools.cmake).

add_test(NAME scripts.thermal_velocity
  COMMAND ${Python3_EXECUTABLE} -m pytest "${_fs_tests}/thermal_scripts_test.py" -q -p no:cacheprovider
  WORKING_DIRECTORY "${_fs_work}")
set_tests_properties(scripts.thermal_velocity PROPERTIES LABELS "scripts;thermal" TIMEOUT 300)
