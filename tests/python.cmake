# Tests of the Python package python/friction (label "python"):
#   python-package     its pytest suite (python/tests), on the built library and program
#   python-install     `pip install` of python/ into a fresh virtual environment (offline:
#                      --no-build-isolation --no-deps, numpy/h5py/matplotlib from the system
#                      site), then `import friction; print(friction.__version__)` there
#   python-installed   the package of `cmake --install` (consumer-install's prefix) finds the
#                      installed library by itself, and the installed scripts use it
#   example.<name>     each docs/examples/<name>.py (notebooks in the percent format) runs
#                      whole, and the PNGs it writes are complete images
# Included from tests/CMakeLists.txt after scripts.cmake (h5py, matplotlib, numpy checked).

# (pytest: checked by cmake/FrictionTestTools.cmake.)

set(_fp_work "${CMAKE_CURRENT_BINARY_DIR}/python")
file(MAKE_DIRECTORY "${_fp_work}")
set(_fp_env "FRICTION_LIBRARY=$<TARGET_FILE:friction>" "FRICTION_PROGRAM=$<TARGET_FILE:friction_app>"
  "FRICTION_STOP_PROGRAM=$<TARGET_FILE:friction_stop_after>")

add_test(NAME python-package
  COMMAND ${Python3_EXECUTABLE} -m pytest "${PROJECT_SOURCE_DIR}/python/tests" -q -p no:cacheprovider
          --basetemp "${_fp_work}/pytest"
  WORKING_DIRECTORY "${_fp_work}")
set_tests_properties(python-package PROPERTIES LABELS "python;capi" TIMEOUT 600
  ENVIRONMENT "${_fp_env}")

add_test(NAME python-install
  COMMAND bash "${CMAKE_CURRENT_SOURCE_DIR}/python_install_test.sh" ${Python3_EXECUTABLE}
          "${PROJECT_SOURCE_DIR}/python" "${_fp_work}/install" $<TARGET_FILE:friction> ${PROJECT_VERSION})
set_tests_properties(python-install PROPERTIES LABELS python TIMEOUT 300)

# consumer-install (tests/CMakeLists.txt) installs into ${consumer_prefix}.
add_test(NAME python-installed
  COMMAND ${CMAKE_COMMAND} -E env --unset=FRICTION_LIBRARY --unset=LD_LIBRARY_PATH
          ${Python3_EXECUTABLE} "${CMAKE_CURRENT_SOURCE_DIR}/python_installed_test.py" "${consumer_prefix}"
          ${PROJECT_VERSION}
  WORKING_DIRECTORY "${_fp_work}")
set_tests_properties(python-installed PROPERTIES FIXTURES_REQUIRED friction_installed
  LABELS "python;consumer" TIMEOUT 120)

file(GLOB _fp_examples CONFIGURE_DEPENDS "${PROJECT_SOURCE_DIR}/docs/examples/*.py")
foreach(example IN LISTS _fp_examples)
  get_filename_component(name "${example}" NAME_WE)
  add_test(NAME example.${name}
    COMMAND ${Python3_EXECUTABLE} "${CMAKE_CURRENT_SOURCE_DIR}/run_example.py" "${example}"
            --inputs "${PROJECT_SOURCE_DIR}/inputs" --workdir "${_fp_work}/examples/${name}")
  set_tests_properties(example.${name} PROPERTIES LABELS "python;examples" TIMEOUT 300
    ENVIRONMENT "${_fp_env}")
endforeach()

# The friction laws from Python alone (friction.law: the C API's laws, SciPy's PCHIP, the fit).
add_test(NAME python-law
  COMMAND ${Python3_EXECUTABLE} -m pytest "${PROJECT_SOURCE_DIR}/python/tests/test_law.py" -q -p no:cacheprovider
          --basetemp "${_fp_work}/pytest-law"
  WORKING_DIRECTORY "${_fp_work}")
set_tests_properties(python-law PROPERTIES LABELS "python;capi" TIMEOUT 120 ENVIRONMENT "${_fp_env}")

# Every unit the program's files state parses with UDUNITS-2 and pint (docs/output.md#units-udunits-strings).
add_test(NAME python-units
  COMMAND ${Python3_EXECUTABLE} -m pytest "${PROJECT_SOURCE_DIR}/python/tests/test_units.py" -q -p no:cacheprovider
          --basetemp "${_fp_work}/pytest-units"
  WORKING_DIRECTORY "${_fp_work}")
set_tests_properties(python-units PROPERTIES LABELS "python;output" TIMEOUT 120 ENVIRONMENT "${_fp_env}")

# The public Python API has type hints and numpydoc docstrings (numpydoc's own validation).
add_test(NAME python-api-docs
  COMMAND ${Python3_EXECUTABLE} -m pytest "${PROJECT_SOURCE_DIR}/python/tests/test_api_docs.py" -q -p no:cacheprovider
          --basetemp "${_fp_work}/pytest-api-docs"
  WORKING_DIRECTORY "${_fp_work}")
set_tests_properties(python-api-docs PROPERTIES LABELS python TIMEOUT 120 ENVIRONMENT "${_fp_env}")
