# Tests of the scan readers and pose files (included by tests/io/CMakeLists.txt).
list(APPEND STRATA_IO_TESTS TestPointCloudReaders.cpp TestBinReader.cpp TestKittiSequence.cpp
  TestPoseFiles.cpp TestReaderFuzzFindings.cpp)
