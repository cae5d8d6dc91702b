"""The add-on's settings: a PropertyGroup on the Scene (scene.sgbake) with a list of layers.

Enum identifiers are sgbake's own names ("tangent-normal", "bicubic"), so scene.py sends them
as they are. Defaults are those of a scene file (docs/baker.md), except where noted.
"""

import bpy
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty,
                       FloatVectorProperty, IntProperty, PointerProperty, StringProperty)

from . import scene

FILTERS = (
    ("bilinear", "Bilinear", "Bilinear interpolation (Blender's Linear)"),
    ("bicubic", "Bicubic", "Cubic B-spline interpolation (Blender's Cubic)"),
    ("hermite", "Hermite", "Hermite interpolation with exact derivatives (height images only)"),
)
WRAPS = (
    ("repeat", "Repeat", "Tile the image (Blender's Repeat)"),
    ("clamp", "Clamp", "Extend the edge texels (Blender's Extend)"),
)
GREENS = (
    ("opengl", "OpenGL (Y+)", "Green = +bitangent, as Blender, Substance and Unity use"),
    ("directx", "DirectX (Y-)", "Green = -bitangent, as Unreal and 3ds Max use"),
)
# Blender's bake Swizzle (Render > Bake > Swizzle), the same names as BakeSettings.normal_r.
SWIZZLE_AXES = (
    ("POS_X", "+X", ""), ("POS_Y", "+Y", ""), ("POS_Z", "+Z", ""),
    ("NEG_X", "-X", ""), ("NEG_Y", "-Y", ""), ("NEG_Z", "-Z", ""),
)
SPACES = (
    ("tangent", "Tangent", "The normal map is in tangent space"),
    ("object", "Object", "The normal map is in object space"),
)
CHANNELS = (
    ("luminance", "Luminance", "The Rec. 709 luminance of RGB, as a colour into the Bump "
                               "node's Height"),
    ("r", "R", "The red channel"),
    ("g", "G", "The green channel"),
    ("b", "B", "The blue channel"),
    ("a", "Alpha", "The alpha channel (the Image Texture node's Alpha output)"),
)
BASES = (
    ("surface", "Surface", "Bump the surface's normal: the layer's surface gradient is added to "
                           "the others'"),
    ("above", "Layers Above", "Bump the normal the layers above make, as a Bump node whose "
                              "Normal input is linked to the node before it"),
)
HEIGHT_SPACES = (
    ("world", "World", "Scale in world units, as a Bump node's Distance or a Displacement node's "
                       "Scale in World space"),
    ("object", "Object", "Scale in object units along the normal, as a Displacement node's Scale "
                         "in Object space: grown with the object's scale along the normal"),
)
SLOPES = (
    ("analytic", "Exact", "The exact slopes of the filtered height"),
    ("bump-node", "As Cycles' Bump", "The slopes Cycles' Bump node takes when it bakes: the "
                                      "height read again half a texel away, so the map is "
                                      "Cycles' bake to float rounding (and changes with the "
                                      "bake's size, as Cycles' does)"),
)
KINDS = (
    ("height", "Height", "The image holds heights"),
    ("tangent-normal", "Tangent Normal", "The image holds tangent-space normals"),
    ("object-normal", "Object Normal", "The image holds object-space normals"),
)
PLANAR_PROJECTIONS = (
    ("axis", "Along Axis", "sgbake's planar projection along Axis (normal kinds in the plane's "
                           "own frame)"),
    ("flat", "Flat", "Blender's Image Texture Flat projection, the (x, y) plane: what Cycles "
                     "bakes (normal kinds decode the colour as a Normal Map node does)"),
    ("sphere", "Sphere", "Blender's Image Texture Sphere projection, wrapped around z of "
                         "2 (coordinates - 0.5): what Cycles bakes"),
    ("tube", "Tube", "Blender's Image Texture Tube projection, wrapped around z of "
                     "2 (coordinates - 0.5): what Cycles bakes"),
)

