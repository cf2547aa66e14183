# What keeps the build short (bench/build_profile.py times every file; docs/building.md has the
# numbers). dynid_precompile_eigen(target): Eigen/Core and Eigen/Geometry, about 1 s of parsing
# in every file of the core, are parsed once into a precompiled header. It changes no generated
# code. The binding files are compiled as a unity build (cmake/dynidPython.cmake).
function(dynid_precompile_eigen target)
  target_precompile_headers(${target} PRIVATE <Eigen/Core> <Eigen/Geometry>)
endfunction()
