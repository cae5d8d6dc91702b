"""The operators: bake, layers from the object's materials, and the layer list's buttons.

Bad input (no active mesh, no UV map, a layer without an image, a library that cannot be
loaded, a scene libsgbake refuses) is reported with self.report({'ERROR'}, message) and the
operator returns {'CANCELLED'}: the user sees one line, never a traceback.
"""

import collections
import threading
import time

import bpy
from bpy.props import BoolProperty, EnumProperty

from . import capi, gather, library, remap, scene

# Image Texture node settings -> layer settings. Cycles' Smart interpolation is cubic; Closest
# has no counterpart and becomes bilinear. Clip and Mirror become Repeat.
INTERPOLATION_FILTERS = {"Linear": "bilinear", "Cubic": "bicubic", "Smart": "bicubic",
                         "Closest": "bilinear"}
NORMAL_MAP_SPACES = {"TANGENT": "tangent", "OBJECT": "object"}


class BakeJob:
    """One bake, split so that the part without bpy can run on a worker thread: prepare()
    reads everything from Blender (in the main thread), run() calls libsgbake (any thread;
    ctypes releases the GIL meanwhile), finish() writes the target image (main thread)."""

    def __init__(self, context):
        settings = context.scene.sgbake
        ob = context.active_object
        if ob is None or ob.type != "MESH":
            raise gather.BakeInputError("sgbake bakes the active object, which must be a mesh")
        layers = scene.baked_layers(settings)
        self.images = gather.layer_images(layers)
        gather.follow_coordinates(layers, ob)

        if ob.mode == "EDIT":
            ob.update_from_editmode()
        # The exact limit surface is that of the mesh under the last modifier (sgbake
        # evaluates it): the mesh is evaluated without that modifier.
        self.surface = settings.surface
        modifier = None
        if self.surface == "limit":
            try:
                modifier = gather.limit_modifier(ob)
            except gather.BakeInputError as exc:
                raise gather.BakeInputError(f"object '{ob.name}' {exc}") from None
        subdivision = None
        # The modifiers as Cycles bakes them (render visibility and levels); the limit
        # surface's own modifier hidden.
        with gather.render_settings(ob, hidden=modifier):
            ob_eval = ob.evaluated_get(context.evaluated_depsgraph_get())
            # Cycles shades the object in world space: the mesh goes in object space, with the
            # matrix that places it (heights then in world units, as the Bump Distance is).
            transform, self.notes = gather.world_transform(ob_eval, settings.map)
            mesh = ob_eval.to_mesh()
            try:
                try:
                    uv_names, bake_uv = gather.uv_sets(mesh, settings.uv_map, layers)
                    render_uv = gather.render_uv_name(mesh)
                    self.uv_names = uv_names  # the mesh's UV maps sent, in their set order
                except gather.BakeInputError as exc:
                    raise gather.BakeInputError(f"object '{ob.name}' {exc}") from None
                if len(mesh.polygons) == 0:
                    raise gather.BakeInputError(f"object '{ob.name}' has no faces")
                mesh.calc_normals_split()
                # Each face's material slot: layers made from a slot's material apply to its
                # faces (Cycles shades each face with its own material's node tree).
                self.arrays = gather.mesh_arrays(mesh, uv_names, len(ob_eval.material_slots))
                if modifier is not None:
                    subdivision = scene.limit_subdivision_json(modifier, *gather.creases(mesh))
            finally:
                ob_eval.to_mesh_clear()

        self.lib = library.get(context)
        self.threads = settings.threads
        # What finish() needs, fixed now: the settings may change while the bake runs.
        self.map, self.width, self.height = settings.map, settings.width, settings.height
        # The target is found again by its identity, not its name: it may be renamed meanwhile.
        target = settings.target_image
        self.target = target.name if target else None
        self.target_pointer = target.as_pointer() if target else None
        self.default_name = gather.blender_name(f"{ob.name}_{settings.map}")
        # A tiled (UDIM) target gets every one of its tiles, each baked by its own call.
        image = target if target else bpy.data.images.get(self.default_name)
        self.tiled = image is not None and image.source == "TILED"
        if image is not None and not self.tiled:
            gather.check_target(image)
        gather.check_memory(self.width, self.height, settings.padding)
        self.tiles = gather.image_tiles(image)
        try:
            self.scenes = {tile: scene.scene_json(settings, layers, bake_uv, uv_names.index,
                                                  tile, subdivision, transform, render_uv)
                           for tile in self.tiles}
        except scene.LayerError as exc:
            raise gather.BakeInputError(str(exc)) from None
        self.scene = self.scenes[self.tiles[0]]
        self.uv_tiles = gather.uv_tiles(self.arrays[4][bake_uv], self.arrays[1])
        self.progress = capi.Progress(0.0, 0)
        self.tile_index = 0
        self.rgba = None
        self.error = None
        self.seconds = 0.0

    def fraction(self):
        """The bake's progress, 0 to 1, over all its tiles."""
        done = self.tile_index + min(max(self.progress.fraction, 0.0), 1.0)
        return min(done / len(self.tiles), 1.0)

    def run(self):
        """Bakes every tile; keeps the pixels in self.rgba ({tile: RGBA floats}) or the failure
        in self.error."""
        start = time.perf_counter()
        try:
            (positions, face_start, corner_vertex, normals, uvs, face_flat, auto_smooth,
             face_material) = self.arrays
            rgba = {}
            for index, tile in enumerate(self.tiles):
                self.progress.fraction = 0.0
                self.tile_index = index
                rgba[tile] = capi.bake_map(self.lib, self.scenes[tile], positions, face_start,
                                           corner_vertex, normals, uvs, self.images,
                                           threads=self.threads, progress=self.progress,
                                           face_flat=face_flat, auto_smooth=auto_smooth,
                                           face_material=face_material)
            self.rgba = rgba
        except capi.SgbakeError as exc:
            self.error = exc
        except MemoryError:
            self.error = capi.SgbakeError(f"not enough memory for a {self.width} x "
                                          f"{self.height} bake (try a smaller size)")
        except Exception as exc:  # on the worker thread: reported, not lost with the thread
            self.error = capi.SgbakeError(f"the bake failed: {type(exc).__name__}: {exc}")
        self.seconds = time.perf_counter() - start

    def finish(self):
        """Writes the pixels into the target image (after a successful run); returns the image
        and notes for the report. Raises BakeInputError when the target changed meanwhile."""
        target = None
        if self.target_pointer is not None:
            target = next((image for image in bpy.data.images
                           if image.as_pointer() == self.target_pointer), None)
            if target is None:
                raise gather.BakeInputError(f"the target image '{self.target}' was removed "
                                            "during the bake; nothing was written")
        if self.tiled:
            image = target if self.target else bpy.data.images.get(self.default_name)
            if image is None or image.source != "TILED":
                raise gather.BakeInputError(f"image '{self.target or self.default_name}' is no "
                                            "longer a UDIM image; bake again")
            return image, gather.write_tiles(image, self.rgba, self.width, self.height)
        image = gather.target_image(target, self.default_name, self.width, self.height)
        try:
            gather.write_pixels(image, self.rgba[1001])
        except RuntimeError as exc:  # an image Blender cannot hold pixels in after all
            raise gather.BakeInputError(f"image '{image.name}' cannot take the pixels: "
                                        f"{exc}") from None
        return image, []

    def tile_notes(self, image_name):
        """(level, text) about UDIM tiles for the report: tiles the UVs reach that the image
        lacks (a warning: nothing was baked there) and tiles of the image no UV lies in."""
        missing = sorted(self.uv_tiles - set(self.tiles))
        empty = sorted(set(self.tiles) - self.uv_tiles) if self.tiled else []
        notes, level = [], "INFO"
        if missing:
            level = "WARNING"
            where = (f"which image '{image_name}' lacks (add them to bake there)" if self.tiled
                     else "which a single image cannot hold (bake into a UDIM image)")
            notes.append(f"UVs also lie in UDIM tile(s) {_tile_list(missing)}, {where}")
        if empty:
            notes.append(f"no UV lies in tile(s) {_tile_list(empty)} (background only)")
        return level, notes


