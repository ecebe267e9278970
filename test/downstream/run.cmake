# ctest -R downstream: install facyl to a staging prefix, then configure, build and run a
# separate project that uses find_package(facyl), and run the installed tools as a user does
# (no LD_LIBRARY_PATH: their RUNPATH must find the installed libraries).
# Variables: FACYL_BUILD_DIR, DOWNSTREAM_SOURCE_DIR, STAGE_DIR, DATA_DIR (optional),
# CXX_FLAGS and EXE_LINKER_FLAGS (facyl's, e.g. the sanitizers').
file(REMOVE_RECURSE "${STAGE_DIR}")
function(step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}")
  endif()
endfunction()
step(${CMAKE_COMMAND} --install "${FACYL_BUILD_DIR}" --prefix "${STAGE_DIR}/prefix")
step(${CMAKE_COMMAND} -S "${DOWNSTREAM_SOURCE_DIR}" -B "${STAGE_DIR}/build"
     -DCMAKE_BUILD_TYPE=Release "-DCMAKE_PREFIX_PATH=${STAGE_DIR}/prefix"
     "-DCMAKE_CXX_FLAGS=${CXX_FLAGS}" "-DCMAKE_EXE_LINKER_FLAGS=${EXE_LINKER_FLAGS}")
step(${CMAKE_COMMAND} --build "${STAGE_DIR}/build")
step("${STAGE_DIR}/build/facyl_downstream")
step("${STAGE_DIR}/build/facyl_downstream_xyzi")
if(DATA_DIR)
  foreach(tool facyl_fit facyl_detect)
    set(input "${DATA_DIR}/default_cylinder.pcd")
    if(tool STREQUAL "facyl_detect")
      set(input "${DATA_DIR}/default_scene.pcd")
    endif()
    execute_process(COMMAND ${CMAKE_COMMAND} -E env --unset=LD_LIBRARY_PATH
                            "${STAGE_DIR}/prefix/bin/${tool}" "${input}"
                    RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
    if(NOT rc EQUAL 0 OR NOT out MATCHES "\"radius\":")
      message(FATAL_ERROR "installed ${tool} failed (${rc}): ${out} ${err}")
    endif()
    # The installed facyl_detect finds the installed classifier model (p_cylinder is a number).
    if(tool STREQUAL "facyl_detect" AND NOT out MATCHES "\"p_cylinder\":[0-9]")
      message(FATAL_ERROR "installed facyl_detect ran without its model: ${out}")
    endif()
    message(STATUS "installed ${tool}: ok")
  endforeach()
endif()
# The installed Python module imports with the interpreter's path set to its install folder
# (not under the sanitizers: an ASan-built module needs the ASan runtime preloaded).
file(GLOB_RECURSE modules "${STAGE_DIR}/prefix/*/facyl.cpython-*.so")
if(modules AND NOT CXX_FLAGS MATCHES "sanitize")
  list(GET modules 0 module)
  get_filename_component(module_dir "${module}" DIRECTORY)
  execute_process(COMMAND ${CMAKE_COMMAND} -E env --unset=LD_LIBRARY_PATH
                          "PYTHONPATH=${module_dir}" /usr/bin/python3 -c
                          "import facyl; c = facyl.fit_cylinders(facyl.simulate_cylinder(radius=0.05, random_axis=True, seed=1)['points']); print(facyl.__file__, c[0])"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "radius=0.05")
    message(FATAL_ERROR "installed Python module failed (${rc}): ${out} ${err}")
  endif()
  message(STATUS "installed Python module: ${out}")
endif()
