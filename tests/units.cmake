# Values in the wrong unit (docs/input.md, Units): each one runs --print-input
# (the checks, no computation) with a file that sets one value in another
# unit on its line 2, and the warning must name that file and line, the
# group, the variable, the value and the unit expected.  Label "cli".
#   units-angle-radians      scan.angle = 0.122 (7 degrees in radians)
#   units-energy-joules      surface.v0 = 1.6e-19 (1 eV in joules)
#   units-length-metres      surface.sigma(1) = 2.4945e-10 (graphite's sigma in metres)
#   units-lattice-metres     surface.ax = 4.62e-10: refused (exit 3), the error says metres
#   units-stiffness          tip.kx = 10000 N/m
#   units-velocity           scan.velocity = 4e-8 (400 angstrom/s in m/s): a line of 5e8 s
#   units-plausible          2.5 degrees and 0.05 N/m: no warning
#   units-print-input        --print-input gives each variable's unit
#   units-sweep-radians      a sweep of scan.angle from 0.122 to 0.488 (radians): one warning naming
#                            the file and line of sweep_variable, &sweep, the variable, the count and range
#   units-sweep-plausible    a sweep of whole and half degrees: no warning
#   units-paper-<input>      the shipped inputs give no such warning

set(_un_data "${CMAKE_CURRENT_SOURCE_DIR}/data/units")
set(_un_inputs "${PROJECT_SOURCE_DIR}/inputs")
set(_un_any_unit_warning "warning: [^\n]*(looks like radians|looks like joules|looks like metres|springs of AFM tips|more than a day)")

function(friction_units_case name)
  cmake_parse_arguments(U "" "EXPECT" "ARGS" ${ARGN})
  add_test(NAME units-${name} COMMAND $<TARGET_FILE:friction_app> --print-input ${U_ARGS})
  set_tests_properties(units-${name} PROPERTIES LABELS cli PASS_REGULAR_EXPRESSION "${U_EXPECT}")
endfunction()

friction_units_case(angle-radians ARGS "${_un_inputs}/naf.nml" "${_un_data}/angle_radians.nml"
  EXPECT "warning: [^\n]*angle_radians\\.nml:2: &scan: angle = 0\\.122: [^\n]*looks like radians, and the unit is degrees \\(0\\.122[0-9]* rad = 6\\.99")
friction_units_case(energy-joules ARGS "${_un_inputs}/naf.nml" "${_un_data}/v0_joules.nml"
  EXPECT "warning: [^\n]*v0_joules\\.nml:2: &surface: v0 = 1\\.6e-19: [^\n]*looks like joules, and the unit is eV \\([^\n]*= 0\\.99")
friction_units_case(length-metres ARGS "${_un_inputs}/graphite.nml" "${_un_data}/sigma_metres.nml"
  EXPECT "warning: [^\n]*sigma_metres\\.nml:2: &surface: sigma\\(1\\) = 2\\.4945e-10: [^\n]*looks like metres, and the unit is angstrom \\([^\n]*= 2\\.49")
friction_units_case(lattice-metres ARGS "${_un_inputs}/naf.nml" "${_un_data}/ax_metres.nml"
  EXPECT "error: [^\n]*ax_metres\\.nml:2: &surface: ax = [^\n]*must be >= 0\\.01 angstrom[^\n]*looks like metres: [^\n]* = 4\\.62")
friction_units_case(stiffness ARGS "${_un_inputs}/naf.nml" "${_un_data}/kx_stiff.nml"
  EXPECT "warning: [^\n]*kx_stiff\\.nml:2: &tip: kx = 10000[^\n]*: far outside the springs of AFM tips, 1e-3 to 1e3 N/m: the unit is N/m")
friction_units_case(velocity ARGS "${_un_inputs}/naf.nml" "${_un_data}/velocity_metres.nml"
  EXPECT "warning: [^\n]*velocity_metres\\.nml:2: &scan: velocity = 4[^\n]*: a line of 20[^\n]* takes 5[^\n]* s of scan time at this velocity, more than a day: the unit is angstrom/s \\([^\n]* m/s = 400")
friction_units_case(print-input ARGS "${_un_inputs}/naf.nml"
  EXPECT "  v0 = 1\\.0 +! eV\n.*  kx = 10\\.0 +! N/m\n.*  velocity = 400\\.0 +! angstrom/s\n.*  rtol = 0\\.001\n")

friction_units_case(sweep-radians ARGS "${_un_inputs}/naf.nml" "${_un_data}/sweep_angle_radians.nml"
  EXPECT "warning: [^\n]*sweep_angle_radians\\.nml:2: &sweep: sweep_variable = 'scan\\.angle': 4 of its 4 values, from 0\\.122[0-9]* to 0\\.488[0-9]*, look like another unit than degree; the first: [^\n]*looks like radians")
add_test(NAME units-sweep-plausible COMMAND $<TARGET_FILE:friction_app> --print-input "${_un_inputs}/naf.nml"
  "${_un_data}/sweep_plausible.nml")
set_tests_properties(units-sweep-plausible PROPERTIES LABELS cli FAIL_REGULAR_EXPRESSION "warning:")

# The plausible values: no warning, and exit 0.
add_test(NAME units-plausible COMMAND $<TARGET_FILE:friction_app> --print-input "${_un_inputs}/naf.nml" "${_un_data}/plausible.nml")
set_tests_properties(units-plausible PROPERTIES LABELS cli FAIL_REGULAR_EXPRESSION "warning:")

# The paper's inputs (overrides with the file they override): no unit warning, exit 0.
file(GLOB _un_files RELATIVE "${_un_inputs}" "${_un_inputs}/*.nml")
foreach(_un_file ${_un_files})
  string(REGEX REPLACE "\\.nml$" "" _un_name "${_un_file}")
  set(_un_args "${_un_inputs}/${_un_file}")
  if(_un_name MATCHES "^(brake_continuation|brake_dimensional|brake_route)$")
    set(_un_args "${_un_inputs}/brake.nml" "${_un_inputs}/${_un_file}")
  elseif(_un_name MATCHES "^graphite_")
    set(_un_args "${_un_inputs}/graphite.nml" "${_un_inputs}/${_un_file}")
  endif()
  add_test(NAME units-paper-${_un_name} COMMAND $<TARGET_FILE:friction_app> --print-input ${_un_args})
  set_tests_properties(units-paper-${_un_name} PROPERTIES LABELS cli FAIL_REGULAR_EXPRESSION "${_un_any_unit_warning}")
endforeach()