class OBJECT_OT_sgbake_bake(bpy.types.Operator):
    """Bake the chosen map of the active mesh object with sgbake into an image (Esc cancels)"""
    bl_idname = "object.sgbake_bake"
    bl_label = "Bake with sgbake"
    bl_options = {"REGISTER"}

    def execute(self, context):
        """From scripts: bakes before returning."""
        try:
            job = BakeJob(context)
        except (gather.BakeInputError, capi.SgbakeError) as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        job.run()
        return self._finish(job)

    def invoke(self, context, event):
        """From the UI: bakes on a worker thread and shows its progress; Esc cancels it."""
        try:
            self.job = BakeJob(context)
        except (gather.BakeInputError, capi.SgbakeError) as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        self.thread = threading.Thread(target=self.job.run, name="sgbake bake", daemon=True)
        self.thread.start()
        wm = context.window_manager
        self.timer = wm.event_timer_add(0.1, window=context.window)
        wm.progress_begin(0.0, 1.0)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        if event.type == "ESC":
            self.job.progress.cancel = 1  # the library stops within two bands
            return {"RUNNING_MODAL"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}  # the rest of Blender stays usable meanwhile
        context.window_manager.progress_update(self.job.fraction())
        if context.workspace is not None:
            tiles = (f", tile {self.job.tiles[self.job.tile_index]} "
                     f"({self.job.tile_index + 1} of {len(self.job.tiles)})"
                     if self.job.tiled else "")
            context.workspace.status_text_set(
                f"sgbake: baking {self.job.map} {self.job.width} x {self.job.height}{tiles}: "
                f"{100 * self.job.fraction():.0f} % (Esc to cancel)")
        if self.thread.is_alive():
            return {"RUNNING_MODAL"}
        wm = context.window_manager
        wm.event_timer_remove(self.timer)
        wm.progress_end()
        if context.workspace is not None:
            context.workspace.status_text_set(None)
        return self._finish(self.job)

    def _finish(self, job):
        if isinstance(job.error, capi.SgbakeCancelled):
            self.report({"WARNING"}, "sgbake: bake cancelled; the image was not changed")
            return {"CANCELLED"}
        if job.error is not None:
            self.report({"ERROR"}, str(job.error))
            return {"CANCELLED"}
        try:
            image, notes = job.finish()
        except gather.BakeInputError as exc:
            self.report({"ERROR"}, str(exc))
            return {"CANCELLED"}
        level, tile_notes = job.tile_notes(image.name)
        if job.notes:
            level = "WARNING"
        tiles = (f" (UDIM tile(s) {_tile_list(job.tiles)}, packed into the .blend file)"
                 if job.tiled else "")
        surface = " of the exact limit surface" if job.surface == "limit" else ""
        self.report({level}, "; ".join([f"sgbake: {job.map} {job.width} x {job.height}{surface} "
                                        f"into '{image.name}'{tiles} in {job.seconds:.2f} s"]
                                       + notes + job.notes + tile_notes))
        return {"FINISHED"}


def _tile_list(tiles):
    return ", ".join(str(tile) for tile in tiles)


class OBJECT_OT_sgbake_layers_from_material(bpy.types.Operator):
    """Add sgbake layers for the Bump and Normal Map nodes fed by an Image Texture node, and the
    Bump nodes fed by a Noise, Musgrave or Wave Texture's Fac or a Voronoi Texture's Distance,
    in the active object's materials (with several material slots, each layer applies to its
    slot's faces)"""
    bl_idname = "object.sgbake_layers_from_material"
    bl_label = "Layers from Material"
    bl_options = {"REGISTER", "UNDO"}

    replace: BoolProperty(name="Replace", default=True,
                          description="Remove the existing layers first")

    def execute(self, context):
        ob = context.active_object
        sources, skipped = material_sources(ob) if ob is not None else ([], [])
        if not sources:
            self.report({"ERROR"}, "the active object has no active node material"
                        if ob is None or len(ob.material_slots) <= 1 else
                        f"no material slot of object '{ob.name}' holds a node material"
                        + _notes(skipped))
            return {"CANCELLED"}
        render_uv = (gather.render_uv_name(ob.data)
                     if ob.type == "MESH" and ob.data.uv_layers else None)
        found, more_skipped, ignored = object_layers(sources, render_uv, ob)
        skipped += more_skipped
        single = sources[0][0] is None  # one material for every face
        if not found:
            what = (f"material '{sources[0][1].name}' has no" if single
                    else f"no material of object '{ob.name}' has a")
            self.report({"ERROR"}, f"{what} Bump or Normal Map node fed by an Image Texture "
                                   "node (or a Bump fed by a Noise, Musgrave, Wave or Voronoi "
                                   "Texture)"
                        + _notes(skipped))
            return {"CANCELLED"}
        settings = context.scene.sgbake
        if self.replace:
            settings.layers.clear()
        for values in found:
            layer = settings.layers.add()
            for key, value in values.items():
                setattr(layer, key, scene.remap_text(value) if key == "remap" else value)
        settings.active_layer_index = len(settings.layers) - 1
        added = ", ".join(f"{v['type']} '{v['name']}' x {v[_scale_key(v)]:.4g}"
                          + (f" remapped ({len(v['remap'])} points)" if "remap" in v else "")
                          + (f" on slot {v['material_index']}" if "material_index" in v else "")
                          for v in found)
        origin = f"'{sources[0][1].name}'" if single else f"the materials of '{ob.name}'"
        # What the layers could not take over is a warning: the bake will differ from Cycles'.
        self.report({"WARNING" if ignored else "INFO"},
                    f"added {len(found)} layer(s) from {origin}: {added}"
                    + _notes(skipped)
                    + (f" (ignored, the layers read their UV maps as they are: "
                       f"{'; '.join(ignored)})" if ignored else ""))
        return {"FINISHED"}


def material_sources(ob):
    """The materials Layers from Material reads on object `ob`, as (slot, material) pairs, and
    notes on the slots it cannot read.

    Cycles shades each face with the material of its slot, so with several material slots every
    slot whose material uses nodes is read, with its index (the layers made from it apply to
    that slot's faces only; the same material in two slots is read twice, once per slot). An
    empty slot or a material without nodes makes no layer: its faces bake unperturbed, as
    Cycles shades them without a bump. With one slot or none, the active material alone, with
    slot None: its layers apply to every face (there are no other faces to spare)."""
    if len(ob.material_slots) <= 1:
        material = ob.active_material
        if material is None or not material.use_nodes:
            return [], []
        return [(None, material)], []
    sources, skipped = [], []
    for slot, material in enumerate(slot.material for slot in ob.material_slots):
        if material is None:
            skipped.append(f"slot {slot}: empty (its faces are not bumped)")
        elif not material.use_nodes or material.node_tree is None:
            skipped.append(f"material '{material.name}' (slot {slot}): uses no nodes (its "
                           "faces are not bumped)")
        else:
            sources.append((slot, material))
    return sources, skipped


def object_layers(sources, render_uv=None, ob=None):
    """material_layers of every (slot, material) of `sources` (material_sources), in slot
    order: (layer settings, skipped, ignored). With several slots each layer gets its slot as
    material_index (libsgbake applies it to that slot's faces only) and each note names its
    material. A Bump's chain ("base" "above") stays within its own material's layers, as a
    Bump node's Normal input comes from its own node tree: material_layers orders and chains
    each tree's layers on their own, and libsgbake stacks a chain on the layers of the face's
    material only."""
    found, skipped, ignored = [], [], []
    for slot, material in sources:
        cycles = getattr(material, "cycles", None)  # (Cycles' add-on holds the method)
        values, slot_skipped, slot_ignored = material_layers(
            material.node_tree, render_uv, ob,
            getattr(cycles, "displacement_method", "BUMP"))
        if slot is not None:
            where = f"material '{material.name}' (slot {slot})"
            for entry in values:
                entry["material_index"] = slot
            if not values and not slot_skipped:
                slot_skipped.append("no Bump, Normal Map or Displacement node fed by an Image "
                                    "Texture node (or a Bump or Displacement by a Noise, "
                                    "Musgrave, Wave or Voronoi Texture)")
            slot_skipped = [f"{where}: {note}" for note in slot_skipped]
            slot_ignored = [f"{where}: {note}" for note in slot_ignored]
        found += values
        skipped += slot_skipped
        ignored += slot_ignored
    return found, skipped, ignored


def _notes(skipped):
    return f" (skipped: {'; '.join(skipped)})" if skipped else ""


def _source_link(socket):
    """The link that feeds `socket` from a node other than a Reroute (followed back through any
    Reroute nodes), or None: nothing linked, or a muted link on the way (Cycles then takes the
    socket's own value)."""
    while socket.is_linked:
        link = socket.links[0]
        if link.is_muted:
            return None
        if link.from_node.type != "REROUTE":
            return link
        socket = link.from_node.inputs[0]
    return None


# Math and Vector Math operations _constant folds, as Cycles folds them (its safe division:
# 0 where the divisor is 0).
def _divide(a, b):
    return a / b if b != 0.0 else 0.0


