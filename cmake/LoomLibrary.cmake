# loom_library(<name> SOURCES ... [PUBLIC ...] [PRIVATE ...]): one static library per
# pipeline stage, target loom_<name>, alias loom::<name>, exported as loom::<name>.
# Headers are included from the repository root ("routing/audit/audit.hpp"); installed
# under include/loom with the same paths.
function(loom_library name)
  cmake_parse_arguments(L "" "" "SOURCES;PUBLIC;PRIVATE" ${ARGN})
  add_library(loom_${name} STATIC ${L_SOURCES})
  add_library(loom::${name} ALIAS loom_${name})
  set_target_properties(loom_${name} PROPERTIES EXPORT_NAME ${name} OUTPUT_NAME loom_${name})
  target_include_directories(loom_${name} PUBLIC
    $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}> $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/loom>)
  target_link_libraries(loom_${name} PUBLIC ${L_PUBLIC} PRIVATE ${L_PRIVATE})
  loom_target_warnings(loom_${name})
  set_property(GLOBAL APPEND PROPERTY LOOM_LIBRARIES loom_${name})
endfunction()
