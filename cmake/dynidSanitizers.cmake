# DYNID_SANITIZE: every target of the build (the core included, so that an out-of-bounds access
# inside it is caught) compiled and linked with AddressSanitizer and UndefinedBehaviorSanitizer;
# the C++ tests then fail on any sanitizer report (tests/cpp/CMakeLists.txt). -O1 keeps reports
# readable. The preset `sanitize` of CMakePresets.json turns it on.
if(DYNID_SANITIZE)
  if(MSVC)
    message(FATAL_ERROR "DYNID_SANITIZE: GCC or Clang needed")
  endif()
  add_compile_options(-fsanitize=address,undefined -fno-sanitize-recover=undefined
                      -fno-omit-frame-pointer)
  add_link_options(-fsanitize=address,undefined)
  message(STATUS "dynid: sanitizers ON")
endif()
