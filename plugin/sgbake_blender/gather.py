"""Blender data as the flat arrays libsgbake takes, and the baked pixels back into an image.

Everything is moved with foreach_get / foreach_set into numpy arrays (no Python loop per
vertex or texel); the tiles of a UDIM image go in through files (write_tiles). Problems with
the user's data raise BakeInputError with a message meant for the operator's error report.
"""

import contextlib
import os
import shutil
import tempfile

import numpy as np

import bpy

from . import scene


class BakeInputError(Exception):
    """The object, its UV maps or the layers' images cannot be baked as they are."""


def coordinates_matrix(ob, other=None, generated=False, world=False):
    """The coordinates a Texture Coordinate node gives on object `ob`, as an affine map of
    `ob`'s own (12 numbers, row by row), as they are now: with `other`, its Object output naming
    that object, inverse(other.matrix_world) @ ob.matrix_world; with `generated`, its Generated
    output, the texture space of ob's mesh (the bounding box, by default) to [0, 1]; with
    `world`, the world positions a Geometry node's Position gives, ob.matrix_world. None when
    none is given, or the texture space is flat."""
    if world:
        m = ob.matrix_world
        return tuple(m[r][c] for r in range(3) for c in range(4))
    if other is not None:
        m = other.matrix_world.inverted_safe() @ ob.matrix_world
        return tuple(m[r][c] for r in range(3) for c in range(4))
    if generated and ob.type == "MESH":
        loc, size = ob.data.texspace_location, ob.data.texspace_size
        if any(s == 0 for s in size):
            return None
        rows = [[0.0] * 4 for _ in range(3)]
        for i in range(3):
            rows[i][i] = 0.5 / size[i]
            rows[i][3] = 0.5 - 0.5 * loc[i] / size[i]
        return tuple(v for row in rows for v in row)
    return None


def follow_coordinates(layers, ob):
    """Sets the Coordinates (mapping_matrix) of every projected or volume layer that reads
    another object's, the Generated or the world coordinates to what they are now on `ob`, so
    that a moved projector or object, or an edited mesh, bakes as Cycles renders it without
    Layers from Material again."""
    for layer in layers:
        if not scene.on_object_coordinates(layer):
            continue
        if (layer.coordinates_object is None and not layer.coordinates_generated
                and not layer.coordinates_world):
            continue
        matrix = coordinates_matrix(ob, layer.coordinates_object, layer.coordinates_generated,
                                    layer.coordinates_world)
        if matrix is None:
            raise BakeInputError(f"layer '{layer.name}': the Generated coordinates of object "
                                 f"'{ob.name}' have a flat texture space")
        if tuple(layer.mapping_matrix) != matrix:
            layer.mapping_matrix = matrix


def render_uv_name(mesh):
    """The name of the mesh's UV map active for rendering (the camera icon of the UV Maps
    list), which Cycles reads an Image Texture without a UV Map node on; the active UV map
    when none is marked."""
    return next((uv.name for uv in mesh.uv_layers if uv.active_render),
                mesh.uv_layers.active.name)


def uv_sets(mesh, bake_uv_name, layers):
    """The UV maps to send, in order, and the index of the bake's UV map among them.

    Set 0 is the active UV map: libsgbake builds tangent frames on set 0, and Blender's bake
    builds them on the active UV map whatever UV map it bakes on. The bake's UV map (default:
    the active one) and the UV maps layers read follow (a layer's own, else the render UV map,
    render_uv_name), each once, so that a bake never sends more UV maps than it reads."""
    if len(mesh.uv_layers) == 0:
        raise BakeInputError("has no UV map")
    names = [mesh.uv_layers.active.name]
    bake_uv_name = bake_uv_name or names[0]
    render_uv = render_uv_name(mesh)
    wanted = [("the bake", bake_uv_name)]
    wanted += [(f"layer '{layer.name}'", layer.uv_map or render_uv) for layer in layers
               if scene.reads_uv(layer)]
    wanted += [(f"the tangents of layer '{layer.name}'", scene.tangent_frames_uv(layer, render_uv))
               for layer in layers if scene.tangent_frames_uv(layer, render_uv)]
    wanted += [(f"the mask of layer '{layer.name}'", layer.mask_uv_map) for layer in layers
               if layer.mask_image is not None and layer.mask_uv_map]
    for user, name in wanted:
        if name not in mesh.uv_layers:
            raise BakeInputError(f"has no UV map '{name}' (used by {user})")
        if name not in names:
            names.append(name)
    return names, names.index(bake_uv_name)