MAPPING_TYPES = (
    ("POINT", "Point", "Scale, rotate, then move the coordinates (the Mapping node's Point)"),
    ("TEXTURE", "Texture", "The inverse of Point: move back, rotate back, divide by the scale"),
    ("VECTOR", "Vector", "Scale and rotate the coordinates; the Location is not used"),
)

PROJECTIONS = (
    ("blended", "Blended", "sgbake's triplanar: each plane weighted by |normal|^Sharpness"),
    ("box", "Box", "Blender's Image Texture Box projection with its Blend: what Cycles bakes "
                   "(normal kinds as a Normal Map node decodes the colour it reads)"),
)
AXES = (("x", "X", "Project along X"), ("y", "Y", "Project along Y"),
        ("z", "Z", "Project along Z"))
FUNCTIONS = (
    ("sine", "Sine", "amplitude * sin(2 pi frequency (direction . p) + phase)"),
    ("noise", "Noise", "Gradient noise of the given frequency and octaves"),
    ("blender-noise", "Blender Noise",
     "Blender's Noise Texture (3D) Fac, as Cycles evaluates it: Frequency is the node's Scale, "
     "with its Detail, Roughness and Distortion"),
    ("blender-musgrave", "Blender Musgrave",
     "Blender's Musgrave Texture (3D) Fac, as Cycles evaluates it: Frequency is the node's "
     "Scale, with its type, Detail, Dimension, Lacunarity, Offset and Gain"),
    ("blender-wave", "Blender Wave",
     "Blender's Wave Texture Fac, as Cycles evaluates it: Frequency is the node's Scale, with "
     "its type, direction, profile, Phase Offset, Distortion, Detail, Detail Scale and Detail "
     "Roughness"),
    ("blender-voronoi", "Blender Voronoi",
     "Blender's Voronoi Texture (3D) Distance, as Cycles evaluates it: Frequency is the "
     "node's Scale, with its Feature Output, Distance Metric, Smoothness, Randomness and "
     "Exponent"),
    ("blender-brick", "Blender Brick",
     "Blender's Brick Texture Fac (the mortar), as Cycles evaluates it: Frequency is the node's "
     "Scale, with its Mortar Size and Smooth, Brick Width, Row Height, Offset, Squash and their "
     "Frequencies"),
    ("blender-gradient", "Blender Gradient",
     "Blender's Gradient Texture Fac, as Cycles evaluates it: its Gradient Type (the node has "
     "no Scale)"),
    ("blender-magic", "Blender Magic",
     "Blender's Magic Texture Fac (its Color's mean), as Cycles evaluates it: Frequency is the "
     "node's Scale, with its Depth and Distortion"),
)
# The Gradient Texture's types in the scene's names.
GRADIENT_TYPES = (
    ("linear", "Linear", "Blender Gradient: x"),
    ("quadratic", "Quadratic", "Blender Gradient: max(x, 0)^2"),
    ("easing", "Easing", "Blender Gradient: 3r^2 - 2r^3 of r = x clamped to [0, 1]"),
    ("diagonal", "Diagonal", "Blender Gradient: (x + y) / 2"),
    ("spherical", "Spherical", "Blender Gradient: 1 - |p| (0 beyond the unit sphere)"),
    ("quadratic-sphere", "Quadratic Sphere", "Blender Gradient: (1 - |p|)^2 inside the sphere"),
    ("radial", "Radial", "Blender Gradient: the angle about z, atan2(y, x) / 2 pi + 1/2"),
)
# The Wave Texture's enums in the scene's names (Blender's Wave Type, Bands or Rings Direction,
# Wave Profile). The directions depend on the type, as the node's two properties: the fourth
# is Diagonal for Bands, Spherical for Rings.
WAVE_TYPES = (
    ("bands", "Bands", "Bands along the direction"),
    ("rings", "Rings", "Rings about the direction's axis (or spherical shells)"),
)
BANDS_DIRECTIONS = (
    ("x", "X", "Bands across the X axis"), ("y", "Y", "Bands across the Y axis"),
    ("z", "Z", "Bands across the Z axis"),
    ("diagonal", "Diagonal", "Bands across the diagonal (x + y + z)"),
)
RINGS_DIRECTIONS = (
    ("x", "X", "Rings about the X axis"), ("y", "Y", "Rings about the Y axis"),
    ("z", "Z", "Rings about the Z axis"),
    ("spherical", "Spherical", "Spherical shells about the origin"),
)
WAVE_PROFILES = (
    ("sine", "Sine", "The Wave Texture's Sine profile"),
    ("saw", "Saw", "The Wave Texture's Saw profile"),
    ("triangle", "Triangle", "The Wave Texture's Triangle profile"),
)


