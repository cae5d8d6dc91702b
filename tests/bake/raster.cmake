# raster tests: Blender's looptris, texel-centre coverage and the edge rule, UDIM tiles, the
# per-texel frame and the map kinds, object <-> tangent conversion, edge padding, and
# bit-identical results for 1 and N threads.
sgbake_add_gtest(bake_raster_tests
  raster_test.cpp
  maps_test.cpp
  convert_test.cpp
  padding_test.cpp)
# rowSpan, a private helper of the raster, is tested directly against the exact inside test.
target_include_directories(bake_raster_tests PRIVATE ${PROJECT_SOURCE_DIR}/src)