MATH_OPERATIONS = {
    "ADD": lambda a, b, c: a + b, "SUBTRACT": lambda a, b, c: a - b,
    "MULTIPLY": lambda a, b, c: a * b, "DIVIDE": lambda a, b, c: _divide(a, b),
    "MULTIPLY_ADD": lambda a, b, c: a * b + c, "MINIMUM": lambda a, b, c: min(a, b),
    "MAXIMUM": lambda a, b, c: max(a, b), "ABSOLUTE": lambda a, b, c: abs(a),
}
VECTOR_MATH_OPERATIONS = {
    "ADD": lambda a, b, s: tuple(x + y for x, y in zip(a, b)),
    "SUBTRACT": lambda a, b, s: tuple(x - y for x, y in zip(a, b)),
    "MULTIPLY": lambda a, b, s: tuple(x * y for x, y in zip(a, b)),
    "DIVIDE": lambda a, b, s: tuple(_divide(x, y) for x, y in zip(a, b)),
    "SCALE": lambda a, b, s: tuple(x * s for x in a),
}


def _constant(socket):
    """The value input `socket` takes when every node feeding it is a constant: its own value
    when nothing (or a muted link) feeds it, a Value node's, a Combine XYZ of constants, a Math
    or Vector Math node of the operations above on constants (clamped when the node clamps),
    through Reroutes; a float fed into a vector is (f, f, f), as Blender converts it. A float,
    a 3-tuple, or None when something else feeds it (a texture, an attribute, a muted node)."""
    link = _source_link(socket)
    if link is None:
        value = socket.default_value
        return float(value) if socket.type == "VALUE" else tuple(float(v) for v in value)
    node, output = link.from_node, link.from_socket
    value = None
    if node.mute:
        return None
    if node.type == "VALUE":
        value = float(output.default_value)
    elif node.type == "COMBXYZ":
        parts = [_constant(node.inputs[name]) for name in ("X", "Y", "Z")]
        value = None if any(p is None for p in parts) else tuple(parts)
    elif node.type == "MATH" and node.operation in MATH_OPERATIONS:
        args = [_constant(node.inputs[i]) for i in range(3)]
        if all(isinstance(a, float) for a in args):
            value = MATH_OPERATIONS[node.operation](*args)
            if node.use_clamp:
                value = min(max(value, 0.0), 1.0)
    elif (node.type == "VECT_MATH" and node.operation in VECTOR_MATH_OPERATIONS
          and output.name == "Vector"):
        a, b = _constant(node.inputs[0]), _constant(node.inputs[1])
        scale = _constant(node.inputs["Scale"])
        if isinstance(a, tuple) and isinstance(b, tuple) and isinstance(scale, float):
            value = VECTOR_MATH_OPERATIONS[node.operation](a, b, scale)
    if value is None:
        return None
    if socket.type == "VALUE":
        return value if isinstance(value, float) else None
    return (value,) * 3 if isinstance(value, float) else value


# The luminance Cycles takes of a colour linked into a float input: its rgb_to_y, the Y row
# of Blender's scene linear to XYZ (the default colour management: Rec. 709 primaries, D65),
# as measured from Cycles 3.4 (an Emission bake of pure R, G and B through a Math node; float
# values). Not quite the 0.2126, 0.7152, 0.0722 of the config's "luma" (a Color Ramp's kink
# lands ~1e-5 elsewhere with those: 0.04 deg at p99 of a bake).
LUMINANCE = (0.212672979, 0.715152621, 0.072175443)
SEPARATED_CHANNELS = {"R": "r", "G": "g", "B": "b", "Red": "r", "Green": "g", "Blue": "b"}


def _affine_step(node):
    """How Math node or Map Range node `node` changes the height fed into its input the chain
    comes through (the one input linked to something other than constants): (that input,
    factor, offset) when its output is factor x height + offset; None for any other operation
    or more than one varying input. A clamp after it is _chain_step's."""
    if node.type == "MATH":
        operands = {"ADD": 2, "SUBTRACT": 2, "MULTIPLY": 2, "DIVIDE": 2, "MULTIPLY_ADD": 3}
        count = operands.get(node.operation)
        if count is None:
            return None
        values = [_constant(node.inputs[i]) for i in range(count)]
        varying = [i for i, v in enumerate(values) if v is None]
        if len(varying) != 1:
            return None
        i = varying[0]
        other = values[1 - i] if count == 2 else None
        line = {"ADD": lambda: (1.0, other),
                "SUBTRACT": lambda: (1.0, -values[1]) if i == 0 else (-1.0, values[0]),
                "MULTIPLY": lambda: (other, 0.0),
                "DIVIDE": lambda: (_divide(1.0, values[1]), 0.0) if i == 0 else None,
                "MULTIPLY_ADD": lambda: ((values[1], values[2]) if i == 0
                                         else (values[0], values[2]) if i == 1
                                         else (1.0, values[0] * values[1]))}[node.operation]()
        return None if line is None else (node.inputs[i],) + line
    if (node.type == "MAP_RANGE" and node.data_type == "FLOAT"
            and node.interpolation_type == "LINEAR"):
        ends = [_constant(node.inputs[name]) for name in ("From Min", "From Max", "To Min",
                                                          "To Max")]
        if any(v is None for v in ends):
            return None
        factor = _divide(ends[3] - ends[2], ends[1] - ends[0])
        return node.inputs["Value"], factor, ends[2] - factor * ends[0]
    return None


def _ramp_values(node, output, channel):
    """Color Ramp node `node`'s table as Cycles makes it (its colour at i / 255, i = 0 .. 255)
    as read from its `output`: the alpha, else the colour's `channel` (r, g, b; None: the
    Rec. 709 luminance, as a colour into a float input)."""
    values = []
    last = remap.RAMP_TABLE_SIZE - 1
    for i in range(remap.RAMP_TABLE_SIZE):
        r, g, b, a = node.color_ramp.evaluate(i / last)
        if output == "Alpha":
            values.append(a)
        elif channel is None:
            values.append(LUMINANCE[0] * r + LUMINANCE[1] * g + LUMINANCE[2] * b)
        else:
            values.append({"r": r, "g": g, "b": b}[channel])
    return values


def _float_curve_table(node):
    """Float Curve node `node`'s function as Cycles reads it (remap.curve): its curve tabulated
    at RAMP_TABLE_SIZE values from its points' least to greatest x, extrapolated beyond; None
    when its Fac is not the constant 1 (a blend with the value) or its points share one x."""
    if _constant(node.inputs["Factor"]) != 1.0:
        return None
    mapping = node.mapping
    curve_map = mapping.curves[0]
    xs = [point.location[0] for point in curve_map.points]
    low, high = min(xs), max(xs)
    if not high > low:
        return None
    mapping.initialize()
    last = remap.RAMP_TABLE_SIZE - 1
    values = [mapping.evaluate(curve_map, low + i / last * (high - low))
              for i in range(remap.RAMP_TABLE_SIZE)]
    return remap.curve(values, low, high)


def _chain_step(node, link, channel):
    """How `node` (fed into the chain through `link`) changes the height it is fed, the
    `channel` of its output the chain reads (r, g, b of a colour, or None): (its input the
    chain goes on from, the function of that input's value (remap's kinds), the channel read
    there), or None when it is not followed. Math (the affine operations of _affine_step, then
    clamped to [0, 1] when the node clamps) and Map Range (linear, then clamped to the To range
    when it clamps) read a float: the channel read before them is the grey's. Clamp (Min and
    Max constants): Min Max, min(max(v, Min), Max) (Max alone when Min > Max); Range, between
    the lower and the higher. Color Ramp: Cycles' table of it read at its Fac (remap.table),
    its Color's luminance (or the channel read), or its Alpha. Float Curve of Factor 1: Cycles'
    table of its curve, extrapolated (_float_curve_table). Invert of a constant Fac:
    (1 - Fac) c + Fac (1 - c) on each channel."""
    if node.type == "INVERT":
        fac = _constant(node.inputs["Fac"])
        if not isinstance(fac, float):
            return None
        return node.inputs["Color"], ("affine", 1.0 - 2.0 * fac, fac), channel
    if node.type == "CLAMP":
        low, high = _constant(node.inputs["Min"]), _constant(node.inputs["Max"])
        if not isinstance(low, float) or not isinstance(high, float):
            return None
        if node.clamp_type == "RANGE":
            low, high = min(low, high), max(low, high)
        elif low > high:  # min(max(v, Min), Max) is Max
            low = high
        return node.inputs["Value"], remap.clamp(low, high), None
    if node.type == "CURVE_FLOAT":
        table = _float_curve_table(node)
        return None if table is None else (node.inputs["Value"], table, None)
    if node.type == "VALTORGB":
        output = link.from_socket.name
        constant = node.color_ramp.interpolation == "CONSTANT"
        return (node.inputs["Fac"],
                remap.table(_ramp_values(node, output, channel), constant), None)
    step = _affine_step(node)
    if step is None:
        return None
    socket, factor, offset = step
    line = ("affine", factor, offset)
    if node.type == "MATH" and node.use_clamp:
        line = remap.compose(remap.clamp(0.0, 1.0), line)
    elif node.type == "MAP_RANGE" and node.clamp:
        ends = (_constant(node.inputs["To Min"]), _constant(node.inputs["To Max"]))
        line = remap.compose(remap.clamp(min(ends), max(ends)), line)
    return socket, line, None


