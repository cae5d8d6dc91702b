/* The C side of the consumer: sgbake.h from plain C99. */
#include <sgbake/sgbake.h>

int consumer_c_tangents(float out_tangents[9], float out_signs[3], char* error, size_t size);

/* One triangle in the z = 0 plane with UVs equal to its x and y: the tangent is +x. */
int consumer_c_tangents(float out_tangents[9], float out_signs[3], char* error, size_t size) {
  static const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  static const uint32_t face_start[2] = {0, 3};
  static const uint32_t corner_vertex[3] = {0, 1, 2};
  static const float normals[9] = {0, 0, 1, 0, 0, 1, 0, 0, 1};
  static const float uvs[6] = {0, 0, 1, 0, 0, 1};
  return sgbake_compute_tangents(positions, 3, face_start, 1, corner_vertex, normals, uvs, 3, 0,
                                 out_tangents, out_signs, error, size);
}
