# The Eigen settings a program must share with the compiled core (docs/cpp.md, "Eigen settings
# shared with the core"): the alignment of Eigen's objects and whether Eigen's heap allocations
# trust malloc's alignment. Eigen derives both from the compiler flags: -mavx raises
# EIGEN_MAX_ALIGN_BYTES to 32, and AddressSanitizer (__SANITIZE_ADDRESS__) or a 32-byte alignment
# turns EIGEN_MALLOC_ALREADY_ALIGNED off, so that Eigen then stores an offset before each block it
# allocates. A Workspace or RecursiveLeastSquares allocated by the core and freed by a program
# with the other setting would free a wrong pointer (AddressSanitizer reports a heap-buffer-
# overflow in handmade_aligned_free). The values the core is compiled with are therefore measured
# here and put on dynid_core as PUBLIC definitions: the core and every program that links
# dynid::core (the exported target carries them) compile Eigen alike.
#
#   dynid_eigen_abi_definitions(<out-var>)  sets <out-var> to the list of definitions.
include(CheckCXXSourceCompiles)

function(dynid_eigen_abi_definitions out)
  get_target_property(eigen_include Eigen3::Eigen INTERFACE_INCLUDE_DIRECTORIES)
  set(CMAKE_REQUIRED_INCLUDES ${eigen_include})
  set(CMAKE_REQUIRED_QUIET ON)
  if(CMAKE_BUILD_TYPE)
    string(TOUPPER "${CMAKE_BUILD_TYPE}" config)
    set(CMAKE_REQUIRED_FLAGS "${CMAKE_CXX_FLAGS} ${CMAKE_CXX_FLAGS_${config}}")
  endif()
  set(align "")
  foreach(candidate 16 32 64 0)
    check_cxx_source_compiles("#include <Eigen/Core>
#if EIGEN_MAX_ALIGN_BYTES != ${candidate}
#error other alignment
#endif
int main() { return 0; }" DYNID_EIGEN_MAX_ALIGN_BYTES_IS_${candidate})
    if(DYNID_EIGEN_MAX_ALIGN_BYTES_IS_${candidate})
      set(align ${candidate})
      break()
    endif()
  endforeach()
  check_cxx_source_compiles("#include <Eigen/Core>
#if !EIGEN_MALLOC_ALREADY_ALIGNED
#error Eigen aligns its own allocations
#endif
int main() { return 0; }" DYNID_EIGEN_MALLOC_ALREADY_ALIGNED)
  if(align STREQUAL "")
    message(FATAL_ERROR "dynid: could not determine EIGEN_MAX_ALIGN_BYTES of this compiler")
  endif()
  if(DYNID_EIGEN_MALLOC_ALREADY_ALIGNED)
    set(malloc_aligned 1)
  else()
    set(malloc_aligned 0)
  endif()
  set(${out} "EIGEN_MAX_ALIGN_BYTES=${align};EIGEN_MALLOC_ALREADY_ALIGNED=${malloc_aligned}"
      PARENT_SCOPE)
endfunction()