def _height_source(socket):
    """The texture node that feeds height input `socket`, the channel it is read on and the
    function of its value the nodes between make: (node, channel, factor, points), or None when
    the chain is not followed, or a string saying why its height is not taken (a constant, a
    Noise Texture's Color). The texture: an Image Texture node with an image, or a Noise,
    Musgrave or Wave Texture node's Fac (or a Wave Texture's Color, the Fac as a grey), a
    Voronoi Texture's Distance (PROCEDURAL_TEXTURES' outputs; every channel its value;
    _procedural_settings says whether a volume layer takes the node). Followed back through
    Reroutes, RGB to BW (the luminance, as the input's own conversion), Separate RGB or Color
    (RGB mode: channel r, g or b; the image's Alpha output is channel a, its Color the
    luminance) and the nodes of _chain_step (Math, Map Range, Clamp, Color Ramp, Invert),
    composed into one function (remap.compose). Without a clamp or Color Ramp it is factor x
    value + an offset no slope sees: points is None; with one, points is the whole function's
    remap (its y as the chain makes them: the outer affine steps in them, not in factor, which
    is then 1)."""
    function, channel = remap.IDENTITY, None
    while True:
        link = _source_link(socket)
        if link is None or link.from_node.mute:
            return None
        node = link.from_node
        if node.type == "TEX_IMAGE":
            if node.image is None:
                return None
            if link.from_socket.name == "Alpha":
                if channel is not None:
                    return None
                channel = "a"
            break
        if node.type in PROCEDURAL_TEXTURES:
            texture = PROCEDURAL_TEXTURES[node.type]
            if link.from_socket.name not in texture.outputs:
                return f"'{node.name}' {link.from_socket.name} output ({texture.others})"
            channel = None  # (a grey: any channel of it is the Fac)
            break
        if node.type in ("SEPRGB", "SEPARATE_COLOR"):
            if channel is not None or getattr(node, "mode", "RGB") != "RGB":
                return None
            channel = SEPARATED_CHANNELS.get(link.from_socket.name)
            if channel is None:
                return None
            socket = node.inputs[0]
            continue
        if node.type == "RGBTOBW":
            socket, channel = node.inputs[0], None  # (a grey: every channel its value)
            continue
        step = _chain_step(node, link, channel)
        if step is None:
            return None
        socket, inner, channel = step
        function = remap.compose(function, inner)
    channel = channel or "luminance"
    if not remap.finite(function):
        return "the nodes between it and its texture make a height that is not finite"
    if function[0] == "affine":
        return node, channel, function[1], None
    if remap.is_constant(function):
        return ("the nodes between it and its texture make a constant height (no bump, as in "
                "Cycles)")
    if len(function[1]) > remap.MAX_POINTS:
        return (f"the nodes between it and its texture make a remap of "
                f"{len(function[1])} points (libsgbake takes {remap.MAX_POINTS})")
    return node, channel, 1.0, [[x, y] for x, y in function[1]]


def _recombined_normal_map(socket):
    """The Image Texture node whose colour reaches normal-map input `socket` split into its
    channels and combined again, and the green convention that makes: (node, "opengl" or
    "directx"), or None. A Combine RGB or Color node (RGB) whose R, G and B are the R, G and B
    of one Separate RGB or Color node (RGB) of the texture's Color, G through a Math node
    computing 1 - G (unclamped) where a DirectX map is turned into Blender's convention."""
    link = _source_link(socket)
    node = link.from_node if link else None
    if (node is None or node.mute or node.type not in ("COMBRGB", "COMBINE_COLOR")
            or getattr(node, "mode", "RGB") != "RGB"):
        return None
    separated, flipped = set(), []
    for i, channel in enumerate("rgb"):
        link = _source_link(node.inputs[i])
        inverted = (link is not None and link.from_node.type == "MATH" and not link.from_node.mute
                    and link.from_node.operation == "SUBTRACT" and not link.from_node.use_clamp
                    and _constant(link.from_node.inputs[0]) == 1.0)
        if inverted:
            link = _source_link(link.from_node.inputs[1])
        if (link is None or link.from_node.mute
                or link.from_node.type not in ("SEPRGB", "SEPARATE_COLOR")
                or getattr(link.from_node, "mode", "RGB") != "RGB"
                or SEPARATED_CHANNELS.get(link.from_socket.name) != channel):
            return None
        separated.add(link.from_node.name)
        flipped.append(inverted)
    if len(separated) != 1 or flipped[0] or flipped[2]:
        return None
    split = _source_link(link.from_node.inputs[0])
    if (split is None or split.from_node.type != "TEX_IMAGE" or split.from_node.image is None
            or split.from_socket.name != "Color"):
        return None
    return split.from_node, "directx" if flipped[1] else "opengl"


def _linked_image_node(socket):
    """The Image Texture node (with an image) that feeds `socket` (_source_link), or None."""
    link = _source_link(socket)
    node = link.from_node if link else None
    return node if node is not None and node.type == "TEX_IMAGE" and node.image is not None \
        else None


def _source_node(socket):
    """The node that feeds `socket` (_source_link), or None."""
    link = _source_link(socket)
    return link.from_node if link else None


def _surface_nodes(node_tree):
    """The names of the nodes whose outputs reach the Surface input of the output node Cycles
    renders, or None when there is no such node."""
    output = node_tree.get_output_node("CYCLES")
    if output is None:
        return None
    seen, todo = set(), [link.from_node for link in output.inputs["Surface"].links
                         if not link.is_muted]
    while todo:
        node = todo.pop()
        if node.name in seen:
            continue
        seen.add(node.name)
        todo += [link.from_node for socket in node.inputs for link in socket.links
                 if not link.is_muted]
    return seen


def _not_image(socket):
    """Why `socket` gave no layer: what is linked into it instead of an Image Texture node
    (or, into a height, a Noise, Musgrave or Wave Texture's Fac, a Voronoi Texture's
    Distance)."""
    link = _source_link(socket)
    if link is not None and link.from_node.type == "TEX_IMAGE":
        return f"{socket.name}'s Image Texture node has no image"
    if socket.is_linked and link is None:
        return f"{socket.name}'s link is muted"
    if socket.name == "Height":
        return (f"{socket.name} is not an Image Texture, Noise Texture, Musgrave Texture or "
                "Wave Texture node")
    return f"{socket.name} is not an Image Texture node"


MAPPING_INPUTS = ("Location", "Rotation", "Scale")


def _coordinates_source(link):
    """What a Texture Coordinate node's output `link` reads other than the object's own
    coordinates: {"coordinates_object": the object its Object output names} or
    {"coordinates_generated": True}, or a Geometry node's Position output (world positions):
    {"coordinates_world": True}; None for the object's own, and for other outputs."""
    node, output = link.from_node, link.from_socket.name
    if node.type == "NEW_GEOMETRY":
        return {"coordinates_world": True} if output == "Position" else None
    if output == "Object" and node.object is not None:
        return {"coordinates_object": node.object}
    if output == "Generated":
        return {"coordinates_generated": True}
    return None


def _object_coordinates(tex, ob=None):
    """How Image Texture node `tex` reads object coordinates: None when it does not; else the
    layer settings of what lies between (empty for the object's own). It does when its
    projection is Flat, Box, Sphere or Tube and its Vector reads them (_vector_coordinates: a
    Texture Coordinate node's Object output, the baked object's own coordinates; another
    object's, or its Generated output, when the baked object `ob` is known; straight or
    through one Mapping node). Its height is then sgbake's planar layer on axis z (Flat), with
    its Sphere or Tube projection (Sphere, Tube), or its triplanar layer with Blender's Box
    projection (Box)."""
    if tex.projection not in ("FLAT", "BOX", "SPHERE", "TUBE"):
        return None
    settings = _vector_coordinates(tex.inputs["Vector"], ob)
    if isinstance(settings, str) or ("mapping_matrix" not in settings
                                     and _coordinates_of(settings)):
        return None  # (another object's or the Generated coordinates with no object to map)
    return settings


def _coordinates_of(settings):
    """Whether layer `settings` read another object's, the Generated or world coordinates."""
    return any(key in settings
               for key in ("coordinates_object", "coordinates_generated", "coordinates_world"))


