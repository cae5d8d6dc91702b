# Planner tests: the scene parser (strict keys, ranges, suggestions), writeImage (formats, bit
# depths, orientation, alpha, all-or-nothing files, <UDIM>), and the planner (only the work the
# outputs need, --explain, the manifest, execution, failures that leave outputs untouched).
sgbake_add_gtest(bake_planner_tests
  scene_test.cpp
  image_output_test.cpp
  planner_test.cpp)
# The tests read images back with OpenImageIO itself, not through sgbake, edit manifests, and
# write images from task arenas of their own.
target_link_libraries(bake_planner_tests PRIVATE OpenImageIO::OpenImageIO nlohmann_json::nlohmann_json
                      TBB::tbb)
