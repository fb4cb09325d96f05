# `make package`: the Debian package pegasus_<version>_<arch>.deb (CPack's DEB generator) of what `cmake --install`
# puts in place, under /usr: the `pegasus` CLI, the libraries, the public headers, the CMake package files
# (find_package(pegasus)), the report bundle, and the Python package where Debian's python3 finds it
# (/usr/lib/python3/dist-packages: python/CMakeLists.txt installs it there as the component python_deb). Its
# Depends: the shared libraries the binaries link (dpkg-shlibdeps), and the development packages that
# find_package(pegasus) and the public headers need (Random123: the scenarios' generator, header-only, included by
# <pegasus/pegasus.hpp>). The `packaging.DebianPackage` test unpacks it into a
# temporary root and builds and runs examples/own-model and `import pegasus` against it.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME pegasus)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "reward shaping and PEGASUS policy search (CLI, C++ library, Python module)")
set(CPACK_PACKAGE_CONTACT "Pegasus developers")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)  # pegasus_<version>_<arch>.deb
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(pegasus_deb_depends
    "libeigen3-dev, nlohmann-json3-dev, libfmt-dev, libnlopt-cxx-dev, librandom123-dev, libssl-dev, zlib1g-dev")
# pegasus::commands links the command line's parser.
string(APPEND pegasus_deb_depends ", libcli11-dev")
if(PEGASUS_MPI)
  string(APPEND pegasus_deb_depends ", libopenmpi-dev")
endif()
if(PEGASUS_MUJOCO)
  string(APPEND pegasus_deb_depends ", libmujoco-dev")
endif()
# What `cmake --install` installs (the component "Unspecified"), and the Python package at Debian's path
# instead of the build's own prefix's ("python").
set(CPACK_INSTALL_CMAKE_PROJECTS "${CMAKE_BINARY_DIR};pegasus;Unspecified;/")
if(PEGASUS_PYTHON)
  string(APPEND pegasus_deb_depends ", python3, python3-numpy")
  list(APPEND CPACK_INSTALL_CMAKE_PROJECTS "${CMAKE_BINARY_DIR};pegasus;python_deb;/")
endif()
set(CPACK_DEBIAN_PACKAGE_DEPENDS "${pegasus_deb_depends}")
include(CPack)
