# `cmake --install`: the program, the controller SDK (headers, CMake package, pkg-config file), the
# demo and test worlds, the example plugin and the docs; and CPack's Debian package of the same.
# docs/controllers.md ("Install") lists where each goes.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(TURTLEGAS_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/turtlegas)

install(TARGETS turtlegas EXPORT turtlegasTargets RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS turtlegas_controller_sdk EXPORT turtlegasTargets)
# The controller API and what it includes; tests/package/install_test.py compiles each on its own.
install(FILES turtle_runtime/include/turtlegas/turtle/turtle.hpp turtle_runtime/include/turtlegas/turtle/registry.hpp
        turtle_runtime/include/turtlegas/turtle/view.hpp
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/turtlegas/turtle)
install(FILES sim/include/turtlegas/sim/vec2.hpp DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/turtlegas/sim)

install(EXPORT turtlegasTargets NAMESPACE turtlegas:: DESTINATION ${TURTLEGAS_CMAKE_DIR})
configure_package_config_file(cmake/turtlegasConfig.cmake.in ${PROJECT_BINARY_DIR}/turtlegasConfig.cmake
                              INSTALL_DESTINATION ${TURTLEGAS_CMAKE_DIR} PATH_VARS CMAKE_INSTALL_BINDIR)
# A plugin must be built against the headers of the program that loads it: same minor version.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/turtlegasConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/turtlegasConfig.cmake ${PROJECT_BINARY_DIR}/turtlegasConfigVersion.cmake
              cmake/TurtlegasPlugin.cmake
        DESTINATION ${TURTLEGAS_CMAKE_DIR})

# pkg-config, relocatable: the prefix is found from the file's own place.
file(RELATIVE_PATH TURTLEGAS_PC_TO_PREFIX /${CMAKE_INSTALL_LIBDIR}/pkgconfig /)
string(REGEX REPLACE "/$" "" TURTLEGAS_PC_TO_PREFIX "${TURTLEGAS_PC_TO_PREFIX}")
configure_file(cmake/turtlegas.pc.in ${PROJECT_BINARY_DIR}/turtlegas.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/turtlegas.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)

# Worlds (demo, tests, benchmarks), the example plugin as an out-of-tree project, the docs.
install(DIRECTORY worlds/ DESTINATION ${CMAKE_INSTALL_DATADIR}/turtlegas/worlds)
install(FILES controllers/examples/feeler.cpp controllers/examples/feeler.json controllers/examples/CMakeLists.txt
        DESTINATION ${CMAKE_INSTALL_DATADIR}/turtlegas/examples/feeler)
# The viewer's page: `serve` finds it at ../share/turtlegas/web from its own binary (server/CMakeLists.txt).
install(DIRECTORY server/web/ DESTINATION ${CMAKE_INSTALL_DATADIR}/turtlegas/web)
install(DIRECTORY docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR} PATTERN "bench" EXCLUDE)
install(FILES README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})

# `cpack -G DEB` in the build directory: turtlegas_<version>_<arch>.deb, for
# `apt install ./turtlegas_*.deb`. Its Depends come from dpkg-shlibdeps (the shared libraries the
# program links: Boost.Context, spdlog, fmt, the C++ runtime, MPI when built with it), so they are
# the ones this build needs; tests/package/deb_test.py checks them against the program's NEEDED.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME turtlegas)
set(CPACK_PACKAGE_VENDOR "turtlegas")
set(CPACK_PACKAGE_CONTACT "turtlegas maintainers <turtlegas@invalid>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "2-D gas of discs and walls, with touch-sensing turtles (after MIT AI Memo 272)")
set(CPACK_PACKAGE_DESCRIPTION "An exact, event-driven disc and wall collision engine with turtles driven by
 C++ controller programs, after MIT AI Memo 272 (the GAS program). Includes the turtlegas
 command-line program, the demo and test worlds, and the controller SDK (headers, CMake
 package, pkg-config file) for building controller plugins out of tree.")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# The SDK's headers include <nlohmann/json.hpp> (registry.hpp): a package that ships them depends
# on it (merged with the shared libraries' Depends). The tools to build a plugin are suggested.
set(CPACK_DEBIAN_PACKAGE_DEPENDS "nlohmann-json3-dev")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "cmake, g++, pkg-config")
include(CPack)
