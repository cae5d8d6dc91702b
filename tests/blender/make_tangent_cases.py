"""Generates MikkTSpace reference cases with Blender (runs inside Blender).

    blender -b --factory-startup --python-exit-code 1 \\
        --python tests/blender/make_tangent_cases.py -- OUT_DIR [--only NAME ...]

For every case it builds a mesh with bpy/bmesh, lets Blender compute split normals and
tangents (`Mesh.calc_normals_split()`, `Mesh.calc_tangents()`), and writes into OUT_DIR
  NAME.obj           the mesh: vertices, one vt and vn per corner, faces (see objio.py)
  NAME.tangents.csv  Blender's loop.tangent and loop.bitangent_sign in the same corner order
and finally cases.json, a list of {name, faces, corners, triangles, quads, max_tangent_len_error}.
compare_tangents.py runs the sgbake CLI on each OBJ and compares with the CSV.

The cases cover what can go wrong in a MikkTSpace port: triangles and quads mixed, flat and
smooth shading, split normals (auto smooth), UV seams, mirrored UVs (negative bitangent
sign, welded across the mirror line), coincident positions (degenerate triangles and quads),
collapsed and collinear UVs (zero-area texture triangles), n-gons triangulated beforehand
(calc_tangents refuses n-gons), and a mesh large enough for Blender's multi-threaded path.
"""

import json
import math
import os
import sys

import bmesh
import bpy

sys.dont_write_bytecode = True  # keep __pycache__ out of the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bake_common  # noqa: E402  (needs the sys.path entry above)
import objio  # noqa: E402


# ---------------------------------------------------------------------------------------------
# Helpers


def triangulate_ngons(me):
    """Triangulates faces with more than four corners; triangles and quads stay as they are."""
    bm = bmesh.new()
    bm.from_mesh(me)
    ngons = [f for f in bm.faces if len(f.verts) > 4]
    if ngons:
        bmesh.ops.triangulate(bm, faces=ngons)
    bm.to_mesh(me)
    bm.free()
    me.update()


def wave(x, y):
    """A smooth height field that makes flat grids non-planar (so quads are not planar)."""
    return 0.15 * math.sin(2.1 * x + 0.3) * math.cos(1.7 * y - 0.2) + 0.05 * x * y


def displace_grid(ob):
    """Lifts the vertices of a grid by wave(x, y)."""
    for v in ob.data.vertices:
        v.co.z = wave(v.co.x, v.co.y)
    ob.data.update()


def face_centre_x(me, poly):
    return sum(me.vertices[i].co.x for i in poly.vertices) / len(poly.vertices)


# ---------------------------------------------------------------------------------------------
# Cases: each builder adds one object to the empty scene and returns it.


def case_suzanne_flat():
    """Suzanne as the primitive makes her: flat shaded, triangles and quads, her own UVs."""
    bpy.ops.mesh.primitive_monkey_add(calc_uvs=True)
    return bpy.context.object


def case_suzanne_smooth():
    bpy.ops.mesh.primitive_monkey_add(calc_uvs=True)
    ob = bpy.context.object
    bake_common.set_smooth(ob, True)
    return ob


def case_suzanne_subsurf2():
    """Suzanne, smooth, Subdivision Surface level 2 applied (7872 quads, ~31k corners)."""
    ob = case_suzanne_smooth()
    mod = ob.modifiers.new("Subdivision", "SUBSURF")
    mod.levels = 2
    mod.render_levels = 2
    bpy.ops.object.modifier_apply(modifier=mod.name)
    return ob


def case_suzanne_mixed_no_normals():
    """Suzanne, every third face flat and the rest smooth, written without `vn` (with `s 0` /
    `s 1` lines): the reader computes the normals, flat faces' from the face alone, as
    Blender's importer does for such a file."""
    ob = case_suzanne_smooth()
    me = ob.data
    me.polygons.foreach_set("use_smooth", [f % 3 != 0 for f in range(len(me.polygons))])
    me.update()
    return ob


