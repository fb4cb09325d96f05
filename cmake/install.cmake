# `cmake --install BUILD --prefix P` puts in place: the public headers (P/include/pegasus), the libraries (the
# engine's components pegasus::core, ::mpi, ::mujoco and ::digest, pegasus::pegasus for all of them, and
# pegasus::runs for run directories and reports, pegasus::commands for the CLI's commands from a program), the
# `pegasus` CLI, the report bundle (P/share/pegasus, from
# web/) and the CMake package files, so that an outside project can write
#   find_package(pegasus REQUIRED COMPONENTS core)
#   target_link_libraries(my_tool PRIVATE pegasus::core)
# (examples/own-model is such a project; the `examples.OwnModel` test builds it against an installed tree).
# Each component has its own export set, so that the package file finds only the dependencies of the
# components asked for (pegasusConfig.cmake.in).
include(CMakePackageConfigHelpers)
set(PEGASUS_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/pegasus)

foreach(target ${PEGASUS_ENGINE_TARGETS})
  get_target_property(component ${target} EXPORT_NAME)
  install(TARGETS ${target} EXPORT pegasus_${component}_targets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
          INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  install(EXPORT pegasus_${component}_targets NAMESPACE pegasus:: DESTINATION ${PEGASUS_CMAKE_DIR})
  list(APPEND PEGASUS_CONFIG_COMPONENTS ${component})
endforeach()
install(TARGETS pegasus pegasus_runs EXPORT pegasusTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
# pegasus::commands (the command table, call_command) in its own export set: only it needs CLI11.
install(TARGETS pegasus_commands EXPORT pegasus_commands_targets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(EXPORT pegasus_commands_targets NAMESPACE pegasus:: DESTINATION ${PEGASUS_CMAKE_DIR})
install(TARGETS pegasus_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY include/pegasus DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} FILES_MATCHING PATTERN "*.hpp")
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/include/pegasus/version.hpp
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/pegasus)
install(EXPORT pegasusTargets NAMESPACE pegasus:: DESTINATION ${PEGASUS_CMAKE_DIR})

# The package file has to find what the static libraries link, component by component.
configure_package_config_file(cmake/pegasusConfig.cmake.in ${CMAKE_CURRENT_BINARY_DIR}/pegasusConfig.cmake
                              INSTALL_DESTINATION ${PEGASUS_CMAKE_DIR})
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/pegasusConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/pegasusConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/pegasusConfigVersion.cmake
        DESTINATION ${PEGASUS_CMAKE_DIR})
