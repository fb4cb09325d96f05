# examples.OwnModel: installs this build tree into a fresh prefix, then configures, builds and runs
# examples/own-model (pegasus::core alone) and examples/run-pipeline (pegasus::commands: the helicopter
# pipeline as a library call) against it as an outside project would (find_package(pegasus)). Run by ctest with
#   -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=...
include(${CMAKE_CURRENT_LIST_DIR}/steps.cmake)
step(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix)
foreach(installed include/pegasus/version.hpp include/pegasus/models/model.hpp include/pegasus/cli/command.hpp
        bin/pegasus lib/cmake/pegasus/pegasusConfig.cmake)
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
# The pipeline from an outside program, into a run directory of its own: the same summary keys as the CLI's.
step(${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples/run-pipeline -B ${WORK_DIR}/pipeline-build -DCMAKE_BUILD_TYPE=Release
     -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix)
step(${CMAKE_COMMAND} --build ${WORK_DIR}/pipeline-build)
step(${WORK_DIR}/pipeline-build/run_pipeline ${WORK_DIR}/pipeline-run)
string(FIND "${last_output}" "flights 2, crashes 0" at)
if(at EQUAL -1 OR NOT EXISTS ${WORK_DIR}/pipeline-run/hover/policy.json)
  message(FATAL_ERROR "run_pipeline did not fly its 2 flights without a crash:\n${last_output}")
endif()