def case_uv_sphere():
    """UV sphere: quads plus triangle fans at the poles, one UV seam."""
    bpy.ops.mesh.primitive_uv_sphere_add(segments=32, ring_count=16, calc_uvs=True)
    ob = bpy.context.object
    bake_common.set_smooth(ob, True)
    return ob


def case_torus():
    """Torus: all quads, UVs stretched unevenly (quads split on the shorter UV diagonal)."""
    bpy.ops.mesh.primitive_torus_add(major_segments=48, minor_segments=12, generate_uvs=True)
    ob = bpy.context.object
    bake_common.set_smooth(ob, True)
    return ob


def case_torus_dense():
    """A dense torus, 10240 quads (20480 triangles): above Blender's threshold for running
    MikkTSpace on several threads, whatever it counts (faces or triangles)."""
    bpy.ops.mesh.primitive_torus_add(major_segments=128, minor_segments=80, generate_uvs=True)
    ob = bpy.context.object
    bake_common.set_smooth(ob, True)
    return ob


def case_cube_flat():
    """The default cube: six flat quads, every vertex split by normal and by UV."""
    bpy.ops.mesh.primitive_cube_add(calc_uvs=True)
    ob = bpy.context.object
    bake_common.set_smooth(ob, False)
    return ob


def case_cylinder_autosmooth():
    """Cylinder with n-gon caps (triangulated), smooth with auto smooth at 30 degrees: the split
    normals differ at the cap rims, so the same position carries several normals."""
    bpy.ops.mesh.primitive_cylinder_add(vertices=24, end_fill_type="NGON", calc_uvs=True)
    ob = bpy.context.object
    bake_common.set_smooth(ob, True)
    ob.data.use_auto_smooth = True
    ob.data.auto_smooth_angle = math.radians(30.0)
    return ob


def case_grid_mirrored_uv():
    """A wavy grid whose left half has its UVs mirrored in u about the centre line (u -> 1-u),
    as a Mirror modifier with "Mirror U" makes them: negative bitangent signs on the left, and
    the corners on the mirror line weld across it (same position, normal and UV)."""
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=12, y_subdivisions=10, size=2.0,
                                    calc_uvs=True)
    ob = bpy.context.object
    displace_grid(ob)
    bake_common.set_smooth(ob, True)
    me = ob.data
    uv = me.uv_layers.active.data
    for poly in me.polygons:
        if face_centre_x(me, poly) < 0.0:
            for li in poly.loop_indices:
                uv[li].uv.x = 1.0 - uv[li].uv.x
    return ob


def case_collapsed_vertices():
    """A wavy grid, right half triangulated, with vertices moved onto their neighbours: quads
    that became triangles, triangles of zero area, and a few faces collapsed to one point."""
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=12, y_subdivisions=12, size=2.0,
                                    calc_uvs=True)
    ob = bpy.context.object
    displace_grid(ob)
    bm = bmesh.new()
    bm.from_mesh(ob.data)
    bmesh.ops.triangulate(bm, faces=[f for f in bm.faces if f.calc_center_median().x > 0.0])
    bm.verts.ensure_lookup_table()
    bm.edges.ensure_lookup_table()
    bm.faces.ensure_lookup_table()
    moved = set()
    # Every 11th edge: move its first vertex onto its second (a zero-length edge).
    for e in list(bm.edges)[::11]:
        a, b = e.verts
        if a.index in moved or b.index in moved:
            continue
        a.co = b.co.copy()
        moved.add(a.index)
    # Every 23rd face: move all its vertices onto its first vertex (a face of zero size).
    for f in list(bm.faces)[5::23]:
        target = f.verts[0].co.copy()
        for v in f.verts:
            v.co = target
            moved.add(v.index)
    bm.to_mesh(ob.data)
    bm.free()
    ob.data.update()
    bake_common.set_smooth(ob, True)
    return ob