def mesh_arrays(mesh, uv_names, material_slots=1):
    """The mesh as sgbake_mesh arrays: positions (#V x 3), face_start (#F + 1), corner_vertex
    (#C), corner normals (#C x 3, Blender's split normals: calc_normals_split must have run),
    one (#C x 2) array per UV map name, face_flat (#F, 1 where the face is flat-shaded),
    whether Auto Smooth is on, and face_material (#F material slot indices).

    face_material is each face's material_index clamped to the object's `material_slots` slots,
    as Cycles clamps it: a face whose index has no slot is shaded with the last slot's material
    (with no slot, every face with the default one, index 0). A layer's "material" then applies
    to the faces Cycles shades with that slot's node tree.

    sgbake wants each face's corners contiguous and in face order. Blender's meshes almost
    always store them so; when loop_start says otherwise, the corner arrays are reordered."""
    nv, nf, nc = len(mesh.vertices), len(mesh.polygons), len(mesh.loops)
    positions = np.empty(nv * 3, np.float32)
    mesh.vertices.foreach_get("co", positions)
    loop_start = np.empty(nf, np.int64)
    mesh.polygons.foreach_get("loop_start", loop_start)
    loop_total = np.empty(nf, np.int64)
    mesh.polygons.foreach_get("loop_total", loop_total)
    corner_vertex = np.empty(nc, np.uint32)
    mesh.loops.foreach_get("vertex_index", corner_vertex)
    normals = np.empty(nc * 3, np.float32)
    mesh.loops.foreach_get("normal", normals)
    smooth = np.empty(nf, bool)
    mesh.polygons.foreach_get("use_smooth", smooth)
    face_flat = (~smooth).astype(np.uint8)
    # Auto Smooth on (custom normals need it): Cycles shades flat faces with their split normals.
    auto_smooth = bool(mesh.use_auto_smooth)
    material_index = np.empty(nf, np.int64)
    mesh.polygons.foreach_get("material_index", material_index)
    face_material = np.clip(material_index, 0, max(material_slots - 1, 0)).astype(np.uint32)
    uvs = []
    for name in uv_names:
        uv = np.empty(nc * 2, np.float32)
        mesh.uv_layers[name].data.foreach_get("uv", uv)
        uvs.append(uv)

    face_start = np.zeros(nf + 1, np.int64)
    np.cumsum(loop_total, out=face_start[1:])
    if not np.array_equal(loop_start, face_start[:-1]):
        # Corner k of the reordered arrays is Blender's loop order[k].
        order = np.repeat(loop_start - face_start[:-1], loop_total) + np.arange(nc)
        corner_vertex = corner_vertex[order]
        normals = normals.reshape(-1, 3)[order].reshape(-1)
        uvs = [uv.reshape(-1, 2)[order].reshape(-1) for uv in uvs]
    return (positions, face_start.astype(np.uint32), corner_vertex, normals, uvs, face_flat,
            auto_smooth, face_material)


def limit_modifier(ob):
    """The Subdivision Surface modifier whose exact limit surface a "limit" bake reads: the
    object's last modifier, which must be one, Catmull-Clark (anything after it would change
    the surface; Simple subdivision has no surface beyond the mesh's faces)."""
    if len(ob.modifiers) == 0:
        raise BakeInputError("has no modifiers: the exact limit surface is that of a "
                             "Subdivision Surface modifier, last in the object's stack")
    modifier = ob.modifiers[-1]
    if modifier.type != "SUBSURF":
        raise BakeInputError(f"has modifier '{modifier.name}' last: the exact limit surface "
                             "is that of a Subdivision Surface modifier, last in the stack")
    if modifier.subdivision_type != "CATMULL_CLARK":
        raise BakeInputError(f"has Subdivision Surface modifier '{modifier.name}' set to "
                             "Simple: only Catmull-Clark has a limit surface")
    return modifier


