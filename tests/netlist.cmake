# Tests of `friction --netlist` (the paper's network model for ngspice) and
# scripts/ngspice_compare.py (label "netlist"):
#   netlist-brake, netlist-naf   the netlist in ngspice agrees with the kernel
#   netlist-hopg, netlist-row    the same for the other potentials' SPICE forms
#   netlist-fourier              (and the Fourier series')
#   netlist-switched             a switched brake is written as the arctan law
#   netlist-compare              scripts/ngspice_compare.py end to end
#   netlist-bad-*                bad input: clear message, exit code, no file
# Included from tests/CMakeLists.txt (after find_package(Python3)).  ngspice is
# required, not optional: scripts/install-deps installs it, and a skipped
# comparison could hide a broken network model.
# (FRICTION_NGSPICE_EXECUTABLE: found, or configuration stopped, by cmake/FrictionTestTools.cmake.)

foreach(case brake naf hopg row fourier switched bad-graphite bad-no-name bad-switched-mu bad-exists compare bad-compare)
  add_test(NAME netlist-${case}
    COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/netlist_test.py
      --binary $<TARGET_FILE:friction_app> --inputs ${PROJECT_SOURCE_DIR}/inputs
      --scripts ${PROJECT_SOURCE_DIR}/scripts
      --workdir ${CMAKE_CURRENT_BINARY_DIR}/netlist/${case} ${case})
  set_tests_properties(netlist-${case} PROPERTIES LABELS "netlist;cli" TIMEOUT 120)
endforeach()
