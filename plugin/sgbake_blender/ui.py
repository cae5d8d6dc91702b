"""The panel in Properties > Render > sgbake: output settings, the layer list and the bake
button, with the library's version (or why it cannot be loaded) at the top."""

import bpy

from . import library, scene


class SGBAKE_UL_layers(bpy.types.UIList):
    """One row per layer: name, type, image (or volume function), material slot (when it
    applies to one slot's faces) and weight."""

    def draw_item(self, context, layout, data, item, icon, active_data, active_propname, index):
        row = layout.row(align=True)
        row.prop(item, "name", text="", emboss=False,
                 icon="NODE_MATERIAL" if item.type == "normal" else "MOD_DISPLACE")
        row.label(text=item.type)
        if item.type in scene.IMAGE_LAYER_TYPES:
            row.label(text=item.image.name if item.image else "(no image)",
                      icon="IMAGE_DATA" if item.image else "ERROR")
        else:
            row.label(text=item.function)
        if item.material_index >= 0:
            row.label(text=f"slot {item.material_index}", icon="MATERIAL")
        row.prop(item, "weight", text="", emboss=False)


class SGBAKE_PT_bake(bpy.types.Panel):
    """Output settings and the bake button."""
    bl_label = "sgbake"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        settings = context.scene.sgbake
        loaded, line = library.describe(context)
        layout.label(text=line, icon="CHECKMARK" if loaded else "ERROR")

        ob = context.active_object
        layout.operator("sgbake.from_blender_bake", icon="IMPORT")
        layout.prop(settings, "map")
        layout.prop(settings, "surface")
        col = layout.column(align=True)
        col.prop(settings, "width", text="Size X")
        col.prop(settings, "height", text="Y")
        layout.prop(settings, "padding")
        row = layout.row()
        row.active = settings.padding != "push-pull"
        row.prop(settings, "margin")
        layout.prop(settings, "samples")
        if settings.map == "tangent-normal":
            layout.prop(settings, "green")
        if settings.map in ("tangent-normal", "object-normal"):
            row = layout.row(align=True)
            row.label(text="Swizzle")
            row.prop(settings, "swizzle_r", text="")
            row.prop(settings, "swizzle_g", text="")
            row.prop(settings, "swizzle_b", text="")
        if ob is not None and ob.type == "MESH":
            layout.prop_search(settings, "uv_map", ob.data, "uv_layers")
        else:
            layout.prop(settings, "uv_map")
        layout.prop(settings, "use_alpha")
        layout.prop(settings, "threads")
        layout.template_ID(settings, "target_image", new="image.new", open="image.open")
        target = settings.target_image
        if target is not None and target.source == "TILED":
            tiles = ", ".join(str(tile.number) for tile in target.tiles)
            layout.label(text=f"UDIM: bakes tile(s) {tiles}", icon="UV")

        row = layout.row()
        row.scale_y = 1.4
        row.enabled = ob is not None and ob.type == "MESH"
        row.operator("object.sgbake_bake", icon="RENDER_STILL")


