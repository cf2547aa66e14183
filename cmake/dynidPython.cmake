# The Python extension dynid._core: the binding files of cpp/bindings/ over dynid_core.
find_package(Python 3.9 COMPONENTS Interpreter Development.Module REQUIRED)
set(PYBIND11_FINDPYTHON ON)
find_package(pybind11 CONFIG REQUIRED)
file(GLOB DYNID_BINDING_SOURCES CONFIGURE_DEPENDS "${CMAKE_CURRENT_SOURCE_DIR}/cpp/bindings/*.cpp")
pybind11_add_module(_core ${DYNID_BINDING_SOURCES})
target_link_libraries(_core PRIVATE dynid_core)
# Each binding file spends ~3 of its ~5 s compiling what pybind11.h defines inline; compiled in
# batches of files (a unity build), that cost is paid once per batch. Two batches keep both
# cores of a small machine busy beside the core library.
set_target_properties(_core PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 6)
install(TARGETS _core DESTINATION dynid)