def case_collapsed_uvs():
    """UV sphere (triangles and quads) with broken UVs on some faces: all corners on one UV,
    all corners on one line (zero UV area), and one corner doubled (a quad with one
    zero-area half)."""
    bpy.ops.mesh.primitive_uv_sphere_add(segments=24, ring_count=12, calc_uvs=True)
    ob = bpy.context.object
    bake_common.set_smooth(ob, True)
    me = ob.data
    uv = me.uv_layers.active.data
    for poly in me.polygons:
        loops = list(poly.loop_indices)
        first = uv[loops[0]].uv.copy()
        kind = poly.index % 11
        if kind == 0:  # every corner on the first corner's UV
            for li in loops:
                uv[li].uv = first
        elif kind == 4:  # every corner on the line from the first to the second corner's UV
            direction = uv[loops[1]].uv - first
            for k, li in enumerate(loops):
                uv[li].uv = first + direction * (0.5 * k)
        elif kind == 8:  # the second corner on the first corner's UV
            uv[loops[1]].uv = first
    return ob


CASES = [
    ("suzanne_flat", case_suzanne_flat),
    ("suzanne_smooth", case_suzanne_smooth),
    ("suzanne_subsurf2", case_suzanne_subsurf2),
    ("suzanne_mixed_no_normals", case_suzanne_mixed_no_normals),
    ("uv_sphere", case_uv_sphere),
    ("torus", case_torus),
    ("torus_dense", case_torus_dense),
    ("cube_flat", case_cube_flat),
    ("cylinder_autosmooth", case_cylinder_autosmooth),
    ("grid_mirrored_uv", case_grid_mirrored_uv),
    ("collapsed_vertices", case_collapsed_vertices),
    ("collapsed_uvs", case_collapsed_uvs),
]


# Cases written without `vn`: the OBJ then carries Blender's smooth flags instead.
WITHOUT_NORMALS = {"suzanne_mixed_no_normals"}


# ---------------------------------------------------------------------------------------------


def write_case(name, ob, out_dir):
    """Computes Blender's tangents for the object's mesh and writes NAME.obj and the CSV."""
    import numpy as np

    me = ob.data
    triangulate_ngons(me)
    me.calc_normals_split()
    me.calc_tangents(uvmap=me.uv_layers.active.name)
    arrays = objio.mesh_arrays(me)
    tangents, signs = objio.mesh_tangents(me)
    me.free_tangents()
    with_normals = name not in WITHOUT_NORMALS
    if not with_normals:  # the smooth flags then say how to shade
        smooth = np.empty(len(me.polygons), bool)
        me.polygons.foreach_get("use_smooth", smooth)
        arrays["smooth"] = smooth
    objio.write_obj(os.path.join(out_dir, name + ".obj"), arrays,
                    comment=f"sgbake tangent oracle case {name} (Blender {bpy.app.version_string})",
                    normals=with_normals)
    objio.write_tangent_csv(os.path.join(out_dir, name + ".tangents.csv"),
                            arrays["face_size"], tangents, signs)
    length = np.linalg.norm(tangents.astype(np.float64), axis=1)
    sizes = arrays["face_size"]
    return {
        "name": name,
        "faces": int(len(sizes)),
        "corners": int(sizes.sum()),
        "triangles": int((sizes == 3).sum()),
        "quads": int((sizes == 4).sum()),
        "negative_signs": int((signs < 0).sum()),
        "max_tangent_len_error": float(np.abs(length - 1.0).max()),
    }


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if not argv or argv[0].startswith("-"):
        print(__doc__)
        raise SystemExit("usage: ... -- OUT_DIR [--only NAME ...]")
    out_dir = argv[0]
    only = set(argv[argv.index("--only") + 1:]) if "--only" in argv else None
    os.makedirs(out_dir, exist_ok=True)
    manifest = []
    for name, build in CASES:
        if only and name not in only:
            continue
        bake_common.reset_scene()
        info = write_case(name, build(), out_dir)
        manifest.append(info)
        print("case %-20s faces %6d corners %6d (tris %d, quads %d, sign -1: %d, "
              "max | |t|-1 | %.2g)" % (name, info["faces"], info["corners"], info["triangles"],
                                       info["quads"], info["negative_signs"],
                                       info["max_tangent_len_error"]))
    with open(os.path.join(out_dir, "cases.json"), "w", encoding="ascii") as f:
        json.dump(manifest, f, indent=1)


main()
