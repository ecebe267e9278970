# ctest -R downstream: install facyl to a staging prefix, then configure, build and run a
# separate project that uses find_package(facyl).
# Variables: FACYL_BUILD_DIR, DOWNSTREAM_SOURCE_DIR, STAGE_DIR.
file(REMOVE_RECURSE "${STAGE_DIR}")
function(step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}")
  endif()
endfunction()
step(${CMAKE_COMMAND} --install "${FACYL_BUILD_DIR}" --prefix "${STAGE_DIR}/prefix")
step(${CMAKE_COMMAND} -S "${DOWNSTREAM_SOURCE_DIR}" -B "${STAGE_DIR}/build"
     -DCMAKE_BUILD_TYPE=Release "-DCMAKE_PREFIX_PATH=${STAGE_DIR}/prefix")
step(${CMAKE_COMMAND} --build "${STAGE_DIR}/build")
step("${STAGE_DIR}/build/facyl_downstream")
