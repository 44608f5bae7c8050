# Output read back by independent readers: sphfsi's .vtu/.pvd files checked with VTK's own Python reader.
#   io.vtk_write_sample   (fixture) writes known particle sets in both encodings, 2D and 3D, float and double
#   io.vtk_python_reader  reads them with vtkXMLUnstructuredGridReader; SKIPPED (exit 77) without Python or vtk
# Configure with -DPython3_EXECUTABLE=/path/to/python3 to choose the interpreter that has the vtk module.
add_executable(sphfsi_vtk_write_sample ${CMAKE_CURRENT_LIST_DIR}/write_sample.cpp)
target_link_libraries(sphfsi_vtk_write_sample PRIVATE sphfsi::sphfsi)
target_compile_options(sphfsi_vtk_write_sample PRIVATE $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic>)

set(SPHFSI_VTK_SAMPLE_DIR ${CMAKE_CURRENT_BINARY_DIR}/output/vtk_sample)
add_test(NAME io.vtk_write_sample COMMAND sphfsi_vtk_write_sample ${SPHFSI_VTK_SAMPLE_DIR})
set_tests_properties(io.vtk_write_sample PROPERTIES FIXTURES_SETUP sphfsi_vtk_sample)

if(NOT Python3_Interpreter_FOUND)
  find_package(Python3 COMPONENTS Interpreter QUIET)
endif()
if(Python3_Interpreter_FOUND)
  add_test(NAME io.vtk_python_reader
           COMMAND ${Python3_EXECUTABLE} ${CMAKE_CURRENT_LIST_DIR}/check_vtk.py ${SPHFSI_VTK_SAMPLE_DIR})
else()
  # Visible skip rather than a silent pass: the test exists and reports why it did not run.
  add_test(NAME io.vtk_python_reader
           COMMAND sphfsi_vtk_write_sample --skip "no Python 3 interpreter found; configure with -DPython3_EXECUTABLE=...")
endif()
set_tests_properties(io.vtk_python_reader PROPERTIES FIXTURES_REQUIRED sphfsi_vtk_sample SKIP_RETURN_CODE 77)
