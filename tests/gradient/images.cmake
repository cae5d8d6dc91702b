# images tests: loading image files (PNG 8/16-bit, TIFF, EXR; orientation; bad files) and the
# bilinear / Catmull-Rom / Hermite filters with their exact derivatives, UDIM textures.
sgbake_add_gtest(gradient_images_tests image_test.cpp filters_test.cpp udim_test.cpp)
# The tests write their input images with OpenImageIO (the library links it privately).
target_link_libraries(gradient_images_tests PRIVATE OpenImageIO::OpenImageIO)
target_include_directories(gradient_images_tests PRIVATE ${PROJECT_SOURCE_DIR}/src)  # io/image_check.hpp
