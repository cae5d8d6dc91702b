"""The add-on's settings as an sgbake scene (the JSON of `sgbake bake SCENE.json`, docs/baker.md).

No bpy here: the functions read the settings and layers through their attributes only (the
PropertyGroups of properties.py, or anything with the same attributes).

The scene parser refuses keys that do not apply (a "green" on an object-space normal map, a
"phase" on a noise volume, an "image" on a volume), so every key below is sent only for the
layer types, spaces and maps it applies to (scene.cpp's layerKeys and kMapOutputKeys).
Every per-layer key of the scene format is covered: the common ones (name, weight, material,
mask with its image, uv, tiling, offset and filter), the image ones (image, filter, wrap, tiling,
offset), uv, scale/strength, space, green, kind, axis, sharpness, min_weight and the volume's
function, amplitude, frequency, direction, phase, seed, octaves, detail, roughness,
distortion, dimension, lacunarity, wave, wave_direction, profile, detail_scale,
detail_roughness, gradient and step; a
height's remap (its Remap text, parsed by remap_points: LayerError for text that is not one).
"""

import json
import math

MAPS = (
    ("tangent-normal", "Tangent Normal", "Normal map in tangent space (n/2 + 0.5)"),
    ("object-normal", "Object Normal", "Normal map in object space (n/2 + 0.5)"),
    ("height", "Height", "The layers' heights (world units, as the Bump node's Distance)"),
    ("derivative", "Derivative", "Height derivatives along u and v (signed, 2 channels)"),
    ("surface-gradient", "Surface Gradient", "Object-space surface gradient (signed)"),
    ("tangent", "Tangent", "MikkTSpace tangent (n/2 + 0.5)"),
    ("bitangent", "Bitangent", "Bitangent, sign x N x T (n/2 + 0.5)"),
    ("mask", "Mask", "1 where a triangle covers the texel, else 0"),
)
# The volume functions that are Blender's procedural textures -> the layer settings holding the
# node's enum properties (in the scene's names) and its inputs besides its Scale (the
# frequency), sent under the same keys (but SETTING_KEYS'); libsgbake refuses another
# function's keys (a "roughness" on a blender-musgrave volume).
BLENDER_TEXTURE_SETTINGS = {
    "blender-noise": ("texture_dimensions", "w", "detail", "roughness", "distortion"),
    "blender-musgrave": ("texture_dimensions", "w", "musgrave_type", "detail", "dimension",
                         "lacunarity", "musgrave_offset", "gain"),
    "blender-wave": ("wave", "wave_direction", "profile", "distortion", "detail", "detail_scale",
                     "detail_roughness", "phase"),
    "blender-voronoi": ("feature", "metric", "smoothness", "randomness", "exponent"),
    "blender-brick": ("mortar_size", "mortar_smooth", "brick_width", "row_height", "brick_offset",
                      "offset_frequency", "squash", "squash_frequency"),
    "blender-gradient": ("gradient_type",),
    "blender-magic": ("depth", "magic_distortion"),
}
# Blender's textures without a Scale: their volumes take no "frequency".
UNSCALED_FUNCTIONS = {"blender-gradient"}
# The scene's keys of the settings whose layer property has another name.
SETTING_KEYS = {"musgrave_offset": "offset", "magic_distortion": "distortion",
                "texture_dimensions": "dimensions"}
# The Noise and Musgrave Textures' Dimensions that read W (the others take no "w").
W_DIMENSIONS = {"1D", "4D"}
# The Musgrave Texture's inputs its types do not use (libsgbake refuses them): Multifractal and
# fBM use neither Offset nor Gain, Hetero Terrain no Gain.
MUSGRAVE_UNUSED = {"fbm": ("musgrave_offset", "gain"),
                   "multifractal": ("musgrave_offset", "gain"), "hetero-terrain": ("gain",)}
# The Voronoi Texture's settings its Feature Outputs do not use: Smoothness but for Smooth F1
# (libsgbake refuses it); Distance to Edge has no Distance Metric nor Exponent (Blender hides
# them, Cycles ignores them).
VORONOI_UNUSED = {"f1": ("smoothness",), "f2": ("smoothness",),
                  "distance-to-edge": ("smoothness", "metric", "exponent")}


