# cmake -DBUILD_DIR=... -DCONFIG=... -DEXAMPLE_SOURCE_DIR=... -DCXX_COMPILER=...
#       [-DCXX_COMPILER_LAUNCHER=...] [-DGENERATOR=...] -P run_install_test.cmake
#
# (0) builds the tree, since `cmake --install` needs everything it installs built (after `make`
# this is a no-op; the install also holds the application, not only the libraries), (a) installs
# BUILD_DIR into BUILD_DIR/install-test, (b) configures EXAMPLE_SOURCE_DIR against that prefix
# in BUILD_DIR/library-example-build, (c) builds it, (d) runs it. Any failing step stops the
# test with that step's output.
foreach(var BUILD_DIR CONFIG EXAMPLE_SOURCE_DIR CXX_COMPILER)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "run_install_test.cmake: -D${var}=... is required")
  endif()
endforeach()
set(prefix "${BUILD_DIR}/install-test")
set(example_build "${BUILD_DIR}/library-example-build")
file(REMOVE_RECURSE "${prefix}" "${example_build}")  # nothing stale from an earlier run

function(step name)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0)
    string(REPLACE ";" " " cmd "${ARGN}")
    message(FATAL_ERROR "${name} failed (${rc}):\n  ${cmd}\n${out}")
  endif()
  message(STATUS "${name}: ok")
  set(step_output "${out}" PARENT_SCOPE)
endfunction()

step("build the tree" ${CMAKE_COMMAND} --build "${BUILD_DIR}" --config "${CONFIG}")
step("install" ${CMAKE_COMMAND} --install "${BUILD_DIR}" --config "${CONFIG}" --prefix "${prefix}")

set(configure_args -S "${EXAMPLE_SOURCE_DIR}" -B "${example_build}" "-DCMAKE_PREFIX_PATH=${prefix}"
    "-DCMAKE_BUILD_TYPE=Release" "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}")
if(GENERATOR)
  list(APPEND configure_args -G "${GENERATOR}")
endif()
if(CXX_COMPILER_LAUNCHER)
  list(APPEND configure_args "-DCMAKE_CXX_COMPILER_LAUNCHER=${CXX_COMPILER_LAUNCHER}")
endif()
if(SANITIZE)  # a checked build's libraries are instrumented: the example must link the runtimes
  list(APPEND configure_args "-DCMAKE_CXX_FLAGS=-fsanitize=${SANITIZE}" "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=${SANITIZE}")
endif()
step("configure the example" ${CMAKE_COMMAND} ${configure_args})
step("build the example" ${CMAKE_COMMAND} --build "${example_build}" --config Release)

# The executable (single-config generators: at the top; multi-config: under Release/).
find_program(example NAMES cart_pendulum PATHS "${example_build}" "${example_build}/Release" NO_DEFAULT_PATH)
if(NOT example)
  message(FATAL_ERROR "the example built, but no cart_pendulum executable in ${example_build}")
endif()
step("run the example" "${example}")
message("${step_output}")

# (e) the installed application builds a problem of one's own against the installed package (its
# build log names the prefix's package, not the build tree's) and solves it. Skipped in a checked build (its plugin would need the sanitizer runtimes loaded
# into a non-instrumented host).
if(NOT SANITIZE)
  set(plugin_cache "${BUILD_DIR}/install-test-plugins")
  file(REMOVE_RECURSE "${plugin_cache}")
  execute_process(COMMAND "${prefix}/bin/lpshoot" solve --problem "${PLUGIN_SOURCE}" --plugin-cache "${plugin_cache}"
                          "${PLUGIN_SCENE}" --no-plot --out "${plugin_cache}/out"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0 OR NOT out MATCHES "status: converged")
    message(FATAL_ERROR "the installed lpshoot with --problem ${PLUGIN_SOURCE} failed (${rc}):\n${out}")
  endif()
  file(GLOB built "${plugin_cache}/*/build.log")
  file(READ "${built}" log)
  if(NOT log MATCHES "lpshoot_DIR=${prefix}/")
    message(FATAL_ERROR "the plugin was not built against the installed package ${prefix}:\n${log}")
  endif()
  message(STATUS "the installed lpshoot solves a problem of one's own: ok")
endif()

# (f) the installed Python module imports from the prefix (not the build tree) and solves a scene.
if(PYTHON AND PYTHON_PACKAGE_DIR)
  set(site "${prefix}/${PYTHON_PACKAGE_DIR}")
  step("the installed Python module" ${CMAKE_COMMAND} -E env "PYTHONPATH=${site}" "${PYTHON}"
       "${CMAKE_CURRENT_LIST_DIR}/check_python_module.py" "${PYTHON_SCENE}")
  if(NOT step_output MATCHES "^${site}/lpshoot/__init__.py converged")
    message(FATAL_ERROR "the Python module was not the installed one:\n${step_output}")
  endif()
endif()
