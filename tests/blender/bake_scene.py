"""Builds bump-mapped test scenes in Blender and bakes them with Cycles (runs inside Blender).

    blender -b --factory-startup --python-exit-code 1 \\
        --python tests/blender/bake_scene.py -- OUT_DIR [--cases NAME,...] [--size N]
        [--passes object,tangent,mask] [--margin M] [--margin-type EXTEND|ADJACENT_FACES]
        [--height-size H] [--samples S] [--swizzle R,G,B]

Used by bake_oracle.py (the BlenderBakeOracle test) and, as a module, by
bench/bake_vs_cycles.py. For every case it builds one object at the origin (identity
transform, so object space = world space; the stretch_* cases move, turn and scale it, see
TRANSFORMS, and list its matrix_world as "transform"), gives it the material

    Image Texture (height.exr, Non-Color, Linear, Repeat) --Color--> Bump.Height
    Bump (Strength 1, Distance = the case's scale S, not inverted) --Normal--> Diffuse BSDF.Normal
    Add Shader(Diffuse BSDF, Emission(white, strength 1)) --> Material Output.Surface

or, for the normal-map cases (NORMAL_MAPS: the names that start with nmap_),

    Image Texture (normal.exr, Non-Color, Linear, Repeat) --Color--> Normal Map.Color
    Normal Map (space TANGENT or OBJECT, UV map = the mesh's, Strength s) --Normal-->
        Diffuse BSDF.Normal

and bakes with Cycles on the CPU (1 sample, denoising off, margin 0 unless --margin, of
--margin-type, default EXTEND):
  blender_object.exr   NORMAL, normal_space OBJECT,  channels POS_X / POS_Y / POS_Z
  blender_tangent.exr  NORMAL, normal_space TANGENT, channels POS_X / POS_Y / POS_Z
  (--swizzle: the bake's Swizzle instead, e.g. NEG_Z,POS_X,NEG_Y; swizzle_oracle.py)
  blender_mask.exr     EMIT of the white emission: 1 where a triangle covers the texel centre
Texels no triangle covers keep the image's initial (0, 0, 0). Each bake goes into a 32-bit
float Non-Color image whose raw pixels are saved as OpenEXR and checked bit for bit after
reloading. The case directory OUT_DIR/NAME also receives
  mesh.obj    the baked mesh, written by objio.write_obj (every float exact)
  height.exr  the height image, h in R = G = B (see below), A = 1
and OUT_DIR/cases.json lists the cases: name, dir, size, scale, filter, faces, corners,
covered texels, bake seconds per pass, Blender version and Cycles thread count. A normal-map
case writes normal.exr (normal_field or object_normal_field, 512^2, RGB = n / 2 + 0.5, A = 1)
instead of height.exr, has scale 0 and lists "normal_map": {space, strength, tilt_deg}.

What we learnt about Cycles' bake (Blender 3.4.1), checked with a plane and linear/sine heights:
- Bump Distance is exactly sgbake's --height-scale: Cycles computes
  N' = normalize(|det| N - sign(det) Distance surfgrad) with the unnormalised surface gradient,
  i.e. N - Distance * (object-space gradient of h). A linear h = 0.3 u on a 2 x 2 plane baked to
  a tangent-space slope of 0.01498 for Distance 0.1 (analytic 0.015).
- The Height socket takes the image's Color output converted to a float by LUMINANCE
  (0.2127 R + 0.7152 G + 0.0722 B; CYCLES_LUMINANCE): a height in R alone bakes 0.2127x too flat. So the height
  is written into R, G and B (the weights sum to 1); sgbake reads the same value from any channel.
- The bump's finite difference is isotropic and about half a texel long: Blender passes
  half-texel UV differentials to Cycles, which keeps only their mean length and re-derives two
  orthonormal directions in the tangent plane (not u and v). On the plane the effective step
  along u is 0.355 texel (0.5 / sqrt 2). That is the "finite-difference noise" relative to
  sgbake's exact derivative.
- With 1 sample each texel is shaded exactly at its centre (no jitter): two bakes agree to
  2e-5 deg (float rounding between threads). 4 samples jitter inside the texel and move the
  sphere's tangent bake by a median 0.075 deg (p99 0.33 deg).
- The per-texel frame (CONVENTIONS.md) is built on Blender's looptris: quads split on the
  0-2 diagonal (1-3 only for folded quads). A numpy re-implementation with that split
  reproduced Blender's object -> tangent conversion to a median 0.0025 deg; splitting on 1-3
  instead gave a median 0.65 deg, p99 8.3 deg on Suzanne, and using the transpose of
  [T B N] instead of its inverse a median 0.24 deg, p99 3.3 deg: test (a) catches both.
- The shading normal is passed through ensure_valid_reflection(Ng, I = Ng, N): normals more
  than ~44.7 deg from the geometric (flat) normal are bent back. The scales below keep the
  bumps well under that.
- Uncovered texels are left untouched with margin 0 (use_clear=False).
- The Normal Map node (Cycles' svm_node_normal_map) decodes c -> n = 2c - 1 without clamping;
  in tangent space N' = normalize(n.x T + n.y sign (N_i x T) + n.z N_i) with N_i the
  interpolated normal BEFORE it is renormalized (shorter than 1 inside a curved smooth
  triangle), in object space N' = normalize(n); Strength s then gives
  normalize(N + s (N' - N)) (a blend of normals, not a scaled slope), and the result goes
  through ensure_valid_reflection like the Bump node's: on a flat face nothing leans more than
  44.71 deg, which is why the maps tilt up to 60 deg.
"""

import json
import math
import os
import sys
import time

import bpy
import mathutils

sys.dont_write_bytecode = True  # keep __pycache__ out of the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bake_common  # noqa: E402  (needs the sys.path entry above)
import objio  # noqa: E402

RESULT_TAG = "BAKE_SCENE_RESULT "
HEIGHT_SIZE = 512

# name -> (builder, bake size, Bump Distance = sgbake --height-scale)
# Scales chosen so the median bump tilt is ~5-10 deg and the 99th percentile stays < 35 deg.
CASES = {}


# name -> Subdivision Surface levels of a modifier the case keeps live: mesh.obj is then the
# coarse mesh, Cycles bakes the subdivided one, and sgbake is asked to subdivide (--subdivide).
SUBDIVISION = {}


def case(name, size, scale, subdivision=0):
    def register(fn):
        CASES[name] = (fn, size, scale)
        SUBDIVISION[name] = subdivision
        return fn
    return register


# name -> the normal map of a normal-map case: space (TANGENT / OBJECT), Normal Map Strength,
# largest tilt of the map's normals from the surface normal (degrees). Such a case bakes the
# mesh of `mesh_case` with Normal Map node instead of a Bump node (make_normal_material).
NORMAL_MAPS = {}


def normal_map_case(name, mesh_case, size, space, strength, tilt_deg, bump=None):
    """Registers case `name`: the mesh of case `mesh_case`, its material a Normal Map node in
    `space` with `strength`, fed by a normal image whose normals lean up to `tilt_deg` from the
    surface normal (normal_field, or object_normal_field in object space). With `bump` (a
    Distance), a Bump node of that Distance fed by the height image follows it, its Normal
    input linked to the Normal Map node's output (a chain)."""
    CASES[name] = (CASES[mesh_case][0], size, 0.0)
    SUBDIVISION[name] = SUBDIVISION[mesh_case]
    NORMAL_MAPS[name] = {"space": space, "strength": strength, "tilt_deg": tilt_deg}
    if bump is not None:
        NORMAL_MAPS[name]["bump"] = bump


