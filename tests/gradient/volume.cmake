# volume tests: procedural height volumes (directional sine, gradient noise) and their gradients.
sgbake_add_gtest(gradient_volume_tests volume_test.cpp)