def world_transform(ob, map_name):
    """The scene's "transform" for the evaluated object `ob` and notes for the report.

    Cycles shades an object in world space: a Bump node's Distance is a world distance and its
    bump is taken on the world surface, normal maps are carried to world space as normals, and
    Blender's baker brings the result back to object space. libsgbake does the same given the
    object's matrix_world (4 rows of 4 Python floats), so heights are sent as they are, in
    world units, and any scale, even, uneven or mirrored, is matched. None for the identity
    (nothing to carry; a translation alone is sent, it changes nothing).

    A matrix with a zero scale (determinant 0, or an inverse beyond floats) has no world normals
    to carry: libsgbake would refuse it, and Cycles has nothing sensible to bake. The object is
    then baked in object space, as if it were unscaled, with a note when `map_name` is one the
    transform shades (scene.WORLD_SHADED_MAPS; the others come out the same either way)."""
    rows = [[float(value) for value in row] for row in ob.matrix_world]
    if rows == [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0],
                [0.0, 0.0, 0.0, 1.0]]:
        return None, []
    linear = np.array(rows, np.float64)[:3, :3]
    with np.errstate(all="ignore"):
        determinant = float(np.linalg.det(linear))
        # M^-T = cof(M) / det(M), what libsgbake carries normals with; the columns of cof(M)
        # are those of M crossed in turn (b x c, c x a, a x b).
        cofactor = np.cross(linear[:, [1, 2, 0]], linear[:, [2, 0, 1]], axis=0)
        carried = cofactor / determinant
    if determinant != 0 and np.isfinite(determinant) and np.isfinite(carried).all():
        return rows, []
    if map_name not in scene.WORLD_SHADED_MAPS:
        return None, []
    scales = ", ".join(f"{column.length:.4g}" for column in ob.matrix_world.to_3x3().col)
    return None, [f"object '{ob.name}' has a zero scale (its matrix_world is singular; axes "
                  f"scaled {scales}): it is baked in object space, as if unscaled, heights in "
                  "object units (give every axis a scale to bake it as Cycles shades it)"]


@contextlib.contextmanager
def render_settings(ob, hidden=None):
    """Evaluates the object's modifiers as Cycles bakes them: each shown as it is for rendering
    (show_render), Subdivision Surface and Multiresolution at their render levels, and the
    modifier `hidden` (the limit surface's, or None) not at all; everything is set back
    afterwards, as it was."""
    saved = []
    try:
        for modifier in ob.modifiers:
            levels = modifier.type in ("SUBSURF", "MULTIRES")
            saved.append((modifier, modifier.show_viewport,
                          modifier.levels if levels else None))
            shown = modifier.show_render and modifier != hidden
            if modifier.show_viewport != shown:
                modifier.show_viewport = shown
            if levels and modifier.levels != modifier.render_levels:
                modifier.levels = modifier.render_levels
        yield
    finally:
        for modifier, shown, levels in reversed(saved):
            if modifier.show_viewport != shown:
                modifier.show_viewport = shown
            if levels is not None and modifier.levels != levels:
                modifier.levels = levels


def creases(mesh):
    """The mesh's Edge Crease and Vertex Crease as a scene's lists: [[a, b, crease], ...] of
    every creased edge (by its vertices) and [[v, crease], ...] of every creased vertex, the
    creases as Blender holds them."""
    edge_vertices = np.empty(len(mesh.edges) * 2, np.int64)
    mesh.edges.foreach_get("vertices", edge_vertices)
    edge_crease = np.empty(len(mesh.edges), np.float32)
    mesh.edges.foreach_get("crease", edge_crease)
    creased = np.flatnonzero(edge_crease)
    ends = edge_vertices.reshape(-1, 2)
    edges = [[int(ends[e, 0]), int(ends[e, 1]), float(edge_crease[e])] for e in creased]
    vertices = []
    if len(mesh.vertex_creases) > 0:
        vertex_crease = np.empty(len(mesh.vertices), np.float32)
        mesh.vertex_creases[0].data.foreach_get("value", vertex_crease)
        vertices = [[int(v), float(vertex_crease[v])] for v in np.flatnonzero(vertex_crease)]
    return edges, vertices