# name -> how a displacement case feeds its height: {"space": "WORLD" | "OBJECT"}, the space of
# a Displacement node (Scale = the case's Distance) into the Material Output's Displacement, the
# material's Displacement method Bump Only, instead of a Bump node: Cycles then bumps the
# surface as a Bump node of Distance 1 fed by the displacement along the normal, (h - 0.5) x
# Scale in world space; in object space the displacement is carried to world space along the
# normal first, so its Scale grows with the object's scale along the normal. The case's
# manifest entry has "displacement": {"space": "world" | "object"}: sgbake's height layer of
# scale Distance with "height_space" that space bakes what Cycles bakes.
DISPLACEMENT = {}


def displacement_case(name, of_case, space, transform=None):
    """Registers case `name`: case `of_case` (mesh, transform, size, Distance) with its Bump node
    replaced by a Displacement node in `space` (DISPLACEMENT), and the object moved, turned and
    scaled by `transform` = (location, rotation, scale) when given."""
    CASES[name] = CASES[of_case]
    SUBDIVISION[name] = SUBDIVISION[of_case]
    if transform is not None:
        TRANSFORMS[name] = transform
    elif of_case in TRANSFORMS:
        TRANSFORMS[name] = TRANSFORMS[of_case]
    DISPLACEMENT[name] = {"space": space}


def bump_by_displacement(mat, space):
    """Replaces `mat`'s Bump node (make_material) by a Displacement node in `space` of the same
    Scale, fed by the same texture, into the Material Output's Displacement; the material's
    Displacement method Bump Only."""
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    bump = next(n for n in nodes if n.bl_idname == "ShaderNodeBump")
    tex = bump.inputs["Height"].links[0].from_node
    node = nodes.new("ShaderNodeDisplacement")
    node.space = space
    node.inputs["Scale"].default_value = bump.inputs["Distance"].default_value
    node.inputs["Midlevel"].default_value = 0.5
    links.new(tex.outputs["Color"], node.inputs["Height"])
    out = next(n for n in nodes if n.bl_idname == "ShaderNodeOutputMaterial")
    links.new(node.outputs["Displacement"], out.inputs["Displacement"])
    nodes.remove(bump)
    mat.cycles.displacement_method = "BUMP"


# name -> a node between the texture and the Bump node's Height that reshapes the height:
# "ramp", a Color Ramp (Ease, coloured stops, rising and falling) whose Color feeds the Height;
# "clamp", a Math node computing 2.5 h - 0.6 with Clamp. Cycles reads a Color Ramp from a table of
# 256 entries, ramp(i / 255), linearly between them, the value clamped to [0, 1]; a Color into a
# float socket becomes its luminance. The manifest entry has "remap": the points of that
# function, sgbake's height layer's "remap".
REMAPS = {}
RAMP_STOPS = ((0.15, (0.05, 0.02, 0.0)), (0.45, (0.9, 0.8, 0.3)), (0.7, (0.2, 0.5, 0.9)),
              (0.9, (0.6, 0.6, 0.6)))
CLAMP_LINE = (2.5, -0.6)  # Math Multiply Add: h x 2.5 - 0.6, clamped to [0, 1]
# Cycles' luminance of a colour in a float socket (rgb_to_y), measured with an Emission bake of
# pure R, G and B through a Math node (the config's rounded 0.2126, 0.7152, 0.0722: ramp_sphere's
# p99 0.0051 deg instead of 0.0026 deg).
CYCLES_LUMINANCE = (0.212672979, 0.715152621, 0.072175443)


def remap_case(name, of_case, kind, size=None):
    """Registers case `name`: case `of_case` (or baked at `size`) with a `kind` node (REMAPS)
    before its Bump."""
    builder, case_size, distance = CASES[of_case]
    CASES[name] = (builder, size or case_size, distance)
    SUBDIVISION[name] = SUBDIVISION[of_case]
    if of_case in TRANSFORMS:
        TRANSFORMS[name] = TRANSFORMS[of_case]
    REMAPS[name] = kind


def reshape_height(mat, kind):
    """Puts a `kind` node (REMAPS) between `mat`'s texture and its Bump node; returns the points
    of the function it applies to the texture's value."""
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    bump = next(n for n in nodes if n.bl_idname == "ShaderNodeBump")
    tex = bump.inputs["Height"].links[0].from_node
    if kind == "ramp":
        node = nodes.new("ShaderNodeValToRGB")
        ramp = node.color_ramp
        ramp.interpolation = "EASE"
        while len(ramp.elements) < len(RAMP_STOPS):
            ramp.elements.new(0.5)
        for element, (position, rgb) in zip(ramp.elements, RAMP_STOPS):
            element.position, element.color = position, (*rgb, 1.0)
        links.new(tex.outputs["Color"], node.inputs["Fac"])
        links.new(node.outputs["Color"], bump.inputs["Height"])
        table = [ramp.evaluate(i / 255) for i in range(256)]
        return [[i / 255, sum(w * v for w, v in zip(CYCLES_LUMINANCE, c[:3]))]
                for i, c in enumerate(table)]
    node = nodes.new("ShaderNodeMath")
    node.operation, node.use_clamp = "MULTIPLY_ADD", True
    node.inputs[1].default_value, node.inputs[2].default_value = CLAMP_LINE
    links.new(tex.outputs["Color"], node.inputs[0])
    links.new(node.outputs["Value"], bump.inputs["Height"])
    a, b = CLAMP_LINE
    return [[-b / a, 0.0], [(1 - b) / a, 1.0]]


# name -> a Noise Texture (3D) feeding the Bump node instead of the image, read at the object's
# coordinates (Texture Coordinate Object) through a Mapping node (Point): {"scale", "detail",
# "roughness", "distortion", "mapping": (location, rotation, scale)}; or with "kind":
# "musgrave" a Musgrave Texture (3D; its "musgrave_type", Blender's name, FBM unless given) of
# {"scale", "detail", "dimension", "lacunarity", "mapping"} and "offset", "gain" where given, with "kind": "wave" a Wave Texture of {"wave", "direction", "profile" (Blender's
# names), "scale", "distortion", "detail", "detail_scale", "detail_roughness", "phase",
# "mapping"}, with "kind": "voronoi" a Voronoi Texture (3D, its Distance; its "feature",
# Blender's name, F1 unless given) of {"scale", "randomness", "metric" (Blender's name),
# "exponent", "mapping"} and "smoothness" where given. The manifest entry has
# "noise": these settings, sgbake's "blender-noise" (or "blender-musgrave", "blender-wave",
# "blender-voronoi") volume layer with that "mapping". With "coordinates": "UV" the texture reads
# the Texture Coordinate node's UV output instead, and the layer has "coordinates": "uv".
NOISE = {}


def noise_case(name, of_case, size, distance, **settings):
    """Registers case `name`: the mesh (and transform) of case `of_case` at `size`, its Bump
    (Distance `distance`) fed by a Noise Texture of `settings` (NOISE)."""
    builder = CASES[of_case][0]
    CASES[name] = (builder, size, distance)
    SUBDIVISION[name] = SUBDIVISION[of_case]
    if of_case in TRANSFORMS:
        TRANSFORMS[name] = TRANSFORMS[of_case]
    NOISE[name] = settings


