# `cmake --install BUILD --prefix P` puts in place: the public headers (P/include/pegasus), the libraries
# (pegasus::pegasus, the engine; pegasus::runs, run directories and reports), the `pegasus` CLI, the report
# bundle (P/share/pegasus, from web/) and the CMake package files, so that an outside project can write
#   find_package(pegasus REQUIRED)
#   target_link_libraries(my_tool PRIVATE pegasus::pegasus)
# (examples/own-model is such a project; the `examples.OwnModel` test builds it against an installed tree).
include(CMakePackageConfigHelpers)
set(PEGASUS_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/pegasus)

install(TARGETS pegasus pegasus_runs EXPORT pegasusTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS pegasus_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY include/pegasus DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} FILES_MATCHING PATTERN "*.hpp")
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/include/pegasus/version.hpp
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/pegasus)
install(EXPORT pegasusTargets NAMESPACE pegasus:: DESTINATION ${PEGASUS_CMAKE_DIR})

# The package file has to find what the static libraries link: the engine's public dependencies, and NLopt
# (and Open MPI when built with it), which the optimizers and the evaluators call.
set(PEGASUS_CONFIG_WITH_MPI ${PEGASUS_MPI})
set(PEGASUS_CONFIG_WITH_MUJOCO ${PEGASUS_MUJOCO})
configure_package_config_file(cmake/pegasusConfig.cmake.in ${CMAKE_CURRENT_BINARY_DIR}/pegasusConfig.cmake
                              INSTALL_DESTINATION ${PEGASUS_CMAKE_DIR})
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/pegasusConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/pegasusConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/pegasusConfigVersion.cmake
        DESTINATION ${PEGASUS_CMAKE_DIR})
