# ctest script: installs the build tree into a fresh prefix, builds
# examples/consumer against the installed package only, and runs it and the
# installed program. Variables: BUILD_DIR, SOURCE_DIR, WORK_DIR, GENERATOR,
# LAUNCHER (compiler launcher, may be empty).
file(REMOVE_RECURSE ${WORK_DIR})
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE code OUTPUT_VARIABLE out
                  ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "failed (${code}): ${ARGN}\n${out}\n${err}")
  endif()
  set(run_output "${out}" PARENT_SCOPE)
endfunction()

run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix)
foreach(file bin/puzzlecal include/puzzlecal/calib/calibrate.h
        include/puzzlecal/detection/detector.h lib/cmake/puzzlecal/puzzlecalConfig.cmake)
  if(NOT EXISTS ${WORK_DIR}/prefix/${file})
    message(FATAL_ERROR "not installed: ${file}")
  endif()
endforeach()
run(${WORK_DIR}/prefix/bin/puzzlecal --version)

set(configure ${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples/consumer
    -B ${WORK_DIR}/build -G ${GENERATOR} -DCMAKE_BUILD_TYPE=Release
    -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix)
if(LAUNCHER)
  list(APPEND configure -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER})
endif()
run(${configure})
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
file(GLOB images ${SOURCE_DIR}/testdata/sample/*.png)
run(${WORK_DIR}/build/puzzlecal_consumer ${images})
message("${run_output}")
# The sample set's truth: fx 400, fy 400.4 (testdata/sample/truth.yaml).
if(NOT run_output MATCHES "fx (399\\.9|400\\.0)[0-9]* fy 400\\.[34]")
  message(FATAL_ERROR "the consumer's calibration is off the truth:\n${run_output}")
endif()
file(REMOVE_RECURSE ${WORK_DIR})