def bump_by_noise(mat, settings):
    """Replaces the texture feeding `mat`'s Bump node by a Noise Texture of `settings` (NOISE) on
    object coordinates (or the Texture Coordinate node's output settings["coordinates"], "UV")
    through a Mapping node."""
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    bump = next(n for n in nodes if n.bl_idname == "ShaderNodeBump")
    coordinates = nodes.new("ShaderNodeTexCoord")
    mapping = nodes.new("ShaderNodeMapping")
    mapping.vector_type = "POINT"
    for socket, value in zip(("Location", "Rotation", "Scale"), settings["mapping"]):
        mapping.inputs[socket].default_value = value
    if settings.get("kind") == "musgrave":
        noise = nodes.new("ShaderNodeTexMusgrave")
        noise.musgrave_dimensions = "3D"
        noise.musgrave_type = settings.get("musgrave_type", "FBM")
        inputs = ("Scale", "Detail", "Dimension", "Lacunarity") + tuple(
            socket for socket in ("Offset", "Gain") if socket.lower() in settings)
    elif settings.get("kind") == "voronoi":
        noise = nodes.new("ShaderNodeTexVoronoi")
        noise.voronoi_dimensions, noise.feature = "3D", settings.get("feature", "F1")
        noise.distance = settings["metric"]
        inputs = ("Scale", "Randomness", "Exponent") + (
            ("Smoothness",) if "smoothness" in settings else ())
    elif settings.get("kind") == "brick":
        noise = nodes.new("ShaderNodeTexBrick")
        noise.offset, noise.offset_frequency = settings["brick_offset"], settings["offset_frequency"]
        noise.squash, noise.squash_frequency = settings["squash"], settings["squash_frequency"]
        inputs = ("Scale", "Mortar Size", "Mortar Smooth", "Brick Width", "Row Height")
    elif settings.get("kind") == "gradient":
        noise = nodes.new("ShaderNodeTexGradient")
        noise.gradient_type = settings["gradient_type"]
        inputs = ()
    elif settings.get("kind") == "magic":
        noise = nodes.new("ShaderNodeTexMagic")
        noise.turbulence_depth = settings["depth"]
        inputs = ("Scale", "Distortion")
    elif settings.get("kind") == "wave":
        noise = nodes.new("ShaderNodeTexWave")
        noise.wave_type, noise.wave_profile = settings["wave"], settings["profile"]
        if settings["wave"] == "BANDS":
            noise.bands_direction = settings["direction"]
        else:
            noise.rings_direction = settings["direction"]
        inputs = ("Scale", "Distortion", "Detail", "Detail Scale", "Detail Roughness",
                  "Phase Offset")
    else:
        noise = nodes.new("ShaderNodeTexNoise")
        noise.noise_dimensions = settings.get("dimensions", "3D")
        inputs = ("Scale", "Detail", "Roughness", "Distortion") + (
            ("W",) if "w" in settings else ())
    for socket in inputs:
        key = "phase" if socket == "Phase Offset" else socket.lower().replace(" ", "_")
        noise.inputs[socket].default_value = settings[key]
    links.new(coordinates.outputs[settings.get("coordinates", "Object")], mapping.inputs["Vector"])
    links.new(mapping.outputs["Vector"], noise.inputs["Vector"])
    output = "Distance" if settings.get("kind") == "voronoi" else "Fac"
    links.new(noise.outputs[output], bump.inputs["Height"])


# name -> the object transform of a case (location, XYZ Euler rotation in radians, scale):
# mesh.obj stays in object space, Cycles shades the object in world space, and sgbake is given
# the object's matrix_world ("transform" in the JSON scene). Cases not listed sit at the origin
# with the identity transform.
TRANSFORMS = {}


def transformed_case(name, of_case, location, rotation, scale, size=None):
    """Registers case `name`: case `of_case` (its mesh, material and bake size, or `size`) with
    the object moved, turned and scaled by (location, rotation, scale)."""
    builder, case_size, distance = CASES[of_case]
    CASES[name] = (builder, size or case_size, distance)
    SUBDIVISION[name] = SUBDIVISION[of_case]
    if of_case in NORMAL_MAPS:
        NORMAL_MAPS[name] = dict(NORMAL_MAPS[of_case])
    TRANSFORMS[name] = (location, rotation, scale)


# name -> how a projected case reads its height: the mesh of another case whose Bump reads its
# height through Texture Coordinate Object into an Image Texture, not through a UV map (a height
# read at a position). {"projection": "FLAT"}: the image at the object's (x, y), sgbake's
# "planar" height layer on axis z. {"projection": "BOX", "blend": b}: Blender's Box projection
# with Blend b, sgbake's "triplanar" layer with "projection": "box". "SPHERE", "TUBE": the image
# wrapped around z, sgbake's "planar" layer with "projection": "sphere" or "tube".
PLANAR = {}


def planar_case(name, mesh_case, size, scale, projection="FLAT", blend=0.0, mapping=None,
                coordinates=None, strength=1.0):
    """Registers case `name`: the mesh (and transform) of case `mesh_case`, its Bump (Distance
    `scale`) fed by the height image projected onto object coordinates (`projection`), moved
    first by a Mapping node (Point) when `mapping` = (location, rotation, scale). `coordinates`:
    ("EMPTY", (location, rotation, scale)), the Object coordinates of an Empty placed so, or
    ("GENERATED",), the Generated ones, instead of the object's own. `strength`: the Bump
    node's Strength."""
    CASES[name] = (CASES[mesh_case][0], size, scale)
    SUBDIVISION[name] = SUBDIVISION[mesh_case]
    if mesh_case in TRANSFORMS:
        TRANSFORMS[name] = TRANSFORMS[mesh_case]
    PLANAR[name] = {"projection": projection, "blend": blend}
    if strength != 1.0:
        PLANAR[name]["strength"] = strength
    if mapping is not None:
        PLANAR[name]["mapping"] = {"location": list(mapping[0]), "rotation": list(mapping[1]),
                                   "scale": list(mapping[2])}
    if coordinates is not None:
        PLANAR[name]["coordinates"] = coordinates


def projected_normal_map_case(name, mesh_case, size, space, strength, tilt_deg,
                              projection="BOX", blend=0.0, mapping=None):
    """Registers case `name`: normal_map_case's, its Image Texture read with `projection`
    (Box with Blend `blend`: sgbake's triplanar layer with "projection": "box"; Flat, Sphere,
    Tube: its planar layer with that "projection") on the object's coordinates instead of its UV
    map, moved first by a Mapping node (Point) when `mapping` = (location, rotation, scale), of
    kind tangent-normal or object-normal. Its image is normal_field in either space: as
    object-space normals they lean up to `tilt_deg` from +z."""
    normal_map_case(name, mesh_case, size, space, strength, tilt_deg)
    if mesh_case in TRANSFORMS:
        TRANSFORMS[name] = TRANSFORMS[mesh_case]
    PLANAR[name] = {"projection": projection, "blend": blend}
    if mapping is not None:
        PLANAR[name]["mapping"] = {"location": list(mapping[0]), "rotation": list(mapping[1]),
                                   "scale": list(mapping[2])}


def apply_subdivision(ob, levels):
    mod = ob.modifiers.new("Subdivision", "SUBSURF")
    mod.levels = levels
    mod.render_levels = levels
    bpy.ops.object.modifier_apply(modifier=mod.name)


@case("suzanne", 512, 0.1)
def build_suzanne():
    """Suzanne with its UVs (two mirrored halves: both bitangent signs), Subdivision Surface
    level 1 applied, smooth: 1,968 quads."""
    bpy.ops.mesh.primitive_monkey_add(calc_uvs=True)
    ob = bpy.context.object
    apply_subdivision(ob, 1)
    bake_common.set_smooth(ob, True)
    return ob


@case("suzanne_live", 512, 0.1, subdivision=1)
def build_suzanne_live():
    """Suzanne, smooth, with a live Subdivision Surface modifier at level 1 and a new modifier's
    settings (UV Smooth Keep Boundaries, Boundary Smooth All, Use Limit Surface, Quality 3):
    mesh.obj is the coarse Suzanne (500 faces, triangles among them), sgbake subdivides it."""
    bpy.ops.mesh.primitive_monkey_add(calc_uvs=True)
    ob = bpy.context.object
    bake_common.set_smooth(ob, True)
    mod = ob.modifiers.new("Subdivision", "SUBSURF")
    mod.levels = SUBDIVISION["suzanne_live"]
    mod.render_levels = SUBDIVISION["suzanne_live"]
    return ob


