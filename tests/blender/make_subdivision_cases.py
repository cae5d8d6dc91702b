"""Generates Subdivision Surface reference cases with Blender (runs inside Blender).

    blender -b --factory-startup --python-exit-code 1 \\
        --python tests/blender/make_subdivision_cases.py -- OUT_DIR

Builds nine coarse meshes with bpy, all smooth shaded, with their own UVs:
  cube       the default cube (6 quads, closed, UV seams)
  suzanne    the monkey primitive (triangles and quads, open boundaries at the eyes)
  cylinder   a 7-sided cylinder with n-gon caps (the caps are 7-gons, not triangulated)
  grid       an open 4 x 3 grid of size 2, lifted by a wave (4 boundary corners of valence 2)
  cube_creased, suzanne_creased, cylinder_creased
             the cube, Suzanne and the cylinder with Edge Creases (0.3 to 1.0) on some edges
             and Vertex Creases on some vertices
  cube_flat, suzanne_flat
             the cube with two neighbouring faces flat-shaded, Suzanne with every third face
             flat (their OBJ files mark them with `s 0` / `s 1` as Blender's exporter does)
and writes each as OUT_DIR/MESH.obj (objio.write_obj: exact floats, one vt and vn per corner,
n-gons kept). Then, for every case in ALL_CASES, it gives the object a Subdivision Surface modifier
(Catmull-Clark, Use Limit Surface on, Quality 3, the case's Levels, UV Smooth, Boundary
Smooth and Use Creases), evaluates it, lets Blender compute split normals and MikkTSpace tangents of the
subdivided mesh (`Mesh.calc_normals_split()`, `Mesh.calc_tangents()`), and writes
  TAG.npz   positions (V, 3), face_size (F,), corner_vertex (C,), uvs (C, 2), normals (C, 3)
            (split normals), tangents (C, 3), signs (C,), smooth (F,) of the subdivided mesh,
            in Blender's order
and finally cases.json: {"blender": version, "python": Blender's Python interpreter (it has
numpy), "meshes": {MESH: {vertices, edges, faces, valence2, edge_creases, vertex_creases}},
"cases": [{tag, mesh, level, uv_smooth, boundary_smooth, use_creases, vertices, faces,
corners}]}, where valence2 counts the coarse vertices with exactly two edges (the open boundary
corners), edge_creases lists [v0, v1, crease] of every creased edge and vertex_creases [v,
crease] of every creased vertex (the creases as Blender stores them, float32, read back from the
mesh), and uv_smooth / boundary_smooth are Blender's enum names.
subdivision_oracle.py runs sgbake on MESH.obj with the same settings and compares.
"""

import json
import math
import os
import sys

import bpy

sys.dont_write_bytecode = True  # keep __pycache__ out of the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bake_common  # noqa: E402  (needs the sys.path entry above)
import objio  # noqa: E402


# ---------------------------------------------------------------------------------------------
# Coarse meshes: each builder adds one object to the empty scene and returns it.


def mesh_cube():
    bpy.ops.mesh.primitive_cube_add(calc_uvs=True)
    return bpy.context.object


def mesh_suzanne():
    bpy.ops.mesh.primitive_monkey_add(calc_uvs=True)
    return bpy.context.object


def mesh_cylinder():
    """Seven sides, so that the caps are n-gons (the modifier splits them into 7 quads)."""
    bpy.ops.mesh.primitive_cylinder_add(vertices=7, end_fill_type="NGON", calc_uvs=True)
    return bpy.context.object


def mesh_grid():
    """An open grid (4 x 3 quads, size 2), lifted so that it is not planar."""
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=4, y_subdivisions=3, size=2.0,
                                    calc_uvs=True)
    ob = bpy.context.object
    for v in ob.data.vertices:
        v.co.z = 0.3 * math.sin(3.0 * v.co.x) * math.cos(2.0 * v.co.y)
    ob.data.update()
    return ob


def mesh_cube_creased():
    """The cube with creases 0.3, 0.7 and 1.0 on three edges around one face, 0.5 on an edge
    of the opposite face, and vertex creases 0.6 and 1.0 (one on a creased edge, one not)."""
    ob = mesh_cube()
    bake_common.set_creases(ob, [(0, 0.3), (1, 0.7), (2, 1.0), (8, 0.5)], [(5, 0.6), (2, 1.0)])
    return ob