def _vector_coordinates(socket, ob=None, generated=False, uv=False):
    """The object coordinates texture input `socket` (a Vector) reads, as layer settings (empty
    for the object's own), or a string saying why they are not object coordinates. They are
    when it comes from a Texture Coordinate node's Object output (the object's own, or another
    object's: coordinates_object) or Generated output (coordinates_generated), or a Geometry
    node's Position output (world positions: coordinates_world), straight or
    through one Mapping node of type Point, Texture or Vector whose Location, Rotation and
    Scale are constants (_constant: their own values, or Value, Combine XYZ and Math nodes of
    constants; not type Normal, which normalizes the coordinates); with `generated` (a
    procedural texture, which Cycles reads on the Generated coordinates when its Vector is
    unlinked) also when nothing is linked. Other objects', the Generated and world coordinates
    get their affine map of the object's own as `ob` has them now (mapping_matrix;
    gather.follow_coordinates brings it up to date at every bake), none when `ob` is None. With
    `uv` (a procedural texture, which a volume layer reads on a UV map too) a Texture Coordinate
    node's UV output or a UV Map node is taken as well: coordinates_uv, and the UV Map node's
    uv_map when it names one (else the layer reads the render UV map, as Cycles does)."""
    link = _source_link(socket)
    settings = {}
    if link is None and generated:
        return _mapped_coordinates(settings, {"coordinates_generated": True}, ob)
    if link is not None and link.from_node.type == "MAPPING":
        node = link.from_node
        values = {name: _constant(node.inputs[name]) for name in MAPPING_INPUTS}
        if node.vector_type == "NORMAL":
            return f"'{node.name}' is of type Normal (it normalizes the coordinates)"
        varying = [name for name, value in values.items() if value is None]
        if varying:
            return f"'{node.name}' {' and '.join(varying)} from a node (not constants)"
        settings["mapping_type"] = node.vector_type
        for name, value in values.items():
            settings[f"mapping_{name.lower()}"] = value
        link = _source_link(node.inputs["Vector"])
        if link is None:
            return f"'{node.name}' Vector is not linked (a constant: no bump)"
    if link is None:
        return f"{socket.name} is not linked"
    if uv and (link.from_node.type == "UVMAP"
               or (link.from_node.type == "TEX_COORD" and link.from_socket.name == "UV")):
        settings["coordinates_uv"] = True  # (u, v, 0) of the UV map
        if link.from_node.type == "UVMAP" and link.from_node.uv_map:
            settings["uv_map"] = link.from_node.uv_map
        return settings
    if link.from_node.type not in ("TEX_COORD", "NEW_GEOMETRY"):
        return (f"{socket.name} from '{link.from_node.name}' (not a Texture Coordinate "
                "node's Object or Generated output, a Geometry node's Position"
                + (", a UV output or UV Map node)" if uv else ")"))
    if (link.from_node.type == "TEX_COORD" and link.from_socket.name == "Object"
            and link.from_node.object is None):
        return settings  # the object's own coordinates
    source = _coordinates_source(link)
    if source is None:
        return (f"{socket.name} from '{link.from_node.name}' {link.from_socket.name} (not "
                "object, Generated or world coordinates" + (" or a UV map)" if uv else ")"))
    return _mapped_coordinates(settings, source, ob)


def _mapped_coordinates(settings, source, ob):
    """`settings` with another object's, the Generated or the world coordinates, `source`
    (_coordinates_source), and their map now on `ob` (gather.coordinates_matrix; none when
    `ob` is None); a string when the Generated coordinates have no map (a flat texture
    space)."""
    settings.update(source)
    if ob is None:
        return settings
    matrix = gather.coordinates_matrix(ob, source.get("coordinates_object"),
                                       source.get("coordinates_generated", False),
                                       source.get("coordinates_world", False))
    if matrix is None:
        return f"the Generated coordinates of object '{ob.name}' have a flat texture space"
    settings["mapping_matrix"] = matrix
    return settings


def _object_projected(tex, ob=None):
    """Whether Image Texture node `tex` reads object coordinates (_object_coordinates): then a
    layer takes its projection over, for a Bump or a Normal Map alike (Flat, Sphere, Tube: a
    planar layer, Box: a triplanar one; a normal map's colour decoded as the Normal Map node
    decodes it)."""
    return _object_coordinates(tex, ob) is not None


def _height_settings(node, tex, channel, render_uv, ob, ignored, points=None):
    """The settings of a height layer read from Image Texture node `tex` on `channel`
    (_height_source) into the Height input of `node` (a Bump or a Displacement node), through
    the remap `points` when the nodes between make one (_height_source), before its scale: the
    texture's, with the slopes as Cycles takes them when it bakes (forward differences half a
    texel apart, of the remapped height: the layer then bakes what Cycles bakes from it); on
    object coordinates the projection's (which reads the luminance: another channel is named
    in `ignored`)."""
    values = _texture_settings(tex, render_uv)
    values.update(type="height", slopes="bump-node")
    if points is not None:
        values["remap"] = points
    if _object_projected(tex, ob):
        # Object coordinates: the height projected along z onto the object (Flat), wrapped
        # around z (Sphere, Tube), or on the three axis planes as Blender's Box projection
        # blends them (Box).
        values.pop("uv_map", None)
        values.update(_object_coordinates(tex, ob))
        values.update(_projection_settings(tex, "height"))
        if channel != "luminance":
            ignored.append(f"'{node.name}' Height from '{tex.name}' channel {channel.upper()} "
                           f"(a {values['type']} layer reads the luminance)")
    elif channel != "luminance":
        values["channel"] = channel
    return values


def _height_layer(node, source, inputs, render_uv, ob, ignored):
    """The settings of the layer of height input "Height" of `node` (a Bump or a Displacement
    node) fed as `source` says (_height_source), before its scale (_scale_key): an Image
    Texture's (_height_settings), a Noise, Musgrave, Wave or Voronoi Texture's volume
    (_procedural_settings; a string when it is not taken); what of `node` (its `inputs` fed by
    nodes) and the texture the layer cannot take over goes into `ignored`."""
    tex, channel, _, points = source
    if tex.type in PROCEDURAL_TEXTURES:
        values = _procedural_settings(tex, ob)
        if isinstance(values, str):
            return values
        ignored += _inputs_ignored(node, inputs)
        if points is not None:
            values["remap"] = points
        return values
    ignored += _ignored(node, tex, inputs, "Height", ob)
    return _height_settings(node, tex, channel, render_uv, ob, ignored, points)


def _scale_key(values):
    """The setting that holds the height per unit of a layer's value (the Bump's Distance,
    times the chain's factor): a volume's amplitude, any other layer's scale."""
    return "amplitude" if values["type"] == "volume" else "scale"


# The Noise and Musgrave Textures' Dimensions, named as the scene names them.
TEXTURE_DIMENSIONS = {"1D": "1D", "2D": "2D", "3D": "3D", "4D": "4D"}

# A procedural texture whose value a volume layer takes: the volume's function; the node's
# property holding its Dimensions where only 3D is baked (None: the node is 3D only, or its
# Dimensions is one of its enums, "texture_dimensions"); the node's properties that must
# have one value (property -> that value) for the function to be what Cycles computes; the
# outputs the layer reads (grey: the Fac, a Wave Texture's Color (Fac, Fac, Fac) alike); the
# node's enum properties the function takes (setting -> (the node's property, or a function of
# the node naming it; Blender's values -> the scene's names)); the inputs whose name is not
# their setting's in title case (setting -> input); why its other outputs make no layer; and
# the node's other properties the function takes as they are (setting -> property); and whether
# the node has a Scale (the layer's frequency).
ProceduralTexture = collections.namedtuple(
    "ProceduralTexture", "function dimensions fixed outputs enums inputs others props scaled",
    defaults=({}, ("Fac",), {}, {}, "three noises seeded apart; a volume layer is the noise of "
                                    "its Fac", {}, True))
