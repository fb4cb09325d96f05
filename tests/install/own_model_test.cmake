# examples.OwnModel: installs this build tree into a fresh prefix, then configures, builds and runs
# examples/own-model against it as an outside project would (find_package(pegasus)). Run by ctest with
#   -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=...
include(${CMAKE_CURRENT_LIST_DIR}/steps.cmake)
step(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix)
foreach(installed include/pegasus/version.hpp include/pegasus/models/model.hpp bin/pegasus
        lib/cmake/pegasus/pegasusConfig.cmake)
  if(NOT EXISTS ${WORK_DIR}/prefix/${installed})
    message(FATAL_ERROR "the install lacks ${installed}")
  endif()
endforeach()
step(${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples/own-model -B ${WORK_DIR}/build -DCMAKE_BUILD_TYPE=Release
     -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix)
step(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
step(${WORK_DIR}/build/own_model)
message(STATUS "own_model: ${last_output}")
check_core_only_links(${WORK_DIR}/build/own_model)
# The installed CLI runs from its prefix and finds nothing of the build tree's.
step(${WORK_DIR}/prefix/bin/pegasus --version)