# The Noise and Musgrave Textures' Dimensions.
TEXTURE_DIMENSIONS = (
    ("1D", "1D", "W alone: one value over the whole surface, no bump"),
    ("2D", "2D", "The coordinates' x and y"),
    ("3D", "3D", "The coordinates' x, y and z"),
    ("4D", "4D", "The coordinates' x, y and z, and W"),
)
# The Musgrave Texture's types in the scene's names (Blender's FBM, MULTIFRACTAL, ...).
MUSGRAVE_TYPES = (
    ("fbm", "fBM", "Fractal Brownian motion: the octaves added"),
    ("multifractal", "Multifractal", "The octaves multiplied"),
    ("ridged-multifractal", "Ridged Multifractal",
     "Ridges: each octave (Offset - |noise|)^2, weighted by Gain times the one before"),
    ("hybrid-multifractal", "Hybrid Multifractal",
     "The octaves plus Offset added, each weighted by Gain times the ones before"),
    ("hetero-terrain", "Hetero Terrain",
     "The octaves plus Offset, each scaled by the height so far"),
)


# The Voronoi Texture's Distance Metric in the scene's names (Blender spells one Chebychev).
METRICS = (
    ("euclidean", "Euclidean", "Straight-line distance to the nearest cell point"),
    ("manhattan", "Manhattan", "Sum of the coordinates' distances"),
    ("chebyshev", "Chebyshev", "Largest of the coordinates' distances"),
    ("minkowski", "Minkowski", "(sum of |d|^Exponent)^(1/Exponent)"),
)


# The Voronoi Texture's Feature Outputs that have a Distance, in the scene's names.
VORONOI_FEATURES = (
    ("f1", "F1", "Distance to the nearest cell point"),
    ("f2", "F2", "Distance to the second-nearest cell point"),
    ("smooth-f1", "Smooth F1", "A smooth minimum of the distances to the cell points "
                               "(Smoothness)"),
    ("distance-to-edge", "Distance to Edge",
     "Distance to the nearest cell's boundary (Euclidean: no Distance Metric)"),
)


def _wave_directions(layer, _context):
    """The Direction items of a Blender Wave layer of Wave Type `layer.wave`."""
    return RINGS_DIRECTIONS if layer.wave == "rings" else BANDS_DIRECTIONS


GRADIENTS = (
    ("analytic", "Analytic", "Exact derivative of the function"),
    ("central", "Central", "Central differences (6 evaluations)"),
    ("tetrahedral", "Tetrahedral", "Tetrahedral differences (4 evaluations)"),
    ("bump-node", "As Cycles' Bump", "The slopes Cycles' Bump node takes when it bakes: the "
                                      "height read again a bake texel's step away (changes "
                                      "with the bake's size, as Cycles' does)"),
)
PADDINGS = (
    ("extend", "Extend", "Extend the islands' edge texels by Margin texels (Blender's Extend)"),
    ("adjacent-faces", "Adjacent Faces",
     "Fill Margin texels with the surface across the UV seam each faces (Blender's default)"),
    ("push-pull", "Push-Pull", "Fill every uncovered texel from the islands (Margin unused)"),
)


