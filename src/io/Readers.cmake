# Scan readers and pose files (owned by the readers; included by src/io/CMakeLists.txt).
list(APPEND STRATA_IO_SOURCES
  BinaryCursor.cpp TextParsing.cpp ScanBuilder.cpp
  PcdHeader.cpp PcdReader.cpp PlyHeader.cpp PlyReader.cpp LasReader.cpp TextReader.cpp BinReader.cpp
  ReadPointCloud.cpp KittiFiles.cpp KittiSequence.cpp PoseFiles.cpp MatchPoses.cpp)
