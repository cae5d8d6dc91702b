"""The operators: bake, layers from the active material, and the layer list's buttons.

Bad input (no active mesh, no UV map, a layer without an image, a library that cannot be
loaded, a scene libsgbake refuses) is reported with self.report({'ERROR'}, message) and the
operator returns {'CANCELLED'}: the user sees one line, never a traceback.
"""

import time

import bpy
from bpy.props import BoolProperty, EnumProperty

from . import capi, gather, library, scene

# Image Texture node settings -> layer settings. Cycles' Smart interpolation is cubic; Closest
# has no counterpart and becomes bilinear. Clip and Mirror become Repeat.
INTERPOLATION_FILTERS = {"Linear": "bilinear", "Cubic": "bicubic", "Smart": "bicubic",
                         "Closest": "bilinear"}
NORMAL_MAP_SPACES = {"TANGENT": "tangent", "OBJECT": "object"}


class OBJECT_OT_sgbake_bake(bpy.types.Operator):
    """Bake the chosen map of the active mesh object with sgbake into an image"""
    bl_idname = "object.sgbake_bake"
    bl_label = "Bake with sgbake"
    bl_options = {"REGISTER"}

    def execute(self, context):
        try:
            image, seconds = self.bake(context)
        except (gather.BakeInputError, capi.SgbakeError) as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        settings = context.scene.sgbake
        self.report({"INFO"}, f"sgbake: {settings.map} {settings.width} x {settings.height} "
                              f"into '{image.name}' in {seconds:.2f} s")
        return {"FINISHED"}

    @staticmethod
    def bake(context):
        """Bakes and writes the target image; returns (image, seconds in sgbake)."""
        settings = context.scene.sgbake
        ob = context.active_object
        if ob is None or ob.type != "MESH":
            raise gather.BakeInputError("sgbake bakes the active object, which must be a mesh")
        layers = scene.baked_layers(settings)
        images = gather.layer_images(layers)

        if ob.mode == "EDIT":
            ob.update_from_editmode()
        ob_eval = ob.evaluated_get(context.evaluated_depsgraph_get())
        mesh = ob_eval.to_mesh()
        try:
            try:
                uv_names, bake_uv = gather.uv_sets(mesh, settings.uv_map, layers)
            except gather.BakeInputError as exc:
                raise gather.BakeInputError(f"object '{ob.name}' {exc}") from None
            if len(mesh.polygons) == 0:
                raise gather.BakeInputError(f"object '{ob.name}' has no faces")
            mesh.calc_normals_split()
            arrays = gather.mesh_arrays(mesh, uv_names)
        finally:
            ob_eval.to_mesh_clear()

        scene_dict = scene.scene_json(settings, layers, bake_uv, uv_names.index)
        positions, face_start, corner_vertex, normals, uvs = arrays
        lib = library.get(context)
        start = time.perf_counter()
        rgba = capi.bake_map(lib, scene_dict, positions, face_start, corner_vertex, normals,
                             uvs, images, threads=settings.threads)
        seconds = time.perf_counter() - start
        image = gather.target_image(settings, ob.name)
        gather.write_pixels(image, rgba)
        return image, seconds


class OBJECT_OT_sgbake_layers_from_material(bpy.types.Operator):
    """Add sgbake layers for the Bump and Normal Map nodes of the active material that are fed
    directly by an Image Texture node"""
    bl_idname = "object.sgbake_layers_from_material"
    bl_label = "Layers from Material"
    bl_options = {"REGISTER", "UNDO"}

    replace: BoolProperty(name="Replace", default=True,
                          description="Remove the existing layers first")

    def execute(self, context):
        ob = context.active_object
        material = ob.active_material if ob is not None else None
        if material is None or not material.use_nodes:
            self.report({"ERROR"}, "the active object has no active node material")
            return {"CANCELLED"}
        found, skipped = material_layers(material.node_tree)
        if not found:
            self.report({"ERROR"}, f"material '{material.name}' has no Bump or Normal Map node "
                                   "fed by an Image Texture node" + _notes(skipped))
            return {"CANCELLED"}
        settings = context.scene.sgbake
        if self.replace:
            settings.layers.clear()
        for values in found:
            layer = settings.layers.add()
            for key, value in values.items():
                setattr(layer, key, value)
        settings.active_layer_index = len(settings.layers) - 1
        added = ", ".join(f"{v['type']} '{v['image'].name}' x {v['scale']:.4g}" for v in found)
        self.report({"INFO"}, f"added {len(found)} layer(s) from '{material.name}': {added}"
                              + _notes(skipped))
        return {"FINISHED"}


