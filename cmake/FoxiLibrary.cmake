# foxi_library(TARGET EXPORT_NAME): what every foxi library shares.
#  - its public headers at include/ (build tree: <lib>/include and the generated headers; installed:
#    <prefix>/include), its private ones at <lib>/src;
#  - symbols hidden unless marked FOXI_API (foxi/api.hpp), so a shared libfoxi_*.so exports only the
#    entry points of its public headers;
#  - installed into the export set foxiTargets as foxi::EXPORT_NAME, and the alias foxi::EXPORT_NAME
#    in the build tree, so code in the repository and a host spell the targets alike. An optional
#    third argument names another export set (foxi::qt: foxiQtTargets, loaded only where Qt5 is found).
function(foxi_library target export_name)
  set(export_set foxiTargets)
  if(ARGC GREATER 2)
    set(export_set ${ARGV2})
  endif()
  add_library(foxi::${export_name} ALIAS ${target})
  target_include_directories(${target}
    PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
           $<BUILD_INTERFACE:${FOXI_GENERATED_INCLUDE_DIR}>
           $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>
    PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  # Position-independent in static builds too, so that a host can link a static foxi into a shared
  # library of its own (a plugin, a Python module); with hidden visibility this costs next to nothing
  # on x86-64 (no GOT or PLT for internal calls). And no foxi_<lib>_EXPORTS define (FOXI_API does not
  # need one): a static and a shared build compile the same objects, which ccache then shares.
  set_target_properties(${target} PROPERTIES
    EXPORT_NAME ${export_name}
    CXX_VISIBILITY_PRESET hidden
    VISIBILITY_INLINES_HIDDEN ON
    POSITION_INDEPENDENT_CODE ON
    DEFINE_SYMBOL ""
    # A shared library finds the foxi libraries it needs beside itself, whatever the host's own
    # RUNPATH says (RUNPATH is not inherited by a program's libraries).
    INSTALL_RPATH "$ORIGIN"
    VERSION ${PROJECT_VERSION}
    SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
  # __FILE__ (FOXI_ASSERT's messages, in Debug or with FOXI_CHECKS) relative to the source tree, so
  # that no path of the build machine is baked into an installed library.
  target_compile_options(${target} PRIVATE
    $<$<CXX_COMPILER_ID:GNU,Clang>:-fmacro-prefix-map=${PROJECT_SOURCE_DIR}/=>)
  # Warnings are for foxi's own build: a host linking a static foxi must not inherit them.
  target_link_libraries(${target} PRIVATE $<BUILD_INTERFACE:foxi_warnings>)
  install(TARGETS ${target} EXPORT ${export_set}
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
    RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
    FILES_MATCHING PATTERN "*.hpp")
endfunction()