@case("suzanne2", 4096, 0.1)
def build_suzanne2():
    """meshes/suzanne.obj's recipe (meshes/make_meshes.py): Suzanne, Subdivision Surface level
    2 applied, smooth: 7,872 quads. The benchmark's mesh; not part of the test."""
    bpy.ops.mesh.primitive_monkey_add(calc_uvs=True)
    ob = bpy.context.object
    apply_subdivision(ob, 2)
    bake_common.set_smooth(ob, True)
    return ob


@case("sphere", 256, 0.1)
def build_sphere():
    """UV sphere (32 segments, 16 rings, radius 1), smooth: triangle fans at the poles, a UV
    seam, tangents that degenerate towards the poles."""
    bpy.ops.mesh.primitive_uv_sphere_add(segments=32, ring_count=16, radius=1.0, calc_uvs=True)
    ob = bpy.context.object
    bake_common.set_smooth(ob, True)
    return ob


@case("suzanne_flat", 256, 0.1)
def build_suzanne_flat():
    """Suzanne as the primitive makes it (500 faces, quads and triangles), FLAT shading: its
    quads are not planar, and Blender shades each of their two triangles with its own normal."""
    bpy.ops.mesh.primitive_monkey_add(calc_uvs=True)
    ob = bpy.context.object
    bake_common.set_smooth(ob, False)
    return ob


@case("cylinder_twist", 256, 0.1)
def build_cylinder_twist():
    """A 12-sided cylinder with n-gon caps, twisted and with caps made non-planar, smooth: its
    12-gons are cut into triangles the way Blender's loop triangles cut them, and a different
    cut bakes visibly different normals (28 % of texels more than 1 deg off before sgbake
    reproduced Blender's)."""
    import math
    bpy.ops.mesh.primitive_cylinder_add(vertices=12, end_fill_type="NGON", calc_uvs=True)
    ob = bpy.context.object
    for v in ob.data.vertices:
        a, x, y = 0.6 * v.co.z, v.co.x, v.co.y
        v.co.x = x * math.cos(a) - y * math.sin(a)
        v.co.y = x * math.sin(a) + y * math.cos(a)
        v.co.z += 0.25 * math.sin(2 * math.atan2(y, x))
    bake_common.set_smooth(ob, True)
    return ob


@case("sphere_backfacing", 256, 0.1)
def build_sphere_backfacing():
    """The UV sphere of case sphere with custom normals leaning north by up to
    BACKFACING_LEAN_DEG, the lean a function of longitude (sin^2 2*lon): in two bands its
    interpolated normals face away from their triangles (N . Ng < 0), where Cycles shades the
    point from behind (gradient_detail::backFacingNormal)."""
    from mathutils import Vector
    bpy.ops.mesh.primitive_uv_sphere_add(segments=32, ring_count=16, radius=1.0, calc_uvs=True)
    ob = bpy.context.object
    bake_common.set_smooth(ob, True)
    me = ob.data
    me.use_auto_smooth = True
    me.auto_smooth_angle = math.pi
    normals = []
    for v in me.vertices:
        p = v.co.normalized()
        north = Vector((-p.x * p.z, -p.y * p.z, 1.0 - p.z * p.z))
        if north.length < 1e-6:  # a pole: no north, keep the sphere's normal
            normals.append(p)
            continue
        north.normalize()
        lean = math.radians(BACKFACING_LEAN_DEG) * math.sin(2 * math.atan2(p.y, p.x)) ** 2
        normals.append(math.cos(lean) * p + math.sin(lean) * north)
    me.normals_split_custom_set_from_vertices(normals)
    return ob


BACKFACING_LEAN_DEG = 110.0


@case("cube_flat", 512, 0.25)
def build_cube_flat():
    """Default cube (size 2) with its cross-shaped UV layout, FLAT shading: the per-texel frame
    uses the face normal, and neighbouring faces in one UV island have different normals."""
    bpy.ops.mesh.primitive_cube_add(size=2.0, calc_uvs=True)
    ob = bpy.context.object
    bake_common.set_smooth(ob, False)
    return ob


# The normal-map cases (bake_oracle.py checks them with sgbake bake --normal). Tilts up to 60 deg
# so that Cycles' valid-reflection guard bends a good part of them (> 44.71 deg on the cube's
# flat faces); Strength 0.5 and 2 (40 deg map: up to 67 deg after the blend) for the node's
# blend of normals; one object-space map. 256^2 bakes: ~1 s each in Cycles.
normal_map_case("nmap_sphere", "sphere", 256, "TANGENT", 1.0, 60.0)
normal_map_case("nmap_sphere_s05", "sphere", 256, "TANGENT", 0.5, 60.0)
normal_map_case("nmap_sphere_s2", "sphere", 256, "TANGENT", 2.0, 40.0)
normal_map_case("nmap_sphere_object", "sphere", 256, "OBJECT", 1.0, 60.0)
normal_map_case("nmap_cube", "cube_flat", 256, "TANGENT", 1.0, 60.0)
normal_map_case("nmap_cube_s2", "cube_flat", 256, "TANGENT", 2.0, 40.0)
# Suzanne's quads (UVs no parallelograms): Cycles' Normal Map node decodes in MikkTSpace of its
# triangulated mesh, which the polygon mesh's frames miss by a median 0.32 deg here.
normal_map_case("nmap_suzanne", "suzanne", 256, "TANGENT", 1.0, 40.0)
# Flat Suzanne: Cycles' MikkTSpace runs on its own split of the quads it cuts on the other
# diagonal, and welds a flat quad's triangles where their float normals are equal.
normal_map_case("nmap_suzanne_flat", "suzanne_flat", 256, "TANGENT", 1.0, 40.0)
normal_map_case("nmap_sphere_backfacing", "sphere_backfacing", 256, "TANGENT", 1.0, 40.0)
# Tilts up to 150 deg: a third of the texels (z < 0) decode below the surface, 7 % so far
# below (past 135 deg) that Cycles' guard passes them as they are.
normal_map_case("nmap_sphere_steep", "sphere", 256, "TANGENT", 1.0, 150.0)
# A Bump node on the normal map's output (its Normal input linked): sgbake's "base": "above".
normal_map_case("chain_sphere", "sphere", 512, "TANGENT", 1.0, 40.0, bump=0.1)
normal_map_case("chain_suzanne", "suzanne", 512, "TANGENT", 1.0, 40.0, bump=0.1)
# Unevenly scaled objects (a cube scaled without Apply Scale is the everyday example): Cycles
# bumps in world space (Distance in world units), decodes normal maps in object space and
# carries them to world space as normals, guards in world space, and the baker brings the
# result back to object space. The stretched sphere bakes at 512^2: its bump's finite
# difference spans more of the height image where the object is squeezed (0.91 deg median
# at 256^2, 0.18 at 1024^2).
transformed_case("stretch_sphere", "sphere", (0.5, -1.0, 2.0), (0.4, 0.2, 0.7), (2.0, 1.0, 0.5),
                 size=512)
transformed_case("stretch_nmap_sphere", "nmap_sphere", (0.5, -1.0, 2.0), (0.4, 0.2, 0.7),
                 (2.0, 1.0, 0.5))
transformed_case("stretch_nmap_sphere_object", "nmap_sphere_object", (0.5, -1.0, 2.0),
                 (0.4, 0.2, 0.7), (2.0, 1.0, 0.5))
transformed_case("stretch_chain_suzanne", "chain_suzanne", (0.0, 0.0, 0.0), (0.0, 0.0, 0.3),
                 (0.6, 1.5, 1.0))
