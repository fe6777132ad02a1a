# The GMS law on the brake (tests/brake_gms_oracles.py): the spectrum across a large slip, whose steps end at
# the elements' switch-band edges, against Liouville's time average of tr J and against the flow map's central
# differences along the first tangent vector, both from the flow written with SciPy (LSODA, the edges located);
# the periodic orbit on the creep band's exit against the differences of that section map.
# Included from tests/CMakeLists.txt.
foreach(case spectrum-sum spectrum-largest orbit-scipy)
  add_test(NAME brake-gms-${case}
    COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/brake_gms_oracles.py
      --binary $<TARGET_FILE:friction_app> --inputs ${PROJECT_SOURCE_DIR}/inputs
      --workdir ${CMAKE_CURRENT_BINARY_DIR}/brake-gms/${case} ${case})
  set_tests_properties(brake-gms-${case} PROPERTIES LABELS "cli;brake" TIMEOUT 180)
endforeach()
