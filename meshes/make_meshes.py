"""Regenerates the bundled meshes in meshes/ with Blender (run from the repository root):

    blender -b --factory-startup --python-exit-code 1 --python meshes/make_meshes.py

- suzanne.obj: Blender's Suzanne with its UVs, Subdivision Surface level 2 applied, smooth
  shading: 7,958 vertices, 7,872 quads, per-corner normals and UVs exactly as Blender holds them.
"""

import os
import sys

import bpy

sys.dont_write_bytecode = True
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tests", "blender"))
import objio  # noqa: E402

bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.mesh.primitive_monkey_add()
suzanne = bpy.context.object
modifier = suzanne.modifiers.new("subdivision", "SUBSURF")
modifier.levels = 2
bpy.ops.object.modifier_apply(modifier=modifier.name)
bpy.ops.object.shade_smooth()
mesh = suzanne.data
mesh.calc_normals_split()
objio.write_obj(os.path.join(HERE, "suzanne.obj"), objio.mesh_arrays(mesh),
                comment="Suzanne, Subdivision Surface level 2, smooth (meshes/make_meshes.py)")
print(f"suzanne.obj: {len(mesh.vertices)} vertices, {len(mesh.polygons)} faces, {len(mesh.loops)} corners")