PROCEDURAL_TEXTURES = {
    "TEX_NOISE": ProceduralTexture(
        "blender-noise", None,
        enums={"texture_dimensions": ("noise_dimensions", TEXTURE_DIMENSIONS)}),
    "TEX_MUSGRAVE": ProceduralTexture(
        "blender-musgrave", None,
        enums={"texture_dimensions": ("musgrave_dimensions", TEXTURE_DIMENSIONS),
               "musgrave_type": ("musgrave_type", {
            "FBM": "fbm", "MULTIFRACTAL": "multifractal",
            "RIDGED_MULTIFRACTAL": "ridged-multifractal",
            "HYBRID_MULTIFRACTAL": "hybrid-multifractal", "HETERO_TERRAIN": "hetero-terrain"})},
        inputs={"musgrave_offset": "Offset"}),
    "TEX_WAVE": ProceduralTexture(
        "blender-wave", None, outputs=("Fac", "Color"),
        enums={"wave": ("wave_type", {"BANDS": "bands", "RINGS": "rings"}),
               "wave_direction": (lambda tex: ("bands_direction" if tex.wave_type == "BANDS"
                                               else "rings_direction"),
                                  {"X": "x", "Y": "y", "Z": "z", "DIAGONAL": "diagonal",
                                   "SPHERICAL": "spherical"}),
               "profile": ("wave_profile", {"SIN": "sine", "SAW": "saw", "TRI": "triangle"})},
        inputs={"phase": "Phase Offset"}),
    "TEX_VORONOI": ProceduralTexture(
        "blender-voronoi", "voronoi_dimensions", outputs=("Distance",),
        enums={"feature": ("feature", {"F1": "f1", "F2": "f2", "SMOOTH_F1": "smooth-f1",
                                       "DISTANCE_TO_EDGE": "distance-to-edge"}),
               "metric": (lambda tex: None if tex.feature == "DISTANCE_TO_EDGE" else "distance",
                          {"EUCLIDEAN": "euclidean", "MANHATTAN": "manhattan",
                           "CHEBYCHEV": "chebyshev", "MINKOWSKI": "minkowski"})},
        others="each cell's random colour or its point, not a height; a volume layer is the "
               "Distance"),
    "TEX_BRICK": ProceduralTexture(
        "blender-brick", None,
        others="the bricks' colours tinted at random, not a height; a volume layer is the Fac "
               "(the mortar)",
        props={"brick_offset": "offset", "offset_frequency": "offset_frequency",
               "squash": "squash", "squash_frequency": "squash_frequency"}),
    "TEX_GRADIENT": ProceduralTexture(
        "blender-gradient", None, outputs=("Fac", "Color"),
        enums={"gradient_type": ("gradient_type", {
            "LINEAR": "linear", "QUADRATIC": "quadratic", "EASING": "easing",
            "DIAGONAL": "diagonal", "SPHERICAL": "spherical",
            "QUADRATIC_SPHERE": "quadratic-sphere", "RADIAL": "radial"})},
        scaled=False),
    "TEX_MAGIC": ProceduralTexture(
        "blender-magic", None,
        others="three channels of their own, not a height; a volume layer is the Fac (their "
               "mean)",
        inputs={"magic_distortion": "Distortion"}, props={"depth": "turbulence_depth"}),
}


def _texture_inputs(texture, enums):
    """The inputs of procedural texture `texture` (PROCEDURAL_TEXTURES) whose enums are `enums`
    (in the scene's names) -> the layer settings that hold them: its Scale the frequency, the
    others of scene.texture_settings (a Musgrave Texture's Offset and Gain only where its type
    uses them, a Voronoi Texture's Smoothness, Exponent and metric only where its feature uses
    them) but its enums under their own names (input Detail Scale -> detail_scale, but as
    texture.inputs renames them: Phase Offset -> phase, Offset -> musgrave_offset)."""
    inputs = {"Scale": "frequency"} if texture.scaled else {}
    inputs.update((texture.inputs.get(key, key.replace("_", " ").title()), key)
                  for key in scene.texture_settings(texture.function,
                                                    enums.get("musgrave_type", "fbm"),
                                                    enums.get("feature", "f1"),
                                                    enums.get("texture_dimensions", "3D"))
                  if key not in texture.enums and key not in texture.props)
    return inputs


def _enum_name(node, prop):
    """The name Blender's interface shows for enum property `prop` of `node` (Ridged
    Multifractal for RIDGED_MULTIFRACTAL)."""
    value = getattr(node, prop)
    item = node.bl_rna.properties[prop].enum_items.get(value)
    return item.name if item is not None else value


def _procedural_settings(tex, ob=None):
    """The settings of the volume layer of procedural texture node `tex`'s height output (a
    Noise, Musgrave or Wave Texture's Fac, a Voronoi Texture's Distance: PROCEDURAL_TEXTURES):
    its function with the node's enum properties in the scene's names (a Musgrave Texture's
    type, a Wave Texture's type, direction and profile, a Voronoi Texture's Feature Output and
    Distance Metric (none for Distance to Edge), a Noise or Musgrave Texture's Dimensions) and
    its inputs (_texture_inputs: its Scale as the frequency, Detail, Roughness and Distortion of
    a Noise Texture, Detail, Dimension and Lacunarity of a Musgrave Texture and the Offset and
    Gain its type uses, the W of either in 1D and 4D, Distortion, Detail, Detail
    Scale, Detail Roughness and Phase Offset of a Wave Texture, Randomness, Exponent and
    Smoothness of a Voronoi Texture where its feature uses them), the slopes as Cycles' Bump node takes them (gradient "bump-node"), on the
    coordinates its Vector reads (_vector_coordinates: object, Generated or world coordinates,
    or a UV map's; unlinked, the Generated coordinates, as Cycles reads a procedural texture);
    or a string saying why none is made: a Voronoi Texture's Dimensions other than 3D, a type
    the function is not
    (a Voronoi Texture's N-Sphere Radius), an input fed by anything but constants
    (_constant), a Vector that is none of those coordinates (a normal, ...)."""
    texture = PROCEDURAL_TEXTURES[tex.type]
    if texture.dimensions and getattr(tex, texture.dimensions) != "3D":
        return (f"'{tex.name}' Dimensions {_enum_name(tex, texture.dimensions)} (a volume "
                "layer is the 3D texture)")
    for prop, value in texture.fixed.items():
        if getattr(tex, prop) != value:
            rna = tex.bl_rna.properties[prop]
            return (f"'{tex.name}' {rna.name.lower()} {_enum_name(tex, prop)} (a volume layer "
                    f"is the {rna.enum_items[value].name} {rna.name.lower()})")
    enums = {}  # (in the table's order: a Wave Texture's type before its direction)
    for key, (prop, names) in texture.enums.items():
        prop = prop(tex) if callable(prop) else prop
        if prop is None:  # (not one the node has now: Distance to Edge's Distance Metric)
            continue
        enums[key] = names.get(getattr(tex, prop))
        if enums[key] is None:
            return (f"'{tex.name}' {tex.bl_rna.properties[prop].name} "
                    f"{_enum_name(tex, prop)} (not one libsgbake has)")
    inputs = _texture_inputs(texture, enums)
    values = {name: _constant(tex.inputs[name]) for name in inputs}
    varying = [name for name, value in values.items() if value is None]
    if varying:
        return (f"'{tex.name}' {' and '.join(varying)} from a node (a volume layer takes "
                "constants)")
    coordinates = _vector_coordinates(tex.inputs["Vector"], ob, generated=True, uv=True)
    if isinstance(coordinates, str):
        return f"'{tex.name}' {coordinates}"
    settings = {"type": "volume", "name": tex.name, "function": texture.function,
                "gradient": "bump-node"}
    settings.update(enums)
    settings.update((key, getattr(tex, prop)) for key, prop in texture.props.items())
    settings.update((key, values[name]) for name, key in inputs.items())
    settings.update(coordinates)
    return settings


def _displacement_layer(node_tree, render_uv, ob, method, skipped, ignored):
    """The height layer of the Material Output's Displacement (None when there is none to bake): a
    Displacement node fed by an Image Texture (or a Noise, Musgrave or Wave Texture's Fac, a
    Voronoi Texture's Distance: a volume layer, _height_layer, its amplitude the scale below),
    with the material's Displacement method Bump Only, which Cycles bakes as a Bump node of
    Distance 1 fed by the displacement along the normal, (height - Midlevel) x Scale in world
    units (in object space, grown with the object's scale along the normal): a height layer of
    scale Scale in the node's space (height_space), its slopes as Cycles takes them, its height
    through the nodes between as _height_source composes them (a factor in the scale, or a
    "remap"). Other methods displace the mesh, which sgbake does not; other nodes are not read
    (notes in `skipped`)."""
    output = node_tree.get_output_node("CYCLES")
    link = _source_link(output.inputs["Displacement"]) if output is not None else None
    if link is None:
        return None
    where = f"'{output.name}' Displacement"
    if method != "BUMP":
        skipped.append(f"{where}: method {method.replace('_', ' ').title()} displaces the mesh "
                       "(only Bump Only is baked)")
        return None
    node = link.from_node
    if node.type != "DISPLACEMENT":
        skipped.append(f"{where} from '{node.name}' (a Displacement node is read)")
        return None
    source = _height_source(node.inputs["Height"])
    if not isinstance(source, tuple):
        skipped.append(f"'{node.name}': {source or _not_image(node.inputs['Height'])}")
        return None
    values = _height_layer(node, source, ("Scale",), render_uv, ob, ignored)
    if isinstance(values, str):
        skipped.append(f"'{node.name}': {values}")
        return None
    if _source_link(node.inputs["Normal"]) is not None:
        ignored.append(f"'{node.name}' Normal from a node (the layer displaces along the "
                       "surface's normal)")
    values.update({_scale_key(values): source[2] * _input_value(node, "Scale"),
                   "strength": 1.0,
                   "height_space": "object" if node.space == "OBJECT" else "world"})
    return values


