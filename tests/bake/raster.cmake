# raster tests: Blender's looptris, texel-centre coverage and the edge rule, UDIM tiles, the
# per-texel frame and the map kinds, object <-> tangent conversion, edge padding, and
# bit-identical results for 1 and N threads, the lane-parallel shader against the per-sample one,
# and numerical stability (object scales 1e-6 … 1e6, degenerate faces, extreme bumps).
sgbake_add_gtest(bake_raster_tests
  raster_test.cpp
  maps_test.cpp
  convert_test.cpp
  padding_test.cpp
  shading_test.cpp
  limit_bake_test.cpp
  stability_test.cpp)
# rowSpan and the shaders, private to the library, are tested directly (rowSpan against the exact
# inside test, shadeBatch against shade()).
target_include_directories(bake_raster_tests PRIVATE ${PROJECT_SOURCE_DIR}/src)