def _notes(skipped):
    return f" (skipped: {'; '.join(skipped)})" if skipped else ""


def _linked_image_node(socket):
    """The Image Texture node (with an image) linked directly into `socket`, or None."""
    if not socket.is_linked:
        return None
    node = socket.links[0].from_node
    return node if node.type == "TEX_IMAGE" and node.image is not None else None


def _texture_settings(node):
    """Layer settings taken from an Image Texture node: image, filter, wrap and, when its
    Vector input comes from a UV Map node, that UV map."""
    values = {"image": node.image, "name": node.image.name,
              "filter": INTERPOLATION_FILTERS.get(node.interpolation, "bilinear"),
              "wrap": "clamp" if node.extension == "EXTEND" else "repeat"}
    vector = node.inputs["Vector"]
    if vector.is_linked and vector.links[0].from_node.type == "UVMAP":
        values["uv_map"] = vector.links[0].from_node.uv_map
    return values


def material_layers(node_tree):
    """Layer settings (dicts of SgbakeLayer attributes) for each Bump node whose Height input
    and each Normal Map node whose Color input is an Image Texture node, in node order; and
    notes on the Bump and Normal Map nodes that were not used.

    Bump: scale = Distance x Strength, negated when Invert is on (Cycles blends the bumped
    normal by Strength; for a Strength of 1 the two are the same). Normal Map: its space
    (Tangent or Object) and its Strength."""
    found, skipped = [], []
    for node in node_tree.nodes:
        if node.type == "BUMP":
            tex = _linked_image_node(node.inputs["Height"])
            if tex is None:
                skipped.append(f"'{node.name}': Height is not an Image Texture node")
                continue
            scale = node.inputs["Distance"].default_value * node.inputs["Strength"].default_value
            values = _texture_settings(tex)
            values.update(type="height", scale=-scale if node.invert else scale)
            found.append(values)
        elif node.type == "NORMAL_MAP":
            tex = _linked_image_node(node.inputs["Color"])
            space = NORMAL_MAP_SPACES.get(node.space)
            if tex is None or space is None:
                why = ("Color is not an Image Texture node" if tex is None
                       else f"space {node.space} is not Tangent or Object")
                skipped.append(f"'{node.name}': {why}")
                continue
            values = _texture_settings(tex)
            values.update(type="normal", space=space, scale=node.inputs["Strength"].default_value)
            if space == "tangent" and node.uv_map:
                values["uv_map"] = node.uv_map
            found.append(values)
    return found, skipped


class SGBAKE_OT_layer_add(bpy.types.Operator):
    """Add a layer below the active one"""
    bl_idname = "sgbake.layer_add"
    bl_label = "Add Layer"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        settings = context.scene.sgbake
        settings.layers.add().name = f"Layer {len(settings.layers)}"
        new, wanted = len(settings.layers) - 1, settings.active_layer_index + 1
        if len(settings.layers) > 1 and wanted < new:
            settings.layers.move(new, wanted)
            new = wanted
        settings.active_layer_index = new
        return {"FINISHED"}


class SGBAKE_OT_layer_remove(bpy.types.Operator):
    """Remove the active layer"""
    bl_idname = "sgbake.layer_remove"
    bl_label = "Remove Layer"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        settings = context.scene.sgbake
        return 0 <= settings.active_layer_index < len(settings.layers)

    def execute(self, context):
        settings = context.scene.sgbake
        settings.layers.remove(settings.active_layer_index)
        settings.active_layer_index = max(0, min(settings.active_layer_index,
                                                 len(settings.layers) - 1))
        return {"FINISHED"}


class SGBAKE_OT_layer_move(bpy.types.Operator):
    """Move the active layer up or down the list"""
    bl_idname = "sgbake.layer_move"
    bl_label = "Move Layer"
    bl_options = {"REGISTER", "UNDO"}

    direction: EnumProperty(items=(("UP", "Up", ""), ("DOWN", "Down", "")))

    @classmethod
    def poll(cls, context):
        return len(context.scene.sgbake.layers) > 1

    def execute(self, context):
        settings = context.scene.sgbake
        index = settings.active_layer_index
        target = index - 1 if self.direction == "UP" else index + 1
        if 0 <= target < len(settings.layers):
            settings.layers.move(index, target)
            settings.active_layer_index = target
        return {"FINISHED"}


CLASSES = (OBJECT_OT_sgbake_bake, OBJECT_OT_sgbake_layers_from_material, SGBAKE_OT_layer_add,
           SGBAKE_OT_layer_remove, SGBAKE_OT_layer_move)