def texture_settings(function, musgrave_type="fbm", feature="f1", dimensions="3D"):
    """The settings a volume of `function` sends (BLENDER_TEXTURE_SETTINGS; none for sine and
    noise), a Blender Musgrave's less the inputs its `musgrave_type` does not use, a Blender
    Voronoi's less those its `feature` does not use, a Blender Noise's or Musgrave's W only for
    the `dimensions` that read it (W_DIMENSIONS)."""
    unused = (MUSGRAVE_UNUSED.get(musgrave_type, ()) if function == "blender-musgrave"
              else VORONOI_UNUSED.get(feature, ()) if function == "blender-voronoi" else ())
    if dimensions not in W_DIMENSIONS:
        unused = (*unused, "w")
    return tuple(key for key in BLENDER_TEXTURE_SETTINGS.get(function, ()) if key not in unused)


# Maps that read no layer: their bakes send none, so an unfinished layer cannot stop them.
LAYERLESS_MAPS = {"tangent", "bitangent", "mask"}
# Maps whose values the object's transform changes (libsgbake's shadedThroughTransform): the
# shaded normal and the surface gradient. Heights, tangents and the mask are the same either way.
WORLD_SHADED_MAPS = {"tangent-normal", "object-normal", "derivative", "surface-gradient"}

LAYER_TYPES = (
    ("height", "Height", "Height image on a UV map"),
    ("normal", "Normal", "Normal map image on a UV map (tangent or object space)"),
    ("volume", "Volume", "Procedural height in object space (sine, noise, or Blender's Noise, "
                         "Musgrave, Wave or Voronoi Texture)"),
    ("planar", "Planar", "Image projected along an object axis"),
    ("triplanar", "Triplanar", "Image projected on the three axis planes and blended"),
)
IMAGE_LAYER_TYPES = {"height", "normal", "planar", "triplanar"}
UV_LAYER_TYPES = {"height", "normal"}  # layer types with their own "uv" (and reads_uv)

SURFACES = (
    ("mesh", "Evaluated Mesh",
     "The mesh as the object's modifiers make it for rendering (their render visibility and "
     "levels): what Cycles bakes"),
    ("limit", "Exact Limit Surface",
     "The exact Catmull-Clark limit surface of the mesh under the object's last modifier, a "
     "Subdivision Surface (its creases, UV Smooth and Boundary Smooth; its levels do not "
     "matter): every texel on the smooth surface itself, not on a subdivided mesh"),
)

# A Subdivision Surface modifier's settings -> the scene's "uv_smooth" and "boundary" names.
UV_SMOOTHS = {
    "NONE": "none",
    "PRESERVE_CORNERS": "keep-corners",
    "PRESERVE_CORNERS_AND_JUNCTIONS": "keep-corners-junctions",
    "PRESERVE_CORNERS_JUNCTIONS_AND_CONCAVE": "keep-corners-junctions-concave",
    "PRESERVE_BOUNDARIES": "keep-boundaries",
    "SMOOTH_ALL": "all",
}
BOUNDARY_SMOOTHS = {"ALL": "all", "PRESERVE_CORNERS": "keep-corners"}


class LayerError(ValueError):
    """A layer's setting cannot be sent as it is (its message names the layer)."""


# libsgbake's limits on a height's "remap" (kMaxRemapPoints).
REMAP_MIN_POINTS, REMAP_MAX_POINTS = 2, 65536


def remap_text(points):
    """A remap's points [[x, y], ...] as the text a layer's Remap holds (JSON)."""
    return json.dumps([[float(x), float(y)] for x, y in points], separators=(",", ":"))


def remap_points(layer):
    """The points [[x, y], ...] of a layer's Remap (JSON text; "" or blank: none, None).
    Raises LayerError, naming the layer, for text that is not a list of 2 to 65536 pairs of
    finite numbers in non-decreasing x with at most two of one x."""
    text = layer.remap.strip()
    if not text:
        return None

    def bad(why):
        return LayerError(f"layer '{layer.name}': Remap {why} (a JSON list of [x, y] points in "
                          "non-decreasing x, at most two of one x)")
    try:
        points = json.loads(text)
    except ValueError as exc:
        raise bad(f"is not JSON: {exc}") from None
    if not isinstance(points, list):
        raise bad("is not a list")
    if not REMAP_MIN_POINTS <= len(points) <= REMAP_MAX_POINTS:
        raise bad(f"has {len(points)} points, not {REMAP_MIN_POINTS} to {REMAP_MAX_POINTS}")
    for i, point in enumerate(points):
        if (not isinstance(point, list) or len(point) != 2
                or not all(isinstance(v, (int, float)) and not isinstance(v, bool)
                           and math.isfinite(v) for v in point)):
            raise bad(f"point {i} {json.dumps(point)[:40]} is not two finite numbers")
        if i > 0 and point[0] < points[i - 1][0]:
            raise bad(f"point {i} has x {point[0]:g} below the one before ({points[i - 1][0]:g})")
        if i > 1 and point[0] == points[i - 1][0] == points[i - 2][0]:
            raise bad(f"has three points of x {point[0]:g}")
    return [[float(x), float(y)] for x, y in points]


