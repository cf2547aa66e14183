# The C++ package (docs/cpp.md): the headers, the static core and a CMake package config, so that
# a C++ project can find_package(dynid CONFIG) and link dynid::core. In a wheel (SKBUILD)
# everything goes under the package folder (scikit-build-core installs into site-packages):
# dynid/include/dynid/*.hpp, dynid/lib/libdynid_core.a, dynid/lib/cmake/dynid/*.cmake; a plain
# `cmake --install` uses the usual include/ and lib/. Every path in the exported files is
# relative to the install prefix, so the installed package can be moved (venvs, wheels).
include(CMakePackageConfigHelpers)
if(SKBUILD)
  set(DYNID_INSTALL_ROOT "dynid/")
else()
  set(DYNID_INSTALL_ROOT "")
endif()
set(DYNID_INSTALL_INCLUDEDIR "${DYNID_INSTALL_ROOT}include")
set(DYNID_INSTALL_LIBDIR "${DYNID_INSTALL_ROOT}lib")
set(DYNID_INSTALL_CMAKEDIR "${DYNID_INSTALL_LIBDIR}/cmake/dynid")

install(TARGETS dynid_core EXPORT dynidTargets
  ARCHIVE DESTINATION "${DYNID_INSTALL_LIBDIR}"
  INCLUDES DESTINATION "${DYNID_INSTALL_INCLUDEDIR}")  # -> INTERFACE_INCLUDE_DIRECTORIES
install(DIRECTORY "${PROJECT_SOURCE_DIR}/cpp/include/dynid"
  DESTINATION "${DYNID_INSTALL_INCLUDEDIR}" FILES_MATCHING PATTERN "*.hpp")
install(EXPORT dynidTargets NAMESPACE dynid:: DESTINATION "${DYNID_INSTALL_CMAKEDIR}")

# dynidConfig.cmake finds Eigen (the dynid::core target links Eigen3::Eigen) and warns when its
# version differs from the one the library was compiled with (DYNID_EIGEN_VERSION).
set(DYNID_EIGEN_VERSION "${Eigen3_VERSION}")
configure_package_config_file(
  "${PROJECT_SOURCE_DIR}/cmake/dynidConfig.cmake.in"
  "${PROJECT_BINARY_DIR}/dynidConfig.cmake"
  INSTALL_DESTINATION "${DYNID_INSTALL_CMAKEDIR}"
  PATH_VARS DYNID_INSTALL_INCLUDEDIR)
write_basic_package_version_file(
  "${PROJECT_BINARY_DIR}/dynidConfigVersion.cmake"
  VERSION "${PROJECT_VERSION}" COMPATIBILITY SameMinorVersion)
install(FILES
  "${PROJECT_BINARY_DIR}/dynidConfig.cmake"
  "${PROJECT_BINARY_DIR}/dynidConfigVersion.cmake"
  DESTINATION "${DYNID_INSTALL_CMAKEDIR}")
