# framework tests: the surface-gradient core (eq. 31, 33, 38, normal-map decoding), planar and
# triplanar projections, layer compositing and the per-corner driver, against analytic
# references (linear and sine height fields with exact derivatives) and invariants.
sgbake_add_gtest(gradient_framework_tests
  surface_gradient_test.cpp
  projection_test.cpp
  layers_test.cpp
  corners_test.cpp
  world_shading_test.cpp
  bump_node_test.cpp
  remap_test.cpp
  blender_noise_test.cpp
  blender_brick_test.cpp
  blender_gradient_test.cpp
  blender_magic_test.cpp)
# Cycles' valid-reflection guard, private to the library, is read directly by the layer tests.
target_include_directories(gradient_framework_tests PRIVATE ${PROJECT_SOURCE_DIR}/src)
