# Installs the sphfsi component of a build tree into a fresh prefix (cmake -P, called by tests.cmake):
#   cmake -DBUILD_DIR=<sphfsi build> -DPREFIX=<prefix> [-DCONFIG=<config>] -P install_package.cmake
# Checks the files a find_package(sphfsi) consumer needs are there.
cmake_minimum_required(VERSION 3.20)

foreach(var BUILD_DIR PREFIX)
  if(NOT ${var})
    message(FATAL_ERROR "install_package.cmake: ${var} is not set")
  endif()
endforeach()

file(REMOVE_RECURSE "${PREFIX}")
set(config_args "")
if(CONFIG)
  set(config_args --config "${CONFIG}")
endif()
execute_process(COMMAND "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${PREFIX}" --component sphfsi
                        ${config_args}
                COMMAND_ERROR_IS_FATAL ANY)

file(GLOB_RECURSE config_files "${PREFIX}/*/sphfsiConfig.cmake")
foreach(required "${PREFIX}/include/sphfsi/sphfsi.hpp" ${config_files})
  if(NOT EXISTS "${required}")
    message(FATAL_ERROR "missing after install: ${required}")
  endif()
endforeach()
if(NOT config_files)
  message(FATAL_ERROR "no sphfsiConfig.cmake under ${PREFIX}")
endif()
message(STATUS "installed sphfsi into ${PREFIX}: ${config_files}")