def mesh_suzanne_creased():
    """Suzanne with a few creased edges (0.3, 0.7, 1.0, chains and single edges, on triangles
    and quads) and two creased vertices."""
    ob = mesh_suzanne()
    bake_common.set_creases(ob, [(e, (0.3, 0.7, 1.0)[e % 3]) for e in range(0, 120, 7)]
                + [(300, 1.0), (301, 1.0), (302, 1.0), (640, 0.45)],
                [(10, 1.0), (200, 0.4)])
    return ob


def mesh_cylinder_creased():
    """The 7-sided cylinder with its top cap's rim fully creased (1.0) and the bottom rim at
    0.5: the n-gon caps next to creases."""
    ob = mesh_cylinder()
    me = ob.data
    top = max(v.co.z for v in me.vertices)
    rim = [(e.index, 1.0 if me.vertices[e.vertices[0]].co.z == top else 0.5)
           for e in me.edges
           if me.vertices[e.vertices[0]].co.z == me.vertices[e.vertices[1]].co.z]
    bake_common.set_creases(ob, rim, [])
    return ob


MESHES = [
    ("cube", mesh_cube),
    ("suzanne", mesh_suzanne),
    ("cylinder", mesh_cylinder),
    ("grid", mesh_grid),
    ("cube_creased", mesh_cube_creased),
    ("suzanne_creased", mesh_suzanne_creased),
    ("cylinder_creased", mesh_cylinder_creased),
    ("cube_flat", mesh_cube),
    ("suzanne_flat", mesh_suzanne),
]

# Meshes with flat-shaded faces (the rest are smooth): name -> the faces to shade flat.
FLAT_FACES = {
    "cube_flat": lambda me: [0, 1],                              # two neighbouring faces
    "suzanne_flat": lambda me: range(0, len(me.polygons), 3),    # every third face
}

# (mesh, level, uv_smooth, boundary_smooth, use_creases), Blender's enum names. Boundary smooth
# matters only on open boundaries, so only the grid tries both; Use Creases only on the creased
# meshes.
UV_SMOOTHS = ("PRESERVE_BOUNDARIES", "NONE", "SMOOTH_ALL")
PLAIN_MESHES = ("cube", "suzanne", "cylinder", "grid")
CREASED_MESHES = ("cube_creased", "suzanne_creased", "cylinder_creased")
FLAT_MESHES = tuple(FLAT_FACES)
CASES = (
    [(mesh, 1, uv, "ALL", True) for mesh in PLAIN_MESHES for uv in UV_SMOOTHS]
    + [("grid", 1, uv, "PRESERVE_CORNERS", True) for uv in UV_SMOOTHS]
    + [(mesh, 2, "PRESERVE_BOUNDARIES", "ALL", True) for mesh in ("suzanne", "cylinder", "grid")]
    + [("grid", 2, "PRESERVE_BOUNDARIES", "PRESERVE_CORNERS", True)]
    + [(mesh, level, "PRESERVE_BOUNDARIES", "ALL", True)
       for mesh in CREASED_MESHES for level in (1, 2)]
    + [("cube_creased", 1, "NONE", "ALL", True), ("cube_creased", 2, "PRESERVE_BOUNDARIES",
                                                   "ALL", False)]
    + [(mesh, level, "PRESERVE_BOUNDARIES", "ALL", True)
       for mesh in FLAT_MESHES for level in (1, 2)]
)


