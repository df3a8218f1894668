# FindTetGen: TetGen's library (Debian's libtet1.5-dev has no CMake package of its own).
# Defines TetGen::TetGen (imported) and TetGen_FOUND. Installed with foxi's package so that a
# static foxi::mesher, which links TetGen privately, can find it again in the host's build.
find_path(TetGen_INCLUDE_DIR tetgen.h)
find_library(TetGen_LIBRARY NAMES tet)
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(TetGen REQUIRED_VARS TetGen_LIBRARY TetGen_INCLUDE_DIR)
if(TetGen_FOUND AND NOT TARGET TetGen::TetGen)
  add_library(TetGen::TetGen UNKNOWN IMPORTED)
  set_target_properties(TetGen::TetGen PROPERTIES IMPORTED_LOCATION "${TetGen_LIBRARY}"
    INTERFACE_SYSTEM_INCLUDE_DIRECTORIES "${TetGen_INCLUDE_DIR}"
    INTERFACE_INCLUDE_DIRECTORIES "${TetGen_INCLUDE_DIR}")
endif()
mark_as_advanced(TetGen_INCLUDE_DIR TetGen_LIBRARY)