def _srgb_to_linear(values):
    """The sRGB transfer function, inverted (what Blender applies to an sRGB byte image)."""
    return np.where(values <= 0.04045, values / 12.92,
                    ((values + 0.055) / 1.055) ** 2.4).astype(np.float32)


def image_pixels(image):
    """(pixels, width, height, channels) of a Blender image, rows bottom first, the values
    an Image Texture node gives the shader: byte images in the sRGB colour space are
    converted to linear as Blender does; float images and Non-Color data are used as stored.
    A UDIM (tiled) image goes through tile_pixels."""
    if image.source == "TILED":
        raise BakeInputError(f"image '{image.name}' is a UDIM (tiled) image: read it with "
                             "tile_pixels")
    width, height = image.size
    channels = image.channels
    if width * height == 0 or len(image.pixels) == 0:
        raise BakeInputError(f"image '{image.name}' has no pixels (is its file missing?)")
    pixels = np.empty(width * height * channels, np.float32)
    image.pixels.foreach_get(pixels)
    if (not image.is_float and image.colorspace_settings.name == "sRGB"
            and not image.colorspace_settings.is_data):
        colour = pixels.reshape(-1, channels)
        colour[:, :min(channels, 3)] = _srgb_to_linear(colour[:, :min(channels, 3)])
    return pixels, width, height, channels


def tile_pixels(image):
    """{tile number: image_pixels of the tile} of a UDIM (tiled) image, read from its tile
    files: Blender 3.4's Image.pixels reaches only a tiled image's first tile. Each file is
    loaded as a temporary image with the tiled image's colour space (so byte tiles in sRGB
    are made linear as the image's would be) and removed again. A tiled image whose tiles are
    not files (generated, packed) or that has unsaved changes is refused: its files would not
    be what the image shows."""
    template = image.filepath_raw
    if "<UDIM>" not in template and "<UVTILE>" not in template:
        raise BakeInputError(f"image '{image.name}' is a UDIM image whose tiles are not files "
                             "(save it with a <UDIM> file name first)")
    if image.packed_file is not None or len(image.packed_files) > 0:
        raise BakeInputError(f"image '{image.name}' is a packed UDIM image (unpack it to files "
                             "first)")
    if image.is_dirty:
        raise BakeInputError(f"image '{image.name}' has unsaved changes (save it first: the "
                             "bake reads its tile files)")
    tiles = {}
    for tile in image.tiles:
        path = bpy.path.abspath(_tile_path(template, tile.number), library=image.library)
        if not os.path.isfile(path):
            raise BakeInputError(f"image '{image.name}': tile {tile.number} has no file "
                                 f"({path})")
        loaded = bpy.data.images.load(path, check_existing=False)
        try:
            loaded.colorspace_settings.name = image.colorspace_settings.name
            tiles[tile.number] = image_pixels(loaded)
        finally:
            bpy.data.images.remove(loaded)
    return tiles