def _number(value):
    """A Blender float/int property as a JSON number (plain Python float/int)."""
    return float(value) if isinstance(value, float) else int(value)


def _setting(value):
    """A Blender property as JSON: an enum's name as it is, a number as _number."""
    return value if isinstance(value, str) else _number(value)


def _pair(values):
    """A 2-vector property as a JSON list of two numbers."""
    return [_number(values[0]), _number(values[1])]


def image_key(image):
    """The name a layer's "image" gives a Blender image in the library's scene: its name, or
    for a UDIM (tiled) image "NAME (tile <UDIM>)", whose tiles gather.layer_images sends as
    "NAME (tile 1001)", "NAME (tile 1002)", ... (not NAME.1001: a single image may be called
    that). '<' and '>' in a name become '‹' and '›', so that no name reads as a <UDIM> token
    (Blender names a UDIM image opened from h.<UDIM>.png "h.<UDIM>.png")."""
    name = image.name.replace("<", "\u2039").replace(">", "\u203a")
    return f"{name} (tile <UDIM>)" if image.source == "TILED" else name


def tile_key(image, tile):
    """The name tile `tile` of the UDIM image `image` is sent under (see image_key)."""
    return image_key(image).replace("<UDIM>", str(tile))


def mask_json(layer, uv_index):
    """A layer's "mask" (it has a mask_image): the image, its lookup and, when the layer names
    a mask UV map, that UV set (otherwise the mask is read on the layer's UV set)."""
    mask = {"image": image_key(layer.mask_image), "tiling": _pair(layer.mask_tiling),
            "offset": _pair(layer.mask_offset), "filter": layer.mask_filter}
    if layer.mask_uv_map:
        mask["uv"] = uv_index(layer.mask_uv_map)
    return mask


def reads_tangent_normals(layer):
    """Whether the layer's image holds tangent-space normals (then "green" applies)."""
    if layer.type == "normal":
        return layer.space == "tangent"
    if layer.type in ("planar", "triplanar"):
        return layer.kind == "tangent-normal"
    return False


def bumps_height(layer):
    """Whether the layer is a height a Bump node bumps (so it has its Strength): height and
    volume layers, and projections of Kind Height."""
    return layer.type in ("height", "volume") or (layer.type in ("planar", "triplanar")
                                                  and layer.kind == "height")


def tangent_frames_uv(layer, default_uv=None):
    """The UV map whose tangent frames decode the layer's tangent-space normals when it is not
    the layer's own UV map, or None: a normal layer's Tangent UV Map; a triplanar Box layer's
    (the Normal Map node's UV map decoding what the Box projection reads), else `default_uv`,
    the render UV map Cycles' Normal Map node takes when its own is empty."""
    if layer.type == "normal" and layer.space == "tangent":
        return layer.tangent_uv_map or None
    if projected_by_blender(layer) and layer.kind == "tangent-normal":
        return layer.tangent_uv_map or default_uv or None
    return None


def reads_uv(layer):
    """Whether `layer` reads a UV map of its own ("uv"): a height or normal layer, or a volume
    on UV coordinates (coordinates_uv)."""
    return layer.type in UV_LAYER_TYPES or (layer.type == "volume" and layer.coordinates_uv)


def on_object_coordinates(layer):
    """Whether `layer` reads object coordinates: a projection, or a volume not on a UV map."""
    return layer.type in ("planar", "triplanar") or (layer.type == "volume"
                                                     and not layer.coordinates_uv)


def projected_by_blender(layer):
    """Whether the layer projects its image as Blender's Image Texture does: a triplanar
    layer's Box projection, a planar layer's Flat, Sphere or Tube one."""
    return ((layer.type == "triplanar" and layer.projection == "box")
            or (layer.type == "planar" and layer.planar_projection != "axis"))


