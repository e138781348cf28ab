# strata view: per-tile answers of BALM at 0.1 m, cold, warm and over HTTP (docs/bench.md,
# Viewer); --keep DIR writes the maps bench/bench_viewer_page.py opens in headless Chromium.
if(TARGET strata_view)
  add_executable(bench_viewer ${CMAKE_CURRENT_LIST_DIR}/bench_viewer.cpp)
  target_link_libraries(bench_viewer PRIVATE Strata::view Strata::store Strata::integration
                                             Strata::io strata_test_support PkgConfig::CPPHTTPLIB)
  target_compile_definitions(bench_viewer PRIVATE STRATA_DATA_DIR="${STRATA_DATA_DIR}")
  strata_set_warnings(bench_viewer)
endif()
