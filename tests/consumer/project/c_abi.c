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

int consumer_c_bake(float out_rgba[64], char* error, size_t size);

/* The same triangle baked to a 4 x 4 object-space normal map: +z, encoded (0.5, 0.5, 1). */
int consumer_c_bake(float out_rgba[64], char* error, size_t size) {
  static const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  static const uint32_t face_start[2] = {0, 3};
  static const uint32_t corner_vertex[3] = {0, 1, 2};
  static const float uvs[6] = {0, 0, 1, 0, 0, 1};
  const float* uv_sets[1] = {uvs};
  sgbake_mesh mesh;
  sgbake_progress progress = {0.0f, 0};
  mesh.positions = positions;
  mesh.num_vertices = 3;
  mesh.face_start = face_start;
  mesh.num_faces = 1;
  mesh.corner_vertex = corner_vertex;
  mesh.corner_normals = NULL; /* smooth normals computed by sgbake */
  mesh.corner_uvs = uv_sets;
  mesh.num_uv_sets = 1;
  mesh.num_corners = 3;
  mesh.face_flat = NULL; /* every face smooth */
  mesh.auto_smooth = 0;
  return sgbake_bake_map("{\"outputs\": [{\"map\": \"object-normal\", \"size\": 4}]}", &mesh,
                         NULL, 0, 0, &progress, out_rgba, 64, error, size);
}
