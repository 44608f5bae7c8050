# Packaging tests (included by tests/CMakeLists.txt): two user projects build against sphfsi exactly as users do.
#   consumer.install                   cmake --install of this build into a prefix inside the build tree (fixture)
#   consumer.find_package[_no_openmp]  find_package(sphfsi) from that prefix + target_link_libraries(sphfsi::sphfsi)
#   consumer.add_subdirectory[_no_openmp]  add_subdirectory(<sphfsi source>)
# The _no_openmp variants configure the consumer with CMAKE_DISABLE_FIND_PACKAGE_OpenMP=ON (OpenMP "not found").
set(SPHFSI_CONSUMER_WORK_DIR ${CMAKE_CURRENT_BINARY_DIR}/consumer)
set(SPHFSI_CONSUMER_PREFIX ${SPHFSI_CONSUMER_WORK_DIR}/prefix)

add_test(NAME consumer.install
         COMMAND ${CMAKE_COMMAND} -DPREFIX=${SPHFSI_CONSUMER_PREFIX} -DBUILD_DIR=${PROJECT_BINARY_DIR} -DCONFIG=$<CONFIG>
                 -P ${CMAKE_CURRENT_LIST_DIR}/install_package.cmake)
set_tests_properties(consumer.install PROPERTIES FIXTURES_SETUP sphfsi_installed LABELS consumer TIMEOUT 120)

# What every consumer gets from this build: generator, compiler, build type and where the dependencies were found.
set(_consumer_common -DGENERATOR=${CMAKE_GENERATOR} -DMAKE_PROGRAM=${CMAKE_MAKE_PROGRAM}
                     -DCXX_COMPILER=${CMAKE_CXX_COMPILER} -DBUILD_TYPE=$<CONFIG>)
set(_consumer_deps "")
foreach(dep Eigen3 fmt)
  if(${dep}_DIR)
    string(APPEND _consumer_deps "|-D${dep}_DIR=${${dep}_DIR}")
  endif()
endforeach()
# The consumer's CMAKE_PREFIX_PATH: the install prefix first, then this build's own CMAKE_PREFIX_PATH.
string(REPLACE ";" "|" _outer_prefix_path "${CMAKE_PREFIX_PATH}")
set(_consumer_prefix_path "${SPHFSI_CONSUMER_PREFIX}")
if(_outer_prefix_path)
  string(APPEND _consumer_prefix_path "|${_outer_prefix_path}")
endif()
if(OpenMP_CXX_FOUND)
  set(_consumer_openmp ON)
else()
  set(_consumer_openmp OFF)
endif()

foreach(variant IN ITEMS "" _no_openmp)
  if(variant STREQUAL "")
    set(_openmp_args "|-DSPHFSI_CONSUMER_EXPECT_OPENMP=${_consumer_openmp}")
  else()
    set(_openmp_args "|-DCMAKE_DISABLE_FIND_PACKAGE_OpenMP=ON|-DSPHFSI_CONSUMER_EXPECT_OPENMP=OFF")
  endif()

  add_test(NAME consumer.find_package${variant}
           COMMAND ${CMAKE_COMMAND} ${_consumer_common}
                   -DCONSUMER_SOURCE_DIR=${CMAKE_CURRENT_LIST_DIR}/find_package
                   -DCONSUMER_BINARY_DIR=${SPHFSI_CONSUMER_WORK_DIR}/find_package${variant}
                   "-DPREFIX_PATH=${_consumer_prefix_path}"
                   "-DCONFIGURE_ARGS=${_consumer_deps}${_openmp_args}"
                   -P ${CMAKE_CURRENT_LIST_DIR}/run_consumer.cmake)
  set_tests_properties(consumer.find_package${variant} PROPERTIES
                       FIXTURES_REQUIRED sphfsi_installed LABELS consumer TIMEOUT 300)

  add_test(NAME consumer.add_subdirectory${variant}
           COMMAND ${CMAKE_COMMAND} ${_consumer_common}
                   -DCONSUMER_SOURCE_DIR=${CMAKE_CURRENT_LIST_DIR}/add_subdirectory
                   -DCONSUMER_BINARY_DIR=${SPHFSI_CONSUMER_WORK_DIR}/add_subdirectory${variant}
                   "-DPREFIX_PATH=${_outer_prefix_path}"
                   "-DCONFIGURE_ARGS=-DSPHFSI_SOURCE_DIR=${PROJECT_SOURCE_DIR}${_consumer_deps}${_openmp_args}"
                   -P ${CMAKE_CURRENT_LIST_DIR}/run_consumer.cmake)
  set_tests_properties(consumer.add_subdirectory${variant} PROPERTIES LABELS consumer TIMEOUT 300)
endforeach()
unset(_consumer_common)
unset(_consumer_deps)
unset(_consumer_prefix_path)
unset(_outer_prefix_path)
unset(_consumer_openmp)
unset(_openmp_args)
