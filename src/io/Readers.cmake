# Scan readers and pose files (owned by the readers; included by src/io/CMakeLists.txt).
list(APPEND STRATA_IO_SOURCES
  TextParsing.cpp PoseFiles.cpp MatchPoses.cpp)
