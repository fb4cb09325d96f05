# packaging.DebianPackage: builds the Debian package of this build tree (cmake/package.cmake), unpacks it into a
# fresh root (dpkg-deb -x, as dpkg would lay it out under /), and builds and runs examples/own-model against the
# unpacked /usr as an outside project would (find_package(pegasus)), runs the unpacked CLI, and imports the
# Python package from where Debian's python3 would find it. Run by ctest with
#   -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK_DIR=...
# (the Python part where the build has the Python package).
include(${CMAKE_CURRENT_LIST_DIR}/steps.cmake)
step(cpack -G DEB --config ${BUILD_DIR}/CPackConfig.cmake -B ${WORK_DIR}/package)
file(GLOB debs ${WORK_DIR}/package/pegasus_*.deb)
list(LENGTH debs count)
if(NOT count EQUAL 1)
  message(FATAL_ERROR "expected one pegasus_<version>_<arch>.deb in ${WORK_DIR}/package, found: ${debs}")
endif()
step(dpkg-deb --field ${debs} Package Version Architecture Depends)
message(STATUS "control fields:\n${last_output}")
# librandom123-dev: <pegasus/pegasus.hpp> includes Random123's headers (the scenarios' generator).
foreach(depends libnlopt0 libstdc.. libfmt-dev libeigen3-dev nlohmann-json3-dev librandom123-dev libcli11-dev)
  if(NOT last_output MATCHES "${depends}")
    message(FATAL_ERROR "Depends lacks ${depends}: ${last_output}")
  endif()
endforeach()
set(root ${WORK_DIR}/root)
step(dpkg-deb -x ${debs} ${root})
foreach(installed usr/bin/pegasus usr/include/pegasus/version.hpp usr/include/pegasus/models/model.hpp
        usr/lib/cmake/pegasus/pegasusConfig.cmake usr/share/pegasus)
  if(NOT EXISTS ${root}/${installed})
    message(FATAL_ERROR "the package lacks /${installed}")
  endif()
endforeach()
# The unpacked CLI runs from its prefix.
step(${root}/usr/bin/pegasus --version)
step(${root}/usr/bin/pegasus horizon --gamma 0.9 --epsilon 0.1 --out ${WORK_DIR}/run --quiet)
if(NOT EXISTS ${WORK_DIR}/run/report.html)
  message(FATAL_ERROR "the packaged CLI wrote no report.html (its bundle is /usr/share/pegasus)")
endif()
step(${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples/own-model -B ${WORK_DIR}/build -DCMAKE_BUILD_TYPE=Release
     -DCMAKE_PREFIX_PATH=${root}/usr)
step(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
step(${WORK_DIR}/build/own_model)
message(STATUS "own_model: ${last_output}")
check_core_only_links(${WORK_DIR}/build/own_model)
if(EXISTS ${BUILD_DIR}/python/pegasus/__init__.py)
  if(NOT EXISTS ${root}/usr/lib/python3/dist-packages/pegasus/__init__.py)
    message(FATAL_ERROR "the package lacks /usr/lib/python3/dist-packages/pegasus")
  endif()
  step(${CMAKE_COMMAND} -E env PYTHONPATH=${root}/usr/lib/python3/dist-packages /usr/bin/python3 -c
       "import pegasus; print(pegasus.__file__); assert pegasus.__file__.startswith('${root}')")
  message(STATUS "python: ${last_output}")
endif()
