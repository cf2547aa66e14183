# ctest's examples_installed (tests/cpp/CMakeLists.txt): what a C++ user does with an installed
# dynid. Installs the build BUILD_DIR into PREFIX, configures cpp/examples (EXAMPLES) with
# find_package(dynid) against it alone, builds it and runs its 1 kHz loop for 1 s.
foreach(var BUILD_DIR PREFIX EXAMPLES GENERATOR CXX)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "examples_installed.cmake: -D${var}=... is required")
  endif()
endforeach()
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE failed)
  if(failed)
    message(FATAL_ERROR "examples_installed: failed (${failed}): ${ARGN}")
  endif()
endfunction()

file(REMOVE_RECURSE "${PREFIX}")
set(config_args "")
if(CONFIG)
  set(config_args --config "${CONFIG}")
endif()
run("${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${PREFIX}" ${config_args})

set(flags "")
if(SANITIZE)  # the installed core is instrumented: the example must link the runtimes too
  set(flags "-DCMAKE_CXX_FLAGS=-fsanitize=address,undefined"
            "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined")
endif()
set(build "${PREFIX}-examples")
file(REMOVE_RECURSE "${build}")
run("${CMAKE_COMMAND}" -S "${EXAMPLES}" -B "${build}" -G "${GENERATOR}"
    "-DCMAKE_CXX_COMPILER=${CXX}" "-DCMAKE_PREFIX_PATH=${PREFIX}" "-DEigen3_DIR=${Eigen3_DIR}"
    -DCMAKE_FIND_PACKAGE_PREFER_CONFIG=ON ${flags})
run("${CMAKE_COMMAND}" --build "${build}" ${config_args})
file(GLOB_RECURSE program "${build}/realtime_loop" "${build}/*/realtime_loop")
if(NOT program)
  message(FATAL_ERROR "examples_installed: realtime_loop not built in ${build}")
endif()
list(GET program 0 program)
run("${program}" 1)