transformed_case("stretch_cube", "cube_flat", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (3.0, 1.0, 0.4))
# Back-facing texels of a stretched object: whether N faces away from Ng is decided in world
# space, where the scale changes both.
transformed_case("stretch_sphere_backfacing", "sphere_backfacing", (0.5, -1.0, 2.0),
                 (0.4, 0.2, 0.7), (2.0, 1.0, 0.5), size=512)
transformed_case("stretch_nmap_sphere_backfacing", "nmap_sphere_backfacing", (0.5, -1.0, 2.0),
                 (0.4, 0.2, 0.7), (2.0, 1.0, 0.5))
# The height projected onto the object's (x, y): one texture unit per object unit, so a
# steeper field than on the sphere's UVs (2 pi units around) and a smaller Distance.
planar_case("planar_sphere", "sphere", 256, 0.02)
planar_case("planar_sphere_backfacing", "sphere_backfacing", 256, 0.02)
# Blender's Box projection, Blend 0.3: every zone of its weights (one plane, two, three) and
# every side's mirror on the sphere; from behind, the mirrors of the sides seen; on the
# stretched sphere, in world space (the weights and mirrors still from the object's normal).
planar_case("box_sphere", "sphere", 256, 0.02, "BOX", 0.3)
planar_case("box_sphere_backfacing", "sphere_backfacing", 256, 0.02, "BOX", 0.3)
planar_case("box_stretch_sphere", "stretch_sphere", 512, 0.02, "BOX", 0.3)
# A Mapping node between the coordinates and the Box projection: moved, turned, unevenly scaled.
planar_case("box_mapped_sphere", "sphere", 256, 0.02, "BOX", 0.3,
            ((0.3, -0.2, 0.1), (0.4, 0.2, 0.7), (1.5, 0.8, 1.2)))
# Coordinates other than the object's own, into the Box projection: an Empty's (the stretched
# sphere read in the frame of an Empty moved, turned and scaled), and the Generated ones (the
# texture space, the bounding box to [0, 1]), after a Mapping node's scale. Both read the image
# more densely than the others, so half their Distance keeps exact slopes within (b)'s bar at
# 256^2.
planar_case("box_empty_sphere", "stretch_sphere", 256, 0.01, "BOX", 0.3,
            coordinates=("EMPTY", ((0.2, 0.4, -0.3), (0.3, -0.5, 0.2), (0.7, 1.3, 0.9))))
planar_case("box_generated_sphere", "sphere", 256, 0.01, "BOX", 0.3,
            ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (3.0, 2.0, 2.5)), coordinates=("GENERATED",))
# Normal maps read by the Box projection (Blend 0.3) into a Normal Map node: decoded in the UV
# map's tangent frames, and in object space (Strength 0.3, so that normals leaning from +z stay
# above the sphere's lower half).
# A Bump Strength of 0.4 on the Box-projected height (the bumped normal blended with N).
planar_case("box_strength_sphere", "sphere", 256, 0.02, "BOX", 0.3, strength=0.4)
projected_normal_map_case("box_nmap_sphere", "sphere", 256, "TANGENT", 1.0, 40.0, "BOX", 0.3)
projected_normal_map_case("box_nmap_sphere_object", "sphere", 256, "OBJECT", 0.3, 40.0, "BOX",
                          0.3)
# The same tangent-space map read with Flat projection (the image at the object's (x, y)).
projected_normal_map_case("flat_nmap_sphere", "sphere", 256, "TANGENT", 1.0, 40.0, "FLAT")
# On the sphere stretched (2, 1, 0.5) and turned, in world space.
projected_normal_map_case("box_nmap_stretch_sphere", "stretch_sphere", 256, "TANGENT", 1.0, 40.0,
                          "BOX", 0.3)
# Blender's Sphere and Tube projections, which wrap the image around z of 2 (P' - 0.5): a Mapping
# node (scale 0.5, location 0.5) centres them on the sphere, turned so that their axis, where u
# has no derivative, crosses the mesh away from its own poles. Heights and normal maps.
WRAP_MAPPING = ((0.5, 0.5, 0.5), (0.5, 0.3, 0.0), (0.5, 0.5, 0.5))
planar_case("sphere_wrap_sphere", "sphere", 256, 0.02, "SPHERE", mapping=WRAP_MAPPING)
planar_case("tube_wrap_sphere", "sphere", 256, 0.02, "TUBE", mapping=WRAP_MAPPING)
# The Sphere projection on the sphere stretched (2, 1, 0.5) and turned: shaded in world space.
planar_case("sphere_wrap_stretch_sphere", "stretch_sphere", 512, 0.02, "SPHERE",
            mapping=WRAP_MAPPING)
# Heights through the Material Output's Displacement (Bump Only) instead of a Bump node: in world
# space on the sphere and on the stretched one (its Scale stays world units), in object space on
# the sphere scaled 3 (and turned and moved) and on the stretched sphere (its Scale grown by
# the object's scale along the normal).
displacement_case("displacement_sphere", "sphere", "WORLD")
displacement_case("displacement_stretch_sphere", "stretch_sphere", "WORLD")
displacement_case("displacement_object_sphere", "sphere", "OBJECT",
                  ((0.3, -0.5, 1.0), (0.5, 0.1, -0.4), (3.0, 3.0, 3.0)))
displacement_case("displacement_object_stretch_sphere", "stretch_sphere", "OBJECT")
# Heights reshaped before the Bump: a Color Ramp on the sphere, a clamped Math node on Suzanne.
# (The ramp steepens the sphere's bumps: at 256^2 the exact slopes are a median 1.15 deg from
# Cycles' differences half a texel long, over the bar of 1 deg; at 512^2 0.70 deg.)
remap_case("ramp_sphere", "sphere", "ramp", size=512)
remap_case("clamp_suzanne", "suzanne", "clamp")
# Blender's Noise Texture into the Bump node: on the sphere (Detail 2.5, Distortion 0.3), and on
# Suzanne stretched and turned (in world space; Detail 3, Roughness 0.6), both through a Mapping.
NOISE_MAPPING = ((0.3, -0.2, 0.1), (0.4, 0.0, -0.6), (1.0, 1.5, 0.8))
noise_case("noise_sphere", "sphere", 512, 0.05, scale=2.0, detail=2.5, roughness=0.5,
           distortion=0.3, mapping=NOISE_MAPPING)
noise_case("noise_stretch_suzanne", "stretch_chain_suzanne", 512, 0.03, scale=3.0, detail=3.0,
           roughness=0.6, distortion=0.0, mapping=NOISE_MAPPING)
# Its Dimensions 4D (x, y, z and W) on Suzanne, distorted.
noise_case("noise_4d_suzanne", "suzanne", 256, 0.04, scale=2.5, detail=2.0, roughness=0.5,
           distortion=0.4, dimensions="4D", w=0.7, mapping=NOISE_MAPPING)
# Procedural textures on the UV map's coordinates (Texture Coordinate UV, (u, v, 0)) through a
# Mapping node: a Noise Texture on Suzanne (its UV islands of every size and stretch), a Voronoi
# Texture on the sphere (its UVs stretched towards the poles).
UV_MAPPING = ((0.2, -0.1, 0.3), (0.0, 0.0, 0.5), (4.0, 3.0, 1.0))
noise_case("noise_uv_suzanne", "suzanne", 512, 0.05, scale=2.0, detail=2.5, roughness=0.55,
           distortion=0.2, mapping=UV_MAPPING, coordinates="UV")
noise_case("voronoi_uv_sphere", "sphere", 512, 0.02, kind="voronoi", scale=3.0, randomness=0.9,
           metric="EUCLIDEAN", exponent=0.5, mapping=UV_MAPPING, coordinates="UV")
