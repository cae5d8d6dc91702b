"""Blender data as the flat arrays libsgbake takes, and the baked pixels back into an image.

Everything is moved with foreach_get / foreach_set into numpy arrays (no Python loop per
vertex or texel). Problems with the user's data raise BakeInputError with a message meant for
the operator's error report.
"""

import numpy as np

import bpy

from . import scene


class BakeInputError(Exception):
    """The object, its UV maps or the layers' images cannot be baked as they are."""


def uv_sets(mesh, bake_uv_name, layers):
    """The UV maps to send, in order, and the index of the bake's UV map among them.

    Set 0 is the active UV map: libsgbake builds tangent frames on set 0, and Blender's bake
    builds them on the active UV map whatever UV map it bakes on. The bake's UV map (default:
    the active one) and the UV maps layers name follow, each once, so that a bake never sends
    more UV maps than it reads."""
    if len(mesh.uv_layers) == 0:
        raise BakeInputError("has no UV map")
    names = [mesh.uv_layers.active.name]
    bake_uv_name = bake_uv_name or names[0]
    wanted = [("the bake", bake_uv_name)]
    wanted += [(f"layer '{layer.name}'", layer.uv_map) for layer in layers
               if layer.type in scene.UV_LAYER_TYPES and layer.uv_map]
    for user, name in wanted:
        if name not in mesh.uv_layers:
            raise BakeInputError(f"has no UV map '{name}' (used by {user})")
        if name not in names:
            names.append(name)
    return names, names.index(bake_uv_name)


def mesh_arrays(mesh, uv_names):
    """The mesh as sgbake_mesh arrays: positions (#V x 3), face_start (#F + 1), corner_vertex
    (#C), corner normals (#C x 3, Blender's split normals: calc_normals_split must have run)
    and one (#C x 2) array per UV map name.

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
    return positions, face_start.astype(np.uint32), corner_vertex, normals, uvs


def _srgb_to_linear(values):
    """The sRGB transfer function, inverted (what Blender applies to an sRGB byte image)."""
    return np.where(values <= 0.04045, values / 12.92,
                    ((values + 0.055) / 1.055) ** 2.4).astype(np.float32)


def image_pixels(image):
    """(pixels, width, height, channels) of a Blender image, rows bottom first, the values
    an Image Texture node gives the shader: byte images in the sRGB colour space are
    converted to linear as Blender does; float images and Non-Color data are used as stored."""
    if image.source == "TILED":
        raise BakeInputError(f"image '{image.name}' is a UDIM image (not supported as a layer)")
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


def layer_images(layers):
    """{Image.name: image_pixels(image)} of every layer that reads an image. Layers are named
    layers[i], counted from 0 as in libsgbake's messages about the same list."""
    images = {}
    for index, layer in enumerate(layers):
        if layer.type not in scene.IMAGE_LAYER_TYPES:
            continue
        if layer.image is None:
            raise BakeInputError(f"layers[{index}] '{layer.name}' ({layer.type}) has no image")
        if layer.image.name not in images:
            images[layer.image.name] = image_pixels(layer.image)
    return images


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
