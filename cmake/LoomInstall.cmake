# `cmake --install` puts the libraries, their headers (include/loom/<module>/...) and a
# package config in place, so that a tool builds against loom with find_package(loom).
include(CMakePackageConfigHelpers)

get_property(loom_libraries GLOBAL PROPERTY LOOM_LIBRARIES)
set(loom_dep_targets loom_dep_octomap loom_dep_edt3d loom_dep_ompl loom_dep_occt loom_dep_lzf)
install(TARGETS ${loom_libraries} ${loom_dep_targets} EXPORT loomTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/loom)
foreach(dir core index routing)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${dir} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/loom
          FILES_MATCHING PATTERN "*.hpp")
endforeach()
if(LOOM_BUILD_APP)
  install(TARGETS loom RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
endif()

set(loom_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/loom)
install(EXPORT loomTargets NAMESPACE loom:: DESTINATION ${loom_cmake_dir})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/loomConfig.cmake.in
  ${PROJECT_BINARY_DIR}/loomConfig.cmake INSTALL_DESTINATION ${loom_cmake_dir})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/loomConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/loomConfig.cmake ${PROJECT_BINARY_DIR}/loomConfigVersion.cmake
        DESTINATION ${loom_cmake_dir})
