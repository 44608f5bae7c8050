# Configures, builds and runs one consumer project from scratch (cmake -P, called by tests.cmake):
#   cmake -DCONSUMER_SOURCE_DIR=... -DCONSUMER_BINARY_DIR=... [-DGENERATOR=...] [-DCXX_COMPILER=...]
#         [-DBUILD_TYPE=...] [-DPREFIX_PATH=p|q] [-DCONFIGURE_ARGS=a|b|c] -P run_consumer.cmake
# PREFIX_PATH (the consumer's CMAKE_PREFIX_PATH) and CONFIGURE_ARGS (extra -D arguments) are lists separated by '|'
# (a ';' would be split by add_test).
cmake_minimum_required(VERSION 3.20)

foreach(var CONSUMER_SOURCE_DIR CONSUMER_BINARY_DIR)
  if(NOT ${var})
    message(FATAL_ERROR "run_consumer.cmake: ${var} is not set")
  endif()
endforeach()

set(args -S "${CONSUMER_SOURCE_DIR}" -B "${CONSUMER_BINARY_DIR}")
if(GENERATOR)
  list(APPEND args -G "${GENERATOR}")
endif()
if(MAKE_PROGRAM)
  list(APPEND args "-DCMAKE_MAKE_PROGRAM=${MAKE_PROGRAM}")
endif()
if(CXX_COMPILER)
  list(APPEND args "-DCMAKE_CXX_COMPILER=${CXX_COMPILER}")
endif()
if(NOT BUILD_TYPE)
  set(BUILD_TYPE Release)
endif()
list(APPEND args "-DCMAKE_BUILD_TYPE=${BUILD_TYPE}")
if(CONFIGURE_ARGS)
  string(REPLACE "|" ";" extra "${CONFIGURE_ARGS}")
  list(APPEND args ${extra})
endif()

if(PREFIX_PATH)
  if(CMAKE_HOST_WIN32)
    string(REPLACE "|" ";" prefix_path "${PREFIX_PATH}")
  else()
    string(REPLACE "|" ":" prefix_path "${PREFIX_PATH}")
  endif()
  set(ENV{CMAKE_PREFIX_PATH} "${prefix_path}")  # the environment form takes a list without quoting trouble
endif()

file(REMOVE_RECURSE "${CONSUMER_BINARY_DIR}")
message(STATUS "configure: ${CMAKE_COMMAND} ${args}")
execute_process(COMMAND "${CMAKE_COMMAND}" ${args} COMMAND_ERROR_IS_FATAL ANY)
execute_process(COMMAND "${CMAKE_COMMAND}" --build "${CONSUMER_BINARY_DIR}" --config "${BUILD_TYPE}" --parallel 2
                COMMAND_ERROR_IS_FATAL ANY)

set(exe "${CONSUMER_BINARY_DIR}/consumer")
if(NOT EXISTS "${exe}" AND EXISTS "${CONSUMER_BINARY_DIR}/${BUILD_TYPE}/consumer${CMAKE_EXECUTABLE_SUFFIX}")
  set(exe "${CONSUMER_BINARY_DIR}/${BUILD_TYPE}/consumer")  # multi-config generators
endif()
execute_process(COMMAND "${CMAKE_COMMAND}" -E env OMP_NUM_THREADS=2 "${exe}" RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the consumer program failed (exit status ${rc})")
endif()