class SGBAKE_PT_layers(bpy.types.Panel):
    """The layer list and the active layer's settings (only those its type uses)."""
    bl_label = "Layers"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    bl_parent_id = "SGBAKE_PT_bake"

    def draw(self, context):
        layout = self.layout
        settings = context.scene.sgbake
        if settings.map in scene.LAYERLESS_MAPS:
            layout.label(text=f"The {settings.map} map reads no layer", icon="INFO")
        row = layout.row()
        row.template_list("SGBAKE_UL_layers", "", settings, "layers", settings,
                          "active_layer_index", rows=3)
        buttons = row.column(align=True)
        buttons.operator("sgbake.layer_add", icon="ADD", text="")
        buttons.operator("sgbake.layer_remove", icon="REMOVE", text="")
        buttons.separator()
        buttons.operator("sgbake.layer_move", icon="TRIA_UP", text="").direction = "UP"
        buttons.operator("sgbake.layer_move", icon="TRIA_DOWN", text="").direction = "DOWN"
        layout.operator("object.sgbake_layers_from_material", icon="MATERIAL")

        if not 0 <= settings.active_layer_index < len(settings.layers):
            return
        layer = settings.layers[settings.active_layer_index]
        layout.use_property_split = True
        layout.use_property_decorate = False
        col = layout.column()
        col.prop(layer, "type")
        col.prop(layer, "weight")
        col.prop(layer, "material_index")
        if layer.material_index >= 0:
            col.label(text=_slot_text(context.active_object, layer.material_index))
        if layer.type in scene.IMAGE_LAYER_TYPES:
            col.template_ID(layer, "image", open="image.open")
            if layer.type in ("planar", "triplanar"):
                col.prop(layer, "kind")
            if layer.type == "planar":
                col.prop(layer, "planar_projection")
                if layer.planar_projection == "axis":
                    col.prop(layer, "axis")
            if layer.type in ("planar", "triplanar"):
                _draw_mapping(col, layer)
            col.prop(layer, "scale", text="Strength" if layer.type == "normal" else "Scale")
            if scene.bumps_height(layer):
                col.prop(layer, "strength")
                col.prop(layer, "height_space")
            if layer.type == "height":
                col.prop(layer, "channel")
            if layer.type == "height" or (layer.type in ("planar", "triplanar")
                                          and layer.kind == "height"):
                col.prop(layer, "base")
                col.prop(layer, "slopes")
            if scene.bumps_height(layer) and layer.remap.strip():
                col.label(text=_remap_text(layer), icon="FCURVE")
            col.prop(layer, "filter")
            col.prop(layer, "wrap")
            col.prop(layer, "tiling")
            col.prop(layer, "offset")
        if scene.reads_uv(layer):
            ob = context.active_object
            if ob is not None and ob.type == "MESH":
                col.prop_search(layer, "uv_map", ob.data, "uv_layers")
            else:
                col.prop(layer, "uv_map")
        if layer.type == "normal":
            col.prop(layer, "space")
        if (layer.type == "normal" and layer.space == "tangent") or (
                scene.projected_by_blender(layer) and layer.kind == "tangent-normal"):
            ob = context.active_object
            if ob is not None and ob.type == "MESH":
                col.prop_search(layer, "tangent_uv_map", ob.data, "uv_layers")
            else:
                col.prop(layer, "tangent_uv_map")
        if layer.type == "triplanar":
            col.prop(layer, "projection")
            if layer.projection == "box":
                col.prop(layer, "box_blend")
            else:
                col.prop(layer, "sharpness")
                col.prop(layer, "min_weight")
        if scene.reads_tangent_normals(layer):
            col.prop(layer, "green")
        if layer.type == "volume":
            col.prop(layer, "function")
            col.prop(layer, "amplitude")
            texture = scene.BLENDER_TEXTURE_SETTINGS.get(layer.function)
            if layer.function not in scene.UNSCALED_FUNCTIONS:
                col.prop(layer, "frequency", text="Scale" if texture else "Frequency")
            if layer.function == "sine":
                col.prop(layer, "direction")
                col.prop(layer, "phase")
            elif layer.function == "noise":
                col.prop(layer, "seed")
                col.prop(layer, "octaves")
            # A Blender texture's enums and inputs (a Musgrave's those of its type, a
            # Voronoi's those of its feature)
            for name in scene.texture_settings(layer.function, layer.musgrave_type,
                                               layer.feature, layer.texture_dimensions):
                col.prop(layer, name)
            col.prop(layer, "gradient")
            if layer.gradient in ("central", "tetrahedral"):
                col.prop(layer, "step")
            col.prop(layer, "strength")
            col.prop(layer, "height_space")
            col.prop(layer, "base")
            if layer.remap.strip():
                col.label(text=_remap_text(layer), icon="FCURVE")
            _draw_mapping(col, layer)

        col = layout.column(heading="Mask")
        col.template_ID(layer, "mask_image", open="image.open")
        if layer.mask_image is not None:
            ob = context.active_object
            if ob is not None and ob.type == "MESH":
                col.prop_search(layer, "mask_uv_map", ob.data, "uv_layers", text="UV Map")
            else:
                col.prop(layer, "mask_uv_map", text="UV Map")
            col.prop(layer, "mask_tiling", text="Tiling")
            col.prop(layer, "mask_offset", text="Offset")
            col.prop(layer, "mask_filter", text="Filter")


def _draw_mapping(col, layer):
    """The Mapping box of a projected or volume layer: the Mapping node's settings and the
    coordinates it maps (the object's own, another object's, the Generated ones)."""
    box = col.box()
    box.label(text="Mapping")
    for name in ("mapping_type", "mapping_location", "mapping_rotation", "mapping_scale"):
        box.prop(layer, name)
    if layer.type == "volume":
        box.prop(layer, "coordinates_uv")
    if not scene.on_object_coordinates(layer):
        return  # (a volume on a UV map: its UV Map above)
    box.prop(layer, "coordinates_object")
    box.prop(layer, "coordinates_generated")
    box.prop(layer, "coordinates_world")
    if (tuple(layer.mapping_matrix) != (1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0)
            and layer.coordinates_object is None and not layer.coordinates_generated
            and not layer.coordinates_world):
        box.label(text="Coordinates: an affine map of the object's own")


def _remap_text(layer):
    """One line on a height layer's Remap: how many points and the range of its values, or why
    it cannot be sent."""
    try:
        points = scene.remap_points(layer)
    except scene.LayerError as exc:
        why = str(exc).split(": Remap ", 1)[-1].split(" (a JSON list", 1)[0]
        return f"Remap: invalid ({why})"
    values = [y for _, y in points]
    return (f"Remap: {len(points)} points, x {points[0][0]:.4g} to {points[-1][0]:.4g}, "
            f"values {min(values):.4g} to {max(values):.4g}")


def _slot_text(ob, index):
    """What material slot `index` of the active object `ob` holds, under a layer's Material
    Slot: the layer bumps the faces of that slot only."""
    if ob is None or ob.type != "MESH":
        return f"the faces of material slot {index}"
    if index >= max(len(ob.material_slots), 1):  # no slot: every face is in slot 0
        return f"'{ob.name}' has no slot {index}: no face"
    if len(ob.material_slots) == 0:
        return f"every face ('{ob.name}' has no material slot)"
    material = ob.material_slots[index].material
    return (f"the faces of slot {index} ('{material.name}')" if material
            else f"the faces of empty slot {index}")


CLASSES = (SGBAKE_UL_layers, SGBAKE_PT_bake, SGBAKE_PT_layers)
