# Tests of the one-dimensional Fourier landscape (&surface potential = 'fourier' with &fourier), label
# "fourier": see tests/fourier_test.py for what each case asserts.
#   fourier-row           one coefficient against potential = 'row', bit for bit, T = 0 and 300 K
#   fourier-shape         the reported barrier shape (beta, F_c) against an independent computation
#   fourier-kramers-rate  the reduced model's jump positions against Kramers' rate on two harmonics
#   fourier-bad-input     refusals naming file, line, group and variable
# Included from tests/CMakeLists.txt (after find_package(Python3)).

foreach(case row shape kramers-rate bad-input)
  add_test(NAME fourier-${case}
    COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_SOURCE_DIR}/fourier_test.py
      --binary $<TARGET_FILE:friction_app> --inputs ${PROJECT_SOURCE_DIR}/inputs
      --workdir ${CMAKE_CURRENT_BINARY_DIR}/fourier/${case} ${case})
  set_tests_properties(fourier-${case} PROPERTIES LABELS "fourier;cli;thermal" TIMEOUT 300)
endforeach()
