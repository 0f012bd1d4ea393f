include(GNUInstallDirs)

# puzzlecal_add_library(NAME SOURCES ... PUBLIC ... PRIVATE ...)
# One library target per folder; includes are full paths from the repository
# root ("grid/grid.h"). PUBLIC: what the folder's headers expose (a user of
# the library needs it too); PRIVATE: what only its .cc files use, so that a
# folder above links only what it reaches through headers. Each library and
# its folder's headers are installed (`cmake --install`, headers under
# include/puzzlecal/<folder>/) and exported as puzzlecal::NAME through the
# puzzlecal CMake package (find_package(puzzlecal)).
#
# The libraries' sources share one precompiled header (Eigen's dense core and
# geometry, the standard library): most of them include both, and parsing
# them again for each file was a large part of the build.
function(puzzlecal_library_pch_host)
  if(TARGET puzzlecal_library_pch)
    return()
  endif()
  add_library(puzzlecal_library_pch OBJECT
              ${PROJECT_SOURCE_DIR}/cmake/pch_host.cc)
  target_link_libraries(puzzlecal_library_pch PRIVATE Eigen3::Eigen)
  target_precompile_headers(puzzlecal_library_pch PRIVATE
    <Eigen/Core> <Eigen/Geometry>
    <algorithm> <array> <cmath> <cstdint> <cstdio> <functional> <limits>
    <map> <memory> <sstream> <string> <utility> <vector>)
endfunction()

function(puzzlecal_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC;PRIVATE" ${ARGN})
  # Installed headers include each other as "camera/camera_models.h", so
  # include/puzzlecal is on the path too; users write <puzzlecal/...>.
  set(includes $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}>
               $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>
               $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}/puzzlecal>)
  if(ARG_SOURCES)
    add_library(${name} STATIC ${ARG_SOURCES})
    target_include_directories(${name} PUBLIC ${includes})
    target_link_libraries(${name} PUBLIC ${ARG_PUBLIC} PRIVATE ${ARG_PRIVATE})
    puzzlecal_library_pch_host()
    target_precompile_headers(${name} REUSE_FROM puzzlecal_library_pch)
    # One compilation per batch of a folder's files (PUZZLECAL_UNITY_BUILD):
    # most of a file's compile time is instantiating the templates it uses
    # (Eigen's decompositions and products, Ceres's dual numbers), and the
    # files of one folder use largely the same ones.
    if(PUZZLECAL_UNITY_BUILD)
      set_target_properties(${name} PROPERTIES UNITY_BUILD ON
                            UNITY_BUILD_BATCH_SIZE 8)
    endif()
  else()  # headers only
    add_library(${name} INTERFACE)
    target_include_directories(${name} INTERFACE ${includes})
    target_link_libraries(${name} INTERFACE ${ARG_PUBLIC})
  endif()
  add_library(puzzlecal::${name} ALIAS ${name})
  install(TARGETS ${name} EXPORT puzzlecalTargets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
          LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
  file(RELATIVE_PATH folder ${PROJECT_SOURCE_DIR} ${CMAKE_CURRENT_SOURCE_DIR})
  install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/
          DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/puzzlecal/${folder}
          FILES_MATCHING PATTERN "*.h")
endfunction()

# The CMake package: puzzlecalTargets.cmake (every library above) and
# puzzlecalConfig.cmake, which finds the libraries' own dependencies.
function(puzzlecal_install_package)
  include(CMakePackageConfigHelpers)
  set(dir ${CMAKE_INSTALL_LIBDIR}/cmake/puzzlecal)
  install(EXPORT puzzlecalTargets NAMESPACE puzzlecal:: DESTINATION ${dir})
  configure_package_config_file(
    ${PROJECT_SOURCE_DIR}/cmake/puzzlecalConfig.cmake.in
    ${PROJECT_BINARY_DIR}/puzzlecalConfig.cmake INSTALL_DESTINATION ${dir})
  write_basic_package_version_file(
    ${PROJECT_BINARY_DIR}/puzzlecalConfigVersion.cmake
    COMPATIBILITY SameMinorVersion)
  install(FILES ${PROJECT_BINARY_DIR}/puzzlecalConfig.cmake
                ${PROJECT_BINARY_DIR}/puzzlecalConfigVersion.cmake
          DESTINATION ${dir})
endfunction()

# puzzlecal_add_tests(DIR DEPS ...): one GoogleTest program of the *_test.cc
# files in DIR, each test registered with CTest (gtest_discover_tests), run from the repository
# root so tests can read configs/ and testdata/.
#
# The test binaries share one precompiled header (GoogleTest, Eigen, OpenCV's
# core, the standard library): they are half of the build, and parsing those headers
# again for each was a third of their compile time.
function(puzzlecal_test_pch_host)
  if(TARGET puzzlecal_test_pch)
    return()
  endif()
  add_executable(puzzlecal_test_pch ${PROJECT_SOURCE_DIR}/tests/support/pch_host.cc)
  target_link_libraries(puzzlecal_test_pch PRIVATE GTest::gtest Eigen3::Eigen
                        opencv_core)
  puzzlecal_test_compile_options(puzzlecal_test_pch)
  target_precompile_headers(puzzlecal_test_pch PRIVATE
    <gtest/gtest.h> <Eigen/Core> <Eigen/Geometry> <opencv2/core.hpp>
    <algorithm> <cmath> <filesystem> <fstream> <map> <memory> <random>
    <sstream> <string> <vector>)
endfunction()

# The tests' own code is compiled for a short build (-O1: a quarter less
# compile time than -O3); the work they test runs in the libraries, which
# keep the build type's optimisation.
function(puzzlecal_test_compile_options target)
  if(CMAKE_BUILD_TYPE MATCHES "^(Release|RelWithDebInfo)$")
    target_compile_options(${target} PRIVATE -O1)
  endif()
endfunction()

# One test program per folder (tests/<folder>/*_test.cc -> <folder>_tests):
# linking a program against OpenCV and Ceres and listing its tests costs
# about two seconds, paid once per folder rather than once per file.
function(puzzlecal_add_tests dir)
  cmake_parse_arguments(ARG "" "" "DEPS" ${ARGN})
  puzzlecal_test_pch_host()
  file(GLOB test_sources CONFIGURE_DEPENDS ${dir}/*_test.cc)
  get_filename_component(folder ${dir} NAME)
  set(target ${folder}_tests)
  add_executable(${target} ${test_sources})
  target_link_libraries(${target} PRIVATE ${ARG_DEPS} GTest::gtest
                        GTest::gtest_main)
  puzzlecal_test_compile_options(${target})
  target_precompile_headers(${target} REUSE_FROM puzzlecal_test_pch)
  set_target_properties(${target} PROPERTIES UNITY_BUILD ON
                        UNITY_BUILD_BATCH_SIZE 8)
  gtest_discover_tests(${target} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
                       DISCOVERY_TIMEOUT 60
                       PROPERTIES ENVIRONMENT
                       "PUZZLECAL_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
endfunction()
