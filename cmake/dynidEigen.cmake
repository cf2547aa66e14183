# Eigen for the core: a given Eigen3_DIR or CMAKE_PREFIX_PATH first, then the cmeel-eigen wheel of
# the Python on PATH (<site-packages>/cmeel.prefix, a build requirement of the wheel and part of
# the test group), then the system's. Defines the imported target Eigen3::Eigen.
find_package(Eigen3 3.3 QUIET NO_MODULE)
if(NOT Eigen3_FOUND)
  find_package(Python COMPONENTS Interpreter QUIET)
  if(Python_Interpreter_FOUND)
    execute_process(
      COMMAND "${Python_EXECUTABLE}" -c
        "import sys, pathlib; print(next((str(p / 'cmeel.prefix') for p in map(pathlib.Path, sys.path) if (p / 'cmeel.prefix').is_dir()), ''))"
      OUTPUT_VARIABLE DYNID_CMEEL_PREFIX OUTPUT_STRIP_TRAILING_WHITESPACE)
  endif()
  find_package(Eigen3 3.3 REQUIRED NO_MODULE HINTS "${DYNID_CMEEL_PREFIX}")
endif()
message(STATUS "dynid: Eigen ${Eigen3_VERSION} from ${Eigen3_DIR}")