def layer_images(layers):
    """{name: image_pixels(image)} of every image the layers read (their images and masks),
    named as scene.image_key and scene.tile_key name them (a UDIM image's tiles as
    "NAME (tile 1001)", ...).
    Layers are named layers[i], counted from 0 as in libsgbake's messages about the same
    list."""
    images = {}
    owners = {}  # key -> the Blender image sent under it

    def add(key, image, pixels):
        if owners.setdefault(key, image.name) != image.name:
            raise BakeInputError(f"images '{owners[key]}' and '{image.name}' would both be sent "
                                 f"as '{key}' (rename one)")
        images[key] = pixels

    for index, layer in enumerate(layers):
        used = [layer.mask_image] if layer.mask_image is not None else []
        if layer.type in scene.IMAGE_LAYER_TYPES:
            if layer.image is None:
                raise BakeInputError(f"layers[{index}] '{layer.name}' ({layer.type}) has no "
                                     "image")
            used.insert(0, layer.image)
        for image in used:
            if image.name in owners.values():  # read once, however many layers use it
                continue
            try:
                if image.source != "TILED":
                    add(scene.image_key(image), image, image_pixels(image))
                    continue
                for tile, pixels in tile_pixels(image).items():
                    add(scene.tile_key(image, tile), image, pixels)
            except BakeInputError as exc:
                raise BakeInputError(f"layers[{index}] '{layer.name}': {exc}") from None
    return images


def uv_tiles(uv, face_start):
    """The UDIM tiles (1001 + u + 10 v) the faces of a UV map lie in, each face counted in the
    tile of its corners' mean UV: a summary for the report, the bake itself covers whatever
    each tile's square holds."""
    uv = uv.reshape(-1, 2).astype(np.float64)
    counts = np.diff(face_start.astype(np.int64))
    if counts.size == 0:
        return set()
    centre = np.add.reduceat(uv, face_start[:-1].astype(np.int64), axis=0) / counts[:, None]
    tile = np.floor(centre).astype(np.int64)
    inside = (tile[:, 0] >= 0) & (tile[:, 0] < 10) & (tile[:, 1] >= 0) & (tile[:, 1] < 100)
    return {int(t) for t in np.unique(1001 + tile[inside, 0] + 10 * tile[inside, 1])}


def image_tiles(image):
    """The UDIM tiles a bake into `image` fills: the tiles of a tiled image, in order, else
    [1001] (a single image holds the 0-1 UV square)."""
    if image is not None and image.source == "TILED":
        return [tile.number for tile in image.tiles]
    return [1001]


def blender_name(name):
    """`name` as Blender stores an ID name: at most 63 bytes of UTF-8, cut at a character
    boundary (so that an image made under `name` is found again under it)."""
    return name.encode("utf-8")[:63].decode("utf-8", errors="ignore")


def check_target(image):
    """Raises BakeInputError when the single image `image` cannot be baked into: Blender's
    render or compositing result, or an image without pixels (its file is missing)."""
    if image.type in {"RENDER_RESULT", "COMPOSITING"}:
        raise BakeInputError(f"image '{image.name}' is Blender's render result: bake into "
                             "another image")
    if image.size[0] == 0 or image.size[1] == 0:
        raise BakeInputError(f"target image '{image.name}' has no pixels (is its file "
                             "missing? reload it or pick another image)")


def check_memory(width, height, padding):
    """Raises BakeInputError when a width x height bake cannot fit in this machine's memory:
    the library holds ~6 floats per texel (the map, its coverage, a copy for padding; Adjacent
    Faces padding 3 more: each texel's face, twice, and its distance to the islands) and the
    add-on 4 more (the RGBA pixels it gets back)."""
    needed = width * height * (13 if padding == "adjacent-faces" else 10) * 4
    try:
        memory = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError):
        return
    if needed > memory:
        raise BakeInputError(f"a {width} x {height} bake needs about {needed / 2**30:.0f} GiB, "
                             f"more than this machine's {memory / 2**30:.0f} GiB (try a "
                             "smaller size)")


def target_image(target, name, width, height):
    """The image to bake into: `target` (an Image or None), else the image `name` (created as
    a 32-bit float Non-Color image when missing), scaled to width x height when it differs."""
    image = target
    if image is None:
        image = bpy.data.images.get(name)
        if image is None:
            image = bpy.data.images.new(name, width, height, alpha=True, float_buffer=True,
                                        is_data=True)
            image.colorspace_settings.name = "Non-Color"
    if tuple(image.size) != (width, height):
        image.scale(width, height)
    return image


