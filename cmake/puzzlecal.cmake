# puzzlecal_add_library(NAME SOURCES ... DEPS ...)
# One library target per folder; includes are full paths from the repository
# root ("grid/kruskal.h").
function(puzzlecal_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  if(ARG_SOURCES)
    add_library(${name} STATIC ${ARG_SOURCES})
    target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
    target_link_libraries(${name} PUBLIC ${ARG_DEPS})
  else()  # headers only, so far
    add_library(${name} INTERFACE)
    target_include_directories(${name} INTERFACE ${PROJECT_SOURCE_DIR})
    target_link_libraries(${name} INTERFACE ${ARG_DEPS})
  endif()
endfunction()

# puzzlecal_add_tests(DIR DEPS ...): one GoogleTest binary per *_test.cc file in
# DIR, registered with CTest (gtest_discover_tests), run from the repository
# root so tests can read configs/ and testdata/.
function(puzzlecal_add_tests dir)
  cmake_parse_arguments(ARG "" "" "DEPS" ${ARGN})
  file(GLOB test_sources CONFIGURE_DEPENDS ${dir}/*_test.cc)
  foreach(source ${test_sources})
    get_filename_component(stem ${source} NAME_WE)
    get_filename_component(folder ${dir} NAME)
    set(target ${folder}_${stem})
    add_executable(${target} ${source})
    target_link_libraries(${target} PRIVATE ${ARG_DEPS} GTest::gtest
                          GTest::gtest_main)
    gtest_discover_tests(${target} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
                         DISCOVERY_TIMEOUT 60
                         PROPERTIES ENVIRONMENT
                         "PUZZLECAL_SOURCE_DIR=${PROJECT_SOURCE_DIR}")
  endforeach()
endfunction()