def layer_json(layer, uv_index, default_uv=None):
    """One entry of "layers". uv_index(name) gives the UV set of a UV map name (for height and
    normal layers: the layer's own UV map, else `default_uv`, the render UV map, else the
    scene's "uv"). A height layer's Scale is in world units, as Cycles' Bump Distance, and is
    sent as it is: the scene's "transform" makes libsgbake bump in world space (scene_json). A
    height's Remap goes as "remap" (remap_points, which raises LayerError for bad text). A
    volume sends its function's own settings only (a Blender Noise's Dimensions, detail,
    roughness and distortion, a Blender Musgrave's Dimensions, type, detail, dimension and
    lacunarity and the offset and gain where its type uses them, both their W in 1D and 4D
    (texture_settings), a Blender Wave's type,
    direction, profile, distortion, detail, detail scale and roughness and phase, a Blender
    Voronoi's feature and the metric, smoothness, randomness and exponent it uses:
    BLENDER_TEXTURE_SETTINGS; libsgbake refuses
    another function's), and like a projection its "mapping" when it has one (a Mapping node,
    another object's or the Generated coordinates). A layer of one material slot
    (material_index >= 0) sends it as "material": libsgbake then applies it to the faces of
    that slot only (the mesh's face_material)."""
    entry = {"type": layer.type, "name": layer.name, "weight": _number(layer.weight)}
    if layer.material_index >= 0:  # the faces of one material slot (-1: every face)
        entry["material"] = int(layer.material_index)
    if layer.type in IMAGE_LAYER_TYPES:
        entry.update(image=image_key(layer.image), filter=layer.filter, wrap=layer.wrap,
                     tiling=_pair(layer.tiling), offset=_pair(layer.offset))
    if layer.mask_image is not None:
        entry["mask"] = mask_json(layer, uv_index)
    if reads_uv(layer) and (layer.uv_map or default_uv):
        entry["uv"] = uv_index(layer.uv_map or default_uv)
    if tangent_frames_uv(layer, default_uv):
        entry["tangent_uv"] = uv_index(tangent_frames_uv(layer, default_uv))
    if bumps_height(layer) and layer.strength != 1.0:  # the Bump's blend of normals (1: none)
        entry["strength"] = _number(layer.strength)
    if bumps_height(layer) and layer.height_space != "world":  # (a Displacement in Object space)
        entry["height_space"] = layer.height_space
    if bumps_height(layer) and layer.remap.strip():  # (a Color Ramp or a clamp on the height)
        entry["remap"] = remap_points(layer)
    if layer.type == "height":
        entry["scale"] = _number(layer.scale)
        if layer.channel != "luminance":
            entry["channel"] = layer.channel
    elif layer.type == "normal":
        entry.update(space=layer.space, strength=_number(layer.scale))
    elif layer.type == "volume":
        entry.update(function=layer.function, amplitude=_number(layer.amplitude),
                     gradient=layer.gradient)
        if layer.function not in UNSCALED_FUNCTIONS:
            entry["frequency"] = _number(layer.frequency)
        if layer.coordinates_uv:  # (u, v, 0) of its UV map, as a texture on a UV output
            entry["coordinates"] = "uv"
        # 0: the library's default; the Bump node's slopes take no step of their own.
        if layer.gradient in ("central", "tetrahedral") and layer.step > 0:
            entry["step"] = _number(layer.step)
        if layer.function == "sine":
            entry.update(direction=[_number(c) for c in layer.direction],
                         phase=_number(layer.phase))
        elif layer.function == "noise":
            entry.update(seed=int(layer.seed), octaves=int(layer.octaves))
        else:  # Blender's Noise, Musgrave, Wave or Voronoi Texture (its Scale: frequency)
            entry.update({SETTING_KEYS.get(key, key): _setting(getattr(layer, key))
                          for key in texture_settings(layer.function, layer.musgrave_type,
                                                      layer.feature, layer.texture_dimensions)})
    elif layer.type == "planar":
        entry.update(kind=layer.kind, axis=layer.axis, scale=_number(layer.scale))
        if layer.planar_projection != "axis":  # Blender's Flat, Sphere and Tube: about z
            entry.update(projection=layer.planar_projection, axis="z")
    elif layer.type == "triplanar":
        entry.update(kind=layer.kind, scale=_number(layer.scale))
        if layer.projection == "box":
            entry.update(projection="box", box_blend=_number(layer.box_blend))
        else:
            entry.update(sharpness=_number(layer.sharpness), min_weight=_number(layer.min_weight))
    if layer.type in ("planar", "triplanar", "volume"):
        mapping = {"location": [_number(c) for c in layer.mapping_location],
                   "rotation": [_number(c) for c in layer.mapping_rotation],
                   "scale": [_number(c) for c in layer.mapping_scale]}
        matrix = [_number(c) for c in layer.mapping_matrix]
        # (other objects' and the Generated coordinates are object coordinates: not a UV map's)
        if (on_object_coordinates(layer)
                and matrix != [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0]):
            mapping["matrix"] = [matrix[0:4], matrix[4:8], matrix[8:12]]
        if mapping != {"location": [0.0] * 3, "rotation": [0.0] * 3, "scale": [1.0] * 3}:
            if layer.mapping_type != "POINT":
                mapping["type"] = layer.mapping_type.lower()
            entry["mapping"] = mapping  # other coordinates, a Mapping node before the texture
    if reads_tangent_normals(layer):
        entry["green"] = layer.green
    if layer.type == "height" or (layer.type in ("planar", "triplanar") and layer.kind == "height"):
        if layer.slopes != "analytic":
            entry["gradient"] = layer.slopes
    if bumps_height(layer) and layer.base != "surface":
        entry["base"] = layer.base
    return entry