def _projection_settings(tex, kind):
    """The layer settings of Image Texture node `tex`'s projection read at object coordinates
    (_object_projected), for an image of `kind`: Box, a triplanar layer with Blender's Box and
    the node's Blend; Flat, Sphere and Tube, a planar layer with that projection."""
    if tex.projection == "BOX":
        return {"type": "triplanar", "kind": kind, "projection": "box",
                "box_blend": tex.projection_blend}
    return {"type": "planar", "kind": kind, "axis": "z",
            "planar_projection": tex.projection.lower()}


def _input_value(node, name):
    """The float `node`'s input `name` takes: _constant's, else (fed by something else, which
    _ignored names) its own value."""
    value = _constant(node.inputs[name])
    return value if value is not None else node.inputs[name].default_value


def _ignored(node, tex, inputs, socket, ob=None):
    """What of a Bump or Normal Map `node` fed by the Image Texture node `tex` into its input
    `socket` a layer cannot take over: a normal map from the texture's Alpha output, a Vector
    input other than a UV map (a Mapping node, object or generated coordinates; those of a
    projection a layer takes, _object_projected, are not named), a projection other than Flat
    (but one a layer takes), Closest interpolation (read bilinear), and `inputs` fed by
    anything but constants (_constant; of which the layer takes the unconnected value)."""
    notes = []
    if (node.type == "NORMAL_MAP"
            and _source_link(node.inputs[socket]).from_socket.name == "Alpha"):
        notes.append(f"'{node.name}' {socket} from '{tex.name}' Alpha (the layer reads its "
                     "colour)")
    if tex.interpolation == "Closest":
        notes.append(f"'{tex.name}' Closest interpolation (read bilinear)")
    link = _source_link(tex.inputs["Vector"])
    if link is not None:
        uv = link.from_node.type == "UVMAP" or (link.from_node.type == "TEX_COORD"
                                                 and link.from_socket.name == "UV")
        if not uv and not _object_projected(tex, ob):
            notes.append(f"'{tex.name}' Vector from '{link.from_node.name}'")
    if tex.projection != "FLAT" and not _object_projected(tex, ob):
        notes.append(f"'{tex.name}' {tex.projection.title()} projection")
    return notes + _inputs_ignored(node, inputs)


def _inputs_ignored(node, inputs):
    """Notes on the `inputs` of `node` fed by anything but constants (_constant): the layer
    takes the unconnected value."""
    return [f"'{node.name}' {name} from a node (its own value "
            f"{node.inputs[name].default_value:.4g} is used)"
            for name in inputs if _constant(node.inputs[name]) is None]


def _texture_settings(node, render_uv=None):
    """Layer settings taken from an Image Texture node: image, filter, wrap and its UV map: a
    UV Map node's, else `render_uv` (Cycles reads an Image Texture without a UV Map node on
    the UV map active for rendering, whichever the bake is on)."""
    values = {"image": node.image, "name": node.image.name,
              "filter": INTERPOLATION_FILTERS.get(node.interpolation, "bilinear"),
              "wrap": "clamp" if node.extension == "EXTEND" else "repeat"}
    vector = _source_node(node.inputs["Vector"])
    if vector is not None and vector.type == "UVMAP" and vector.uv_map:
        values["uv_map"] = vector.uv_map
    elif render_uv:
        values["uv_map"] = render_uv
    return values


# Node properties a flattened copy does not take over (placement and looks, not shading).
UNCOPIED_PROPERTIES = {"name", "label", "location", "width", "height", "width_hidden", "parent",
                       "select", "hide", "mute", "show_options", "show_preview", "show_texture",
                       "use_custom_color", "color", "node_tree"}


def _copy_node(tree, node, name):
    """A copy of `node` in `tree` named `name`: its writable properties, its sockets' values."""
    new = tree.nodes.new(node.bl_idname)
    new.name = name
    for prop in node.bl_rna.properties:
        if prop.is_readonly or prop.identifier in UNCOPIED_PROPERTIES:
            continue
        try:
            setattr(new, prop.identifier, getattr(node, prop.identifier))
        except (AttributeError, TypeError, ValueError, RuntimeError):
            pass  # (properties a node type makes read-only on its own)
    for sockets, copies in ((node.inputs, new.inputs), (node.outputs, new.outputs)):
        for socket, copy in zip(sockets, copies):
            if hasattr(socket, "default_value") and hasattr(copy, "default_value"):
                try:
                    copy.default_value = socket.default_value
                except (AttributeError, TypeError, ValueError):
                    pass
    new.mute = node.mute
    return new


def _flattened(node_tree):
    """A temporary material whose node tree is `node_tree` with its Group nodes expanded, as
    Cycles expands them before it shades: every node inside a group (and inside groups in
    groups) copied once per group node, named by its path ("Group/Bump"), and every link that
    crosses a group's Group Input or Group Output linked straight through (a group input fed
    by nothing gives its socket's value). None when `node_tree` has no Group node. The caller
    removes the material."""
    if not any(node.type == "GROUP" for node in node_tree.nodes):
        return None
    material = bpy.data.materials.new("sgbake flattened")
    material.use_nodes = True
    flat = material.node_tree
    flat.nodes.clear()
    trees, groups, copies = {(): node_tree}, {}, {}

    def copy(tree, path):
        for node in tree.nodes:
            if node.type == "GROUP" and node.node_tree is not None:
                inner = path + (node.name,)
                trees[inner], groups[inner] = node.node_tree, (path, node)
                copy(node.node_tree, inner)
            elif node.type not in ("GROUP", "GROUP_INPUT", "GROUP_OUTPUT", "FRAME"):
                copies[(path, node.name)] = _copy_node(flat, node, "/".join(path + (node.name,)))

    def index(sockets, socket):
        return next(i for i, s in enumerate(sockets) if s == socket)

    def feed(socket, path):
        """What feeds input `socket` of a node at `path`: ("socket", flat output socket),
        ("value", value) or None (nothing; the input's own value)."""
        links = [link for link in socket.links if not link.is_muted]
        if not links:
            return None
        link = links[0]
        node = link.from_node
        if node.type == "GROUP":
            inner = path + (node.name,)
            output = next((n for n in node.node_tree.nodes if n.type == "GROUP_OUTPUT"
                           and n.is_active_output), None) if node.node_tree else None
            if output is None:
                return None
            inside = output.inputs[index(node.outputs, link.from_socket)]
            return feed(inside, inner) or (
                ("value", inside.default_value) if hasattr(inside, "default_value") else None)
        if node.type == "GROUP_INPUT":
            parent, group = groups[path]
            outside = group.inputs[index(node.outputs, link.from_socket)]
            return feed(outside, parent) or (
                ("value", outside.default_value) if hasattr(outside, "default_value") else None)
        made = copies.get((path, node.name))
        if made is None:
            return None
        return "socket", made.outputs[index(node.outputs, link.from_socket)]

    copy(node_tree, ())
    for (path, name), made in copies.items():
        node = trees[path].nodes[name]
        for socket, target in zip(node.inputs, made.inputs):
            source = feed(socket, path)
            if source is None:
                continue
            if source[0] == "socket":
                flat.links.new(source[1], target)
            else:
                try:
                    target.default_value = source[1]
                except (AttributeError, TypeError, ValueError):
                    pass
    return material


def material_layers(node_tree, render_uv=None, ob=None, displacement_method="BUMP"):
    """_tree_layers of `node_tree`, its Group nodes expanded first as Cycles expands them
    (_flattened: the nodes inside a group are named by their path, "Group/Bump")."""
    material = _flattened(node_tree)
    try:
        return _tree_layers(material.node_tree if material else node_tree, render_uv, ob,
                            displacement_method)
    finally:
        if material is not None:
            bpy.data.materials.remove(material)