# Blender's Brick Texture's Fac (the mortar) on Suzanne: wide mortar smoothed over all of it,
# every third row squashed, every second moved.
noise_case("brick_suzanne", "suzanne", 512, 0.005, kind="brick", scale=3.0, mortar_size=0.08,
           mortar_smooth=1.0, brick_width=0.6, row_height=0.3, brick_offset=0.4,
           offset_frequency=2, squash=1.5, squash_frequency=3, mapping=NOISE_MAPPING)
# Blender's Gradient Texture (Quadratic Sphere, mapped so that its unit sphere holds all of
# Suzanne) on Suzanne, and its Magic Texture (Depth 3, Distortion 1.5) on the sphere.
noise_case("gradient_suzanne", "suzanne", 256, 0.2, kind="gradient",
           gradient_type="QUADRATIC_SPHERE",
           mapping=((0.1, -0.1, 0.05), (0.4, 0.0, -0.6), (0.45, 0.6, 0.5)))
noise_case("magic_sphere", "sphere", 256, 0.01, kind="magic", scale=1.2, depth=3,
           distortion=1.5, mapping=NOISE_MAPPING)
# Blender's Musgrave Texture (fBM) on the sphere: Detail 2.5, Dimension 1.5, Lacunarity 2.3.
noise_case("musgrave_sphere", "sphere", 512, 0.02, kind="musgrave", scale=2.0, detail=2.5,
           dimension=1.5, lacunarity=2.3, mapping=NOISE_MAPPING)
# Its Ridged Multifractal on the sphere (Offset 0.9, Gain 1.8), its Hetero Terrain on Suzanne
# (Offset 0.4; a fractional Detail).
noise_case("musgrave_ridged_sphere", "sphere", 512, 0.01, kind="musgrave",
           musgrave_type="RIDGED_MULTIFRACTAL", scale=1.5, detail=3.0, dimension=1.1,
           lacunarity=2.2, offset=0.9, gain=1.8, mapping=NOISE_MAPPING)
noise_case("musgrave_hetero_suzanne", "suzanne", 512, 0.01, kind="musgrave",
           musgrave_type="HETERO_TERRAIN", scale=2.0, detail=2.5, dimension=1.3,
           lacunarity=2.1, offset=0.4, mapping=NOISE_MAPPING)
# Blender's Wave Texture: diagonal bands distorted by its noise on the sphere, spherical rings
# (triangle profile) on Suzanne.
noise_case("wave_sphere", "sphere", 512, 0.02, kind="wave", wave="BANDS", direction="DIAGONAL",
           profile="SIN", scale=0.8, distortion=1.5, detail=2.5, detail_scale=1.5,
           detail_roughness=0.6, phase=0.4, mapping=NOISE_MAPPING)
# Blender's Voronoi Texture's F1 Distance (cells) on the sphere, Euclidean and Minkowski.
noise_case("voronoi_sphere", "sphere", 512, 0.03, kind="voronoi", scale=3.0, randomness=0.8,
           metric="EUCLIDEAN", exponent=0.5, mapping=NOISE_MAPPING)
noise_case("voronoi_minkowski_suzanne", "suzanne", 512, 0.025, kind="voronoi", scale=4.0,
           randomness=1.0, metric="MINKOWSKI", exponent=1.6, mapping=NOISE_MAPPING)
# Its other Feature Outputs' Distance: Distance to Edge on the sphere, F2 (Euclidean) on Suzanne,
# Smooth F1 (Smoothness 0.6) on the sphere.
noise_case("voronoi_edge_sphere", "sphere", 512, 0.03, kind="voronoi",
           feature="DISTANCE_TO_EDGE", scale=3.0, randomness=0.8, metric="EUCLIDEAN",
           exponent=0.5, mapping=NOISE_MAPPING)
noise_case("voronoi_f2_suzanne", "suzanne", 512, 0.025, kind="voronoi", feature="F2",
           scale=3.5, randomness=0.9, metric="EUCLIDEAN", exponent=0.5, mapping=NOISE_MAPPING)
noise_case("voronoi_smooth_sphere", "sphere", 512, 0.03, kind="voronoi", feature="SMOOTH_F1",
           smoothness=0.6, scale=3.0, randomness=0.8, metric="EUCLIDEAN", exponent=0.5,
           mapping=NOISE_MAPPING)
noise_case("wave_suzanne", "suzanne", 512, 0.02, kind="wave", wave="RINGS",
           direction="SPHERICAL", profile="TRI", scale=0.6, distortion=0.0, detail=2.0,
           detail_scale=1.0, detail_roughness=0.5, phase=0.0, mapping=NOISE_MAPPING)
projected_normal_map_case("sphere_nmap_sphere", "sphere", 256, "TANGENT", 1.0, 40.0, "SPHERE",
                          mapping=WRAP_MAPPING)
projected_normal_map_case("tube_nmap_sphere_object", "sphere", 256, "OBJECT", 0.3, 40.0, "TUBE",
                          mapping=WRAP_MAPPING)


def tilt_field(size, tilt_deg):
    """Tilt (radians) and azimuth over the image, (size, size) float64 rows top first: smooth
    and periodic in u and v; the tilt spans [0, tilt_deg] (about a fifth of the texels above
    3/4 of it), the azimuth turns all the way round."""
    import numpy as np
    c = (np.arange(size, dtype=np.float64) + 0.5) / size
    u = c[None, :]
    v = 1.0 - c[:, None]  # file row r has v = 1 - (r + 0.5) / H
    s = 0.5 + 0.5 * np.sin(2 * math.pi * (2 * u + v)) * np.cos(2 * math.pi * 3 * v)
    tilt = math.radians(tilt_deg) * s
    azimuth = 2 * math.pi * (u - 2 * v) + 0.8 * np.sin(2 * math.pi * 3 * u)
    return tilt, azimuth


def normal_field(size, tilt_deg):
    """A tangent-space normal image (size, size, 3), rows top first, encoded n / 2 + 0.5: the
    unit normal (sin t cos a, sin t sin a, cos t) of tilt_field."""
    import numpy as np
    tilt, azimuth = tilt_field(size, tilt_deg)
    n = np.stack([np.sin(tilt) * np.cos(azimuth), np.sin(tilt) * np.sin(azimuth), np.cos(tilt)],
                 axis=-1)
    return (0.5 * n + 0.5).astype(np.float32)


def object_normal_field(normals, tilt_deg):
    """An object-space normal image from `normals` (H, W, 3: the mesh's own interpolated unit
    normal per texel, Blender's OBJECT bake with an Extend margin), encoded n / 2 + 0.5: each
    normal N turned by tilt_field's tilt towards a smooth direction field d projected across N,
    normalize(N + tan(t) d_perp / |d_perp|) (N itself where d is along N)."""
    import numpy as np
    size = normals.shape[0]
    tilt, azimuth = tilt_field(size, tilt_deg)
    n = normals / np.maximum(np.linalg.norm(normals, axis=-1, keepdims=True), 1e-12)
    d = np.stack([np.cos(azimuth), np.sin(azimuth), np.sin(2 * azimuth + 1.0)], axis=-1)
    across = d - np.sum(d * n, axis=-1, keepdims=True) * n
    length = np.linalg.norm(across, axis=-1, keepdims=True)
    out = n + np.tan(tilt)[..., None] * across / np.maximum(length, 1e-6)
    out /= np.linalg.norm(out, axis=-1, keepdims=True)
    return (0.5 * out + 0.5).astype(np.float32)