def write_pixels(image, rgba):
    """Stores width x height x 4 floats (rows bottom first) into the image, keeping the
    channels it has (grey images take R, RGB images R, G and B)."""
    channels = image.channels
    if channels != 4:
        rgba = np.ascontiguousarray(rgba.reshape(-1, 4)[:, :channels]).reshape(-1)
    image.pixels.foreach_set(rgba)
    image.update()


def _tile_path(template, tile):
    """A <UDIM> (or <UVTILE>) path template with tile `tile` filled in."""
    u, v = (tile - 1001) % 10, (tile - 1001) // 10
    return template.replace("<UDIM>", str(tile)).replace("<UVTILE>", f"u{u + 1}_v{v + 1}")


def packed_template(image):
    """Where a tiled image's baked tiles say they belong once packed: the image's own path
    with .exr as extension, or //<name>.<UDIM>.exr beside the .blend file for an image without
    a <UDIM> path (a generated one). Nothing is written there until the user saves."""
    path = image.filepath_raw
    if "<UDIM>" not in path and "<UVTILE>" not in path:
        return f"//{bpy.path.clean_name(image.name)}.<UDIM>.exr"
    root, ext = os.path.splitext(path)
    return path if ext.lower() == ".exr" else root + ".exr"


def write_tiles(image, tiles, width, height):
    """Stores baked UDIM tiles ({tile number: width x height x 4 floats, rows bottom first})
    into the tiled `image`, whose tiles must be exactly those. Returns notes for the report.

    Blender 3.4's Image.pixels reaches only a tiled image's first tile, so each tile is saved
    as a 32-bit float OpenEXR in a temporary folder, the image is pointed at those files
    (<UDIM>) and reloaded, every tile is read (tile.size loads it), and the image is packed
    into the .blend file, which keeps the pixels once the folder is deleted. The image keeps
    its name; its path becomes packed_template(image), and its colour space Non-Color, which
    loads the files' values as they are (any other would convert them or their alpha)."""
    numbers = sorted(tile.number for tile in image.tiles)
    if numbers != sorted(tiles):
        raise BakeInputError(f"the tiles of image '{image.name}' changed during the bake "
                             f"(baked {sorted(tiles)}, now {numbers}); bake again")
    notes = []
    if image.colorspace_settings.name != "Non-Color":
        notes.append(f"colour space {image.colorspace_settings.name} -> Non-Color")
        image.colorspace_settings.name = "Non-Color"
    template = packed_template(image)
    folder = tempfile.mkdtemp(prefix="sgbake-udim-")
    scratch = None
    try:
        scratch = bpy.data.images.new("sgbake tile", width, height, alpha=True,
                                      float_buffer=True, is_data=True)
        scratch.colorspace_settings.name = "Non-Color"
        for tile, rgba in tiles.items():
            scratch.pixels.foreach_set(rgba)
            # Set after the pixels: before, the image has no buffer to take the format.
            scratch.file_format = "OPEN_EXR"
            scratch.use_half_precision = False
            scratch.filepath_raw = os.path.join(folder, f"bake.{tile}.exr")
            scratch.save()
        if image.packed_file is not None or len(image.packed_files) > 0:
            image.unpack(method="REMOVE")  # reload would read the old packed tiles
        original = image.filepath_raw
        image.filepath_raw = os.path.join(folder, "bake.<UDIM>.exr")
        image.reload()
        failed = [tile.number for tile in image.tiles if tuple(tile.size) != (width, height)]
        if failed:
            image.filepath_raw = original
            image.reload()
            raise BakeInputError(f"image '{image.name}': baked tile(s) {failed} did not load "
                                 "back into it")
        image.pack()
        for packed in image.packed_files:
            packed.filepath = _tile_path(template, packed.tile_number)
        image.filepath_raw = template
    except RuntimeError as exc:  # Blender could not save, load or pack a tile
        raise BakeInputError(f"cannot put the baked tiles into image '{image.name}': "
                             f"{str(exc).strip()}") from None
    finally:
        if scratch is not None:
            bpy.data.images.remove(scratch)
        shutil.rmtree(folder, ignore_errors=True)
    image.update()
    return notes
