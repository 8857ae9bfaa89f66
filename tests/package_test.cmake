# SPDX-License-Identifier: MIT
# The installable package, as a consumer sees it: installs the build into a fresh prefix, then
# configures, builds and runs examples/consumer against it with find_package(plaf).
#   cmake -DBUILD=<build dir> -DSOURCE=<source dir> -DWORK=<scratch dir> -P package_test.cmake
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
function(step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "package: ${what} failed (${rc}):\n${out}\n${err}")
  endif()
  message(STATUS "package: ${what}: ok")
  set(last_output "${out}" PARENT_SCOPE)
endfunction()
step("install" ${CMAKE_COMMAND} --install "${BUILD}" --prefix "${WORK}/prefix")
foreach(f lib/cmake/plaf/plafConfig.cmake lib/cmake/plaf/plafTargets.cmake bin/plaf include/plaf/modules/base/error.h
          include/plaf/layers/grow_layers_2d.h lib/libplaf_core.a lib/libplaf_layers.a)
  if(NOT EXISTS "${WORK}/prefix/${f}")
    message(FATAL_ERROR "package: ${f} is not installed")
  endif()
endforeach()
step("configure the consumer" ${CMAKE_COMMAND} -S "${SOURCE}/examples/consumer" -B "${WORK}/consumer"
     -DCMAKE_BUILD_TYPE=Release "-DCMAKE_PREFIX_PATH=${WORK}/prefix")
step("build the consumer" ${CMAKE_COMMAND} --build "${WORK}/consumer")
step("run the consumer" "${WORK}/consumer/plaf_consumer" "${WORK}/consumer.msh")
message(STATUS "${last_output}")
step("the installed CLI" "${WORK}/prefix/bin/plaf" --version)
# The installed Python module (when built): importable from the prefix's site folder, and runs.
if(PYTHON)
  file(GLOB_RECURSE module "${WORK}/prefix/__init__.py")
  list(FILTER module INCLUDE REGEX "/plaf/__init__\\.py$")
  if(NOT module)
    message(FATAL_ERROR "package: the Python module plaf is not installed under ${WORK}/prefix")
  endif()
  list(GET module 0 init)
  get_filename_component(pkg "${init}" DIRECTORY)
  get_filename_component(site "${pkg}" DIRECTORY)
  step("the installed Python module" ${CMAKE_COMMAND} -E env "PYTHONPATH=${site}" "${PYTHON}" -c
       "import plaf; m = plaf.run({'order': 2, 'geometry': {'type': 'annulus', 'r_inner': 1, 'r_outer': 2}, 'metric': {'type': 'uniform', 'h': 0.5}}); assert m.ok and len(m.points) > 0; print(m)")
  message(STATUS "${last_output}")
endif()