def height_field(size):
    """The height image, (size, size) float32 rows top first: smooth, periodic in u and v (so
    the Repeat extension and any wrap mode agree), values in [0.1, 0.9]."""
    import numpy as np
    c = (np.arange(size, dtype=np.float64) + 0.5) / size
    u = c[None, :]
    v = 1.0 - c[:, None]  # file row r has v = 1 - (r + 0.5) / H
    h = (0.5 + 0.25 * np.sin(2 * math.pi * 3 * u) * np.cos(2 * math.pi * 2 * v)
         + 0.15 * np.sin(2 * math.pi * (5 * u + 7 * v)))
    return h.astype(np.float32)


def make_material(height_image, scale):
    """The material described in the module docstring; returns (material, bake target node)."""
    mat = bpy.data.materials.new("bump")
    mat.use_nodes = True
    nt = mat.node_tree
    nodes = nt.nodes
    for node in list(nodes):
        nodes.remove(node)
    out = nodes.new("ShaderNodeOutputMaterial")
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    emission = nodes.new("ShaderNodeEmission")
    emission.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    emission.inputs["Strength"].default_value = 1.0
    add = nodes.new("ShaderNodeAddShader")
    tex = nodes.new("ShaderNodeTexImage")
    tex.image = height_image
    tex.interpolation = "Linear"  # bilinear = sgbake --filter bilinear
    tex.extension = "REPEAT"
    bump = nodes.new("ShaderNodeBump")
    bump.invert = False
    bump.inputs["Strength"].default_value = 1.0
    bump.inputs["Distance"].default_value = scale
    nt.links.new(tex.outputs["Color"], bump.inputs["Height"])
    nt.links.new(bump.outputs["Normal"], diffuse.inputs["Normal"])
    nt.links.new(diffuse.outputs["BSDF"], add.inputs[0])
    nt.links.new(emission.outputs["Emission"], add.inputs[1])
    nt.links.new(add.outputs["Shader"], out.inputs["Surface"])
    target = nodes.new("ShaderNodeTexImage")  # the bake target: the active Image Texture node
    target.name = "bake_target"
    return mat, target


def make_normal_material(normal_image, space, strength, uv_map, height_image=None, bump=None):
    """The normal-map material of the module docstring: an Image Texture of `normal_image`
    (Linear = sgbake's bilinear, Repeat) into a Normal Map node in `space` on UV map `uv_map`
    with `strength`; with `height_image`, the Bump node of make_material (Distance `bump`, fed
    by that image) takes the Normal Map's output into its Normal input and feeds the BSDF.
    Returns (material, bake target node)."""
    mat, target = make_material(height_image, 0.0 if bump is None else bump)
    nt = mat.node_tree
    nodes = nt.nodes
    bump_node = next(n for n in nodes if n.bl_idname == "ShaderNodeBump")
    diffuse = next(n for n in nodes if n.bl_idname == "ShaderNodeBsdfDiffuse")
    nmap = nodes.new("ShaderNodeNormalMap")
    nmap.space = space
    nmap.uv_map = uv_map
    nmap.inputs["Strength"].default_value = strength
    if height_image is None:
        tex = next(n for n in nodes if n.bl_idname == "ShaderNodeTexImage" and n != target)
        tex.image = normal_image
        nodes.remove(bump_node)
        nt.links.new(nmap.outputs["Normal"], diffuse.inputs["Normal"])
    else:
        tex = nodes.new("ShaderNodeTexImage")
        tex.image = normal_image
        tex.interpolation = "Linear"
        tex.extension = "REPEAT"
        nt.links.new(nmap.outputs["Normal"], bump_node.inputs["Normal"])
    nt.links.new(tex.outputs["Color"], nmap.inputs["Color"])
    return mat, target


def bake_pass(ob, mat, target, image, kind, margin, margin_type="EXTEND",
              swizzle=("POS_X", "POS_Y", "POS_Z")):
    """Bakes one pass of `ob` into `image`; returns the seconds bpy.ops.object.bake took.
    kind: "object" / "tangent" (NORMAL in that space, channels `swizzle`) or "mask" (EMIT)."""
    target.image = image
    mat.node_tree.nodes.active = target
    bpy.ops.object.select_all(action="DESELECT")
    ob.select_set(True)
    bpy.context.view_layer.objects.active = ob
    kwargs = dict(margin=margin, margin_type=margin_type, use_clear=False, target="IMAGE_TEXTURES",
                  save_mode="INTERNAL", use_selected_to_active=False)
    if kind == "mask":
        kwargs["type"] = "EMIT"
    else:
        kwargs.update(type="NORMAL", normal_space=kind.upper(), normal_r=swizzle[0],
                      normal_g=swizzle[1], normal_b=swizzle[2])
    t0 = time.perf_counter()
    result = bpy.ops.object.bake(**kwargs)
    seconds = time.perf_counter() - t0
    if result != {"FINISHED"}:
        raise RuntimeError(f"bake {kind} returned {result}")
    return seconds


def project_texture(name, mat, tex, ob):
    """Reads Image Texture node `tex` of `mat` as case `name`'s PLANAR entry says: its
    projection and Blend on the object's coordinates (or an Empty's, or the Generated ones),
    through a Mapping node when given. Records the coordinates' affine map in PLANAR[name]."""
    me = ob.data
    nodes = mat.node_tree.nodes
    tex.projection = PLANAR[name]["projection"]
    tex.projection_blend = PLANAR[name]["blend"]
    coordinates = nodes.new("ShaderNodeTexCoord")
    source = coordinates.outputs["Object"]
    matrix = None  # what the coordinates are, as a map of the object's own
    kind = PLANAR[name].get("coordinates", ("OBJECT",))
    if kind[0] == "EMPTY":
        empty = bpy.data.objects.new("projector", None)
        bpy.context.scene.collection.objects.link(empty)
        empty.location, empty.rotation_euler, empty.scale = kind[1]
        bpy.context.view_layer.update()
        coordinates.object = empty
        matrix = empty.matrix_world.inverted() @ ob.matrix_world
    elif kind[0] == "GENERATED":
        source = coordinates.outputs["Generated"]
        # Generated: the texture space (auto: the bounding box) to [0, 1].
        space_loc, space_size = me.texspace_location, me.texspace_size
        matrix = mathutils.Matrix.Identity(4)
        for i in range(3):
            matrix[i][i] = 0.5 / space_size[i]
            matrix[i][3] = 0.5 - 0.5 * space_loc[i] / space_size[i]
    if matrix is not None:
        PLANAR[name]["matrix"] = [list(matrix[r]) for r in range(3)]
    mapping = PLANAR[name].get("mapping")
    if mapping is None:
        mat.node_tree.links.new(source, tex.inputs["Vector"])
    else:
        node = nodes.new("ShaderNodeMapping")
        node.vector_type = "POINT"
        for key in ("location", "rotation", "scale"):
            node.inputs[key.title()].default_value = mapping[key]
        mat.node_tree.links.new(source, node.inputs["Vector"])
        mat.node_tree.links.new(node.outputs["Vector"], tex.inputs["Vector"])