class SgbakeLayer(bpy.types.PropertyGroup):
    """One layer of the bake; which settings apply depends on its type."""
    name: StringProperty(name="Name", default="Layer")
    type: EnumProperty(name="Type", items=scene.LAYER_TYPES, default="height")
    weight: FloatProperty(name="Weight", default=1.0, soft_min=0.0, soft_max=1.0,
                          description="Multiplies the layer's bump; 0 disables it")
    material_index: IntProperty(
        name="Material Slot", default=-1, min=-1, max=32766,
        description="The material slot (counted from 0) whose faces the layer applies to, as a "
                    "Bump or Normal Map node of that slot's material applies to its faces; "
                    "-1: every face")
    image: PointerProperty(name="Image", type=bpy.types.Image,
                           description="The layer's image (heights, or encoded normals)")
    scale: FloatProperty(
        name="Scale", default=1.0, precision=4, step=1,
        description="Height layers: world units per unit of image value, the Bump node's "
                    "Distance. Normal layers: strength. Projections: world units per unit of "
                    "value (Kind Height), or strength")
    strength: FloatProperty(
        name="Strength", default=1.0, min=0.0, soft_max=1.0, precision=3,
        description="Heights (height and volume layers, projections of Kind Height): the Bump "
                    "node's Strength, which blends the bumped normal with the unbumped one (0: "
                    "no bump, 1: the full bump)")
    channel: EnumProperty(name="Channel", items=CHANNELS, default="luminance",
                          description="What of a height layer's image is the height")
    base: EnumProperty(name="Bumps", items=BASES, default="surface",
                       description="Which normal a height layer bumps")
    height_space: EnumProperty(name="Height Space", items=HEIGHT_SPACES, default="world",
                               description="Heights: the units of Scale (the scene's "
                                           "\"height_space\")")
    slopes: EnumProperty(name="Slopes", items=SLOPES, default="analytic",
                         description="How a height image's slopes are taken (Layers from "
                                     "Material takes a Bump node's as Cycles does; a volume's: "
                                     "its Gradient)")
    remap: StringProperty(
        name="Remap",
        description="Heights: a piecewise-linear function of the image's value, as JSON "
                    "[[x, y], ...] in non-decreasing x (two points of one x: a step), constant "
                    "beyond the ends; the height is Scale x remap(value). Layers from Material "
                    "sets it from a Color Ramp or a clamp on the Bump's height; empty: none")
    filter: EnumProperty(name="Filter", items=FILTERS, default="bilinear")
    wrap: EnumProperty(name="Wrap", items=WRAPS, default="repeat")
    tiling: FloatVectorProperty(name="Tiling", size=2, default=(1.0, 1.0),
                                description="Repetitions of the image per UV unit (u, v)")
    offset: FloatVectorProperty(
        name="Offset", size=2, default=(0.0, 0.0),
        description="Added to the lookup after tiling, in image units: the image is read at "
                    "tiling x (u, v) + offset (projections: of the plane coordinates)")
    uv_map: StringProperty(name="UV Map",
                           description="UV map the image is on; empty: the UV map active for "
                                       "rendering, which Cycles reads textures on")
    space: EnumProperty(name="Space", items=SPACES, default="tangent")
    tangent_uv_map: StringProperty(
        name="Tangent UV Map",
        description="Tangent-space normal layers (and Box-projected ones): the UV map whose "
                    "tangents decode the map (the Normal Map node's UV Map); empty: the layer's "
                    "UV Map (a projection's: the UV map active for rendering)")
    green: EnumProperty(name="Green", items=GREENS, default="opengl",
                        description="Green channel convention of the normal map image")
    kind: EnumProperty(name="Kind", items=KINDS, default="height",
                       description="What the projected image holds")
    axis: EnumProperty(name="Axis", items=AXES, default="z")
    mapping_type: EnumProperty(
        name="Type", items=MAPPING_TYPES, default="POINT",
        description="Projections and volumes: the Mapping node's type (how Location, Rotation and Scale "
                    "move the object coordinates)")
    mapping_location: FloatVectorProperty(
        name="Location", size=3, default=(0.0, 0.0, 0.0), subtype="TRANSLATION",
        description="Projections and volumes: a Mapping node's Location, added to the object coordinates "
                    "after its Rotation and Scale")
    mapping_rotation: FloatVectorProperty(
        name="Rotation", size=3, default=(0.0, 0.0, 0.0), subtype="EULER",
        description="Projections and volumes: a Mapping node's Rotation (XYZ Euler) of the object "
                    "coordinates")
    mapping_scale: FloatVectorProperty(
        name="Scale", size=3, default=(1.0, 1.0, 1.0), subtype="XYZ",
        description="Projections and volumes: a Mapping node's Scale of the object "
                    "coordinates")
    mapping_matrix: FloatVectorProperty(
        name="Coordinates", size=12, default=(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0,
                                              0.0, 0.0, 1.0, 0.0),
        description="Projections and volumes: the coordinates read, as an affine map of the object's own "
                    "(3 rows of 4, before the Mapping; set at every bake from Coordinates "
                    "Object or Generated Coordinates when one is given)")
    planar_projection: EnumProperty(name="Projection", items=PLANAR_PROJECTIONS, default="axis",
                                    description="How a planar layer projects its image")
    coordinates_object: PointerProperty(
        name="Coordinates Object", type=bpy.types.Object,
        description="Projections and volumes: the object whose coordinates are read (a Texture Coordinate "
                    "node's Object output naming it); Coordinates follow it at every bake")
    coordinates_generated: BoolProperty(
        name="Generated Coordinates", default=False,
        description="Projections and volumes: the baked object's Generated coordinates (its "
                    "texture space to [0, 1], what Cycles reads a procedural texture on "
                    "when its Vector is unlinked); Coordinates follow them at every bake")
    coordinates_world: BoolProperty(
        name="World Coordinates", default=False,
        description="Projections and volumes: the world positions (a Geometry node's Position): "
                    "Coordinates follow the object's placement at every bake")
    coordinates_uv: BoolProperty(
        name="UV Coordinates", default=False,
        description="Volumes: read at (u, v, 0) of the layer's UV map (the render UV map when "
                    "empty), as a procedural texture on a Texture Coordinate node's UV output "
                    "or a UV Map node, instead of at the object's coordinates")
    projection: EnumProperty(name="Projection", items=PROJECTIONS, default="blended",
                             description="How a triplanar layer lays out and blends its planes")
    box_blend: FloatProperty(name="Blend", default=0.0, min=0.0, max=1.0, subtype="FACTOR",
                             description="Box projection: the Image Texture node's Blend, the "
                                         "width of the seams where the planes mix")
    sharpness: FloatProperty(name="Sharpness", default=4.0, min=0.0,
                             description="Exponent of the triplanar blend weights")
    min_weight: FloatProperty(name="Minimum Weight", default=0.001, min=0.0, precision=4,
                              description="Triplanar blend weights below this are dropped "
                                          "(their plane is not sampled)")
    function: EnumProperty(name="Function", items=FUNCTIONS, default="sine")
    amplitude: FloatProperty(name="Amplitude", default=1.0, precision=4,
                             description="Height amplitude, world units (as a Bump node's "
                                         "Distance)")
    frequency: FloatProperty(name="Frequency", default=1.0, precision=4,
                             description="Cycles (sine) or noise features per object unit; "
                                         "Blender Noise, Musgrave, Wave and Voronoi: the "
                                         "texture node's Scale (Blender's default 5)")
    direction: FloatVectorProperty(name="Direction", size=3, default=(1.0, 0.0, 0.0),
                                   description="Direction of the sine wave, object space")
    phase: FloatProperty(name="Phase", default=0.0, subtype="ANGLE",
                         description="Sine: the wave's phase; Blender Wave: the Wave "
                                     "Texture's Phase Offset (radians in the node, shown here "
                                     "in degrees: 0.7 is 40.1 degrees)")
    seed: IntProperty(name="Seed", default=0, min=0)
    octaves: IntProperty(name="Octaves", default=1, min=1, max=16)
    # The Noise, Musgrave, Wave and Voronoi Textures' settings (Blender's defaults and the
    # nodes' ranges).
    wave: EnumProperty(name="Wave Type", items=WAVE_TYPES, default="bands",
                       description="Blender Wave: the Wave Texture's type")
    wave_direction: EnumProperty(
        name="Direction", items=_wave_directions, default=0,
        description="Blender Wave: the Wave Texture's Bands or Rings Direction (the fourth, "
                    "Diagonal for Bands, is Spherical for Rings)")
    profile: EnumProperty(name="Wave Profile", items=WAVE_PROFILES, default="sine",
                          description="Blender Wave: the Wave Texture's profile")
    texture_dimensions: EnumProperty(
        name="Dimensions", items=TEXTURE_DIMENSIONS, default="3D",
        description="Blender Noise and Musgrave: the texture's Dimensions (1D reads W alone: "
                    "one value over the surface; 2D the object's x and y; 4D x, y, z and W)")
    w: FloatProperty(name="W", default=0.0, precision=3,
                     description="Blender Noise and Musgrave: the texture's W (1D and 4D), "
                                 "scaled by its Scale as the coordinates are")
    detail: FloatProperty(name="Detail", default=2.0, min=0.0, max=15.0, precision=3,
                          description="Blender Noise, Musgrave and Wave: the texture node's "
                                      "Detail (Noise and Wave: octaves beyond the first; "
                                      "Musgrave: octaves; a fraction blends one more in)")
    roughness: FloatProperty(name="Roughness", default=0.5, min=0.0, max=1.0, subtype="FACTOR",
                             description="Blender Noise: the Noise Texture's Roughness (each "
                                         "octave's weight relative to the one before)")
    distortion: FloatProperty(name="Distortion", default=0.0, precision=3,
                              description="Blender Noise: the Noise Texture's Distortion (the "
                                          "point moved by three other noises first); Blender "
                                          "Wave: the Wave Texture's (the wave moved by a "
                                          "noise)")
    # (Its own property: the Magic Texture's Distortion starts at 1, the others' at 0.)
    magic_distortion: FloatProperty(name="Distortion", default=1.0, precision=3,
                                    description="Blender Magic: the Magic Texture's Distortion")
    detail_scale: FloatProperty(name="Detail Scale", default=1.0, precision=3,
                                description="Blender Wave: the Wave Texture's Detail Scale (the "
                                            "distorting noise's frequency relative to Scale)")
    detail_roughness: FloatProperty(
        name="Detail Roughness", default=0.5, min=0.0, max=1.0, subtype="FACTOR",
        description="Blender Wave: the Wave Texture's Detail Roughness (each octave of the "
                    "distorting noise's weight relative to the one before)")
    dimension: FloatProperty(name="Dimension", default=2.0, min=0.0, max=1000.0, precision=3,
                             description="Blender Musgrave: the Musgrave Texture's Dimension "
                                         "(each octave's weight is Lacunarity^-Dimension times "
                                         "the one before)")
    lacunarity: FloatProperty(name="Lacunarity", default=2.0, min=0.0, max=1000.0,
                              precision=3,
                              description="Blender Musgrave: the Musgrave Texture's Lacunarity "
                                          "(each octave's frequency relative to the one "
                                          "before)")
    musgrave_type: EnumProperty(name="Musgrave Type", items=MUSGRAVE_TYPES, default="fbm",
                                description="Blender Musgrave: the Musgrave Texture's type")
    # (Not "offset": an image layer's UV offset holds that name; the scene's key is "offset".)
    musgrave_offset: FloatProperty(name="Offset", default=0.0, min=-1000.0, max=1000.0,
                                   precision=3,
                                   description="Blender Musgrave: the Musgrave Texture's Offset "
                                               "(Ridged, Hybrid Multifractal and Hetero "
                                               "Terrain)")
    gain: FloatProperty(name="Gain", default=1.0, min=0.0, max=1000.0, precision=3,
                        description="Blender Musgrave: the Musgrave Texture's Gain (Ridged and "
                                    "Hybrid Multifractal)")
    feature: EnumProperty(name="Feature Output", items=VORONOI_FEATURES, default="f1",
                          description="Blender Voronoi: the Voronoi Texture's Feature Output "
                                      "(its Distance is the height)")
    smoothness: FloatProperty(name="Smoothness", default=1.0, min=0.0, max=1.0,
                              subtype="FACTOR",
                              description="Blender Voronoi: the Voronoi Texture's Smoothness "
                                          "(Smooth F1)")
    metric: EnumProperty(name="Distance Metric", items=METRICS, default="euclidean",
                         description="Blender Voronoi: the Voronoi Texture's Distance Metric")
    randomness: FloatProperty(name="Randomness", default=1.0, min=0.0, max=1.0,
                              subtype="FACTOR",
                              description="Blender Voronoi: the Voronoi Texture's Randomness "
                                          "(0: each cell's point at its centre)")
    exponent: FloatProperty(name="Exponent", default=0.5, min=0.0, precision=3,
                            description="Blender Voronoi: the Voronoi Texture's Exponent (of "
                                        "the Minkowski metric; the others ignore it)")
    gradient_type: EnumProperty(name="Gradient Type", items=GRADIENT_TYPES, default="linear",
                                description="Blender Gradient: the Gradient Texture's type (its "
                                            "Fac clamped to [0, 1] as Cycles clamps it)")
    depth: IntProperty(name="Depth", default=2, min=0, max=10,
                       description="Blender Magic: the Magic Texture's Depth (its steps)")
    mortar_size: FloatProperty(name="Mortar Size", default=0.02, min=0.0, max=0.125,
                               precision=3, description="Blender Brick: the Brick Texture's "
                                                        "Mortar Size")
    mortar_smooth: FloatProperty(name="Mortar Smooth", default=0.1, min=0.0, max=1.0,
                                 subtype="FACTOR", description="Blender Brick: the Brick "
                                                               "Texture's Mortar Smooth")
    brick_width: FloatProperty(name="Brick Width", default=0.5, min=0.01, max=100.0,
                               precision=3,
                               description="Blender Brick: the Brick Texture's Brick Width")
    row_height: FloatProperty(name="Row Height", default=0.25, min=0.01, max=100.0,
                              precision=3,
                              description="Blender Brick: the Brick Texture's Row Height")
    brick_offset: FloatProperty(name="Offset", default=0.5, min=0.0, max=1.0, subtype="FACTOR",
                                description="Blender Brick: the Brick Texture's Offset of every "
                                            "Offset Frequency-th row, in brick widths")
    offset_frequency: IntProperty(name="Offset Frequency", default=2, min=1, max=99,
                                  description="Blender Brick: the Brick Texture's Offset "
                                              "Frequency")
    squash: FloatProperty(name="Squash", default=1.0, min=0.0, max=99.0, precision=3,
                          description="Blender Brick: the Brick Texture's Squash, the brick "
                                      "width factor of every Squash Frequency-th row")
    squash_frequency: IntProperty(name="Squash Frequency", default=2, min=1, max=99,
                                  description="Blender Brick: the Brick Texture's Squash "
                                              "Frequency")
    gradient: EnumProperty(name="Gradient", items=GRADIENTS, default="analytic",
                           description="How the volume's gradient is computed")
    step: FloatProperty(
        name="Step", default=0.0, min=0.0, precision=6, step=0.01,
        description="Finite-difference step of the Central and Tetrahedral gradients, object "
                    "units; 0: libsgbake's default (2^-20 of the mesh's bounding-box diagonal)")
    mask_image: PointerProperty(
        name="Mask", type=bpy.types.Image,
        description="Optional mask image: the layer's bump is scaled by its value (luminance, "
                    "clamped to 0..1); empty: no mask")
    mask_uv_map: StringProperty(
        name="Mask UV Map",
        description="UV map the mask is on; empty: the layer's UV map (height and normal "
                    "layers), else the bake's")
    mask_tiling: FloatVectorProperty(name="Mask Tiling", size=2, default=(1.0, 1.0),
                                     description="Repetitions of the mask per UV unit (u, v)")
    mask_offset: FloatVectorProperty(
        name="Mask Offset", size=2, default=(0.0, 0.0),
        description="Added to the mask's lookup after tiling: tiling x (u, v) + offset")
    mask_filter: EnumProperty(name="Mask Filter", items=FILTERS, default="bilinear")


