# Exporters of the io module (VDB bundle, OctoMap .bt/.ot, PLY, PCD, top-down PNG); included by
# CMakeLists.txt next to Readers.cmake.
list(APPEND STRATA_IO_SOURCES
  AtomicFile.cpp
  Image.cpp
  OctomapExport.cpp
  PcdExport.cpp
  PlyExport.cpp
  PngExport.cpp
  VdbExport.cpp)