def build_case(name, out_dir, size=None, passes=("object", "tangent", "mask"), margin=0,
               height_size=HEIGHT_SIZE, save_bakes=True, runs=1, margin_type="EXTEND",
               scale=None, swizzle=("POS_X", "POS_Y", "POS_Z")):
    """Builds case `name`, writes mesh.obj and height.exr into out_dir, bakes `passes`
    (saved as blender_PASS.exr when save_bakes); returns the case's manifest entry. scale
    replaces the case's Bump Distance (0: no bump, the interpolated normal). With
    runs > 1 every pass is baked that many times and bake_s keeps the fastest run; bake_cpu
    is the process CPU time over wall time of that run (how many cores Cycles kept busy)."""
    import numpy as np
    builder, default_size, case_scale = CASES[name]
    scale = case_scale if scale is None else scale
    size = size or default_size
    bake_common.reset_scene()
    os.makedirs(out_dir, exist_ok=True)
    ob = builder()
    if name in TRANSFORMS:
        ob.location, ob.rotation_euler, ob.scale = TRANSFORMS[name]
        bpy.context.view_layer.update()
    me = ob.data
    if len(me.uv_layers) == 0:
        raise RuntimeError(f"case {name}: no UV map")
    me.calc_normals_split()
    arrays = objio.mesh_arrays(me)
    arrays["smooth"] = [p.use_smooth for p in me.polygons]  # `s 0` / `s 1`, as Blender writes
    objio.write_obj(os.path.join(out_dir, "mesh.obj"), arrays,
                    comment=f"bake oracle case {name} (Blender {bpy.app.version_string})")

    nmap = NORMAL_MAPS.get(name)
    if nmap is None:
        height = bake_common.new_float_image("height", height_size, height_size,
                                             height_field(height_size))
        bake_common.save_exr(height, os.path.join(out_dir, "height.exr"))
        mat, target = make_material(height, scale)
        if name in PLANAR:
            tex = next(n for n in mat.node_tree.nodes
                       if n.bl_idname == "ShaderNodeTexImage" and n != target)
            project_texture(name, mat, tex, ob)
            bump = next(n for n in mat.node_tree.nodes if n.bl_idname == "ShaderNodeBump")
            bump.inputs["Strength"].default_value = PLANAR[name].get("strength", 1.0)
        if name in DISPLACEMENT:
            bump_by_displacement(mat, DISPLACEMENT[name]["space"])
        if name in REMAPS:
            remap = reshape_height(mat, REMAPS[name])
        if name in NOISE:
            bump_by_noise(mat, NOISE[name])
    else:
        if nmap["space"] == "TANGENT" or name in PLANAR:
            field = normal_field(height_size, nmap["tilt_deg"])
        else:
            # The mesh's own normals, baked with a plain material (margin: the texels the
            # bilinear filter reaches across island borders get the nearest island's normal).
            plain, plain_target = make_material(None, 0.0)
            plain.node_tree.nodes.remove(plain.node_tree.nodes["Bump"])
            me.materials.clear()
            me.materials.append(plain)
            own = bake_common.new_float_image("own_normals", height_size, height_size)
            bake_pass(ob, plain, plain_target, own, "object", 8)
            field = object_normal_field(
                bake_common.image_array(own)[..., :3].astype(np.float64) * 2.0 - 1.0,
                nmap["tilt_deg"])
            bpy.data.images.remove(own)
        normal = bake_common.new_float_image("normal", height_size, height_size, field)
        bake_common.save_exr(normal, os.path.join(out_dir, "normal.exr"))
        height = None
        if "bump" in nmap:
            height = bake_common.new_float_image("height", height_size, height_size,
                                                 height_field(height_size))
            bake_common.save_exr(height, os.path.join(out_dir, "height.exr"))
        mat, target = make_normal_material(normal, nmap["space"], nmap["strength"],
                                           me.uv_layers[0].name, height, nmap.get("bump"))
        if name in PLANAR:
            tex = next(n for n in mat.node_tree.nodes
                       if n.bl_idname == "ShaderNodeTexImage" and n.image == normal)
            project_texture(name, mat, tex, ob)
    me.materials.clear()
    me.materials.append(mat)

    entry = {"name": name, "dir": os.path.abspath(out_dir), "size": size, "scale": scale,
             "filter": "bilinear", "height_size": height_size, "margin": margin,
             "margin_type": margin_type,
             "faces": len(me.polygons), "corners": len(me.loops), "bake_s": {}, "bake_cpu": {},
             "subdivision": SUBDIVISION[name],
             "transform": [list(row) for row in ob.matrix_world]}
    if name in PLANAR:
        entry["planar"] = {"projection": PLANAR[name]["projection"].lower(),
                           "blend": PLANAR[name]["blend"],
                           "strength": PLANAR[name].get("strength", 1.0)}
        if "mapping" in PLANAR[name] or "matrix" in PLANAR[name]:
            entry["planar"]["mapping"] = dict(PLANAR[name].get("mapping", {}))
            if "matrix" in PLANAR[name]:
                entry["planar"]["mapping"]["matrix"] = PLANAR[name]["matrix"]
    if name in DISPLACEMENT:
        entry["displacement"] = {"space": DISPLACEMENT[name]["space"].lower()}
    if name in REMAPS:
        entry["remap"] = remap
    if name in NOISE:
        entry["noise"] = dict(NOISE[name], mapping=[list(v) for v in NOISE[name]["mapping"]])
    if nmap is not None:
        entry["normal_map"] = {"space": nmap["space"].lower(), "strength": nmap["strength"],
                               "tilt_deg": nmap["tilt_deg"], "size": height_size}
        if "bump" in nmap:
            entry["normal_map"]["bump"] = nmap["bump"]
    for kind in passes:
        img = bake_common.new_float_image(f"blender_{kind}", size, size)
        for _ in range(runs):
            cpu0 = time.process_time()
            seconds = bake_pass(ob, mat, target, img, kind, margin, margin_type, swizzle)
            cpu = time.process_time() - cpu0
            if kind not in entry["bake_s"] or seconds < entry["bake_s"][kind]:
                entry["bake_s"][kind] = seconds
                entry["bake_cpu"][kind] = cpu / seconds if seconds > 0 else 0.0
        if kind == "mask":
            mask = bake_common.image_array(img)[..., 0]
            entry["covered"] = int(np.count_nonzero(mask > 0.5))
            entry["mask_values"] = sorted(set(np.unique(mask).tolist()))[:8]
        if save_bakes:
            bake_common.save_exr(img, os.path.join(out_dir, f"blender_{kind}.exr"))
        bpy.data.images.remove(img)
    return entry


def parse_args(argv):
    import argparse
    parser = argparse.ArgumentParser(prog="bake_scene.py")
    parser.add_argument("out_dir")
    parser.add_argument("--cases", default="suzanne,sphere,cube_flat")
    parser.add_argument("--size", type=int, help="bake size (default: per case)")
    parser.add_argument("--passes", default="object,tangent,mask")
    parser.add_argument("--margin", type=int, default=0)
    parser.add_argument("--margin-type", default="EXTEND", choices=("EXTEND", "ADJACENT_FACES"))
    parser.add_argument("--height-size", type=int, default=HEIGHT_SIZE)
    parser.add_argument("--samples", type=int, default=1)
    parser.add_argument("--threads", type=int, help="Cycles threads (default: all cores)")
    parser.add_argument("--swizzle", default="POS_X,POS_Y,POS_Z",
                        help="the normal passes' Swizzle, R,G,B (Blender's names)")
    return parser.parse_args(argv)


def main(argv):
    args = parse_args(argv)
    scene = bpy.context.scene
    bake_common.setup_cycles(scene, samples=args.samples, threads=args.threads)
    os.makedirs(args.out_dir, exist_ok=True)
    entries = []
    for name in args.cases.split(","):
        if name not in CASES:
            raise SystemExit(f"unknown case {name!r} (known: {', '.join(CASES)})")
        entry = build_case(name, os.path.join(args.out_dir, name), size=args.size,
                           passes=args.passes.split(","), margin=args.margin,
                           margin_type=args.margin_type, height_size=args.height_size,
                           swizzle=tuple(args.swizzle.split(",")))
        entry["blender_version"] = bpy.app.version_string
        entry["cycles_threads"] = scene.render.threads
        entry["samples"] = args.samples
        entry["swizzle"] = args.swizzle
        entries.append(entry)
        print(RESULT_TAG + json.dumps(entry), flush=True)
    with open(os.path.join(args.out_dir, "cases.json"), "w", encoding="ascii") as f:
        json.dump(entries, f, indent=1)


if __name__ == "__main__":
    main(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else [])