class SgbakeSettings(bpy.types.PropertyGroup):
    """What to bake (scene.sgbake)."""
    map: EnumProperty(name="Map", items=scene.MAPS, default="tangent-normal")
    surface: EnumProperty(name="Surface", items=scene.SURFACES, default="mesh",
                          description="The surface the texels are baked on")
    width: IntProperty(name="Width", default=1024, min=1, max=65536, soft_max=16384,
                       subtype="PIXEL")
    height: IntProperty(name="Height", default=1024, min=1, max=65536, soft_max=16384,
                        subtype="PIXEL")
    margin: IntProperty(name="Margin", default=16, min=0, soft_max=64, subtype="PIXEL",
                        description="Texels of padding around the UV islands")
    # Adjacent Faces, as Blender's own bake pads by default (Render > Bake > Margin > Type).
    padding: EnumProperty(name="Padding", items=PADDINGS, default="adjacent-faces")
    samples: IntProperty(name="Samples", default=1, min=1, max=16,
                         description="N x N samples per texel, averaged")
    green: EnumProperty(name="Green", items=GREENS, default="opengl",
                        description="Green channel of the baked tangent-space normal map")
    swizzle_r: EnumProperty(name="R", items=SWIZZLE_AXES, default="POS_X",
                            description="Axis of the normal the red channel stores, as the "
                                        "bake's Swizzle (a DirectX green negates G after it)")
    swizzle_g: EnumProperty(name="G", items=SWIZZLE_AXES, default="POS_Y",
                            description="Axis of the normal the green channel stores, as the "
                                        "bake's Swizzle (a DirectX green negates G after it)")
    swizzle_b: EnumProperty(name="B", items=SWIZZLE_AXES, default="POS_Z",
                            description="Axis of the normal the blue channel stores, as the "
                                        "bake's Swizzle")
    uv_map: StringProperty(
        name="UV Map",
        description="UV map to bake on; empty: the active UV map (Blender's bake default)")
    threads: IntProperty(name="Threads", default=0, min=0,
                         description="Maximum threads; 0 = all cores (same result for any)")
    use_alpha: BoolProperty(name="Alpha from Coverage", default=False,
                            description="Alpha = the texel's coverage by the UV islands; "
                                        "otherwise 1")
    target_image: PointerProperty(
        name="Target", type=bpy.types.Image,
        description="Image to bake into; empty: '<object>_<map>', created as a float image")
    layers: CollectionProperty(type=SgbakeLayer)
    active_layer_index: IntProperty(name="Active Layer", default=0, min=0)


CLASSES = (SgbakeLayer, SgbakeSettings)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Scene.sgbake = PointerProperty(type=SgbakeSettings)


def unregister():
    del bpy.types.Scene.sgbake
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
