# Tests of the io exporters; included by CMakeLists.txt next to Readers.cmake.
list(APPEND STRATA_IO_TESTS
  TestOctomapExport.cpp
  TestPcdExport.cpp
  TestPlyExport.cpp
  TestPngExport.cpp
  TestVdbExport.cpp)