def _tree_layers(node_tree, render_uv=None, ob=None, displacement_method="BUMP"):
    """Layer settings (dicts of SgbakeLayer attributes) for each Bump node whose Height input
    and each Normal Map node whose Color input is an Image Texture node, and each Bump node
    whose Height is a Noise, Musgrave or Wave Texture's Fac or a Voronoi Texture's Distance
    (a volume layer, _procedural_settings, whose amplitude is what a height layer's scale is
    below), among the nodes that reach the Surface of the material's output, and for the
    output's Displacement (_displacement_layer, with the material's `displacement_method`);
    and notes on the nodes that were not used, and on what the layers cannot take over.
    `render_uv` is the mesh's UV map active for rendering (what Cycles reads a texture without
    a UV Map node on); `ob` the object baked (for textures on another object's or Generated
    coordinates).

    Bump: scale = Distance (times the factor of affine nodes on the height, _height_source;
    through a clamp or a Color Ramp the layer's "remap" holds the whole function of the
    texture's value, scale the Distance alone), negated when Invert is on, and its Strength (the blend of the bumped
    normal with the original one, as Cycles' Bump node does it); when its Normal input comes
    from a Bump or Normal Map node that made a layer, base "above" (it bumps that node's
    normal), the layers ordered so that such a node's comes first. Normal Map: its space
    (Tangent or Object) and its Strength. Displacement: Cycles bumps the surface's normal with
    it before the surface's nodes run, so it comes first, and a Bump node whose Normal input is
    unlinked bumps the normal it makes (base "above"); a shader whose Normal input is unlinked
    takes that normal. A tangent- or object-space Normal Map does not start from it: where
    every shader's normal comes from one, the displacement is not baked, as in Cycles. Then
    notes on what the layers cannot take over (_ignored): the layers are made, and the report
    says what differs."""
    found, skipped, ignored = [], [], []
    reaching = _surface_nodes(node_tree)
    displaced = _displacement_layer(node_tree, render_uv, ob, displacement_method, skipped,
                                    ignored)
    made = {}  # node name -> its entry of found
    for node in node_tree.nodes:
        if node.type not in ("BUMP", "NORMAL_MAP"):
            continue
        if reaching is not None and node.name not in reaching:
            skipped.append(f"'{node.name}': not linked to the material output's Surface")
            continue
        if node.type == "BUMP":
            source = _height_source(node.inputs["Height"])
            if not isinstance(source, tuple):
                skipped.append(f"'{node.name}': "
                               f"{source or _not_image(node.inputs['Height'])}")
                continue
            scale = source[2] * _input_value(node, "Distance")
            values = _height_layer(node, source, ("Strength", "Distance"), render_uv, ob,
                                   ignored)
            if isinstance(values, str):
                skipped.append(f"'{node.name}': {values}")
                continue
            values.update({_scale_key(values): -scale if node.invert else scale,
                           "strength": max(_input_value(node, "Strength"), 0.0)})
        else:
            tex, green = _linked_image_node(node.inputs["Color"]), "opengl"
            recombined = _recombined_normal_map(node.inputs["Color"]) if tex is None else None
            if recombined is not None:
                tex, green = recombined
            space = NORMAL_MAP_SPACES.get(node.space)
            if tex is None or space is None:
                why = (_not_image(node.inputs["Color"]) if tex is None
                       else f"space {node.space} is not Tangent or Object")
                skipped.append(f"'{node.name}': {why}")
                continue
            ignored += _ignored(node, tex, ("Strength",), "Color", ob)
            values = _texture_settings(tex, render_uv)
            values.update(type="normal", space=space, scale=_input_value(node, "Strength"))
            if green != "opengl":
                if space == "tangent":
                    values["green"] = green  # (its G flipped in the tree: a DirectX map)
                else:
                    ignored.append(f"'{node.name}' Color with its G flipped (an object-space "
                                   "layer reads the colour)")
            if _object_projected(tex, ob):
                # A projection on object coordinates: the colour it reads, decoded by the node
                # (tangent space: in the frames of the node's UV map, else the render UV
                # map's).
                values.pop("uv_map", None)
                values.update(_object_coordinates(tex, ob))
                values.update(_projection_settings(tex, f"{space}-normal"))
                if space == "tangent" and node.uv_map:
                    values["tangent_uv_map"] = node.uv_map
            elif space == "tangent":
                # Cycles takes the tangents from the node's UV map (empty: the render UV map)
                # and reads the image on the texture's.
                frames = node.uv_map or render_uv
                if frames and frames != values.get("uv_map", frames):
                    values["tangent_uv_map"] = frames
                elif frames:
                    values["uv_map"] = frames
        made[node.name] = values
        found.append(values)
    # A Bump node on the output of another layer's node bumps that node's normal.
    depth = {}

    def chain_depth(name, seen=()):
        if name in depth:
            return depth[name]
        node = node_tree.nodes[name]
        below = 0
        if node.type == "BUMP":
            source = _source_node(node.inputs["Normal"])
            if source is not None and source.name in made and source.name not in seen:
                made[name]["base"] = "above"
                below = chain_depth(source.name, seen + (name,)) + 1
            elif source is None and displaced is not None:
                made[name]["base"] = "above"  # the displaced normal, Cycles' N
                below = 1
            elif source is not None:
                ignored.append(f"'{node.name}' Normal from '{source.name}' (the layer bumps the "
                               "surface's normal)")
        depth[name] = below
        return below

    order = {id(values): chain_depth(name) for name, values in made.items()}
    found.sort(key=lambda values: order[id(values)])
    shaders = [node_tree.nodes[name] for name in sorted(reaching or ())
               if any(output.type == "SHADER" for output in node_tree.nodes[name].outputs)
               and node_tree.nodes[name].inputs.get("Normal") is not None]
    if displaced is not None:
        # The displaced normal reaches the bake through the shaders that take Cycles' N and the
        # Bump nodes that bump it.
        takes_n = [node for node in shaders if _source_node(node.inputs["Normal"]) is None]
        bumps_n = [name for name, values in made.items()
                   if node_tree.nodes[name].type == "BUMP" and values.get("base") == "above"
                   and _source_node(node_tree.nodes[name].inputs["Normal"]) is None]
        if not takes_n and not bumps_n:
            skipped.append("the output's Displacement: no shader takes the displaced normal "
                           "(a Normal Map does not start from it; Cycles bakes none of it)")
            displaced = None
        else:
            found.insert(0, displaced)
            for node in shaders:
                source = _source_node(node.inputs["Normal"])
                if takes_n and source is not None and source.type == "NORMAL_MAP":
                    ignored.append(f"'{node.name}' Normal from '{source.name}' is mixed with "
                                   "the displaced normal (Cycles averages them)")
            for name in made:
                node = node_tree.nodes[name]
                if node.type == "NORMAL_MAP" and _input_value(node, "Strength") != 1.0:
                    ignored.append(f"'{node.name}' Strength blends with the displaced normal "
                                   "(the layer blends with the surface's)")
    # Cycles' normal bake averages the normals of every shader the surface mixes: one without
    # a bump flattens the result, which layers (bumping the whole surface) cannot follow.
    if found and reaching is not None:
        for node in shaders:
            if displaced is None and _source_node(node.inputs["Normal"]) is None:
                ignored.append(f"'{node.name}' has no bump and is mixed in (Cycles averages "
                               "its normal with the bumped ones)")
        for name in sorted(reaching):
            node = node_tree.nodes[name]
            # A Principled BSDF's clearcoat is a closure of its own, on Clearcoat Normal.
            coat = node.inputs.get("Clearcoat")
            coat_normal = node.inputs.get("Clearcoat Normal")
            if (node.type == "BSDF_PRINCIPLED" and coat is not None and coat_normal is not None
                    and (coat.is_linked or coat.default_value > 0)
                    and _source_node(coat_normal) is None
                    and (displaced is None or _source_node(node.inputs["Normal"]) is not None)):
                ignored.append(f"'{node.name}' has a clearcoat without a bump (Clearcoat Normal "
                               "unlinked: Cycles averages its normal with the bumped ones)")
    return found, skipped, ignored


class SGBAKE_OT_from_blender_bake(bpy.types.Operator):
    """Take over the settings of Blender's own bake panel that sgbake has: the normal map's
    space (Normal bakes) and Swizzle, the margin's size and type"""
    bl_idname = "sgbake.from_blender_bake"
    bl_label = "From Blender's Bake Settings"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        settings, bake = context.scene.sgbake, context.scene.render.bake
        taken = []
        cycles = getattr(context.scene, "cycles", None)  # (Cycles' add-on holds the bake type)
        if cycles is not None and cycles.bake_type == "NORMAL":
            settings.map = "tangent-normal" if bake.normal_space == "TANGENT" else "object-normal"
            taken.append(f"map {settings.map}")
        settings.swizzle_r, settings.swizzle_g, settings.swizzle_b = (
            bake.normal_r, bake.normal_g, bake.normal_b)
        settings.green = "opengl"  # the swizzle says G's direction
        settings.margin = bake.margin
        settings.padding = "adjacent-faces" if bake.margin_type == "ADJACENT_FACES" else "extend"
        taken += [f"swizzle {bake.normal_r}, {bake.normal_g}, {bake.normal_b}",
                  f"margin {bake.margin} ({settings.padding})"]
        self.report({"INFO"}, "took " + "; ".join(taken))
        return {"FINISHED"}


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


CLASSES = (OBJECT_OT_sgbake_bake, OBJECT_OT_sgbake_layers_from_material,
           SGBAKE_OT_from_blender_bake, SGBAKE_OT_layer_add,
           SGBAKE_OT_layer_remove, SGBAKE_OT_layer_move)