IDENTITY_SWIZZLE = ("POS_X", "POS_Y", "POS_Z")


def output_json(settings, tile=1001):
    """The single entry of "outputs" (no "file": the pixels come back in memory) for UDIM
    tile `tile` (1001: the 0-1 UV square)."""
    output = {"map": settings.map, "width": int(settings.width), "height": int(settings.height),
              "padding": settings.padding, "samples": int(settings.samples),
              "alpha": bool(settings.use_alpha), "tile": int(tile)}
    if settings.padding != "push-pull":  # push-pull fills every texel: no margin
        output["margin"] = int(settings.margin)
    swizzle = [settings.swizzle_r, settings.swizzle_g, settings.swizzle_b]
    if settings.map in ("tangent-normal", "object-normal") and swizzle != list(IDENTITY_SWIZZLE):
        # The scene takes the green convention in "swizzle" then: a DirectX green negates G.
        if settings.map == "tangent-normal" and settings.green == "directx":
            swizzle[1] = ("NEG_" if swizzle[1].startswith("POS_") else "POS_") + swizzle[1][4:]
        output["swizzle"] = ",".join(swizzle)
    elif settings.map == "tangent-normal":
        output["green"] = settings.green
    return output


def baked_layers(settings):
    """The layers the settings' map reads: all but those of weight 0 (turned off: they need
    no image either), or none for LAYERLESS_MAPS."""
    if settings.map in LAYERLESS_MAPS:
        return []
    return [layer for layer in settings.layers if layer.weight != 0]


def limit_subdivision_json(modifier, edge_creases, vertex_creases):
    """The "subdivision" block of a bake from the exact limit surface of the mesh under
    `modifier`, a Catmull-Clark Subdivision Surface (its uv_smooth, boundary_smooth and
    use_creases: its levels, quality and use_limit_surface do not change the limit surface),
    with the mesh's creases as lists [[a, b, crease], ...] and [[v, crease], ...]."""
    block = {"level": "limit", "uv_smooth": UV_SMOOTHS[modifier.uv_smooth],
             "boundary": BOUNDARY_SMOOTHS[modifier.boundary_smooth],
             "use_creases": bool(modifier.use_creases)}
    if edge_creases:
        block["edge_creases"] = edge_creases
    if vertex_creases:
        block["vertex_creases"] = vertex_creases
    return block


def scene_json(settings, layers, bake_uv_set, uv_index, tile=1001, subdivision=None,
               transform=None, default_uv=None):
    """The scene for sgbake_bake_map: the bake's UV set as the default of the layers and the
    output ("uv"), the layers (baked_layers; their UV map by default `default_uv`) and one
    output, of UDIM tile `tile`, the "subdivision" block when one is given
    (limit_subdivision_json) and the "transform" when one is given: the object's matrix_world
    as rows (gather.world_transform), with which libsgbake shades the object in world space as
    Cycles does (heights in world units, as the Bump node's Distance)."""
    result = {"uv": bake_uv_set,
              "layers": [layer_json(layer, uv_index, default_uv) for layer in layers],
              "outputs": [output_json(settings, tile)]}
    if subdivision is not None:
        result["subdivision"] = subdivision
    if transform is not None:
        result["transform"] = transform
    return result
