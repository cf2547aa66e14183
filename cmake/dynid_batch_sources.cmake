# The wide batch (SIMD lane) kernels of cpp/src/batch/: one translation unit per instruction set,
# each compiled with its own flags and selected at load time (cpp/src/batch_dispatch.cpp), so the
# library stays portable (no -march=native). The 2-lane kernels, which need no special flag (SSE2
# is the x86-64 baseline; GCC/Clang vector extensions elsewhere), are cpp/src/batch_lanes_sse2.cpp,
# part of every build of cpp/src/*.cpp; AVX2+FMA and AVX-512 are added here, on x86-64 only.
# No lane file sees the precompiled Eigen header: they include no library header at all, so
# that no inline function compiled with wide instructions can be shared with baseline code.
function(dynid_add_batch_sources target root)
  set_source_files_properties("${root}/cpp/src/batch_lanes_sse2.cpp" TARGET_DIRECTORY ${target}
                              PROPERTIES SKIP_PRECOMPILE_HEADERS ON)
  if(CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64|amd64)$" AND
     CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
    target_sources(${target} PRIVATE "${root}/cpp/src/batch/lanes_avx2.cpp"
                                     "${root}/cpp/src/batch/lanes_avx512.cpp")
    set_source_files_properties("${root}/cpp/src/batch/lanes_avx2.cpp" TARGET_DIRECTORY ${target}
                                PROPERTIES COMPILE_OPTIONS "-mavx2;-mfma"
                                           SKIP_PRECOMPILE_HEADERS ON)
    set_source_files_properties("${root}/cpp/src/batch/lanes_avx512.cpp" TARGET_DIRECTORY ${target}
                                PROPERTIES COMPILE_OPTIONS "-mavx512f;-mavx512dq;-mavx2;-mfma"
                                           SKIP_PRECOMPILE_HEADERS ON)
    target_compile_definitions(${target} PRIVATE DYNID_X86_LANES)
  endif()
endfunction()