# Cases with a Quality other than a new modifier's 3 (the cases above): (mesh, level, uv_smooth,
# boundary_smooth, use_creases, quality). Quality is the level the patches isolate irregular
# vertices and semi-sharp creases to: 5 resolves the creased cube's corners further, 1 barely
# at all, and 6 moves the grid's open boundary corners.
QUALITY_CASES = [
    ("cube_creased", 2, "PRESERVE_BOUNDARIES", "ALL", True, 5),
    ("suzanne", 1, "SMOOTH_ALL", "ALL", True, 1),
    ("grid", 1, "PRESERVE_BOUNDARIES", "ALL", True, 6),
]
# Cases with Use Limit Surface off: (mesh, level, uv_smooth, boundary_smooth, use_creases,
# quality, use_limit_surface). The modifier then refines the cage uniformly `level` times and
# keeps the refined points (Quality unused): quads and triangles, n-gons, creases, an open
# boundary with its corners kept, UVs linear.
LIMIT_OFF_CASES = [
    ("suzanne", 2, "PRESERVE_BOUNDARIES", "ALL", True, 3, False),
    ("cylinder", 1, "SMOOTH_ALL", "ALL", True, 3, False),
    ("cube_creased", 2, "PRESERVE_BOUNDARIES", "ALL", True, 3, False),
    ("grid", 2, "NONE", "PRESERVE_CORNERS", True, 3, False),
]
# Cases of subdivision type Simple (faces split, the cage's shape kept; creases and Quality
# unused), with (…, use_limit_surface, subdivision_type) last: n-gons and triangles, creases
# (which must make no difference), UVs smoothed (which must not be), limit surface off.
SIMPLE_CASES = [
    ("suzanne", 2, "PRESERVE_BOUNDARIES", "ALL", True, 3, True, "SIMPLE"),
    ("cylinder_creased", 2, "SMOOTH_ALL", "ALL", True, 3, True, "SIMPLE"),
    ("grid", 1, "PRESERVE_BOUNDARIES", "ALL", True, 3, False, "SIMPLE"),
]
# Cases with the mesh's Auto Smooth on, with (…, subdivision_type, auto_smooth degrees) last:
# the subdivided mesh's split normals, split along infinitely sharp creases (cube, cylinder),
# around flat faces (Suzanne) and wherever the subdivided faces meet at a wide angle; at level
# 0 (the modifier leaves the mesh as it is) the coarse mesh's own split normals (meshes of
# triangles and quads: Blender's calc_tangents refuses n-gons).
AUTO_SMOOTH_CASES = [
    ("suzanne_flat", 0, "PRESERVE_BOUNDARIES", "ALL", True, 3, True, "CATMULL_CLARK", 20.0),
    ("suzanne", 0, "PRESERVE_BOUNDARIES", "ALL", True, 3, True, "CATMULL_CLARK", 45.0),
    ("cube_creased", 2, "PRESERVE_BOUNDARIES", "ALL", True, 3, True, "CATMULL_CLARK", 30.0),
    ("cylinder_creased", 1, "PRESERVE_BOUNDARIES", "ALL", True, 3, True, "CATMULL_CLARK", 30.0),
    ("suzanne_flat", 1, "PRESERVE_BOUNDARIES", "ALL", True, 3, True, "CATMULL_CLARK", 20.0),
    ("cylinder", 2, "PRESERVE_BOUNDARIES", "ALL", True, 3, True, "SIMPLE", 45.0),
]
# Cases with edges marked sharp (every k-th edge of the mesh), with (…, auto_smooth, k) last:
# at 180 degrees only the marks split the normals.
SHARP_CASES = [
    ("suzanne", 0, "PRESERVE_BOUNDARIES", "ALL", True, 3, True, "CATMULL_CLARK", 180.0, 5),
    ("suzanne", 1, "PRESERVE_BOUNDARIES", "ALL", True, 3, True, "CATMULL_CLARK", 180.0, 5),
    ("cylinder", 2, "PRESERVE_BOUNDARIES", "ALL", True, 3, True, "CATMULL_CLARK", 60.0, 4),
]
ALL_CASES = ([case + (3, True, "CATMULL_CLARK", None, 0) for case in CASES]
             + [case + (True, "CATMULL_CLARK", None, 0) for case in QUALITY_CASES]
             + [case + ("CATMULL_CLARK", None, 0) for case in LIMIT_OFF_CASES]
             + [case + (None, 0) for case in SIMPLE_CASES]
             + [case + (0,) for case in AUTO_SMOOTH_CASES] + SHARP_CASES)


def case_tag(mesh, level, uv_smooth, boundary_smooth, use_creases=True, quality=3,
             use_limit_surface=True, subdivision_type="CATMULL_CLARK", auto_smooth=None,
             sharp_every=0):
    return (f"{mesh}_L{level}_{uv_smooth}_{boundary_smooth}"
            + ("" if use_creases else "_nocreases") + ("" if quality == 3 else f"_Q{quality}")
            + ("" if use_limit_surface else "_nolimit")
            + ("" if subdivision_type == "CATMULL_CLARK" else "_simple")
            + ("" if auto_smooth is None else f"_autosmooth{auto_smooth:g}")
            + ("" if not sharp_every else f"_sharp{sharp_every}"))


# ---------------------------------------------------------------------------------------------


def write_coarse(name, ob, out_dir):
    """Writes the coarse mesh as NAME.obj; returns its counts."""
    import numpy as np

    me = ob.data
    me.calc_normals_split()
    arrays = objio.mesh_arrays(me)
    smooth = np.array([p.use_smooth for p in me.polygons], dtype=bool)
    if not smooth.all():
        arrays["smooth"] = smooth  # `s 0` / `s 1` lines, as Blender's exporter writes
    objio.write_obj(os.path.join(out_dir, name + ".obj"), arrays,
                    comment=f"sgbake subdivision oracle mesh {name} "
                            f"(Blender {bpy.app.version_string})")
    edge_vertices = np.empty(len(me.edges) * 2, np.int32)
    me.edges.foreach_get("vertices", edge_vertices)
    valence = np.bincount(edge_vertices, minlength=len(me.vertices))
    edge_creases, vertex_creases = bake_common.read_creases(me)
    return {"vertices": len(me.vertices), "edges": len(me.edges), "faces": len(me.polygons),
            "valence2": int((valence == 2).sum()), "edge_creases": edge_creases,
            "vertex_creases": vertex_creases}


def write_case(ob, mod, mesh, level, uv_smooth, boundary_smooth, use_creases, quality,
               use_limit_surface, subdivision_type, auto_smooth, sharp_every, out_dir):
    """Evaluates the object with the modifier set to the case; writes TAG.npz."""
    import math

    import numpy as np

    sharp_edges = []
    for i, e in enumerate(ob.data.edges):
        e.use_edge_sharp = bool(sharp_every) and i % sharp_every == 0
        if e.use_edge_sharp:
            sharp_edges.append([int(e.vertices[0]), int(e.vertices[1])])
    ob.data.use_auto_smooth = auto_smooth is not None
    ob.data.auto_smooth_angle = math.radians(auto_smooth if auto_smooth is not None else 30.0)
    mod.subdivision_type = subdivision_type
    mod.use_limit_surface = use_limit_surface
    mod.quality = quality
    mod.levels = level
    mod.render_levels = level
    mod.uv_smooth = uv_smooth
    mod.boundary_smooth = boundary_smooth
    mod.use_creases = use_creases
    depsgraph = bpy.context.evaluated_depsgraph_get()
    depsgraph.update()
    me = bpy.data.meshes.new_from_object(ob.evaluated_get(depsgraph))
    me.calc_normals_split()
    me.calc_tangents(uvmap=me.uv_layers.active.name)
    arrays = objio.mesh_arrays(me)
    tangents, signs = objio.mesh_tangents(me)
    tag = case_tag(mesh, level, uv_smooth, boundary_smooth, use_creases, quality,
                   use_limit_surface, subdivision_type, auto_smooth, sharp_every)
    np.savez(os.path.join(out_dir, tag + ".npz"), positions=arrays["positions"],
             face_size=arrays["face_size"], corner_vertex=arrays["corner_vertex"],
             uvs=arrays["uvs"], normals=arrays["normals"], tangents=tangents, signs=signs,
             smooth=np.array([p.use_smooth for p in me.polygons], dtype=bool))
    info = {"tag": tag, "mesh": mesh, "level": level, "uv_smooth": uv_smooth,
            "boundary_smooth": boundary_smooth, "use_creases": use_creases,
            "quality": quality, "use_limit_surface": use_limit_surface,
            "subdivision_type": subdivision_type, "auto_smooth": auto_smooth,
            "sharp_edges": sharp_edges,
            "vertices": len(me.vertices),
            "faces": len(me.polygons), "corners": len(me.loops)}
    bpy.data.meshes.remove(me)
    return info


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if not argv or argv[0].startswith("-"):
        print(__doc__)
        raise SystemExit("usage: ... -- OUT_DIR")
    out_dir = argv[0]
    os.makedirs(out_dir, exist_ok=True)
    # "python": Blender's own interpreter, which has numpy; the driver compares with it when
    # the python3 running the driver has no numpy (e.g. a pyenv one under CTest).
    manifest = {"blender": bpy.app.version_string, "python": sys.executable, "meshes": {},
                "cases": []}
    for name, build in MESHES:
        bake_common.reset_scene()
        ob = build()
        bake_common.set_smooth(ob, True)
        if name in FLAT_FACES:
            for f in FLAT_FACES[name](ob.data):
                ob.data.polygons[f].use_smooth = False
        manifest["meshes"][name] = write_coarse(name, ob, out_dir)
        mod = ob.modifiers.new("Subdivision", "SUBSURF")
        for case in ALL_CASES:
            if case[0] != name:
                continue
            info = write_case(ob, mod, *case, out_dir)
            manifest["cases"].append(info)
            print("case %-45s vertices %6d faces %6d corners %6d"
                  % (info["tag"], info["vertices"], info["faces"], info["corners"]))
    with open(os.path.join(out_dir, "cases.json"), "w", encoding="ascii") as f:
        json.dump(manifest, f, indent=1)


main()
