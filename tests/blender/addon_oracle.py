#!/usr/bin/env python3
"""The BlenderAddonBake test: the Blender add-on (plugin/) bakes what the sgbake CLI bakes.

    python3 tests/blender/addon_oracle.py --cli build/src/sgbake --library build/src/libsgbake.so
        [--blender blender] [--keep DIR] [--sabotage]

1. Blender half `make` (this file inside Blender, factory settings): builds Suzanne subdivided
   once, smooth (bake_scene.build_suzanne), a 512^2 float height image (bake_scene.height_field)
   and bake_scene's material (Image Texture -> Bump, Distance 0.1 -> BSDF). It enables the
   add-on from the repository's plugin/ folder (addon_utils, so that its preferences exist)
   with the preferences' Library path set to --library, runs "Layers from Material" (which
   must add one height layer with that image and scale = Distance, strength 1), then bakes with
   `bpy.ops.object.sgbake_bake()` at 256^2 every map in CASES, each into its image; the pixels
   the image then holds are saved as addon_CASE.npy (rows top first). One case bakes into a
   Target image that starts at 64^2 (the add-on must scale it) with margin 8, 2 x 2 samples
   and alpha from coverage. mesh.obj (objio: every float exact) and height.exr (raw float) are
   the same mesh and image for the CLI. One case is padded by Adjacent Faces (margin 8), the
   rest by Extend. The UI's way to bake, the bake job on a worker thread
   (as the modal operator runs it), must report a progress rising to 1, and a cancel set from
   the main thread must stop it without creating an image. It also checks that bad input
   becomes an error report,
   not a traceback: a layer without an image, an object without a UV map, no active object,
   a library path that does not exist, a scene libsgbake refuses (a normal layer with the
   hermite filter: its message must come through), a mask on a missing UV map, and a generated
   UDIM image (its tiles are no files) as a layer's image or mask.
   UDIM (udim_case): a copy of Suzanne whose faces with x < 0 have u + 1 (tile 1002; the rest
   in 1001; mesh_udim.obj) is baked (UDIM_MAP, margin UDIM_MARGIN) into a tiled image with
   tiles 1001, 1002 and 1011 (no UV there) created at 64^2, twice (height first, so that the
   second bake replaces packed tiles). The image must keep its name, be tiled with those tiles
   at 256^2, packed as //udim_target.<UDIM>.exr, Non-Color, with no image or temporary
   folder left behind; the job must name the tiles the UVs lie in, note 1011, and a single
   target must warn about 1002. Blender's own Image.save() then writes the tiles as
   addon_udim.<UDIM>.exr. Then a tiled height image (height_tiles.<UDIM>.exr: tiles 1001 and
   1002 of two different fields, loaded from files) becomes the layer's image and the add-on
   bakes into a new tiled target (addon_udim_in.<UDIM>.exr), leaving no image behind.
   Layer options (options_case): a height layer with an offset and a mask (own tiling, offset,
   bicubic filter, named UV map), a noise volume with central differences and a step, a
   triplanar layer with an offset and a minimum weight: the add-on's scene JSON must carry
   those values (as Blender holds them), and its tangent-normal bake is addon_options.npy.
   The CLI scenes are written from the same values (options.json), plus one per key without
   it (options_no_KEY_LAYER.json), the negative controls.
   Exact limit surface (limit_case): a coarse Suzanne with edge and vertex creases and a live
   Subdivision Surface modifier (level 1, UV Smooth All) is baked with Surface: Exact Limit
   Surface (addon_limit.npy) and Evaluated Mesh (addon_limit_mesh.npy); mesh_limit.obj is the
   coarse mesh. The modifier must be shown again afterwards, and a Displace modifier after it
   must make the add-on refuse the bake.
   Transformed object (world_case): Suzanne moved, turned and scaled unevenly (WORLD_*) is
   baked in tangent and object space by the add-on, whose scene must carry "transform" = the
   object's matrix_world and the height's Scale = the Bump Distance, with no note; by the
   add-on's job with the "transform" taken out (the negative control: the add-on before it
   sent one); and by Cycles (tangent, object and an EMIT mask, 256^2). Besides: an object
   scaled 2x or unevenly sends its matrix_world and the Scale as it is, a zero scale falls back
   to object space with a note naming the object (none for a height map), and a translated
   object bakes as at the origin.
   Two materials (materials_case): a copy of Suzanne with the bump material in slot 0 and, on
   its faces of even index, a material chaining a Bump on a tangent-space Normal Map in slot 1
   (MATERIALS_*). Layers from Material must tag the height layer with slot 0 and the normal
   layer and the height "above" it with slot 1, the bake send those as "material" and the
   faces' slots as face_material (clamped to the slots, as Cycles clamps them); a note about
   one material names it; the same material in a second slot makes its own layers and an
   empty slot none. It is baked by the add-on, by the add-on's job without the "material" keys
   (every layer on every face: the negative control) and by Cycles (the bake target active in
   both materials; tangent and an EMIT mask, 256^2). Back on the one-material Suzanne, the
   layers must have no slot (-1) and send no "material"; a hand-made layer's slot is -1.
   Projector (projector_case): the bump material's Image Texture read with Box projection on an
   Empty's coordinates through a Mapping node of type Texture (PROJECTOR_*). Layers from
   Material must make one triplanar Box layer (bump-node slopes, the node's type); its tangent-normal bake must be Cycles' (median <=
   PROJECTOR_MEDIAN_DEG), and the same job with sgbake's own triplanar blend must not.
   Displacement (displacement_case): the texture also, doubled by a Math node in a node
   group, into an object-space Displacement node into the Material Output's Displacement (Bump
   Only) on Suzanne stretched and turned, the Bump node's Normal unlinked; Layers from Material
   must make the displacement's layer (height space object) and the Bump's above it, baked as
   Cycles bakes them (DISPLACEMENT_*), the Bump added instead of stacked must not be.
   Remap (remap_case): the texture through a Color Ramp (Ease, coloured stops, rising and
   falling) and a Math node x 2 clamped into the Bump: Layers from Material must compose them
   into the layer's "remap" (sent as the layer holds it; a malformed Remap is an error report
   naming the layer), baked as Cycles bakes it (REMAP_*: median and p99), the same job without
   the remap clearly worse. remap_checks compares such remaps (Color Ramp Ease and Constant,
   its Alpha, its Green separated, Map Range clamped with negative factors, the Clamp node's
   two types) with the chains computed here from Blender's ramp at 1000 values, and a chain
   that makes a constant (x 0, a Clamp of Min above Max) must be skipped.
   Noise Texture (noise_case): a Noise Texture (3D, NOISE_INPUTS) on Suzanne's own object
   coordinates through a Mapping node (Point) into the Bump: Layers from Material must make one
   "blender-noise" volume layer of the node's settings and its Mapping (sent so), baked as
   Cycles bakes it (NOISE_*: median and p99), the same job without its "mapping" clearly
   worse; then its Vector unlinked on Suzanne turned and scaled: the layer reads the Generated
   coordinates (its matrix takes the mesh's bounding box to [0, 1]^3), baked as Cycles bakes it,
   its control without the "mapping". noise_checks: its Color output, a Detail fed by another
   texture, a W fed by one in 4D and the normal into its Vector give no layer and a reason;
   Dimensions 4D gives a layer of those Dimensions and its W, 2D one without W; a UV Map node
   into its Vector a layer on that UV map; through a Color Ramp it gives a blender-noise layer
   whose remap is the ramp's; a volume layer made by hand with function Blender Noise (4D)
   sends its Dimensions, W, Detail, Roughness and Distortion and bakes.
   Musgrave Texture (musgrave_case): a Musgrave Texture (fBM, 3D, MUSGRAVE_INPUTS) on Suzanne's
   own object coordinates through a Mapping node (Point) into the Bump: Layers from Material
   must make one "blender-musgrave" volume layer of the node's settings and its Mapping (sent
   so, without a Noise Texture's roughness or distortion), baked as Cycles bakes it
   (MUSGRAVE_*: median and p99), the same job without its "dimension" and "lacunarity"
   (Blender's defaults, 2 and 2) clearly worse; Cycles' normals must lean less than
   MUSGRAVE_LEAN_DEG off the add-on's bake of the layer at amplitude 0. The same with a Ridged
   Multifractal (musgrave_ridged_case, MUSGRAVE_RIDGED_INPUTS): a "blender-musgrave" layer of
   type ridged-multifractal with its Offset and Gain, baked as Cycles bakes it, the same job
   with the layer left at fBM (without its type, offset and gain) clearly worse.
   musgrave_checks: each of the five types makes a layer of its type in the scene's name with
   the Offset and Gain it uses (and not the others; a Hetero Terrain's unused Gain may come
   from a node); Dimensions 1D gives a layer of those Dimensions and its W; a Lacunarity and a
   Hetero Terrain's Offset fed by another texture give no layer and a reason (the node back as
   fBM 3D gives one); volume layers made
   by hand with function Blender Musgrave send their type, Detail, Dimension and Lacunarity
   (nothing of Blender Noise's) and the Offset and Gain their type uses, and bake.
   Wave Texture (wave_case): a Wave Texture (WAVE_NODE: Rings, Spherical, Sine; WAVE_INPUTS) on
   Suzanne's own object coordinates through a Mapping node (Point) into the Bump: Layers from
   Material must make one "blender-wave" volume layer of the node's settings (its enums in the
   scene's names, WAVE_ENUMS) and its Mapping, sent so, baked as Cycles bakes it (WAVE_*:
   median and p99), the same job without its "phase" clearly worse; Cycles' normals must lean
   less than WAVE_LEAN_DEG off the surface's. wave_checks: Bands Diagonal Saw and Rings Z
   Triangle give the scene's names, the Color output the Fac's layer, a Phase Offset fed by
   another texture no layer and a reason; a volume layer made by hand with function Blender
   Wave sends its settings (nothing of the other functions') and bakes.
   Voronoi Texture (voronoi_case): a Voronoi Texture (VORONOI_NODE: F1, 3D, Euclidean;
   VORONOI_INPUTS) on Suzanne's own object coordinates through a Mapping node (Point), its
   Distance into the Bump: Layers from Material must make one "blender-voronoi" volume layer of
   the node's settings (its metric in the scene's name) and its Mapping, sent so, baked as
   Cycles bakes it (VORONOI_*: median and p99), the same job without its "mapping" clearly
   worse; Cycles' normals must lean less than VORONOI_LEAN_DEG off the surface's.
   The same with Feature Output Distance to Edge (voronoi_edge_case, VORONOI_EDGE_INPUTS): a
   "blender-voronoi" layer of feature distance-to-edge (no metric, exponent or smoothness),
   baked as Cycles bakes it, the same job with the layer left at F1 (without its "feature")
   clearly worse.
   voronoi_checks: Manhattan, Chebychev and Minkowski give the scene's metrics (Chebychev ->
   chebyshev); Feature Outputs F2, Smooth F1 and Distance to Edge the scene's features (Smooth
   F1 with its Smoothness, Distance to Edge without the metric and exponent); N-Sphere Radius
   and the Color output no layer and a reason; volume layers made by hand with function
   Blender Voronoi (F1 Minkowski, Smooth F1) send their settings (nothing of the other
   functions', Smoothness only for Smooth F1) and bake.
   Noise Texture on UV coordinates (noise_uv_case): the Noise Texture on Suzanne's UV map's
   coordinates (Texture Coordinate UV) through a Mapping node: Layers from Material must make
   one "blender-noise" volume layer on "coordinates": "uv" of the render UV map's set, baked as
   Cycles bakes it (NOISE_*: median and p99), the same layer on object coordinates clearly
   worse. noise_world_case: the same on world positions (a Geometry node's Position), Suzanne
   turned and scaled: a "blender-noise" layer whose mapping's matrix is the object's
   matrix_world, baked as Cycles bakes it, the layer without its mapping clearly worse.
   Gradient and Magic Textures (gradient_case, magic_case): a Gradient Texture's Fac (Quadratic
   Sphere) and a Magic Texture's (MAGIC_INPUTS, Depth MAGIC_DEPTH) on Suzanne's own coordinates
   through a Mapping node: one "blender-gradient" (no "frequency") and one "blender-magic"
   volume layer, baked as Cycles bakes them, the layers without their mapping clearly worse;
   gradient_magic_checks: the Magic Texture's Color output and a Scale fed by a node give no
   layer and a reason, layers made by hand send their settings and bake.
   Brick Texture (brick_case): a Brick Texture's Fac (BRICK_INPUTS, BRICK_PROPS) on Suzanne's
   own coordinates through a Mapping node: one "blender-brick" volume layer of its inputs and
   properties, baked as Cycles bakes it, the layer without its mapping clearly worse.
2. For each case the CLI bakes the same map from the files:
     sgbake bake --mesh mesh.obj --height height.exr --height-scale S --filter bilinear
                 --map MAP --size 256 --margin M --samples N [--green G] [--alpha]
                 --bit-depth 32 --no-manifest -o cli_CASE.exr
   with S the layer's scale as Blender holds it (float32 0.1), so both read the same number.
   The UDIM bake: `sgbake bake --mesh mesh_udim.obj ... -o cli_udim.<UDIM>.exr` (the tiles the
   UVs touch, 1001 and 1002) and a scene with "tile": 1011 for the empty tile; the layer
   options: `sgbake bake options*.json`; the limit surface: `sgbake bake --mesh mesh_limit.obj
   --subdivide limit --uv-smooth all --edge-crease A,B,C ... --vertex-crease V,C` (the creases
   read from the mesh by the test, not by the add-on), and as negative controls the same
   without the creases and with UV Smooth keep-boundaries.
3. Blender half `compare` (Blender reads the EXRs; the python3 CTest finds may lack numpy):
   every texel's RGB (RGBA with alpha) of the add-on's image must equal the CLI's file within
   1e-5, and the mask exactly. Both are libsgbake's floats and the file stores float32
   exactly, but the mesh is not quite the same twice: Blender 3.4 sums vertex normals in
   parallel, so each evaluation of the mesh (the OBJ's, then each bake's to_mesh()) may move
   some normals by one float ulp (measured: 336 of 7,872 corners between two to_mesh() calls),
   and the maps that read normals then differ by as much (~6e-8) near those corners. Heights,
   derivatives and the mask, which read no normal, come out bit-identical.
   Each UDIM tile must equal the CLI's file of that tile within UDIM_TOLERANCE (1e-6: the
   tiles pass through files, and a 16-bit one would be 7.6e-6 off), and the add-on's tile
   1002 must differ from the CLI's 1001 by more than 1e-5 (negative control); the tiled height
   image's bake must equal the CLI's scene reading "height_tiles.<UDIM>.exr" within
   UDIM_TOLERANCE per tile, and differ from the scene reading the tile files swapped. The layer
   options bake must equal options.json's within 1e-5 and differ from every
   options_no_*.json by more than that. The limit surface bake must equal the CLI's within
   1e-5 (it comes out bit-identical), and differ by more than that from the CLI's negative
   controls and from the add-on's own bake of Blender's level-1 mesh.
   The transformed object's bakes against Cycles' (angles between the decoded normals over
   Cycles' mask less one texel at island borders, as bake_compare.py): median <=
   WORLD_MEDIAN_DEG (0.01 deg: Layers from Material takes the Bump node's slopes as Cycles
   does; measured 0.002), and the negative control at least WORLD_CONTROL_FACTOR (3) times
   worse (measured medians 2.9 and 33 deg). The two-material object likewise: median <=
   MATERIALS_MEDIAN_DEG (measured 0.002 deg) and every texel within MATERIALS_MAX_DEG
   (measured 0.3 deg), every layer on every face at least MATERIALS_CONTROL_FACTOR times
   worse (measured 11 deg).

--sabotage bakes the add-on's tangent-normal cases with green DirectX: the test must FAIL.
Prints per case the largest difference, where it is, and the texels compared.

Exit status: 0 pass, 1 fail (or a tool failed), 2 usage error, 77 Blender is not installed or
the library is built with AddressSanitizer (SGBAKE_SANITIZE: ASan's runtime must come first
in a process, and Blender does not start with it; CTest: SKIP_RETURN_CODE 77).
Takes ~15 s (Blender starts twice; twenty CLI bakes; Cycles bakes seven cases at 256^2).
"""

import argparse
import json
import os
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
PLUGIN_DIR = os.path.join(os.path.dirname(os.path.dirname(HERE)), "plugin")
sys.dont_write_bytecode = True  # keep __pycache__ out of the source tree
sys.path.insert(0, HERE)
import bake_common as bc  # noqa: E402  (needs the sys.path entry above)
import objio  # noqa: E402

SIZE = 256
TOLERANCE = 1e-5
ADDON = "sgbake_blender"

# name -> (map, margin, samples, alpha, target image's initial side or None for the default
# '<object>_<map>' image)
# The UDIM bake: map, margin, and the target image's tiles (1001 and 1002 hold Suzanne's
# two halves; no UV lies in 1011, which must hold the map's background).
UDIM_MAP = "tangent-normal"
UDIM_MARGIN = 4
UDIM_TILES = [1001, 1002, 1011]
# The tiles reach Blender through temporary files: a format that is not 32-bit float must fail
# (16-bit integers put 0.5 at 0.5000076, under TOLERANCE), so the tiles get a bound above the
# 1-ulp noise of the normals (~6e-8) and below that.
UDIM_TOLERANCE = 1e-6
OPTIONS_MAP = "tangent-normal"
LIMIT_MAP = "tangent-normal"
# The transformed object against Cycles (world_case): Suzanne moved, turned and scaled unevenly
# (the scales' geometric mean is 1, so the bake without "transform" is exactly the add-on's
# before it sent one: heights divided by the mean scale), tangent- and object-space maps.
WORLD_LOCATION = (0.5, -1.0, 2.0)
WORLD_ROTATION = (0.4, 0.2, 0.7)
WORLD_SCALE = (2.0, 1.0, 0.5)
WORLD_MAPS = {"tangent-normal": "tangent", "object-normal": "object"}  # -> Cycles' normal_space
# Layers from Material takes a Bump node's slopes as Cycles does (forward differences half a
# bake texel apart, "gradient": "bump-node"), so the bar is BlenderBakeOracle's (e), float
# rounding: measured at 256^2 median 0.002 deg, tangent and object (0.61 and 0.23 deg with
# exact slopes). Without the transform the median is 2.9 (tangent) and 33 deg (object: Blender's
# baker brings the normal back as a direction, M^-1): the control must be WORLD_CONTROL_FACTOR
# times worse.
WORLD_MEDIAN_DEG = 0.01
WORLD_CONTROL_FACTOR = 3.0
# The object of two materials against Cycles (materials_case): a copy of Suzanne whose faces of
# even index are in slot 1, whose material chains a Bump (MATERIALS_CHAIN_DISTANCE, the height
# image) on a tangent-space Normal Map (normal_field leaning up to MATERIALS_TILT_DEG); the
# others keep slot 0, the bump material. Same bar as the transformed object (measured median
# 0.002 deg; 0.22 with exact slopes). The negative control, every layer on every face (the add-on before it
# sent "material"), must be MATERIALS_CONTROL_FACTOR times worse.
MATERIALS_TILT_DEG = 40.0
MATERIALS_CHAIN_DISTANCE = 0.05
MATERIALS_MAP = "tangent-normal"
MATERIALS_MEDIAN_DEG = 0.01
# Texels next to an edge between the materials go to the triangle Blender's nudged sample is in
# (bake.hpp, "Where a texel is sampled"): picked at the texel centre instead, 17 of them came
# out 5-33 deg off. Every texel must be within MATERIALS_MAX_DEG (measured max 0.3 deg; 6.5
# with exact slopes).
MATERIALS_MAX_DEG = 1.0
MATERIALS_CONTROL_FACTOR = 3.0
# The projector case (projector_case): the bump material's Image Texture read with Box
# projection (Blend PROJECTOR_BLEND) on the coordinates of an Empty placed so, through a
# Mapping node of type PROJECTOR_MAPPING_TYPE (the inverse of the Point the bake oracle's
# box_mapped_sphere checks); Layers from Material must make it a triplanar Box layer whose bake is Cycles'
# (bump-node slopes) to float rounding. Its control: the same layer with sgbake's own blend.
PROJECTOR_EMPTY = ((0.2, 0.4, -0.3), (0.3, -0.5, 0.2), (0.7, 1.3, 0.9))
PROJECTOR_MAPPING = ((0.1, 0.0, -0.2), (0.0, 0.3, 0.0), (1.2, 1.0, 0.8))
PROJECTOR_MAPPING_TYPE = "TEXTURE"
PROJECTOR_BLEND = 0.3
PROJECTOR_DISTANCE = 0.01
PROJECTOR_MEDIAN_DEG = 0.01
PROJECTOR_CONTROL_FACTOR = 3.0
# The displacement case (displacement_case): the bump material's texture also fed, through a
# node group whose Math node doubles it, into a Displacement node (object space, on Suzanne
# placed as DISPLACEMENT_PLACEMENT, Scale DISPLACEMENT_SCALE / 2) into the Material Output's
# Displacement (Bump Only), its Bump node left with its Normal input unlinked: Cycles bumps the
# surface with the displacement first and the Bump node bumps that normal. Layers from Material
# must make the displacement's height layer first and the Bump's above it; the bake must be
# Cycles' (median <= DISPLACEMENT_MEDIAN_DEG) and the same job with the Bump added to the
# displacement instead (no "base") at least DISPLACEMENT_CONTROL_FACTOR times worse.
DISPLACEMENT_SCALE = 0.05
DISPLACEMENT_PLACEMENT = ((0.3, -0.2, 0.1), (0.3, -0.2, 0.5), (1.6, 1.0, 0.7))
DISPLACEMENT_MEDIAN_DEG = 0.01
DISPLACEMENT_CONTROL_FACTOR = 3.0
# The remap case (remap_case): the bump material's texture through a Color Ramp (REMAP_STOPS,
# Ease: its luminance rises and falls) and a Math node (x REMAP_FACTOR, clamped to [0, 1]: the
# ramp's peak is cut flat) into the Bump. Layers from Material must compose the two into the
# layer's "remap"; its bake must be Cycles' (median <= REMAP_MEDIAN_DEG, p99 <= REMAP_P99_DEG)
# and the same job without the remap at least REMAP_CONTROL_FACTOR times worse.
REMAP_FACTOR = 2.0
REMAP_MEDIAN_DEG = 0.01
REMAP_P99_DEG = 0.01
REMAP_CONTROL_FACTOR = 3.0
# The Float Curve case (float_curve_case): the bump material's texture through a Float Curve
# node (FLOAT_CURVE_POINTS: its ends inside [0, 1], so that Cycles extrapolates the heights
# beyond them) into the Bump. Layers from Material must make the curve the layer's "remap"; its
# bake must be Cycles' (REMAP_* bars) and the same job without the remap clearly worse.
FLOAT_CURVE_POINTS = ((0.15, 0.2), (0.45, 0.7), (0.85, 0.55))
# The noise case (noise_case): a Noise Texture (3D, NOISE_INPUTS) on Suzanne's own object
# coordinates through a Mapping node (Point, NOISE_MAPPING) into the Bump (Distance
# NOISE_DISTANCE: its normals lean at most 32 deg off the surface's, short of Cycles'
# valid-reflection bend). Measured at 256^2: median 0.002, p99 0.004, max 0.010 deg (without
# the mapping: median 9.0, p99 24 deg); Generated: median 0.002, p99 0.004, max 0.008 deg
# (without: median 6.7, p99 20 deg). Layers from Material must make a "blender-noise" volume layer of
# those settings; its bake must be Cycles' (median <= NOISE_MEDIAN_DEG, p99 <= NOISE_P99_DEG)
# and the same job without the layer's "mapping" at least NOISE_CONTROL_FACTOR times worse.
# Then the Vector unlinked (Cycles reads the Generated coordinates) on Suzanne turned and
# scaled (NOISE_PLACEMENT): the layer's Coordinates are the Generated ones, judged alike, its
# control without the "mapping" (the object's own coordinates).
NOISE_INPUTS = {"Scale": 4.0, "Detail": 3.5, "Roughness": 0.6, "Distortion": 0.3}
NOISE_MAPPING = ((0.3, -0.2, 0.5), (0.4, -0.3, 0.8), (1.3, 0.8, 1.1))
NOISE_DISTANCE = 0.05
NOISE_PLACEMENT = ((0.0, 0.0, 0.0), (0.5, -0.3, 0.9), (1.4, 0.8, 1.2))
NOISE_MEDIAN_DEG = 0.01
NOISE_P99_DEG = 0.01
NOISE_CONTROL_FACTOR = 3.0
# The Musgrave case (musgrave_case): a Musgrave Texture (fBM, 3D, MUSGRAVE_INPUTS) on Suzanne's
# own object coordinates through a Mapping node (Point, MUSGRAVE_MAPPING) into the Bump
# (Distance MUSGRAVE_DISTANCE: Cycles' normals lean less than MUSGRAVE_LEAN_DEG off the
# surface's, checked against the add-on's bake of the layer at amplitude 0). Layers from Material must make a "blender-musgrave" volume layer of
# those settings and that mapping; its bake must be Cycles' (median <= MUSGRAVE_MEDIAN_DEG, p99
# <= MUSGRAVE_P99_DEG) and the same job without the layer's "dimension" and "lacunarity"
# (libsgbake's defaults, Blender's: 2 and 2) at least MUSGRAVE_CONTROL_FACTOR times worse.
MUSGRAVE_INPUTS = {"Scale": 3.0, "Detail": 3.5, "Dimension": 1.5, "Lacunarity": 2.3}
MUSGRAVE_MAPPING = ((-0.4, 0.3, 0.2), (0.2, 0.5, -0.6), (0.9, 1.2, 1.1))
MUSGRAVE_DISTANCE = 0.05
MUSGRAVE_LEAN_DEG = 35.0
MUSGRAVE_MEDIAN_DEG = 0.01
MUSGRAVE_P99_DEG = 0.01
MUSGRAVE_CONTROL_FACTOR = 3.0
# The same with a Ridged Multifractal (musgrave_ridged_case: MUSGRAVE_RIDGED_INPUTS, Distance
# MUSGRAVE_RIDGED_DISTANCE, the same mapping and bars): a "blender-musgrave" layer of type
# ridged-multifractal with its offset and gain; its control the layer left at fBM.
MUSGRAVE_RIDGED_INPUTS = {"Scale": 2.5, "Detail": 3.0, "Dimension": 1.2, "Lacunarity": 2.1,
                          "Offset": 0.9, "Gain": 1.7}
MUSGRAVE_RIDGED_DISTANCE = 0.02
# The Wave case (wave_case): a Wave Texture (WAVE_NODE, WAVE_INPUTS) on Suzanne's own object
# coordinates through a Mapping node (Point, WAVE_MAPPING) into the Bump (Distance
# WAVE_DISTANCE: Cycles' normals lean less than WAVE_LEAN_DEG off the surface's, as the
# Musgrave case checks). Layers from Material must make a "blender-wave" volume layer of those
# settings (its enums as WAVE_ENUMS) and that mapping; its bake must be Cycles' (median <=
# WAVE_MEDIAN_DEG, p99 <= WAVE_P99_DEG) and the same job without the layer's "phase" at least
# WAVE_CONTROL_FACTOR times worse.
WAVE_NODE = {"wave_type": "RINGS", "rings_direction": "SPHERICAL", "wave_profile": "SIN"}
WAVE_ENUMS = {"wave": "rings", "wave_direction": "spherical", "profile": "sine"}
WAVE_INPUTS = {"Scale": 1.5, "Distortion": 1.2, "Detail": 2.5, "Detail Scale": 1.3,
               "Detail Roughness": 0.6, "Phase Offset": 0.7}
WAVE_MAPPING = ((0.2, -0.3, 0.1), (0.3, -0.4, 0.5), (1.1, 0.9, 1.2))
WAVE_DISTANCE = 0.02
WAVE_LEAN_DEG = 35.0
WAVE_MEDIAN_DEG = 0.01
WAVE_P99_DEG = 0.01
WAVE_CONTROL_FACTOR = 3.0
# The Voronoi case (voronoi_case): a Voronoi Texture (VORONOI_NODE: F1, 3D, Euclidean;
# VORONOI_INPUTS) on Suzanne's own object coordinates through a Mapping node (Point,
# VORONOI_MAPPING), its Distance into the Bump (Distance VORONOI_DISTANCE: Cycles' normals lean
# less than VORONOI_LEAN_DEG off the surface's). Layers from Material must make a
# "blender-voronoi" volume layer of those settings (its metric as VORONOI_ENUMS) and that
# mapping; its bake must be Cycles' (median <= VORONOI_MEDIAN_DEG, p99 <= VORONOI_P99_DEG) and
# the same job without the layer's "mapping" at least VORONOI_CONTROL_FACTOR times worse.
# The Noise on UV case (noise_uv_case): the Noise Texture (NOISE_INPUTS) on Suzanne's UV map's
# coordinates (Texture Coordinate UV, (u, v, 0)) through a Mapping node (Point,
# NOISE_UV_MAPPING), Distance NOISE_UV_DISTANCE. Layers from Material must make a
# "blender-noise" volume layer on "coordinates": "uv" (its "uv" the render UV map's set); its
# bake must be Cycles' (median <= NOISE_MEDIAN_DEG, p99 <= NOISE_P99_DEG) and the same layer on
# the object's coordinates at least NOISE_CONTROL_FACTOR times worse.
NOISE_UV_MAPPING = ((0.2, -0.1, 0.3), (0.0, 0.0, 0.4), (3.0, 2.5, 1.0))
NOISE_UV_DISTANCE = 0.01
# The Brick case (brick_case): a Brick Texture (BRICK_INPUTS, its properties BRICK_PROPS as the
# layer's settings) on Suzanne's own coordinates through a Mapping node (BRICK_MAPPING), its Fac
# into the Bump (Distance BRICK_DISTANCE). Layers from Material must make a "blender-brick"
# volume layer of those settings; its bake must be Cycles' (NOISE_* bars) and the same job
# without the layer's "mapping" clearly worse.
BRICK_INPUTS = {"Scale": 3.0, "Mortar Size": 0.08, "Mortar Smooth": 1.0, "Brick Width": 0.6,
                "Row Height": 0.3}
BRICK_PROPS = {"brick_offset": 0.25, "offset_frequency": 3, "squash": 1.5, "squash_frequency": 2}
BRICK_MAPPING = ((0.1, 0.3, -0.2), (0.3, -0.2, 0.4), (1.1, 1.2, 0.9))
BRICK_DISTANCE = 0.005
# The Gradient and Magic cases (gradient_case, magic_case): a Gradient Texture (Quadratic Sphere)
# and a Magic Texture (MAGIC_INPUTS, Depth MAGIC_DEPTH) on Suzanne's own coordinates through a
# Mapping node, their Fac into the Bump: one "blender-gradient" (no "frequency": the node has no
# Scale) and one "blender-magic" volume layer, baked as Cycles bakes them (NOISE_* bars), the
# same jobs without the layer's "mapping" clearly worse.
GRADIENT_MAPPING = ((0.2, -0.1, 0.1), (0.2, 0.3, -0.4), (1.2, 1.0, 1.4))
GRADIENT_DISTANCE = 0.1
MAGIC_INPUTS = {"Scale": 1.3, "Distortion": 1.4}
MAGIC_DEPTH = 3
MAGIC_DISTANCE = 0.01
# The Noise on world positions case (noise_world_case): Suzanne moved, turned and scaled so.
NOISE_WORLD_PLACEMENT = ((0.4, -0.3, 0.2), (0.5, -0.3, 0.9), (1.4, 0.8, 1.2))
VORONOI_NODE = {"voronoi_dimensions": "3D", "feature": "F1", "distance": "EUCLIDEAN"}
VORONOI_ENUMS = {"metric": "euclidean"}
VORONOI_INPUTS = {"Scale": 4.0, "Randomness": 0.85, "Exponent": 0.5}
VORONOI_MAPPING = ((0.3, 0.2, -0.1), (-0.2, 0.4, 0.3), (1.2, 1.0, 0.9))
VORONOI_DISTANCE = 0.08
VORONOI_LEAN_DEG = 35.0
VORONOI_MEDIAN_DEG = 0.01
VORONOI_P99_DEG = 0.01
VORONOI_CONTROL_FACTOR = 3.0
# The same with Feature Output Distance to Edge (voronoi_edge_case: VORONOI_EDGE_INPUTS,
# Distance VORONOI_EDGE_DISTANCE, the same mapping and bars): a "blender-voronoi" layer of
# feature distance-to-edge; its control the layer left at F1.
VORONOI_EDGE_INPUTS = {"Scale": 3.0, "Randomness": 0.9}
VORONOI_EDGE_DISTANCE = 0.05

CASES = {
    "tangent-normal": ("tangent-normal", 0, 1, False, None),
    "object-normal": ("object-normal", 0, 1, False, None),
    "height": ("height", 0, 1, False, None),
    "derivative": ("derivative", 0, 1, False, None),
    "surface-gradient": ("surface-gradient", 0, 1, False, None),
    "tangent": ("tangent", 0, 1, False, None),
    "bitangent": ("bitangent", 0, 1, False, None),
    "mask": ("mask", 0, 1, False, None),
    "tangent-normal-padded": ("tangent-normal", 8, 2, True, 64),
    "object-normal-adjacent": ("object-normal", 8, 1, False, None),
}
# Cases padded otherwise than by the add-on's default, Extend.
CASE_PADDING = {"object-normal-adjacent": "adjacent-faces"}


# ---------------------------------------------------------------------------------------------
# Blender halves


def expect_error(name, substring, bake):
    """Runs bake() (a bpy.ops call) that must fail with an error report containing `substring`
    (bpy.ops turns an operator's ERROR report into RuntimeError). Returns a check record."""
    try:
        result = bake()
    except RuntimeError as exc:
        message = str(exc).strip()
        return {"name": name, "ok": substring in message, "message": message,
                "expected": substring}
    return {"name": name, "ok": False, "message": f"no error (returned {result})",
            "expected": substring}


def enable_addon(library_path):
    """Enables the add-on from plugin/ as a user would (so its preferences exist) and points
    its Library preference at `library_path`."""
    import addon_utils
    import bpy
    sys.path.insert(0, PLUGIN_DIR)

    def raise_error(exc):
        raise exc
    addon_utils.enable(ADDON, default_set=True, handle_error=raise_error)
    prefs = bpy.context.preferences.addons[ADDON].preferences
    prefs.library_path = library_path
    return prefs


def build_scene(work):
    """Suzanne with the bump material, every seventh face flat-shaded (the add-on must say so:
    flat faces are shaded per triangle); writes mesh.obj (with `s 0` / `s 1`) and height.exr.
    Returns (object, height image, Bump Distance)."""
    import bake_scene
    bc.reset_scene()
    ob = bake_scene.build_suzanne()
    me = ob.data
    for polygon in me.polygons:
        polygon.use_smooth = polygon.index % 7 != 0
    me.calc_normals_split()
    arrays = objio.mesh_arrays(me)
    arrays["smooth"] = [p.use_smooth for p in me.polygons]
    objio.write_obj(os.path.join(work, "mesh.obj"), arrays,
                    comment="add-on test Suzanne (tests/blender/addon_oracle.py)")
    side = bake_scene.HEIGHT_SIZE
    height = bc.new_float_image("height", side, side, bake_scene.height_field(side))
    bc.save_exr(height, os.path.join(work, "height.exr"))
    distance = bake_scene.CASES["suzanne"][2]
    mat, _ = bake_scene.make_material(height, distance)
    me.materials.append(mat)
    return ob, height, distance


def layers_from_material(settings, distance):
    """Runs "Layers from Material"; returns its manifest entry (with "error" when the layers
    are not the one bilinear height layer of 'height' with scale Distance and strength 1)."""
    import bpy
    result = bpy.ops.object.sgbake_layers_from_material()
    layers = [{"type": layer.type, "image": layer.image.name if layer.image else None,
               "scale": layer.scale, "filter": layer.filter} for layer in settings.layers]
    entry = {"result": sorted(result), "layers": layers}
    expected = {"type": "height", "image": "height", "filter": "bilinear"}
    if (len(layers) != 1 or any(layers[0][k] != v for k, v in expected.items())
            or abs(layers[0]["scale"] - distance) > 1e-7):  # float32 0.1 x 1
        entry["error"] = f"expected one {expected} layer with scale {distance}, got {layers}"
    # A Mapping node before the Image Texture: the layer is still made, and what it cannot
    # take over is named (the report then warns).
    from sgbake_blender import operators
    tree = bpy.context.active_object.active_material.node_tree
    tex = next(node for node in tree.nodes if node.type == "TEX_IMAGE")
    mapping = tree.nodes.new("ShaderNodeMapping")
    tree.links.new(mapping.outputs["Vector"], tex.inputs["Vector"])
    found, _, ignored = operators.material_layers(tree)
    tree.nodes.remove(mapping)
    # A Bump Strength is the layer's strength (Cycles' blend of normals), not part of its scale.
    bump = next(node for node in tree.nodes if node.type == "BUMP")
    bump.inputs["Strength"].default_value = 0.5
    weak, _, _ = operators.material_layers(tree)
    bump.inputs["Strength"].default_value = 1.0
    if len(weak) != 1 or abs(weak[0].get("strength", 1.0) - 0.5) > 1e-7 \
            or abs(weak[0]["scale"] - distance) > 1e-7:
        entry["error"] = f"a Bump Strength 0.5 should give strength 0.5, scale {distance}: {weak}"
    # A Strength fed by a texture is not a constant: named, the node's own value taken; fed by a
    # Math node of constants (clamped), folded as Cycles folds it, nothing named.
    noise = tree.nodes.new("ShaderNodeTexNoise")
    tree.links.new(noise.outputs["Fac"], bump.inputs["Strength"])
    _, _, textured = operators.material_layers(tree)
    tree.nodes.remove(noise)
    math = tree.nodes.new("ShaderNodeMath")
    math.operation, math.use_clamp = "SUBTRACT", True
    math.inputs[0].default_value, math.inputs[1].default_value = 0.25, 0.5
    tree.links.new(math.outputs[0], bump.inputs["Strength"])
    clamped, _, clamped_ignored = operators.material_layers(tree)
    tree.nodes.remove(math)
    if (not any("Strength from a node" in note for note in textured) or clamped_ignored
            or len(clamped) != 1 or clamped[0].get("strength", 1.0) != 0.0):
        entry["error"] = (f"a Strength from a Noise Texture should be named ({textured}); one "
                          f"from a clamped Math node of 0.25 - 0.5 should be 0 and nothing named "
                          f"({clamped}, {clamped_ignored})")
    _, _, none_ignored = operators.material_layers(tree)
    if len(found) != 1 or not any("Vector from 'Mapping'" in note for note in ignored) \
            or none_ignored:
        entry["error"] = (f"a Mapping node should be named as ignored (and nothing without "
                          f"it): {ignored}, then {none_ignored}")
    # Object coordinates into a Flat Image Texture: the height projected along z, a planar
    # layer (sgbake's "planar", which BlenderBakeOracle's planar cases check against Cycles),
    # nothing named; another object's coordinates are named instead.
    coordinates = tree.nodes.new("ShaderNodeTexCoord")
    tree.links.new(coordinates.outputs["Object"], tex.inputs["Vector"])
    planar, _, planar_ignored = operators.material_layers(tree)
    # Box projection there: sgbake's triplanar with "projection": "box" and the node's Blend
    # (BlenderBakeOracle's box cases check it against Cycles).
    # Its Bump Strength goes along (BlenderBakeOracle's box_strength_sphere checks the bake).
    tex.projection, tex.projection_blend = "BOX", 0.25
    bump.inputs["Strength"].default_value = 0.5
    box, _, box_ignored = operators.material_layers(tree)
    bump.inputs["Strength"].default_value = 1.0
    # A Mapping node (Point) between them: its Location, Rotation and Scale, nothing named.
    mapping = tree.nodes.new("ShaderNodeMapping")
    moved = {"Location": (0.5, -0.25, 1.0), "Rotation": (0.1, 0.2, 0.3), "Scale": (2.0, 1.0, 0.5)}
    for name, value in moved.items():
        mapping.inputs[name].default_value = value
    tree.links.new(coordinates.outputs["Object"], mapping.inputs["Vector"])
    tree.links.new(mapping.outputs["Vector"], tex.inputs["Vector"])
    mapped, _, mapped_ignored = operators.material_layers(tree)
    # Its type goes along (Vector: no Location); Normal, which normalizes, is named instead.
    mapping.vector_type = "VECTOR"
    vector, _, _ = operators.material_layers(tree)
    mapping.vector_type = "NORMAL"
    normal, _, normal_ignored = operators.material_layers(tree)
    tree.nodes.remove(mapping)
    # Another object's coordinates (an Empty as a projector) and the Generated ones, given the
    # baked object: an affine map of its own, row by row (BlenderBakeOracle's box_empty_sphere
    # and box_generated_sphere check such maps against Cycles).
    ob = bpy.context.active_object
    empty = bpy.data.objects.new("projector", None)
    bpy.context.scene.collection.objects.link(empty)
    empty.location, empty.rotation_euler, empty.scale = (0.2, 0.4, -0.3), (0.3, -0.5, 0.2), \
        (0.7, 1.3, 0.9)
    bpy.context.view_layer.update()
    coordinates.object = empty
    tree.links.new(coordinates.outputs["Object"], tex.inputs["Vector"])
    projector, _, projector_ignored = operators.material_layers(tree, None, ob)
    want = empty.matrix_world.inverted() @ ob.matrix_world
    coordinates.object = None
    tree.links.new(coordinates.outputs["Generated"], tex.inputs["Vector"])
    generated, _, _ = operators.material_layers(tree, None, ob)
    bpy.data.objects.remove(empty)
    tree.links.new(coordinates.outputs["Object"], tex.inputs["Vector"])
    got = projector[0].get("mapping_matrix", ()) if len(projector) == 1 else ()
    size = ob.data.texspace_size
    gen = generated[0].get("mapping_matrix", ()) if len(generated) == 1 else ()
    if (len(got) != 12 or projector_ignored
            or max(abs(got[4 * r + c] - want[r][c]) for r in range(3) for c in range(4)) > 1e-6
            or len(gen) != 12 or abs(gen[0] - 0.5 / size[0]) > 1e-6):
        entry["error"] = (f"an Empty's coordinates should give mapping_matrix {list(want)} and "
                          f"nothing named, the Generated ones 0.5 / size first: {projector}, "
                          f"{projector_ignored}, {generated}")
    tex.projection = "FLAT"
    coordinates.object = bpy.context.active_object
    _, _, other_ignored = operators.material_layers(tree)
    tree.nodes.remove(coordinates)
    expected_planar = {"type": "planar", "kind": "height", "axis": "z", "slopes": "bump-node"}
    if (len(planar) != 1 or any(planar[0].get(k) != v for k, v in expected_planar.items())
            or "uv_map" in planar[0] or abs(planar[0]["scale"] - distance) > 1e-7
            or planar_ignored
            or not any("Vector from 'Texture Coordinate'" in n for n in other_ignored)):
        entry["error"] = (f"Object coordinates should make one {expected_planar} layer of "
                          f"scale {distance}, nothing named: {planar}, {planar_ignored}; "
                          f"another object's named: {other_ignored}")
    expected_box = {"type": "triplanar", "kind": "height", "projection": "box",
                    "slopes": "bump-node", "strength": 0.5}
    if (len(box) != 1 or any(box[0].get(k) != v for k, v in expected_box.items())
            or abs(box[0].get("box_blend", -1) - 0.25) > 1e-7 or "uv_map" in box[0]
            or box_ignored):
        entry["error"] = (f"a Box projection on object coordinates (Bump Strength 0.5) should "
                          f"make one {expected_box} layer with box_blend 0.25, nothing named: "
                          f"{box}, {box_ignored}")
    got = mapped[0] if len(mapped) == 1 else {}
    if (got.get("type") != "triplanar" or mapped_ignored
            or any(max((abs(a - b) for a, b in zip(got.get(f"mapping_{name.lower()}", ()),
                                                   value)), default=1) > 1e-6
                   for name, value in moved.items())):
        entry["error"] = (f"a Mapping node between the coordinates and the Box projection should "
                          f"give its {moved}, nothing named: {mapped}, {mapped_ignored}")
    if (got.get("mapping_type") != "POINT" or len(vector) != 1
            or vector[0].get("mapping_type") != "VECTOR"
            or not any("Vector from 'Mapping'" in n for n in normal_ignored)):
        entry["error"] = (f"a Mapping node's type should go along (POINT, VECTOR: {mapped}, "
                          f"{vector}) and type Normal be named: {normal}, {normal_ignored}")
    return entry


def bake_cases(settings, ob, work, sabotage):
    """Bakes every case of CASES with the add-on's operator; saves the image it filled as
    addon_CASE.npy. Returns {case: manifest entry}."""
    import bpy
    import numpy as np
    cases = {}
    for case, (kind, margin, samples, alpha, target_side) in CASES.items():
        settings.map = kind
        settings.width = settings.height = SIZE
        settings.margin, settings.samples, settings.use_alpha = margin, samples, alpha
        settings.padding = CASE_PADDING.get(case, "extend")  # (the add-on's default: Adjacent Faces)
        settings.green = "directx" if sabotage else "opengl"
        settings.target_image = (bc.new_float_image(f"target_{case}", target_side, target_side)
                                 if target_side else None)
        entry = cases[case] = {"map": kind, "margin": margin, "samples": samples, "alpha": alpha,
                               "padding": settings.padding}
        try:
            entry["result"] = sorted(bpy.ops.object.sgbake_bake())
        except RuntimeError as exc:  # the operator reported an error
            entry.update(result=["ERROR"], error=str(exc).strip())
            continue
        image = settings.target_image or bpy.data.images[f"{ob.name}_{kind}"]
        np.save(os.path.join(work, f"addon_{case}.npy"), bc.image_array(image))
        entry.update(image=image.name, image_size=list(image.size))
    settings.target_image = None
    settings.padding = "extend"  # what the bakes after these expect
    return cases


def error_reports(settings, prefs, height, work, library_path):
    """Bakes that must end in an error report; returns their check records."""
    import bpy
    bake = bpy.ops.object.sgbake_bake
    checks = []
    settings.map = "tangent-normal"
    layer = settings.layers.add()
    layer.name = "empty"
    checks.append(expect_error("layer without an image", "has no image", bake))
    layer.weight = 0.0  # turned off: it needs no image
    try:
        off = sorted(bake())
    except RuntimeError as exc:
        off = ["ERROR", str(exc).strip()]
    checks.append({"name": "a layer of weight 0 without an image is left out", "ok": off == [
        "FINISHED"], "expected": "FINISHED", "message": str(off)})
    layer.weight = 1.0
    layer.type, layer.image, layer.filter = "normal", height, "hermite"
    checks.append(expect_error("scene refused by libsgbake", "filter 'hermite' is only", bake))
    layer.filter = "bilinear"
    layer.mask_image, layer.mask_uv_map = height, "NoSuchMap"
    checks.append(expect_error("mask on a UV map the object lacks",
                               "has no UV map 'NoSuchMap' (used by the mask of layer", bake))
    layer.mask_uv_map = ""
    tiled = bpy.data.images.new("tiled_input", 8, 8, float_buffer=True, tiled=True)
    layer.mask_image = tiled
    checks.append(expect_error("generated UDIM image as a mask",
                               "'tiled_input' is a UDIM image whose tiles are not files", bake))
    layer.mask_image, layer.image = None, tiled
    checks.append(expect_error("generated UDIM image as a layer",
                               "'tiled_input' is a UDIM image whose tiles are not files", bake))
    settings.layers.remove(len(settings.layers) - 1)

    # A target whose file went missing, and a size no machine here holds: one-line reports
    # before the bake, no traceback and no image made.
    images_before = set(bpy.data.images.keys())
    gone = bpy.data.images.new("gone_target", 8, 8)
    gone.filepath_raw = os.path.join(work, "missing", "gone_target.png")
    gone.source = "FILE"
    gone.reload()
    settings.target_image = gone
    checks.append(expect_error("target image whose file is missing", "has no pixels", bake))
    settings.target_image = None
    bpy.data.images.remove(gone)
    width, height_px = settings.width, settings.height
    settings.width = settings.height = 65536
    checks.append(expect_error("a size beyond the machine's memory", "GiB, more than this "
                               "machine's", bake))
    settings.width, settings.height = width, height_px
    stray = set(bpy.data.images.keys()) - images_before
    checks.append({"name": "refused bakes leave no image", "ok": not stray,
                   "expected": "no new image", "message": f"new images {sorted(stray)}"})

    prefs.library_path = os.path.join(work, "missing", "libsgbake.so")
    checks.append(expect_error("library path that does not exist", "does not exist", bake))
    prefs.library_path = library_path

    plain = bpy.data.meshes.new("no_uv")
    plain.from_pydata([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [], [(0, 1, 2, 3)])
    plain_ob = bpy.data.objects.new("no_uv", plain)
    bpy.context.scene.collection.objects.link(plain_ob)
    bpy.context.view_layer.objects.active = plain_ob
    checks.append(expect_error("object without a UV map", "has no UV map", bake))
    bpy.context.view_layer.objects.active = None
    checks.append(expect_error("no active object", "must be a mesh", bake))
    return checks


def material_checks(settings, ob, distance):
    """Layers from Material on chains and strays, the UV map textures are read on, and what a
    bake takes from the object (its transform, a Subdivision Surface's render levels). Returns
    check records like expect_error's."""
    import bpy
    import numpy as np
    from sgbake_blender import operators
    tree = ob.active_material.node_tree
    tex = next(node for node in tree.nodes if node.type == "TEX_IMAGE" and node.image)
    bump = next(node for node in tree.nodes if node.type == "BUMP")
    checks = []

    def check(name, ok, expected, message):
        checks.append({"name": name, "ok": bool(ok), "expected": expected, "message": message})

    # A Normal Map node into the Bump's Normal input: its layer first, the height on top of it.
    nmap = tree.nodes.new("ShaderNodeNormalMap")
    tree.links.new(tex.outputs["Color"], nmap.inputs["Color"])
    tree.links.new(nmap.outputs["Normal"], bump.inputs["Normal"])
    chain, _, _ = operators.material_layers(tree)
    check("Layers from Material: Normal Map into a Bump's Normal",
          [(v["type"], v.get("base", "surface")) for v in chain]
          == [("normal", "surface"), ("height", "above")],
          "a normal layer, then the height with base 'above'", str(chain))
    # Its image read on UV2 through a UV Map node, its own UV Map empty: the tangents are the
    # render UV map's (Cycles), the lookup UV2's.
    uvmap = tree.nodes.new("ShaderNodeUVMap")
    uvmap.uv_map = "UV2"
    tree.links.new(uvmap.outputs["UV"], tex.inputs["Vector"])
    split, _, _ = operators.material_layers(tree, "UVMap")
    normal = next((v for v in split if v["type"] == "normal"), {})
    check("Layers from Material: a Normal Map's tangents on another UV map than its image",
          normal.get("uv_map") == "UV2" and normal.get("tangent_uv_map") == "UVMap",
          "uv_map 'UV2', tangent_uv_map 'UVMap'", str(normal))
    tree.nodes.remove(uvmap)
    # Its image read with Box projection on object coordinates: a triplanar Box layer of the
    # node's space, decoded in the frames of the node's UV map (BlenderBakeOracle's
    # box_nmap_sphere checks such a layer against Cycles); with Flat projection, a planar Flat
    # layer (flat_nmap_sphere).
    coordinates = tree.nodes.new("ShaderNodeTexCoord")
    tree.links.new(coordinates.outputs["Object"], tex.inputs["Vector"])
    tex.projection, tex.projection_blend, nmap.uv_map = "BOX", 0.2, "UV2"
    boxed, _, boxed_ignored = operators.material_layers(tree, "UVMap")
    boxed_normal = next((v for v in boxed if v["type"] != "height"), {})
    tex.projection = "FLAT"
    flat, _, flat_ignored = operators.material_layers(tree, "UVMap")
    flat_normal = next((v for v in flat if v["type"] != "height"), {})
    # Sphere and Tube: planar layers with those projections (sphere_nmap_sphere and
    # tube_nmap_sphere_object check such layers against Cycles).
    wrapped = {}
    for projection in ("SPHERE", "TUBE"):
        tex.projection = projection
        layers, _, named = operators.material_layers(tree, "UVMap")
        wrapped[projection] = (next((v for v in layers if v["type"] != "height"), {}), named)
    tex.projection, nmap.uv_map = "FLAT", ""
    tree.nodes.remove(coordinates)
    check("Layers from Material: a Normal Map of a Sphere- or Tube-projected image",
          all(layer.get("type") == "planar" and layer.get("planar_projection") == proj.lower()
              and layer.get("tangent_uv_map") == "UV2" and "uv_map" not in layer
              and not any(tex.name in note for note in named)
              for proj, (layer, named) in wrapped.items()),
          "planar layers, planar_projection sphere and tube, tangent_uv_map 'UV2', nothing "
          "named", str(wrapped))
    want = {"type": "triplanar", "kind": "tangent-normal", "projection": "box",
            "tangent_uv_map": "UV2"}
    want_flat = {"type": "planar", "kind": "tangent-normal", "planar_projection": "flat",
                 "axis": "z", "tangent_uv_map": "UV2"}
    check("Layers from Material: a Normal Map of a Box- or Flat-projected image",
          all(boxed_normal.get(k) == v for k, v in want.items())
          and abs(boxed_normal.get("box_blend", -1) - 0.2) < 1e-6 and "uv_map" not in boxed_normal
          and not any(tex.name in note for note in boxed_ignored)
          and all(flat_normal.get(k) == v for k, v in want_flat.items())
          and not any(tex.name in note for note in flat_ignored),
          f"{want}, box_blend 0.2; Flat: {want_flat}; nothing named",
          f"{boxed_normal}; named {boxed_ignored}; Flat: {flat_normal}, named {flat_ignored}")
    # Its colour split and combined again with G flipped by a Math node (1 - G): a DirectX
    # map turned into Blender's convention, the layer's Green DirectX; not flipped, OpenGL;
    # the channels crossed, no layer.
    split = tree.nodes.new("ShaderNodeSeparateColor")
    joined = tree.nodes.new("ShaderNodeCombineColor")
    flip = tree.nodes.new("ShaderNodeMath")
    flip.operation, flip.inputs[0].default_value = "SUBTRACT", 1.0
    tree.links.new(tex.outputs["Color"], split.inputs[0])
    tree.links.new(split.outputs["Red"], joined.inputs["Red"])
    tree.links.new(split.outputs["Green"], flip.inputs[1])
    tree.links.new(flip.outputs[0], joined.inputs["Green"])
    tree.links.new(split.outputs["Blue"], joined.inputs["Blue"])
    tree.links.new(joined.outputs[0], nmap.inputs["Color"])
    recombined = {}
    for state in ("directx", "opengl", "crossed"):
        if state == "opengl":
            tree.links.new(split.outputs["Green"], joined.inputs["Green"])
        if state == "crossed":
            tree.links.new(split.outputs["Green"], joined.inputs["Red"])
        layers, _, _ = operators.material_layers(tree, "UVMap")
        recombined[state] = [v.get("green", "opengl") for v in layers if v["type"] == "normal"]
    for node in (split, joined, flip):
        tree.nodes.remove(node)
    tree.links.new(tex.outputs["Color"], nmap.inputs["Color"])
    check("Layers from Material: a Normal Map's colour split and combined again",
          recombined == {"directx": ["directx"], "opengl": ["opengl"], "crossed": []},
          "green directx with G flipped, opengl without, no layer with the channels crossed",
          str(recombined))
    tree.nodes.remove(nmap)
    # A Bump node linked to nothing makes no layer.
    stray = tree.nodes.new("ShaderNodeBump")
    tree.links.new(tex.outputs["Color"], stray.inputs["Height"])
    found, skipped, _ = operators.material_layers(tree)
    check("Layers from Material: a Bump linked to nothing",
          len(found) == 1 and any("not linked" in note for note in skipped),
          "one layer, the stray Bump skipped", f"{found}; skipped {skipped}")
    tree.nodes.remove(stray)
    # A shader without a bump mixed with the bumped one is named (Cycles averages normals).
    diffuse = next(node for node in tree.nodes if node.type == "BSDF_DIFFUSE")
    plain = tree.nodes.new("ShaderNodeBsdfGlossy")
    mix = tree.nodes.new("ShaderNodeMixShader")
    add = diffuse.outputs["BSDF"].links[0].to_node
    tree.links.new(diffuse.outputs["BSDF"], mix.inputs[1])
    tree.links.new(plain.outputs["BSDF"], mix.inputs[2])
    tree.links.new(mix.outputs["Shader"], add.inputs[0])
    _, _, mixed = operators.material_layers(tree)
    check("Layers from Material: an unbumped shader mixed in",
          any(f"'{plain.name}' has no bump" in note for note in mixed), "a note", str(mixed))
    tree.links.new(diffuse.outputs["BSDF"], add.inputs[0])
    tree.nodes.remove(mix)
    tree.nodes.remove(plain)
    _, _, plain_notes = operators.material_layers(tree)
    check("Layers from Material: no note for the plain material", not plain_notes,
          "no note", str(plain_notes))
    # The texture and the Bump inside a node group (its Distance a group input, fed from
    # outside by a Value node; its Normal the group's output into the shader), in a group in a
    # group: the same layer as the Bump made outside, the nodes named by their path.
    direct, _, _ = operators.material_layers(tree)
    inner = bpy.data.node_groups.new("sgbake inner", "ShaderNodeTree")
    inner.inputs.new("NodeSocketFloat", "Distance")
    inner.outputs.new("NodeSocketVector", "Normal")
    inner_in, inner_out = inner.nodes.new("NodeGroupInput"), inner.nodes.new("NodeGroupOutput")
    inner_tex = inner.nodes.new("ShaderNodeTexImage")
    inner_tex.image, inner_tex.interpolation = tex.image, "Closest"  # (named, by its path)
    inner_bump = inner.nodes.new("ShaderNodeBump")
    inner_bump.inputs["Distance"].default_value = 5.0  # (its own value: not the one used)
    inner.links.new(inner_tex.outputs["Color"], inner_bump.inputs["Height"])
    inner.links.new(inner_in.outputs["Distance"], inner_bump.inputs["Distance"])
    inner.links.new(inner_bump.outputs["Normal"], inner_out.inputs["Normal"])
    outer = bpy.data.node_groups.new("sgbake outer", "ShaderNodeTree")
    outer.inputs.new("NodeSocketFloat", "Distance")
    outer.outputs.new("NodeSocketVector", "Normal")
    outer_in, outer_out = outer.nodes.new("NodeGroupInput"), outer.nodes.new("NodeGroupOutput")
    nested = outer.nodes.new("ShaderNodeGroup")
    nested.node_tree = inner
    outer.links.new(outer_in.outputs["Distance"], nested.inputs["Distance"])
    outer.links.new(nested.outputs["Normal"], outer_out.inputs["Normal"])
    grouped = tree.nodes.new("ShaderNodeGroup")
    grouped.node_tree = outer
    value = tree.nodes.new("ShaderNodeValue")
    value.outputs[0].default_value = distance
    tree.links.new(value.outputs[0], grouped.inputs["Distance"])
    tree.links.new(grouped.outputs["Normal"], diffuse.inputs["Normal"])
    in_groups, skipped_groups, named_groups = operators.material_layers(tree)
    path = f"{grouped.name}/{nested.name}/{inner_tex.name}"
    tree.links.new(bump.outputs["Normal"], diffuse.inputs["Normal"])
    tree.nodes.remove(grouped)
    tree.nodes.remove(value)
    bpy.data.node_groups.remove(outer)
    bpy.data.node_groups.remove(inner)
    keys = ("type", "image", "filter", "wrap", "slopes", "strength", "scale")
    check("Layers from Material: a Bump inside a group inside a group",
          len(in_groups) == 1 and len(direct) == 1
          and all(in_groups[0].get(k) == direct[0].get(k) for k in keys)
          and named_groups == [f"'{path}' Closest interpolation (read bilinear)"]
          and any(f"'{bump.name}': not linked" in n for n in skipped_groups)
          and not bpy.data.materials.get("sgbake flattened"),
          f"the direct layer {[{k: direct[0].get(k) for k in keys}] if direct else direct}, "
          f"'{path}' named, the Bump outside skipped, no flattened material left",
          f"{in_groups}, {skipped_groups}, {named_groups}")
    # A height through nodes that change it affinely (Math x 0.5, then Map Range 0..1 to
    # 0.2..0.8: x 0.3 in all) scales the layer, with no remap; through Separate Color's Green,
    # channel g; a clamped Math node is not affine: a remap, 0.2 + 0.6 clamp(0.5 h, 0, 1)
    # (remap_checks checks such chains closely), the scale the Distance.
    half = tree.nodes.new("ShaderNodeMath")
    half.operation, half.inputs[1].default_value = "MULTIPLY", 0.5
    ranged = tree.nodes.new("ShaderNodeMapRange")
    ranged.clamp = False
    ranged.inputs["To Min"].default_value, ranged.inputs["To Max"].default_value = 0.2, 0.8
    tree.links.new(tex.outputs["Color"], half.inputs[0])
    tree.links.new(half.outputs[0], ranged.inputs["Value"])
    tree.links.new(ranged.outputs["Result"], bump.inputs["Height"])
    affine, _, affine_notes = operators.material_layers(tree)
    half.use_clamp = True
    clamped, clamped_skipped, _ = operators.material_layers(tree)
    separate = tree.nodes.new("ShaderNodeSeparateColor")
    tree.links.new(tex.outputs["Color"], separate.inputs[0])
    tree.links.new(separate.outputs["Green"], bump.inputs["Height"])
    green, _, _ = operators.material_layers(tree)
    invert = tree.nodes.new("ShaderNodeInvert")  # Fac 1: 1 - h, the bump turned over
    tree.links.new(tex.outputs["Color"], invert.inputs["Color"])
    tree.links.new(invert.outputs["Color"], bump.inputs["Height"])
    inverted, _, _ = operators.material_layers(tree)
    tree.links.new(tex.outputs["Color"], bump.inputs["Height"])
    for extra in (half, ranged, separate, invert):
        tree.nodes.remove(extra)
    check("Layers from Material: a height through Math, Map Range, Separate Color, Invert nodes",
          len(affine) == 1 and abs(affine[0]["scale"] - 0.3 * distance) < 1e-7
          and "remap" not in affine[0] and not affine_notes and len(clamped) == 1
          and abs(clamped[0]["scale"] - distance) < 1e-7
          and all(abs(remap_at(clamped[0].get("remap") or [[0, 0], [1, 0]], x)
                      - (0.2 + 0.6 * min(max(0.5 * x, 0.0), 1.0))) < 1e-7
                  for x in (-0.5, 0.3, 1.7, 2.5)) and not clamped_skipped
          and len(green) == 1 and green[0].get("channel") == "g"
          and abs(green[0]["scale"] - distance) < 1e-7
          and len(inverted) == 1 and abs(inverted[0]["scale"] + distance) < 1e-7,
          f"scale {0.3 * distance:.4g}, no remap, nothing named; clamped: scale "
          f"{distance:.4g}, remap 0.2 + 0.6 clamp(0.5 h, 0, 1); Green: channel g; "
          f"Invert: scale {-distance:.4g}",
          f"{affine}, {affine_notes}; {clamped}, {clamped_skipped}; {green}; {inverted}")
    # The Material Output's Displacement: with Displacement only (true displacement) it is
    # skipped and named; in object space on Suzanne scaled unevenly, a layer of height space
    # object; where every shader's normal comes from a Normal Map (which does not start from
    # the displaced normal) it is not baked, as in Cycles.
    material = ob.active_material
    output = tree.get_output_node("CYCLES")
    displace = tree.nodes.new("ShaderNodeDisplacement")
    displace.inputs["Scale"].default_value = 0.2
    tree.links.new(tex.outputs["Color"], displace.inputs["Height"])
    tree.links.new(displace.outputs["Displacement"], output.inputs["Displacement"])
    material.cycles.displacement_method = "DISPLACEMENT"
    true_found, true_skipped, _ = operators.object_layers([(None, material)], None, ob)
    material.cycles.displacement_method = "BUMP"
    displace.space = "OBJECT"
    scale = tuple(ob.scale)
    ob.scale = (2.0, 1.0, 0.8)
    bpy.context.view_layer.update()
    object_found, _, object_notes = operators.object_layers([(None, material)], None, ob)
    ob.scale = scale
    bpy.context.view_layer.update()
    mapped = tree.nodes.new("ShaderNodeNormalMap")
    tree.links.new(tex.outputs["Color"], mapped.inputs["Color"])
    tree.links.new(mapped.outputs["Normal"], diffuse.inputs["Normal"])
    tree.links.new(tex.outputs["Color"], mapped.inputs["Color"])
    mapped_found, mapped_skipped, _ = operators.material_layers(tree, None, ob)
    tree.links.new(bump.outputs["Normal"], diffuse.inputs["Normal"])
    tree.nodes.remove(mapped)
    tree.nodes.remove(displace)
    check("Layers from Material: the output's Displacement, true, in object space, under a "
          "Normal Map",
          len(true_found) == 1 and any("displaces the mesh" in n for n in true_skipped)
          and len(object_found) == 2 and abs(object_found[0]["scale"] - 0.2) < 1e-6
          and object_found[0].get("height_space") == "object"
          and object_found[1].get("base") == "above" and not object_notes
          and not any(v["type"] == "height" and v.get("base") != "above"
                      for v in mapped_found if v is not mapped_found[-1])
          and any("no shader takes the displaced normal" in n for n in mapped_skipped),
          "skipped as true displacement; scale 0.2 in object space then the Bump above it, "
          "nothing named; not baked under a Normal Map",
          f"{true_found}, {true_skipped}; {object_found}, {object_notes}; {mapped_found}, "
          f"{mapped_skipped}")
    # A Principled BSDF bumped through Normal: its clearcoat (a closure on Clearcoat Normal) is
    # named while it is on and unbumped.
    principled = tree.nodes.new("ShaderNodeBsdfPrincipled")
    tree.links.new(bump.outputs["Normal"], principled.inputs["Normal"])
    tree.links.new(principled.outputs["BSDF"], add.inputs[0])
    coat_notes = {}
    for state in ("off", "on", "bumped"):
        principled.inputs["Clearcoat"].default_value = 0.0 if state == "off" else 0.5
        if state == "bumped":
            tree.links.new(bump.outputs["Normal"], principled.inputs["Clearcoat Normal"])
        coat_notes[state] = [note for note in operators.material_layers(tree)[2]
                             if "clearcoat" in note]
    check("Layers from Material: an unbumped clearcoat on a bumped Principled BSDF",
          not coat_notes["off"] and len(coat_notes["on"]) == 1 and not coat_notes["bumped"],
          "a note with Clearcoat 0.5 only", str(coat_notes))
    tree.links.new(diffuse.outputs["BSDF"], add.inputs[0])
    tree.nodes.remove(principled)
    # A Bump fed by the texture's Alpha output reads the alpha channel.
    tree.links.new(tex.outputs["Alpha"], bump.inputs["Height"])
    alpha, _, _ = operators.material_layers(tree)
    tree.links.new(tex.outputs["Color"], bump.inputs["Height"])
    check("Layers from Material: a Height from the Alpha output",
          len(alpha) == 1 and alpha[0].get("channel") == "a", "channel 'a'", str(alpha))
    # Reroute nodes between the image and the Bump's Height are followed (the Alpha output
    # still told apart); a muted link feeds nothing (Cycles takes the socket's own value).
    first = tree.nodes.new("NodeReroute")
    second = tree.nodes.new("NodeReroute")
    tree.links.new(tex.outputs["Alpha"], first.inputs[0])
    tree.links.new(first.outputs[0], second.inputs[0])
    tree.links.new(second.outputs[0], bump.inputs["Height"])
    rerouted, _, _ = operators.material_layers(tree)
    check("Layers from Material: a Height through two Reroute nodes",
          len(rerouted) == 1 and rerouted[0].get("image") == tex.image
          and rerouted[0].get("channel") == "a", f"one layer of '{tex.image.name}', channel 'a'",
          str(rerouted))
    second.inputs[0].links[0].is_muted = True
    muted, muted_skipped, _ = operators.material_layers(tree)
    check("Layers from Material: a muted link into the Height",
          not muted and any("muted" in note for note in muted_skipped),
          "no layer, skipped as muted", f"{muted}; skipped {muted_skipped}")
    tree.nodes.remove(first)
    tree.nodes.remove(second)
    tree.links.new(tex.outputs["Color"], bump.inputs["Height"])
    # An Image Texture without a UV Map node is read on the UV map active for rendering.
    render_uv, _, _ = operators.material_layers(tree, "UVMap")
    check("Layers from Material: the render UV map",
          len(render_uv) == 1 and render_uv[0].get("uv_map") == "UVMap",
          "uv_map 'UVMap'", str(render_uv))

    # A transformed object: the scene carries its matrix_world ("transform", with which
    # libsgbake shades it in world space as Cycles does) and the height's Scale as it is (world
    # units, the Bump Distance), for an even scale as for an uneven one, without a note.
    settings.map = "tangent-normal"
    layer_scale = float(settings.layers[0].scale)
    for what, scale in (("scaled 2x", (2.0, 2.0, 2.0)), ("scaled unevenly", (1.0, 2.0, 1.0))):
        ob.scale = scale
        bpy.context.view_layer.update()
        job = operators.BakeJob(bpy.context)
        rows = [[float(v) for v in row] for row in ob.matrix_world]
        sent = job.scene.get("transform")
        scale_sent = job.scene["layers"][0]["scale"]
        check(f"bake: an object {what} sends its matrix_world and the height's Scale as it is",
              sent == rows and scale_sent == layer_scale and abs(scale_sent - distance) < 1e-7
              and not job.notes,
              f"transform {rows}, scale {layer_scale}, no note",
              f"transform {sent}, scale {scale_sent}, notes {job.notes}")
    # A zero scale has no world normals: the bake falls back to object space, with a note
    # naming the object (the maps the transform does not change get none).
    ob.scale = (1.0, 0.0, 1.0)
    bpy.context.view_layer.update()
    job = operators.BakeJob(bpy.context)
    check("bake: an object of zero scale is baked in object space, with a note",
          "transform" not in job.scene and job.scene["layers"][0]["scale"] == layer_scale
          and any(f"object '{ob.name}' has a zero scale" in n for n in job.notes),
          "no transform, the Scale as it is, a note", f"{sorted(job.scene)}, {job.notes}")
    settings.map = "height"
    job = operators.BakeJob(bpy.context)
    check("bake: no zero-scale note for a map the transform does not change",
          not job.notes, "no note", str(job.notes))
    settings.map = "tangent-normal"
    # A translation alone changes nothing: the pixels at the origin (within TOLERANCE: each
    # to_mesh() may move a normal by an ulp, see the module docstring).
    ob.scale = (1.0, 1.0, 1.0)
    settings.width = settings.height = 64
    bpy.context.view_layer.update()
    at_origin = operators.BakeJob(bpy.context)
    ob.location = (0.5, -2.0, 3.0)
    bpy.context.view_layer.update()
    moved = operators.BakeJob(bpy.context)
    at_origin.run()
    moved.run()
    apart = (float(np.abs(at_origin.rgba[1001] - moved.rgba[1001]).max())
             if at_origin.error is None and moved.error is None else None)
    check("bake: a translated object bakes as at the origin",
          apart is not None and apart <= TOLERANCE and "transform" not in at_origin.scene,
          f"pixels within {TOLERANCE:g}, no transform at the origin",
          f"errors {at_origin.error} / {moved.error}, max difference {apart}, origin's "
          f"scene keys {sorted(at_origin.scene)}")
    ob.location = (0.0, 0.0, 0.0)
    settings.width = settings.height = SIZE
    bpy.context.view_layer.update()
    # A Subdivision Surface at other render levels than viewport levels bakes its render
    # levels (as Cycles does), and its viewport levels are set back; one hidden for rendering
    # is left out.
    faces = len(ob.data.polygons)
    modifier = ob.modifiers.new("Subdivision", "SUBSURF")
    modifier.levels, modifier.render_levels = 0, 1
    bpy.context.view_layer.update()
    job = operators.BakeJob(bpy.context)
    baked = len(job.arrays[1]) - 1  # face_start has #F + 1 entries
    quads = len(ob.data.loops)  # level 1 makes a quad of each corner
    check("bake: a Subdivision Surface's render levels",
          baked == quads and modifier.levels == 0 and modifier.show_viewport,
          f"{quads} faces, viewport levels 0 again", f"{baked} faces (of {faces}), levels "
          f"{modifier.levels}")
    modifier.levels, modifier.show_render = 1, False
    bpy.context.view_layer.update()
    job = operators.BakeJob(bpy.context)
    baked = len(job.arrays[1]) - 1
    check("bake: a modifier hidden for rendering", baked == faces and modifier.show_viewport,
          f"{faces} faces, shown in the viewport again", f"{baked} faces")
    ob.modifiers.remove(modifier)
    bpy.context.view_layer.update()
    return checks


# The remap checks: Layers from Material's "remap" against the chain computed here, at
# REMAP_SAMPLES values of x in [-0.5, 1.5] (seeded, so that none falls on a step's x), within
# REMAP_TOLERANCE.
REMAP_SAMPLES = 1000
REMAP_TOLERANCE = 1e-6
# Cycles' colour into a float input (its rgb_to_y, measured: an Emission bake of R, G and B).
REMAP_LUMINANCE = (0.212672979, 0.715152621, 0.072175443)
# The Color Ramp of the remap checks and of remap_case: (position, colour) of three stops whose
# luminances rise and fall (0.27, 0.64, 0.23), Ease between them.
REMAP_STOPS = ((0.15, (0.9, 0.1, 0.1, 1.0)), (0.5, (0.2, 0.8, 0.3, 1.0)),
               (0.85, (0.1, 0.2, 0.9, 0.6)))


def remap_at(points, x):
    """The scene's "remap" through `points` at x: linear between points, constant beyond the
    ends, at a step (two points of one x) the second's value."""
    if x < points[0][0]:
        return points[0][1]
    for (x0, y0), (x1, y1) in zip(points, points[1:]):
        if x0 <= x < x1:
            return y0 + (x - x0) * (y1 - y0) / (x1 - x0)
    return points[-1][1]


def cycles_ramp(ramp, fac):
    """Cycles' Color Ramp at `fac`, computed here: its table of 256 colours ramp(i / 255), read
    at fac clamped to [0, 1] times 255, between entries i and i + 1 (entry i alone when the ramp
    is Constant). RGBA."""
    f = min(max(fac, 0.0), 1.0) * 255
    i = int(f)
    t = f - i
    low = ramp.evaluate(i / 255)
    if ramp.interpolation == "CONSTANT" or t == 0:
        return tuple(low)
    high = ramp.evaluate((i + 1) / 255)
    return tuple((1 - t) * a + t * b for a, b in zip(low, high))


def make_ramp(tree, interpolation="EASE"):
    """A Color Ramp node of REMAP_STOPS with `interpolation`."""
    node = tree.nodes.new("ShaderNodeValToRGB")
    ramp = node.color_ramp
    ramp.interpolation = interpolation
    ramp.elements[0].position, ramp.elements[0].color = REMAP_STOPS[0]
    ramp.elements[1].position, ramp.elements[1].color = REMAP_STOPS[2]
    middle = ramp.elements.new(REMAP_STOPS[1][0])
    middle.color = REMAP_STOPS[1][1]
    return node


def remap_checks(ob, distance):
    """Layers from Material on heights through clamps and Color Ramps: the layer's "remap",
    evaluated as the scene format defines it (remap_at), against the chain computed here from
    Blender's own Color Ramp (cycles_ramp) and the nodes' settings. Returns check records like
    expect_error's."""
    import random
    from sgbake_blender import operators
    tree = ob.active_material.node_tree
    tex = next(node for node in tree.nodes if node.type == "TEX_IMAGE" and node.image
               and node.name != "bake_target")
    bump = next(node for node in tree.nodes if node.type == "BUMP")
    rng = random.Random(1234)
    xs = [rng.uniform(-0.5, 1.5) for _ in range(REMAP_SAMPLES)]
    checks = []

    def luminance(rgba):
        return sum(w * c for w, c in zip(REMAP_LUMINANCE, rgba))

    def clamp(v, low, high):
        return min(max(v, low), high)

    def compare(name, reference, extra=None, scale=None):
        """The one layer Layers from Material makes now against `reference` (x -> height /
        scale); `extra(layer)` an additional condition, with its description."""
        found, skipped, _ = operators.material_layers(tree)
        layer = found[0] if len(found) == 1 else {}
        points = layer.get("remap")
        want_scale = distance if scale is None else scale
        worst = (max(abs(remap_at(points, x) - reference(x)) for x in xs)
                 if points else None)
        more, more_what = extra(layer) if extra else (True, "")
        checks.append({
            "name": f"Layers from Material: a height through {name}",
            "ok": worst is not None and worst <= REMAP_TOLERANCE
            and abs(layer.get("scale", 0) - want_scale) < 1e-7 and more,
            "expected": f"one layer with a remap within {REMAP_TOLERANCE:g} of the chain at "
                        f"{REMAP_SAMPLES} values of x in [-0.5, 1.5], scale {want_scale:.4g}"
                        + more_what,
            "message": f"max difference {worst}, {len(points or ())} points, scale "
                       f"{layer.get('scale')}, keys {sorted(layer)}, skipped {skipped}"})

    # Image -> Color Ramp (Ease, coloured stops: its luminance) -> Math x 2 clamped -> Bump.
    ramp = make_ramp(tree)
    double = tree.nodes.new("ShaderNodeMath")
    double.operation, double.use_clamp = "MULTIPLY", True
    double.inputs[1].default_value = 2.0
    tree.links.new(tex.outputs["Color"], ramp.inputs["Fac"])
    tree.links.new(ramp.outputs["Color"], double.inputs[0])
    tree.links.new(double.outputs[0], bump.inputs["Height"])
    compare("a Color Ramp (Ease) and a clamped Math node (x 2)",
            lambda x: clamp(2 * luminance(cycles_ramp(ramp.color_ramp, x)), 0, 1))
    # Constant: a step at each entry of the table.
    ramp.color_ramp.interpolation = "CONSTANT"
    compare("a Color Ramp (Constant) and a clamped Math node (x 2)",
            lambda x: clamp(2 * luminance(cycles_ramp(ramp.color_ramp, x)), 0, 1),
            lambda layer: (any(a[0] == b[0] for a, b in zip(layer.get("remap", []),
                                                            layer.get("remap", [])[1:])),
                           ", with steps"))
    ramp.color_ramp.interpolation = "EASE"
    # Its Alpha output (straight into the Bump: x 2 clamped would make it 1); its Color's
    # green through a Separate Color node (the ramp reads the luminance at its Fac: the layer's
    # channel stays the luminance).
    tree.links.new(ramp.outputs["Alpha"], bump.inputs["Height"])
    compare("a Color Ramp's Alpha", lambda x: cycles_ramp(ramp.color_ramp, x)[3])
    tree.links.new(double.outputs[0], bump.inputs["Height"])
    separate = tree.nodes.new("ShaderNodeSeparateColor")
    tree.links.new(ramp.outputs["Color"], separate.inputs[0])
    tree.links.new(separate.outputs["Green"], double.inputs[0])
    compare("a Color Ramp's Color, its Green separated, and a clamped Math node (x 2)",
            lambda x: clamp(2 * cycles_ramp(ramp.color_ramp, x)[1], 0, 1),
            lambda layer: ("channel" not in layer, ", no channel (the luminance)"))
    tree.nodes.remove(separate)
    # A factor of 0 before the clamp makes a constant: no bump, skipped with the reason.
    zero = tree.nodes.new("ShaderNodeMath")
    zero.operation, zero.inputs[1].default_value = "MULTIPLY", 0.0
    tree.links.new(tex.outputs["Color"], zero.inputs[0])
    tree.links.new(zero.outputs[0], ramp.inputs["Fac"])
    tree.links.new(ramp.outputs["Color"], double.inputs[0])
    flat, flat_skipped, _ = operators.material_layers(tree)
    checks.append({
        "name": "Layers from Material: a height through x 0 then a Color Ramp is skipped",
        "ok": not flat and any("constant height" in note for note in flat_skipped),
        "expected": "no layer, skipped as a constant height",
        "message": f"{flat}; skipped {flat_skipped}"})
    tree.nodes.remove(zero)
    tree.nodes.remove(ramp)
    tree.nodes.remove(double)
    # Image -> Math (1 - x: a negative factor) -> Map Range clamped (0.2..0.8 to 0.9..0.1) ->
    # Math x 0.5 + 0.1 (after the clamp: in the remap's values) -> Bump.
    flip = tree.nodes.new("ShaderNodeMath")
    flip.operation, flip.inputs[0].default_value = "SUBTRACT", 1.0
    ranged = tree.nodes.new("ShaderNodeMapRange")
    ranged.clamp = True
    for name, value in (("From Min", 0.2), ("From Max", 0.8), ("To Min", 0.9), ("To Max", 0.1)):
        ranged.inputs[name].default_value = value
    after = tree.nodes.new("ShaderNodeMath")
    after.operation = "MULTIPLY_ADD"
    after.inputs[1].default_value, after.inputs[2].default_value = 0.5, 0.1
    tree.links.new(tex.outputs["Color"], flip.inputs[1])
    tree.links.new(flip.outputs[0], ranged.inputs["Value"])
    tree.links.new(ranged.outputs["Result"], after.inputs[0])
    tree.links.new(after.outputs[0], bump.inputs["Height"])
    compare("1 - h, a clamped Map Range (0.2..0.8 to 0.9..0.1), then x 0.5 + 0.1",
            lambda x: 0.5 * clamp(0.9 + ((1 - x) - 0.2) / 0.6 * (0.1 - 0.9), 0.1, 0.9) + 0.1)
    # Without the 1 - h: the Map Range's own negative factor alone turns the points over.
    tree.links.new(tex.outputs["Color"], ranged.inputs["Value"])
    compare("a clamped Map Range (0.2..0.8 to 0.9..0.1), then x 0.5 + 0.1",
            lambda x: 0.5 * clamp(0.9 + (x - 0.2) / 0.6 * (0.1 - 0.9), 0.1, 0.9) + 0.1)
    tree.nodes.remove(flip)
    tree.nodes.remove(ranged)
    # A Clamp node, Min Max and Range (Min above Max), then the Bump inverted.
    limit = tree.nodes.new("ShaderNodeClamp")
    limit.inputs["Min"].default_value, limit.inputs["Max"].default_value = 0.35, 0.6
    tree.links.new(tex.outputs["Color"], limit.inputs["Value"])
    tree.links.new(limit.outputs["Result"], after.inputs[0])
    compare("a Clamp node (Min Max, 0.35..0.6), then x 0.5 + 0.1",
            lambda x: 0.5 * clamp(x, 0.35, 0.6) + 0.1)
    limit.clamp_type = "RANGE"
    limit.inputs["Min"].default_value, limit.inputs["Max"].default_value = 0.7, 0.25
    bump.invert = True
    compare("a Clamp node (Range, Min 0.7 above Max 0.25), then x 0.5 + 0.1, the Bump inverted",
            lambda x: 0.5 * clamp(x, 0.25, 0.7) + 0.1, scale=-distance)
    bump.invert = False
    # Min Max with Min above Max is Max: a constant, skipped.
    limit.clamp_type = "MINMAX"
    constant, constant_skipped, _ = operators.material_layers(tree)
    checks.append({
        "name": "Layers from Material: a height through a Clamp node of Min above Max is skipped",
        "ok": not constant and any("constant height" in n for n in constant_skipped),
        "expected": "no layer, skipped as a constant height (Cycles gives Max)",
        "message": f"{constant}; skipped {constant_skipped}"})
    tree.nodes.remove(limit)
    tree.nodes.remove(after)
    tree.links.new(tex.outputs["Color"], bump.inputs["Height"])
    return checks


def worker_thread_checks(settings, ob):
    """The UI's way to bake (operators.BakeJob.run on a worker thread, as the modal operator
    runs it): progress rises to 1, and a cancel set from this thread stops the bake without
    touching any image. Returns check records like expect_error's."""
    import threading
    import bpy
    from sgbake_blender import capi, operators
    settings.map, settings.width, settings.height = "tangent-normal", 1024, 1024
    settings.target_image = None
    checks = []

    job = operators.BakeJob(bpy.context)
    seen = []
    worker = threading.Thread(target=job.run)
    worker.start()
    while worker.is_alive():
        seen.append(job.progress.fraction)
        worker.join(0.005)
    seen.append(job.progress.fraction)
    ok = job.error is None and seen[-1] == 1.0 and seen == sorted(seen)
    checks.append({"name": "progress from a worker thread", "ok": ok,
                   "expected": "no error, fractions rising to 1",
                   "message": f"error {job.error}, {len(seen)} polls, fractions "
                              f"{sorted(set(seen))[:6]}..., last {seen[-1]}"})

    name = f"{ob.name}_tangent-normal"
    if name in bpy.data.images:
        bpy.data.images.remove(bpy.data.images[name])
    job = operators.BakeJob(bpy.context)
    job.progress.cancel = 1
    worker = threading.Thread(target=job.run)
    worker.start()
    worker.join()
    ok = isinstance(job.error, capi.SgbakeCancelled) and name not in bpy.data.images
    checks.append({"name": "cancel from another thread", "ok": ok,
                   "expected": "SgbakeCancelled and no image",
                   "message": f"{type(job.error).__name__}: {job.error}"})
    settings.width = settings.height = SIZE
    return checks


def shifted_suzanne(ob, work):
    """A copy of Suzanne whose faces with x < 0 have their UVs moved by +1 in u (UDIM tile
    1002), the others staying in tile 1001; writes it as mesh_udim.obj. Returns the object."""
    import bpy
    import numpy as np
    me = ob.data.copy()
    me.name = "suzanne_udim"
    centres = np.empty(len(me.polygons) * 3, np.float32)
    me.polygons.foreach_get("center", centres)
    uv = np.empty(len(me.loops) * 2, np.float32)
    me.uv_layers.active.data.foreach_get("uv", uv)
    uv = uv.reshape(-1, 2)
    for poly, centre in zip(me.polygons, centres.reshape(-1, 3)):
        if centre[0] < 0:
            uv[poly.loop_start:poly.loop_start + poly.loop_total, 0] += 1.0
    me.uv_layers.active.data.foreach_set("uv", uv.ravel())
    udim = bpy.data.objects.new("SuzanneUdim", me)
    bpy.context.scene.collection.objects.link(udim)
    me.calc_normals_split()
    arrays = objio.mesh_arrays(me)
    arrays["smooth"] = [p.use_smooth for p in me.polygons]  # the copy keeps the flat faces
    objio.write_obj(os.path.join(work, "mesh_udim.obj"), arrays,
                    comment="add-on test Suzanne on UDIM tiles 1001 and 1002")
    return udim


def sgbake_temp_dirs():
    """The add-on's temporary tile folders currently in the temporary directory."""
    return {name for name in os.listdir(tempfile.gettempdir())
            if name.startswith("sgbake-udim-")}


def udim_case(settings, ob, work, sabotage):
    """Bakes UDIM_MAP of the UV-shifted Suzanne into a tiled image (tiles UDIM_TILES, created
    at 64^2: each must come out SIZE^2) with the add-on, twice (a height bake first, so the
    second replaces tiles already packed); saves the image's tiles with Blender's own
    Image.save() as addon_udim.<UDIM>.exr. Returns the manifest entry: checks (the image keeps
    its name, every tile baked, nothing left behind, the report's tile notes) and the CLI
    commands of the same bake."""
    import bpy
    from sgbake_blender import operators
    udim = shifted_suzanne(ob, work)
    bpy.context.view_layer.objects.active = udim
    image = bpy.data.images.new("udim_target", 64, 64, alpha=True, float_buffer=True,
                                tiled=True)
    for tile in UDIM_TILES[1:]:
        image.tiles.new(tile)
    images_before = set(bpy.data.images.keys())
    dirs_before = sgbake_temp_dirs()
    settings.target_image = image
    settings.width = settings.height = SIZE
    settings.margin, settings.samples, settings.use_alpha = UDIM_MARGIN, 1, False
    settings.green = "directx" if sabotage else "opengl"
    entry = {"map": UDIM_MAP, "margin": UDIM_MARGIN, "tiles": UDIM_TILES, "checks": []}
    checks = entry["checks"]
    job = operators.BakeJob(bpy.context)
    level, notes = job.tile_notes(image.name)
    checks.append({"name": "UDIM: tiles baked and UV tiles seen",
                   "ok": (job.tiles == UDIM_TILES and job.uv_tiles == set(UDIM_TILES[:2])
                          and any("no UV lies in tile(s) 1011" in n for n in notes)),
                   "expected": f"tiles {UDIM_TILES}, UVs in {UDIM_TILES[:2]}, a note on 1011",
                   "message": f"tiles {job.tiles}, UV tiles {sorted(job.uv_tiles)}, {notes}"})
    settings.target_image = None  # the default '<object>_<map>' image: a single image
    single = operators.BakeJob(bpy.context)
    level, notes = single.tile_notes("single")
    checks.append({"name": "UDIM: a single target reports the UVs it cannot hold",
                   "ok": (single.tiles == [1001] and level == "WARNING"
                          and any("tile(s) 1002, which a single image" in n for n in notes)),
                   "expected": "tiles [1001], a warning naming 1002",
                   "message": f"tiles {single.tiles}, {level} {notes}"})
    settings.target_image = image
    results = []
    for kind in ("height", UDIM_MAP):
        settings.map = kind
        try:
            results.append(sorted(bpy.ops.object.sgbake_bake()))
        except RuntimeError as exc:
            results.append(["ERROR", str(exc).strip()])
    entry["result"] = results[-1]
    sizes = [tuple(tile.size) for tile in image.tiles]
    packed = [(p.tile_number, p.filepath) for p in image.packed_files]
    checks.append({
        "name": "UDIM: bakes into the tiled image",
        "ok": (results == [["FINISHED"]] * 2 and settings.target_image == image
               and image.name == "udim_target" and image.source == "TILED"
               and [t.number for t in image.tiles] == UDIM_TILES
               and sizes == [(SIZE, SIZE)] * len(UDIM_TILES)
               and sorted(packed) == [(t, f"//udim_target.{t}.exr") for t in UDIM_TILES]
               and image.filepath_raw == "//udim_target.<UDIM>.exr"
               and image.colorspace_settings.name == "Non-Color"),
        "expected": f"FINISHED twice, 'udim_target' tiled, tiles {UDIM_TILES} at {SIZE}^2, "
                    "packed as //udim_target.<UDIM>.exr, Non-Color",
        "message": f"{results}, '{image.name}' {image.source}, tiles "
                   f"{[t.number for t in image.tiles]} sizes {sizes}, packed {packed}, "
                   f"path {image.filepath_raw}, {image.colorspace_settings.name}"})
    stray_images = set(bpy.data.images.keys()) - images_before
    stray_dirs = sgbake_temp_dirs() - dirs_before
    checks.append({"name": "UDIM: nothing left behind", "ok": not stray_images and not stray_dirs,
                   "expected": "no new image, no temporary folder",
                   "message": f"images {sorted(stray_images)}, folders {sorted(stray_dirs)}"})
    image.filepath_raw = os.path.join(work, "addon_udim.<UDIM>.exr")
    image.file_format = "OPEN_EXR"
    image.save()
    input_cli = udim_input_case(settings, work, checks)
    settings.target_image = None
    bpy.context.view_layer.objects.active = ob
    # The CLI: '<UDIM>' bakes the tiles the UVs touch (1001, 1002); a scene with "tile" bakes
    # the empty one.
    scale = float(settings.layers[0].scale)
    entry["cli"] = [
        ["bake", "--mesh", "mesh_udim.obj", "--height", "height.exr", "--height-scale",
         repr(scale), "--height-gradient", "bump-node", "--filter", "bilinear", "--map", UDIM_MAP, "--size", str(SIZE),
         "--margin", str(UDIM_MARGIN), "--green", "opengl", "--bit-depth", "32",
         "--no-manifest", "-o", "cli_udim.<UDIM>.exr"],
        ["bake", "udim_1011.json", "--no-manifest"]] + input_cli
    with open(os.path.join(work, "udim_1011.json"), "w", encoding="ascii") as out:
        json.dump({"mesh": "mesh_udim.obj",
                   "layers": [{"type": "height", "image": "height.exr", "scale": scale,
                               "filter": "bilinear", "gradient": "bump-node"}],
                   "outputs": [{"map": UDIM_MAP, "size": SIZE, "margin": UDIM_MARGIN,
                                "green": "opengl", "tile": 1011, "file": "cli_udim.1011.exr",
                                "format": "exr", "bit_depth": 32}]}, out, indent=1)
    return entry


def udim_input_case(settings, work, checks):
    """A UDIM image as the height layer's image: tiles 1001 and 1002 of two different height
    fields (height_tiles.<UDIM>.exr), baked by the add-on (the UV-shifted Suzanne is active)
    into a tiled target saved as addon_udim_in.<UDIM>.exr. Appends its check; returns the CLI
    commands: the scene reading height_tiles.<UDIM>.exr, and the negative control reading the
    two tile files swapped."""
    import bpy
    import numpy as np
    import bake_scene
    side = 128
    first = bake_scene.height_field(side)
    fields = {1001: first, 1002: np.roll(first[::-1], side // 3, axis=1) * 0.8 + 0.1}
    for tile, field in fields.items():
        img = bc.new_float_image(f"height tile {tile}", side, side, field)
        bc.save_exr(img, os.path.join(work, f"height_tiles.{tile}.exr"))
        bc.save_exr(img, os.path.join(work, f"height_swapped.{2003 - tile}.exr"))
        bpy.data.images.remove(img)
    heights = bc.load_tiled(os.path.join(work, "height_tiles.<UDIM>.exr"), list(fields))
    # Named as Image > Open names a tiled image it finds by a tile's file: with "<UDIM>" in it.
    heights.name = "height_tiles.<UDIM>.exr"
    target = bpy.data.images.new("udim_in_target", 64, 64, alpha=True, float_buffer=True,
                                 tiled=True)
    target.tiles.new(1002)
    layer = settings.layers[0]
    single = layer.image
    layer.image = heights
    settings.target_image = target
    settings.map = UDIM_MAP
    images_before = set(bpy.data.images.keys())
    try:
        result = sorted(bpy.ops.object.sgbake_bake())
    except RuntimeError as exc:
        result = ["ERROR", str(exc).strip()]
    stray = set(bpy.data.images.keys()) - images_before  # the tiles' temporary images
    layer.image = single
    checks.append({"name": "UDIM: a tiled height image as the layer's image",
                   "ok": result == ["FINISHED"] and not stray,
                   "expected": "FINISHED, no image left behind",
                   "message": f"{result}, new images {sorted(stray)}"})
    target.filepath_raw = os.path.join(work, "addon_udim_in.<UDIM>.exr")
    target.file_format = "OPEN_EXR"
    target.save()
    scale = float(layer.scale)
    commands = []
    for name, heights_file in (("udim_in", "height_tiles"), ("udim_in_swapped", "height_swapped")):
        with open(os.path.join(work, f"{name}.json"), "w", encoding="ascii") as out:
            json.dump({"mesh": "mesh_udim.obj",
                       "layers": [{"type": "height", "image": f"{heights_file}.<UDIM>.exr",
                                   "scale": scale, "filter": "bilinear",
                                   "gradient": "bump-node"}],
                       "outputs": [{"map": UDIM_MAP, "size": SIZE, "margin": UDIM_MARGIN,
                                    "green": "opengl", "file": f"cli_{name}.<UDIM>.exr",
                                    "bit_depth": 32}]}, out, indent=1)
        commands.append(["bake", f"{name}.json", "--no-manifest"])
    return commands


def mask_field(side):
    """The mask image (side, side) float32 rows top first: a smooth ramp, values in [0, 1]
    (clamped at both ends, so the mask's clamp is exercised)."""
    import numpy as np
    c = (np.arange(side, dtype=np.float64) + 0.5) / side
    u, v = c[None, :], 1.0 - c[:, None]
    return np.clip(1.2 * np.sin(2 * np.pi * u) * np.cos(2 * np.pi * v) + 0.5, 0, 1).astype(
        np.float32)


def options_case(settings, height, work):
    """Task of the per-layer keys the scene format has beyond the basics: a masked, offset
    height layer (mask with its own tiling, offset, filter and UV map), a noise volume with
    central differences and a step, an offset triplanar layer with a minimum weight. Checks
    the add-on's scene JSON for them, bakes OPTIONS_MAP with the add-on (addon_options.npy),
    and writes the CLI scenes: the same keys (options.json) and, as negative controls, the
    scene without each key (options_no_KEY.json), whose bakes must differ."""
    import bpy
    import numpy as np
    from sgbake_blender import operators
    side = 128
    mask = bc.new_float_image("mask", side, side, mask_field(side))
    bc.save_exr(mask, os.path.join(work, "mask.exr"))
    settings.layers.clear()
    spec = []
    layer = settings.layers.add()
    layer.name, layer.type, layer.image, layer.scale = "masked", "height", height, 0.1
    layer.offset = (0.25, -0.125)
    layer.mask_image, layer.mask_uv_map = mask, "UVMap"
    layer.mask_tiling, layer.mask_offset, layer.mask_filter = (1.0, 2.0), (0.1, 0.3), "bicubic"
    layer = settings.layers.add()
    layer.name, layer.type, layer.function = "noise", "volume", "noise"
    layer.amplitude, layer.frequency, layer.octaves = 0.02, 3.0, 2
    layer.gradient, layer.step = "central", 0.05
    layer = settings.layers.add()
    layer.name, layer.type, layer.image, layer.kind = "tri", "triplanar", height, "height"
    layer.scale, layer.offset, layer.min_weight = 0.05, (0.3, 0.7), 0.2
    settings.map, settings.target_image = OPTIONS_MAP, None
    settings.width = settings.height = SIZE
    settings.margin, settings.samples, settings.use_alpha = 0, 1, False
    settings.green = "opengl"

    # The values as Blender holds them (float32), read back from the properties.
    f = float
    first, vol, tri = settings.layers
    expected = [
        {"offset": [f(first.offset[0]), f(first.offset[1])],
         "mask": {"image": "mask", "uv": 0, "tiling": [f(first.mask_tiling[0]),
                                                        f(first.mask_tiling[1])],
                  "offset": [f(first.mask_offset[0]), f(first.mask_offset[1])],
                  "filter": "bicubic"}},
        {"gradient": "central", "step": f(vol.step)},
        {"offset": [f(tri.offset[0]), f(tri.offset[1])], "min_weight": f(tri.min_weight)},
    ]
    job = operators.BakeJob(bpy.context)
    sent = job.scene["layers"]
    wrong = [(i, key, sent[i].get(key), value) for i, want in enumerate(expected)
             for key, value in want.items() if sent[i].get(key) != value]
    checks = [{"name": "layer options in the add-on's scene JSON", "ok": not wrong,
               "expected": json.dumps(expected),
               "message": f"sent {json.dumps(sent)}; wrong (layer, key, sent, expected) "
                          f"{wrong}"}]
    # Projection Box sends Blender's Blend instead of the blended projection's keys.
    tri.projection, tri.box_blend, tri.mapping_rotation = "box", 0.4, (0.0, 0.5, 0.0)
    tri.mapping_type, tri.strength = "TEXTURE", 0.5
    sent_box = operators.BakeJob(bpy.context).scene["layers"][2]
    tri.strength = 1.0
    want_box = {"projection": "box", "box_blend": f(tri.box_blend), "strength": 0.5,
                "mapping": {"location": [0.0] * 3, "rotation": [0.0, f(tri.mapping_rotation[1]), 0.0],
                            "scale": [1.0] * 3, "type": "texture"}}
    # A Box-projected tangent-space map sends the UV set whose frames decode it: the render
    # UV map's, as Cycles' Normal Map node takes them when its own UV Map is empty.
    tri.kind = "tangent-normal"
    job = operators.BakeJob(bpy.context)
    sent_frames = job.scene["layers"][2].get("tangent_uv")
    render_uv = next((uv.name for uv in bpy.context.active_object.data.uv_layers
                      if uv.active_render), None)
    want_frames = job.uv_names.index(render_uv) if render_uv in job.uv_names else "(none)"
    tri.kind = "height"
    tri.projection, tri.mapping_rotation, tri.mapping_type = "blended", (0.0, 0.0, 0.0), "POINT"
    checks.append({"name": "a triplanar layer's Projection Box and Mapping in the add-on's "
                           "scene JSON",
                   "ok": all(sent_box.get(k) == v for k, v in want_box.items())
                   and "sharpness" not in sent_box and "min_weight" not in sent_box,
                   "expected": json.dumps(want_box), "message": f"sent {json.dumps(sent_box)}"})
    checks.append({"name": "a Box-projected tangent-space layer's tangent frames in the add-on's "
                           "scene JSON",
                   "ok": sent_frames == want_frames, "expected": f"tangent_uv {want_frames}",
                   "message": f"tangent_uv {sent_frames}"})
    # The output's Swizzle: sent as "swizzle" (a DirectX green folded into its G), not "green";
    # the default sends "green" alone, as before. (BlenderSwizzleOracle checks the bake.)
    for kind, axes, green, want in (
            ("tangent-normal", ("NEG_Z", "POS_X", "NEG_Y"), "directx",
             {"swizzle": "NEG_Z,NEG_X,NEG_Y"}),
            ("object-normal", ("NEG_Z", "POS_X", "NEG_Y"), "opengl",
             {"swizzle": "NEG_Z,POS_X,NEG_Y"}),
            ("tangent-normal", ("POS_X", "POS_Y", "POS_Z"), "directx", {"green": "directx"})):
        settings.map, settings.green = kind, green
        settings.swizzle_r, settings.swizzle_g, settings.swizzle_b = axes
        output = operators.BakeJob(bpy.context).scene["outputs"][0]
        got = {key: output[key] for key in ("swizzle", "green") if key in output}
        checks.append({"name": f"swizzle {','.join(axes)}, green {green}: the {kind} output",
                       "ok": got == want, "expected": json.dumps(want),
                       "message": f"sent {json.dumps(output)}"})
    # From Blender's Bake Settings: the Normal bake's space and Swizzle, the margin.
    bake = bpy.context.scene.render.bake
    bpy.context.scene.cycles.bake_type = "NORMAL"
    bake.normal_space, bake.margin, bake.margin_type = "OBJECT", 7, "EXTEND"
    bake.normal_r, bake.normal_g, bake.normal_b = "NEG_Y", "POS_Z", "NEG_X"
    settings.green = "directx"
    kept = settings.margin, settings.padding
    result = sorted(bpy.ops.sgbake.from_blender_bake())
    got = [result, settings.map, settings.swizzle_r, settings.swizzle_g, settings.swizzle_b,
           settings.green, settings.margin, settings.padding]
    want = [["FINISHED"], "object-normal", "NEG_Y", "POS_Z", "NEG_X", "opengl", 7, "extend"]
    checks.append({"name": "From Blender's Bake Settings", "ok": got == want,
                   "expected": str(want), "message": str(got)})
    bake.normal_r, bake.normal_g, bake.normal_b = "POS_X", "POS_Y", "POS_Z"
    settings.margin, settings.padding = kept
    settings.swizzle_r, settings.swizzle_g, settings.swizzle_b = ("POS_X", "POS_Y", "POS_Z")
    settings.map, settings.green = OPTIONS_MAP, "opengl"
    try:
        result = sorted(bpy.ops.object.sgbake_bake())
    except RuntimeError as exc:
        result = ["ERROR", str(exc).strip()]
    image = bpy.data.images.get(f"{bpy.context.active_object.name}_{OPTIONS_MAP}")
    if result == ["FINISHED"]:
        np.save(os.path.join(work, "addon_options.npy"), bc.image_array(image))

    # The CLI's scenes, from the values above (not from the add-on's JSON).
    scale = f(first.scale)
    layers = [
        {"type": "height", "image": "height.exr", "scale": scale, "filter": "bilinear",
         "offset": expected[0]["offset"],
         "mask": dict(expected[0]["mask"], image="mask.exr")},
        {"type": "volume", "function": "noise", "amplitude": f(vol.amplitude),
         "frequency": f(vol.frequency), "octaves": 2, "gradient": "central",
         "step": expected[1]["step"]},
        {"type": "triplanar", "image": "height.exr", "kind": "height", "scale": f(tri.scale),
         "offset": expected[2]["offset"], "min_weight": expected[2]["min_weight"]},
    ]
    output = {"map": OPTIONS_MAP, "size": SIZE, "margin": 0, "format": "exr", "bit_depth": 32}
    scenes = {"options": layers}
    for index, key in ((0, "offset"), (0, "mask"), (1, "step"), (2, "offset"),
                       (2, "min_weight")):
        without = [dict(layer) for layer in layers]
        del without[index][key]
        scenes[f"options_no_{key}_{index}"] = without
    for name, scene_layers in scenes.items():
        with open(os.path.join(work, f"{name}.json"), "w", encoding="ascii") as out:
            json.dump({"mesh": "mesh.obj", "layers": scene_layers,
                       "outputs": [dict(output, file=f"cli_{name}.exr")]}, out, indent=1)
    settings.layers.clear()
    return {"map": OPTIONS_MAP, "result": result, "scenes": sorted(scenes), "checks": checks,
            "cli": [["bake", f"{name}.json", "--no-manifest"] for name in sorted(scenes)]}


def limit_case(settings, ob, work, scale):
    """Bakes LIMIT_MAP of a coarse, creased Suzanne with a live Subdivision Surface modifier
    (UV Smooth All, level 1) from the exact limit surface (Surface: Exact Limit Surface) into
    addon_limit.npy, and from Blender's evaluated mesh into addon_limit_mesh.npy (the negative
    control); writes the coarse mesh as mesh_limit.obj. Returns the manifest entry: checks (the
    modifier is shown again afterwards, the report names the limit surface, the add-on refuses
    an object whose last modifier is not a Subdivision Surface) and the CLI command of the
    same bake (`--subdivide limit` with the creases read from the mesh here)."""
    import bpy
    import numpy as np
    bpy.ops.mesh.primitive_monkey_add(calc_uvs=True)
    coarse = bpy.context.object
    coarse.name = "SuzanneLimit"
    bc.set_smooth(coarse, True)
    bc.set_creases(coarse, [(e, (0.4, 1.0)[e % 2]) for e in range(0, 90, 9)], [(7, 0.8)])
    me = coarse.data
    me.calc_normals_split()
    objio.write_obj(os.path.join(work, "mesh_limit.obj"), objio.mesh_arrays(me),
                    comment="add-on test coarse creased Suzanne (limit surface)")
    edge_creases, vertex_creases = bc.read_creases(me)
    modifier = coarse.modifiers.new("Subdivision", "SUBSURF")
    modifier.levels, modifier.uv_smooth = 1, "SMOOTH_ALL"
    settings.map, settings.target_image = LIMIT_MAP, None
    settings.width = settings.height = SIZE
    settings.margin, settings.samples, settings.use_alpha = 0, 1, False
    settings.green = "opengl"
    checks, results = [], {}
    for surface, name in (("limit", "addon_limit"), ("mesh", "addon_limit_mesh")):
        settings.surface = surface
        try:
            results[surface] = sorted(bpy.ops.object.sgbake_bake())
        except RuntimeError as exc:
            results[surface] = ["ERROR", str(exc).strip()]
            continue
        image = bpy.data.images[f"{coarse.name}_{LIMIT_MAP}"]
        np.save(os.path.join(work, f"{name}.npy"), bc.image_array(image))
    checks.append({"name": "the Subdivision Surface modifier is shown again after the bake",
                   "ok": modifier.show_viewport, "expected": "show_viewport True",
                   "message": f"show_viewport {modifier.show_viewport}"})
    settings.surface = "limit"
    coarse.modifiers.new("Displace", "DISPLACE")
    checks.append(expect_error("exact limit surface under another modifier",
                               "has modifier 'Displace' last", bpy.ops.object.sgbake_bake))
    settings.surface = "mesh"
    bpy.context.view_layer.objects.active = ob
    def cli(output, uv_smooth="all", with_creases=True):
        args = ["bake", "--mesh", "mesh_limit.obj", "--subdivide", "limit", "--uv-smooth",
                uv_smooth, "--height", "height.exr", "--height-scale", repr(scale),
                "--height-gradient", "bump-node", "--filter",
                "bilinear", "--map", LIMIT_MAP, "--size", str(SIZE), "--margin", "0",
                "--bit-depth", "32", "--no-manifest", "-o", output]
        for a, b, crease in edge_creases if with_creases else []:
            args += ["--edge-crease", f"{a},{b},{crease!r}"]
        for v, crease in vertex_creases if with_creases else []:
            args += ["--vertex-crease", f"{v},{crease!r}"]
        return args
    # The bake, and as negative controls the same without the creases and with the default
    # UV Smooth: the add-on must send both.
    return {"map": LIMIT_MAP, "result": results, "checks": checks,
            "cli": [cli("cli_limit.exr"), cli("cli_limit_no_creases.exr", with_creases=False),
                    cli("cli_limit_keep_boundaries.exr", uv_smooth="keep-boundaries")],
            "creases": [len(edge_creases), len(vertex_creases)]}


def world_case(settings, ob, work, sabotage):
    """The bump material's Suzanne moved, turned and scaled unevenly (WORLD_*), baked in
    WORLD_MAPS by the add-on (addon_world_MAP.npy), by the add-on's job without the scene's
    "transform" (addon_world_MAP_control.npy, the negative control: the add-on before it sent
    one) and by Cycles (cycles_world_SPACE.npy, and its EMIT mask cycles_world_mask.npy). The
    object is put back afterwards. Returns the manifest entry: checks (the scene carries the
    transform, heights as they are, no note)."""
    import bpy
    import numpy as np
    import bake_scene
    from sgbake_blender import operators
    ob.location, ob.rotation_euler, ob.scale = WORLD_LOCATION, WORLD_ROTATION, WORLD_SCALE
    bpy.context.view_layer.update()
    settings.target_image = None
    settings.width = settings.height = SIZE
    settings.margin, settings.samples, settings.use_alpha = 0, 1, False
    settings.padding, settings.surface = "extend", "mesh"
    settings.green = "directx" if sabotage else "opengl"
    entry = {"location": WORLD_LOCATION, "rotation": WORLD_ROTATION, "scale": WORLD_SCALE,
             "maps": WORLD_MAPS, "result": {}, "checks": []}
    rows = [[float(v) for v in row] for row in ob.matrix_world]
    for kind in WORLD_MAPS:
        settings.map = kind
        job = operators.BakeJob(bpy.context)
        entry["checks"].append({
            "name": f"world: the {kind} scene carries matrix_world and the Bump Distance",
            "ok": (job.scene.get("transform") == rows and not job.notes
                   and job.scene["layers"][0]["scale"] == float(settings.layers[0].scale)),
            "expected": f"transform {rows}, scale {float(settings.layers[0].scale)}, no note",
            "message": f"transform {job.scene.get('transform')}, scale "
                       f"{job.scene['layers'][0]['scale']}, notes {job.notes}"})
        try:
            entry["result"][kind] = sorted(bpy.ops.object.sgbake_bake())
        except RuntimeError as exc:
            entry["result"][kind] = ["ERROR", str(exc).strip()]
            continue
        image = bpy.data.images[f"{ob.name}_{kind}"]
        np.save(os.path.join(work, f"addon_world_{kind}.npy"), bc.image_array(image))
        # The negative control: the same job without the transform, into the same image.
        for scene_of_tile in job.scenes.values():
            scene_of_tile.pop("transform", None)
        job.run()
        if job.error is None:
            image, _ = job.finish()
            np.save(os.path.join(work, f"addon_world_{kind}_control.npy"),
                    bc.image_array(image))
    # Cycles' bakes of the same object and material.
    scene = bpy.context.scene
    engine = scene.render.engine
    bc.setup_cycles(scene)
    mat = ob.active_material
    target = mat.node_tree.nodes["bake_target"]
    for space in list(WORLD_MAPS.values()) + ["mask"]:
        image = bc.new_float_image(f"cycles_world_{space}", SIZE, SIZE)
        bake_scene.bake_pass(ob, mat, target, image, space, 0)
        np.save(os.path.join(work, f"cycles_world_{space}.npy"), bc.image_array(image))
        bpy.data.images.remove(image)
    target.image = None
    scene.render.engine = engine
    ob.location, ob.rotation_euler, ob.scale = (0, 0, 0), (0, 0, 0), (1, 1, 1)
    bpy.context.view_layer.update()
    return entry


def materials_case(settings, ob, height, work, sabotage):
    """An object of two materials (MATERIALS_*): a copy of Suzanne with the bump material in
    slot 0 and, on its faces of even index, a material chaining a Bump on a Normal Map in slot
    1. Layers from Material must make a height layer of slot 0 and a normal layer and a height
    layer "above" it of slot 1, and the bake send them with "material" and the faces' slots as
    face_material. It is baked (MATERIALS_MAP) by the add-on (addon_materials.npy), by the
    add-on's job without the "material" keys (addon_materials_control.npy, every layer on every
    face: the negative control) and by Cycles with the bake target active in both materials
    (cycles_materials.npy and its EMIT mask cycles_materials_mask.npy). Then the object is
    removed, the layers are the bump material's again, and a single-slot object must send no
    "material". Returns the manifest entry: results and checks."""
    import bpy
    import numpy as np
    import bake_scene
    from sgbake_blender import gather, operators
    checks = []

    def check(name, ok, expected, message):
        checks.append({"name": f"materials: {name}", "ok": bool(ok), "expected": expected,
                       "message": message})

    multi = ob.copy()
    multi.data = ob.data.copy()
    multi.name = multi.data.name = "SuzanneMaterials"
    bpy.context.scene.collection.objects.link(multi)
    bump_mat = multi.material_slots[0].material
    side = bake_scene.HEIGHT_SIZE
    normal = bc.new_float_image("materials_normal", side, side,
                                bake_scene.normal_field(side, MATERIALS_TILT_DEG))
    chain_mat, _ = bake_scene.make_normal_material(
        normal, "TANGENT", 1.0, multi.data.uv_layers.active.name, height_image=height,
        bump=MATERIALS_CHAIN_DISTANCE)
    chain_mat.name = "chain"
    multi.data.materials.append(chain_mat)
    slots = (np.arange(len(multi.data.polygons)) % 2 == 0).astype(np.int64)
    multi.data.polygons.foreach_set("material_index", slots)
    multi.data.update()
    bpy.context.view_layer.objects.active = multi
    settings.target_image = None
    settings.map, settings.surface = MATERIALS_MAP, "mesh"
    settings.width = settings.height = SIZE
    settings.margin, settings.samples, settings.use_alpha = 0, 1, False
    settings.padding = "extend"
    settings.green = "directx" if sabotage else "opengl"

    # Layers from Material reads both slots; each layer is its slot's, the chain within slot 1.
    try:
        made = sorted(bpy.ops.object.sgbake_layers_from_material())
    except RuntimeError as exc:
        made = ["ERROR", str(exc).strip()]
    layers = [(layer.type, layer.material_index, layer.base) for layer in settings.layers]
    expected = [("height", 0, "surface"), ("normal", 1, "surface"), ("height", 1, "above")]
    check("Layers from Material tags each layer with its slot", made == ["FINISHED"]
          and layers == expected, f"FINISHED, (type, slot, base) {expected}",
          f"{made}, {layers}")
    job = operators.BakeJob(bpy.context)
    sent = [layer.get("material") for layer in job.scene["layers"]]
    face_material = job.arrays[7]
    check("the bake sends \"material\" and the faces' slots", sent == [0, 1, 1]
          and face_material.dtype == np.uint32 and np.array_equal(face_material, slots),
          "material [0, 1, 1], face_material = the polygons' material_index",
          f"material {sent}, face_material {face_material.dtype} {face_material[:6]}...")
    # Cycles clamps a face's index to the slots: with one slot every face is slot 0's.
    clamped = gather.mesh_arrays(multi.data, [multi.data.uv_layers.active.name], 1)[7]
    check("face_material clamped to the object's slots", not clamped.any(),
          "all 0 with one slot", f"{np.unique(clamped).tolist()}")
    # A note about one material names it.
    tex = next(node for node in chain_mat.node_tree.nodes
               if node.type == "TEX_IMAGE" and node.image == normal)
    mapping = chain_mat.node_tree.nodes.new("ShaderNodeMapping")
    chain_mat.node_tree.links.new(mapping.outputs["Vector"], tex.inputs["Vector"])
    _, _, ignored = operators.object_layers(operators.material_sources(multi)[0])
    chain_mat.node_tree.nodes.remove(mapping)
    check("a note names its material",
          any(note.startswith("material 'chain' (slot 1): ") and "Mapping" in note
              for note in ignored), "a note on 'chain' (slot 1)", str(ignored))
    # The same material in a second slot makes its own layers; an empty slot none.
    multi.data.materials.append(bump_mat)
    multi.data.materials.append(None)
    sources, skipped = operators.material_sources(multi)
    found, _, _ = operators.object_layers(sources)
    multi.data.materials.pop()
    multi.data.materials.pop()
    check("the same material in two slots, and an empty slot",
          [v["material_index"] for v in found] == [0, 1, 1, 2]
          and any("slot 3: empty" in note for note in skipped),
          "layers of slots [0, 1, 1, 2], slot 3 noted empty",
          f"{[v['material_index'] for v in found]}, skipped {skipped}")

    entry = {"map": MATERIALS_MAP, "faces": [int((slots == 0).sum()), int(slots.sum())],
             "checks": checks}
    try:
        entry["result"] = sorted(bpy.ops.object.sgbake_bake())
    except RuntimeError as exc:
        entry["result"] = ["ERROR", str(exc).strip()]
    if entry["result"] == ["FINISHED"]:
        # The negative control: the same job with every layer on every face.
        save_with_control(job, bpy.data.images[f"{multi.name}_{MATERIALS_MAP}"], work,
                          "materials", ("material",))

    # Cycles: each face with its material; the target node active in both.
    scene = bpy.context.scene
    engine = scene.render.engine
    bc.setup_cycles(scene)
    targets = [mat.node_tree.nodes["bake_target"] for mat in (bump_mat, chain_mat)]
    space = "tangent" if MATERIALS_MAP == "tangent-normal" else "object"
    for kind, name in ((space, "cycles_materials"), ("mask", "cycles_materials_mask")):
        image = bc.new_float_image(name, SIZE, SIZE)
        targets[0].image = image
        bump_mat.node_tree.nodes.active = targets[0]
        bake_scene.bake_pass(multi, chain_mat, targets[1], image, kind, 0)
        np.save(os.path.join(work, f"{name}.npy"), bc.image_array(image))
        bpy.data.images.remove(image)
    for target in targets:
        target.image = None
    scene.render.engine = engine

    bpy.data.objects.remove(multi)
    bpy.context.view_layer.objects.active = ob
    # One slot: the layers apply to every face, as before; no "material" is sent.
    bpy.ops.object.sgbake_layers_from_material()
    job = operators.BakeJob(bpy.context)
    check("one slot: no \"material\"",
          [layer.material_index for layer in settings.layers] == [-1]
          and not any("material" in layer for layer in job.scene["layers"]),
          "material_index -1, no \"material\" key",
          f"{[layer.material_index for layer in settings.layers]}, {job.scene['layers']}")
    settings.layers.add()
    check("a hand-made layer applies to every face", settings.layers[-1].material_index == -1,
          "material_index -1", str(settings.layers[-1].material_index))
    settings.layers.remove(len(settings.layers) - 1)
    return entry


def save_with_control(job, image, work, case, keys):
    """Saves the add-on's bake `image` as addon_CASE.npy, then runs the same `job` with `keys`
    taken out of every layer it sends (a negative control) and saves that as
    addon_CASE_control.npy."""
    import numpy as np
    np.save(os.path.join(work, f"addon_{case}.npy"), bc.image_array(image))
    for scene_of_tile in job.scenes.values():
        for layer in scene_of_tile["layers"]:
            for key in keys:
                layer.pop(key, None)
    job.run()
    if job.error is None:
        control, _ = job.finish()
        np.save(os.path.join(work, f"addon_{case}_control.npy"), bc.image_array(control))


def bake_against_cycles(settings, ob, work, case, control_keys):
    """The add-on's 256^2 tangent-normal bake of `ob` with its layers (addon_CASE.npy), the same
    job with `control_keys` taken out of every layer (addon_CASE_control.npy, save_with_control)
    and Cycles' bake of its active material with its mask (cycles_CASE.npy,
    cycles_CASE_mask.npy); returns the add-on bake's result."""
    import bpy
    import numpy as np
    import bake_scene
    from sgbake_blender import operators
    settings.target_image = None
    settings.width = settings.height = SIZE
    settings.margin, settings.samples, settings.use_alpha = 0, 1, False
    settings.padding, settings.surface, settings.green = "extend", "mesh", "opengl"
    settings.map = "tangent-normal"
    job = operators.BakeJob(bpy.context)
    try:
        result = sorted(bpy.ops.object.sgbake_bake())
    except RuntimeError as exc:
        result = ["ERROR", str(exc).strip()]
    if result == ["FINISHED"]:
        save_with_control(job, bpy.data.images[f"{ob.name}_tangent-normal"], work, case,
                          control_keys)
    scene = bpy.context.scene
    engine = scene.render.engine
    bc.setup_cycles(scene)
    mat = ob.active_material
    target = mat.node_tree.nodes["bake_target"]
    for space in ("tangent", "mask"):
        cycles = bc.new_float_image(f"cycles_{case}_{space}", SIZE, SIZE)
        bake_scene.bake_pass(ob, mat, target, cycles, space, 0)
        name = f"cycles_{case}" + ("" if space == "tangent" else "_mask")
        np.save(os.path.join(work, f"{name}.npy"), bc.image_array(cycles))
        bpy.data.images.remove(cycles)
    target.image = None
    scene.render.engine = engine
    return result


def projector_case(settings, ob, work):
    """The bump material's Image Texture switched to Box projection on an Empty's coordinates
    through a Mapping node (PROJECTOR_*), Distance PROJECTOR_DISTANCE: Layers from Material,
    then the add-on's tangent-normal bake (addon_projector.npy), the same job with its layer's
    projection "blended" (addon_projector_control.npy) and Cycles' (cycles_projector.npy, its
    mask cycles_projector_mask.npy). The material is put back afterwards. Returns the manifest
    entry (result, the layer made, checks)."""
    import bpy
    from sgbake_blender import operators
    mat = ob.active_material
    tree = mat.node_tree
    tex = next(n for n in tree.nodes if n.type == "TEX_IMAGE" and n.name != "bake_target")
    bump = next(n for n in tree.nodes if n.type == "BUMP")
    distance = bump.inputs["Distance"].default_value
    empty = bpy.data.objects.new("projector", None)
    bpy.context.scene.collection.objects.link(empty)
    empty.location, empty.rotation_euler, empty.scale = PROJECTOR_EMPTY
    bpy.context.view_layer.update()
    coordinates = tree.nodes.new("ShaderNodeTexCoord")
    coordinates.object = empty
    mapping = tree.nodes.new("ShaderNodeMapping")
    mapping.vector_type = PROJECTOR_MAPPING_TYPE
    for name, value in zip(("Location", "Rotation", "Scale"), PROJECTOR_MAPPING):
        mapping.inputs[name].default_value = value
    tree.links.new(coordinates.outputs["Object"], mapping.inputs["Vector"])
    tree.links.new(mapping.outputs["Vector"], tex.inputs["Vector"])
    tex.projection, tex.projection_blend = "BOX", PROJECTOR_BLEND
    # The Mapping's Scale and the Bump's Distance fed by constant nodes, their own values wrong:
    # a Combine XYZ of (Value x 3, its own Y, Value + Value), and a Value node. Cycles folds
    # them; so must Layers from Material.
    value = tree.nodes.new("ShaderNodeValue")
    value.outputs[0].default_value = PROJECTOR_MAPPING[2][2] / 2
    times = tree.nodes.new("ShaderNodeMath")
    times.operation, times.inputs[1].default_value = "MULTIPLY", 3.0
    twice = tree.nodes.new("ShaderNodeMath")
    twice.operation = "ADD"
    combine = tree.nodes.new("ShaderNodeCombineXYZ")
    combine.inputs["Y"].default_value = PROJECTOR_MAPPING[2][1]
    tree.links.new(value.outputs[0], times.inputs[0])
    tree.links.new(value.outputs[0], twice.inputs[0])
    tree.links.new(value.outputs[0], twice.inputs[1])
    tree.links.new(times.outputs[0], combine.inputs["X"])
    tree.links.new(twice.outputs[0], combine.inputs["Z"])
    tree.links.new(combine.outputs[0], mapping.inputs["Scale"])
    mapping.inputs["Scale"].default_value = (1.0, 1.0, 1.0)
    distance_node = tree.nodes.new("ShaderNodeValue")
    distance_node.outputs[0].default_value = PROJECTOR_DISTANCE
    tree.links.new(distance_node.outputs[0], bump.inputs["Distance"])
    bump.inputs["Distance"].default_value = 5 * PROJECTOR_DISTANCE
    constants = (value, times, twice, combine, distance_node)
    entry = {"result": None, "checks": []}
    try:
        bpy.ops.object.sgbake_layers_from_material()
        layer = settings.layers[0]
        entry["layer"] = {"type": layer.type, "projection": layer.projection,
                          "box_blend": layer.box_blend, "slopes": layer.slopes,
                          "mapping_type": layer.mapping_type,
                          "mapping_scale": tuple(layer.mapping_scale), "scale": layer.scale}
        entry["checks"].append({
            "name": "projector: Layers from Material makes one triplanar Box layer",
            "ok": (len(settings.layers) == 1 and layer.type == "triplanar"
                   and layer.projection == "box" and layer.slopes == "bump-node"
                   and layer.mapping_type == PROJECTOR_MAPPING_TYPE
                   and max(abs(a - b) for a, b in zip(layer.mapping_scale,
                                                      PROJECTOR_MAPPING[2])) < 1e-6
                   and abs(layer.scale - PROJECTOR_DISTANCE) < 1e-9),
            "expected": f"one triplanar layer, projection box, slopes bump-node, mapping type "
                        f"{PROJECTOR_MAPPING_TYPE}, mapping scale {PROJECTOR_MAPPING[2]} and "
                        f"scale {PROJECTOR_DISTANCE} from the constant nodes",
            "message": str(entry["layer"])})
        entry["result"] = bake_against_cycles(settings, ob, work, "projector", ("projection", "box_blend"))
        # The Empty moved after Layers from Material: the next bake reads it where it is now.
        empty.location = (empty.location[0] + 0.5, empty.location[1], empty.location[2] - 0.25)
        bpy.context.view_layer.update()
        sent = operators.BakeJob(bpy.context).scene["layers"][0].get("mapping", {})
        want = empty.matrix_world.inverted() @ ob.matrix_world
        got = [v for row in sent.get("matrix", []) for v in row]
        worst = (max(abs(got[4 * r + c] - want[r][c]) for r in range(3) for c in range(4))
                 if len(got) == 12 else None)
        entry["checks"].append({
            "name": "projector: the Empty moved, the next bake's coordinates follow it",
            "ok": layer.coordinates_object == empty and worst is not None and worst < 1e-6,
            "expected": f"coordinates_object 'projector', matrix {[list(r) for r in want[:3]]}",
            "message": f"coordinates_object {layer.coordinates_object}, sent {sent}, "
                       f"max difference {worst}"})
    finally:
        tree.nodes.remove(mapping)
        tree.nodes.remove(coordinates)
        for node in constants:
            tree.nodes.remove(node)
        tex.projection = "FLAT"
        bump.inputs["Distance"].default_value = distance
        bpy.data.objects.remove(empty)
    return entry


def displacement_case(settings, ob, work):
    """The bump material's texture also into a Displacement node (world space, Scale
    DISPLACEMENT_SCALE) into the Material Output's Displacement, Bump Only, the Bump node's
    Normal input unlinked: Layers from Material, then the add-on's tangent-normal bake
    (addon_displacement.npy), the same job without the layers' "base" (the Bump added to the
    displacement: addon_displacement_control.npy) and Cycles' (cycles_displacement.npy, its
    mask cycles_displacement_mask.npy). The material is put back afterwards. Returns the
    manifest entry (result, the layers made, checks)."""
    import bpy
    mat = ob.active_material
    tree = mat.node_tree
    tex = next(n for n in tree.nodes if n.type == "TEX_IMAGE" and n.name != "bake_target")
    output = tree.get_output_node("CYCLES")
    node = tree.nodes.new("ShaderNodeDisplacement")
    node.space = "OBJECT"  # on Suzanne stretched and turned: grown along the normal
    placement = (tuple(ob.location), tuple(ob.rotation_euler), tuple(ob.scale))
    ob.location, ob.rotation_euler, ob.scale = DISPLACEMENT_PLACEMENT
    bpy.context.view_layer.update()
    # Its height through a Math node (x 2) inside a node group, its Scale halved: the layer's
    # scale is the product.
    node.inputs["Scale"].default_value = DISPLACEMENT_SCALE / 2
    doubling = bpy.data.node_groups.new("sgbake doubling", "ShaderNodeTree")
    doubling.inputs.new("NodeSocketFloat", "Height")
    doubling.outputs.new("NodeSocketFloat", "Height")
    math = doubling.nodes.new("ShaderNodeMath")
    math.operation, math.inputs[1].default_value = "MULTIPLY", 2.0
    doubling.links.new(doubling.nodes.new("NodeGroupInput").outputs["Height"], math.inputs[0])
    doubling.links.new(math.outputs[0], doubling.nodes.new("NodeGroupOutput").inputs["Height"])
    double = tree.nodes.new("ShaderNodeGroup")
    double.node_tree = doubling
    tree.links.new(tex.outputs["Color"], double.inputs["Height"])
    tree.links.new(double.outputs["Height"], node.inputs["Height"])
    tree.links.new(node.outputs["Displacement"], output.inputs["Displacement"])
    mat.cycles.displacement_method = "BUMP"
    entry = {"result": None, "checks": []}
    try:
        bpy.ops.object.sgbake_layers_from_material()
        layers = [{"type": layer.type, "scale": layer.scale, "base": layer.base,
                   "slopes": layer.slopes, "height_space": layer.height_space}
                  for layer in settings.layers]
        entry["layers"] = layers
        entry["checks"].append({
            "name": "displacement: Layers from Material makes its layer, then the Bump's above it",
            "ok": (len(layers) == 2 and all(l["type"] == "height" and l["slopes"] == "bump-node"
                                            for l in layers)
                   and abs(layers[0]["scale"] - DISPLACEMENT_SCALE) < 1e-7
                   and layers[0]["height_space"] == "object"
                   and layers[0]["base"] == "surface" and layers[1]["base"] == "above"),
            "expected": f"two height layers: scale {DISPLACEMENT_SCALE} in object space "
                        "(surface), then the Bump's (above), slopes bump-node",
            "message": str(layers)})
        entry["result"] = bake_against_cycles(settings, ob, work, "displacement", ("base",))
    finally:
        tree.nodes.remove(node)
        tree.nodes.remove(double)
        bpy.data.node_groups.remove(doubling)
        ob.location, ob.rotation_euler, ob.scale = placement
        bpy.context.view_layer.update()
    return entry


def remap_case(settings, ob, work):
    """The bump material's texture through a Color Ramp (REMAP_STOPS, Ease) and a Math node
    (x REMAP_FACTOR, clamped) into the Bump: Layers from Material, then the add-on's
    tangent-normal bake (addon_remap.npy), the same job without the layer's "remap"
    (addon_remap_control.npy: the texture's height as it is) and Cycles' (cycles_remap.npy, its
    mask cycles_remap_mask.npy). Also: the scene sends the layer's Remap as it holds it, and a
    Remap that is not JSON points is an error report naming the layer. The material is put
    back afterwards. Returns the manifest entry (result, the layer made, checks)."""
    import bpy
    from sgbake_blender import operators, scene
    tree = ob.active_material.node_tree
    tex = next(n for n in tree.nodes if n.type == "TEX_IMAGE" and n.name != "bake_target")
    bump = next(n for n in tree.nodes if n.type == "BUMP")
    ramp = make_ramp(tree)
    times = tree.nodes.new("ShaderNodeMath")
    times.operation, times.use_clamp = "MULTIPLY", True
    times.inputs[1].default_value = REMAP_FACTOR
    tree.links.new(tex.outputs["Color"], ramp.inputs["Fac"])
    tree.links.new(ramp.outputs["Color"], times.inputs[0])
    tree.links.new(times.outputs[0], bump.inputs["Height"])
    distance = bump.inputs["Distance"].default_value
    entry = {"result": None, "checks": []}
    try:
        bpy.ops.object.sgbake_layers_from_material()
        layer = settings.layers[0]
        points = scene.remap_points(layer) or []
        entry["layer"] = {"type": layer.type, "scale": layer.scale, "slopes": layer.slopes,
                          "remap points": len(points)}
        sent = operators.BakeJob(bpy.context).scene["layers"][0].get("remap")
        entry["checks"].append({
            "name": "remap: Layers from Material makes one height layer with a remap, sent as "
                    "it is",
            "ok": (len(settings.layers) == 1 and layer.type == "height"
                   and layer.slopes == "bump-node" and abs(layer.scale - distance) < 1e-9
                   and len(points) >= 2 and sent == points),
            "expected": f"one height layer, slopes bump-node, scale {distance:.4g}, a remap, "
                        "the scene's \"remap\" its points",
            "message": f"{entry['layer']}; sent {len(sent or ())} points"
                       f"{'' if sent == points else ' (not the layer points)'}"})
        entry["result"] = bake_against_cycles(settings, ob, work, "remap", ("remap",))
        text = layer.remap
        layer.remap = "[[0, 0], [1]]"
        entry["checks"].append(expect_error("remap: a Remap that is not points is an error "
                                            "naming the layer", f"layer '{layer.name}': Remap",
                                            bpy.ops.object.sgbake_bake))
        layer.remap = text
    finally:
        tree.nodes.remove(ramp)
        tree.nodes.remove(times)
        tree.links.new(tex.outputs["Color"], bump.inputs["Height"])
    return entry


def float_curve_case(settings, ob, work):
    """The bump material's texture through a Float Curve node (FLOAT_CURVE_POINTS) into the
    Bump: Layers from Material (one height layer with a remap), then the add-on's tangent-normal
    bake (addon_float_curve.npy), the same job without the layer's "remap" and Cycles'. The
    material is put back afterwards. Returns the manifest entry (result, the layer made,
    checks)."""
    import bpy
    from sgbake_blender import scene
    tree = ob.active_material.node_tree
    tex = next(n for n in tree.nodes if n.type == "TEX_IMAGE" and n.name != "bake_target")
    bump = next(n for n in tree.nodes if n.type == "BUMP")
    node = tree.nodes.new("ShaderNodeFloatCurve")
    points = node.mapping.curves[0].points
    for i, (x, y) in enumerate(FLOAT_CURVE_POINTS):
        if i < len(points):
            points[i].location = (x, y)
        else:
            points.new(x, y)
    node.mapping.update()
    tree.links.new(tex.outputs["Color"], node.inputs["Value"])
    tree.links.new(node.outputs["Value"], bump.inputs["Height"])
    entry = {"result": None, "checks": []}
    try:
        bpy.ops.object.sgbake_layers_from_material()
        layer = settings.layers[0] if len(settings.layers) == 1 else None
        remap_points = (scene.remap_points(layer) or []) if layer else []
        # Beyond the curve's ends the remap goes on along its first and last segments.
        xs = [x for x, _ in remap_points]
        entry["layer"] = {"type": getattr(layer, "type", None), "remap points": len(xs)}
        entry["checks"].append({
            "name": "float curve: Layers from Material makes one height layer whose remap is "
                    "the curve, extrapolated",
            "ok": (layer is not None and layer.type == "height" and len(xs) >= 256
                   and xs[0] < -1.0 and xs[-1] > 2.0
                   and abs(remap_at(remap_points, FLOAT_CURVE_POINTS[1][0])
                           - FLOAT_CURVE_POINTS[1][1]) < 1e-3),
            "expected": f"one height layer, a remap through {FLOAT_CURVE_POINTS} reaching past "
                        "[0, 1]",
            "message": f"{entry['layer']}"})
        if layer is not None:
            entry["result"] = bake_against_cycles(settings, ob, work, "float_curve", ("remap",))
    finally:
        tree.nodes.remove(node)
        tree.links.new(tex.outputs["Color"], bump.inputs["Height"])
    return entry


def make_noise(tree, inputs=None):
    """A Noise Texture node in `tree` (3D) with `inputs` (NOISE_INPUTS by default)."""
    noise = tree.nodes.new("ShaderNodeTexNoise")
    noise.noise_dimensions = "3D"
    for name, value in (inputs or NOISE_INPUTS).items():
        noise.inputs[name].default_value = value
    return noise


def noise_layer_ok(values, mapping=None, generated=False):
    """Whether layer settings or a layer (`values`: dict or SgbakeLayer) are NOISE_INPUTS' volume
    with the bump node's slopes, amplitude NOISE_DISTANCE, with `mapping` (Point: location,
    rotation, scale) or none, on the Generated coordinates when `generated`."""
    get = values.get if isinstance(values, dict) else (lambda k, d=None: getattr(values, k, d))
    close = lambda a, b: abs(a - b) < 1e-6  # noqa: E731  (float32 properties)
    ok = (get("type") == "volume" and get("function") == "blender-noise"
          and get("gradient") == "bump-node" and close(get("amplitude", 0), NOISE_DISTANCE)
          and close(get("frequency", 0), NOISE_INPUTS["Scale"])
          and close(get("detail", 0), NOISE_INPUTS["Detail"])
          and close(get("roughness", 0), NOISE_INPUTS["Roughness"])
          and close(get("distortion", 0), NOISE_INPUTS["Distortion"])
          and bool(get("coordinates_generated", False)) == generated)
    if mapping is not None:
        ok = ok and get("mapping_type", "POINT") == "POINT" and all(
            close(a, b) for name, want in zip(("location", "rotation", "scale"), mapping)
            for a, b in zip(get(f"mapping_{name}", (9, 9, 9)), want))
    return ok


def noise_case(settings, ob, work):
    """The bump material's Height fed by a Noise Texture (NOISE_INPUTS) on the object's own
    coordinates through a Mapping node (NOISE_MAPPING), Distance NOISE_DISTANCE: Layers from
    Material, then the add-on's tangent-normal bake (addon_noise.npy), the same job without
    the layer's "mapping" (addon_noise_control.npy) and Cycles' (cycles_noise.npy, its mask
    cycles_noise_mask.npy). Then the Vector unlinked on Suzanne placed as NOISE_PLACEMENT: the
    Generated coordinates (addon_noise_generated.npy, its control without the "mapping",
    cycles_noise_generated.npy). The material and the object are put back afterwards. Returns
    the manifest entry (results, the layers made, checks)."""
    import bpy
    from sgbake_blender import operators
    tree = ob.active_material.node_tree
    tex = next(n for n in tree.nodes if n.type == "TEX_IMAGE" and n.name != "bake_target")
    bump = next(n for n in tree.nodes if n.type == "BUMP")
    distance = bump.inputs["Distance"].default_value
    noise = make_noise(tree)
    coordinates = tree.nodes.new("ShaderNodeTexCoord")
    mapping = tree.nodes.new("ShaderNodeMapping")
    mapping.vector_type = "POINT"
    for name, value in zip(("Location", "Rotation", "Scale"), NOISE_MAPPING):
        mapping.inputs[name].default_value = value
    tree.links.new(coordinates.outputs["Object"], mapping.inputs["Vector"])
    tree.links.new(mapping.outputs["Vector"], noise.inputs["Vector"])
    tree.links.new(noise.outputs["Fac"], bump.inputs["Height"])
    bump.inputs["Distance"].default_value = NOISE_DISTANCE
    placement = (tuple(ob.location), tuple(ob.rotation_euler), tuple(ob.scale))
    entry = {"result": None, "generated_result": None, "checks": []}

    def made():
        """Layers from Material's first layer and what the bake sends of it; (None, its error
        or {}) when it makes none."""
        try:
            bpy.ops.object.sgbake_layers_from_material()
        except RuntimeError as exc:
            return None, {"error": str(exc).strip()}
        if not settings.layers:
            return None, {}
        return settings.layers[0], operators.BakeJob(bpy.context).scene["layers"][0]

    try:
        layer, sent = made()
        entry["layer"] = sent
        want = {"type": "volume", "function": "blender-noise", "gradient": "bump-node",
                "mapping": {"location": list(NOISE_MAPPING[0]),
                            "rotation": list(NOISE_MAPPING[1]), "scale": list(NOISE_MAPPING[2])}}
        entry["checks"].append({
            "name": "noise: Layers from Material makes one blender-noise volume of the node's "
                    "settings and its Mapping, sent so",
            "ok": (layer is not None and len(settings.layers) == 1
                   and noise_layer_ok(layer, NOISE_MAPPING)
                   and sent.get("type") == "volume" and sent.get("function") == "blender-noise"
                   and sent.get("gradient") == "bump-node" and "step" not in sent
                   and "seed" not in sent and "octaves" not in sent
                   and all(abs(sent.get(key, -1) - NOISE_INPUTS[name]) < 1e-6
                           for key, name in (("frequency", "Scale"), ("detail", "Detail"),
                                             ("roughness", "Roughness"),
                                             ("distortion", "Distortion")))
                   and "matrix" not in sent.get("mapping", {})
                   and all(abs(a - b) < 1e-6 for key in ("location", "rotation", "scale")
                           for a, b in zip(sent.get("mapping", {}).get(key, [9] * 3),
                                           want["mapping"][key]))),
            "expected": f"one volume layer {want}, {NOISE_INPUTS}, amplitude {NOISE_DISTANCE}",
            "message": f"{len(settings.layers)} layer(s); sent {sent}"})
        if layer is not None:
            entry["result"] = bake_against_cycles(settings, ob, work, "noise", ("mapping",))
        # The Vector unlinked: Cycles reads the Generated coordinates.
        tree.nodes.remove(mapping)
        tree.nodes.remove(coordinates)
        mapping = coordinates = None
        ob.location, ob.rotation_euler, ob.scale = NOISE_PLACEMENT
        bpy.context.view_layer.update()
        layer, sent = made()
        entry["generated_layer"] = sent
        # Independently of the add-on's matrix: Suzanne's texture space is its bounding box
        # (auto), which the Generated coordinates map to [0, 1]^3.
        corners = [ob.data.vertices[0].co.copy(), ob.data.vertices[0].co.copy()]
        for v in ob.data.vertices:
            for i in range(3):
                corners[0][i] = min(corners[0][i], v.co[i])
                corners[1][i] = max(corners[1][i], v.co[i])
        rows = sent.get("mapping", {}).get("matrix")
        mapped = ([[sum(rows[r][c] * corner[c] for c in range(3)) + rows[r][3]
                    for r in range(3)] for corner in corners] if rows else None)
        worst = (max(abs(mapped[k][r] - k) for k in range(2) for r in range(3))
                 if mapped else None)
        entry["checks"].append({
            "name": "noise: the Vector unlinked reads the Generated coordinates",
            "ok": (layer is not None and len(settings.layers) == 1
                   and noise_layer_ok(layer, generated=True)
                   and worst is not None and worst < 1e-5),
            "expected": "a blender-noise volume, Generated Coordinates, its matrix taking the "
                        "bounding box to [0, 1]^3",
            "message": f"generated {getattr(layer, 'coordinates_generated', None)}; sent "
                       f"{sent}; the box's "
                       f"corners to {mapped} (max off {worst})"})
        if layer is not None:
            entry["generated_result"] = bake_against_cycles(settings, ob, work,
                                                            "noise_generated", ("mapping",))
    finally:
        for node in (mapping, coordinates, noise):
            if node is not None:
                tree.nodes.remove(node)
        tree.links.new(tex.outputs["Color"], bump.inputs["Height"])
        bump.inputs["Distance"].default_value = distance
        ob.location, ob.rotation_euler, ob.scale = placement
        bpy.context.view_layer.update()
    return entry


class TextureChecks:
    """What the Layers from Material checks of one procedural texture share: the test material's
    tree, its Image Texture and Bump nodes, the check records, and two ways to add one."""

    def __init__(self, ob, label):
        from sgbake_blender import operators
        self.ob, self.label, self.operators = ob, label, operators
        self.tree = ob.active_material.node_tree
        self.tex = next(n for n in self.tree.nodes
                        if n.type == "TEX_IMAGE" and n.name != "bake_target")
        self.bump = next(n for n in self.tree.nodes if n.type == "BUMP")
        self.checks = []

    def check(self, name, ok, expected, message):
        self.checks.append({"name": name, "ok": bool(ok), "expected": expected,
                            "message": message})

    def refused(self, what, reason):
        """A check that the material makes no layer and names `reason` for the Bump node."""
        found, skipped, _ = self.operators.material_layers(self.tree, "UVMap", self.ob)
        bump = f"'{self.bump.name}'"
        self.check(f"{self.label}: {what} gives no layer and a reason",
                   not found and any(bump in note and reason in note for note in skipped),
                   f"no layer, {bump} skipped: ...{reason}...", f"{found}; skipped {skipped}")


def hand_made_check(settings, label, title, values, want, absent):
    """One check record: a volume layer made by hand (named "by hand", slopes "bump-node") with
    properties `values`, baked at 64^2, must be sent with the settings `want` (key -> value;
    numbers within 1e-6) and none of the keys `absent`, and bake. The layer is removed again."""
    import bpy
    from sgbake_blender import operators
    layer = settings.layers.add()
    layer.name, layer.type, layer.gradient = "by hand", "volume", "bump-node"
    for prop, value in values.items():
        setattr(layer, prop, value)
    settings.width = settings.height = 64
    try:
        job = operators.BakeJob(bpy.context)
        sent = job.scene["layers"][-1]
        job.run()
    except Exception as exc:  # (BakeInputError: reported as the check's failure)
        sent, job = {"error": str(exc)}, None
    finally:
        settings.layers.remove(len(settings.layers) - 1)
        settings.width = settings.height = SIZE
    ok = (job is not None and job.error is None
          and all(sent.get(key) == value if isinstance(value, str)
                  else abs(sent.get(key, -1) - value) < 1e-6 for key, value in want.items())
          and not set(absent) & set(sent))
    return {"name": f"{label}: a {title} volume made by hand is sent with its settings and bakes",
            "ok": bool(ok), "expected": f"{want}; none of {', '.join(absent)}; baked",
            "message": f"sent {sent}; error {job.error if job else None}"}


def noise_checks(settings, ob, distance):
    """Layers from Material on Noise Textures it does not take (its Color output, a Detail fed by
    a node, a W fed by a node in 4D, the normal into its Vector: no layer, a reason), of
    Dimensions 4D and 2D (a layer of those Dimensions, its W in 4D), on a UV Map node's
    coordinates (a volume on that UV map), through a Color Ramp (a remap), and a volume layer
    made by hand with function Blender Noise. Returns check records like expect_error's."""
    import bpy
    from sgbake_blender import operators
    c = TextureChecks(ob, "noise")
    tree, tex, bump, checks, check, refused = c.tree, c.tex, c.bump, c.checks, c.check, c.refused
    noise = make_noise(tree)

    try:
        tree.links.new(noise.outputs["Color"], bump.inputs["Height"])
        refused("its Color output", "Color output")
        tree.links.new(noise.outputs["Fac"], bump.inputs["Height"])
        # Dimensions: 4D sends its W, 2D none; a W fed by a node is refused where it is read.
        noise.noise_dimensions = "4D"
        noise.inputs["W"].default_value = 0.4
        found, skipped, _ = operators.material_layers(tree, "UVMap", ob)
        check("noise: Dimensions 4D makes a layer of its Dimensions and W",
              len(found) == 1 and found[0].get("texture_dimensions") == "4D"
              and abs(found[0].get("w", -1) - 0.4) < 1e-6,
              "one layer, texture_dimensions 4D, w 0.4", f"{found}; skipped {skipped}")
        feeder = tree.nodes.new("ShaderNodeTexNoise")
        tree.links.new(feeder.outputs["Fac"], noise.inputs["W"])
        refused("a W fed by another texture in 4D", "W from a node")
        noise.noise_dimensions = "2D"
        found, skipped, _ = operators.material_layers(tree, "UVMap", ob)
        check("noise: Dimensions 2D makes a layer of its Dimensions without W (its W, fed by a "
              "node, not read)",
              len(found) == 1 and found[0].get("texture_dimensions") == "2D"
              and "w" not in found[0],
              "one layer, texture_dimensions 2D, no w", f"{found}; skipped {skipped}")
        tree.nodes.remove(feeder)
        noise.noise_dimensions = "3D"
        feeder = tree.nodes.new("ShaderNodeTexNoise")
        tree.links.new(feeder.outputs["Fac"], noise.inputs["Detail"])
        refused("a Detail fed by another texture", "Detail from a node")
        tree.nodes.remove(feeder)
        # A UV Map node naming a UV map: a volume on those UV coordinates; world positions
        # (the Geometry node's Position) make none.
        uv = tree.nodes.new("ShaderNodeUVMap")
        uv.uv_map = "UVMap"
        tree.links.new(uv.outputs["UV"], noise.inputs["Vector"])
        found, skipped, _ = operators.material_layers(tree, "UVMap", ob)
        check("noise: a UV Map node into its Vector makes a volume on that UV map's coordinates",
              len(found) == 1 and found[0].get("function") == "blender-noise"
              and found[0].get("coordinates_uv") is True and found[0].get("uv_map") == "UVMap"
              and "coordinates_generated" not in found[0],
              "one blender-noise layer, coordinates_uv, uv_map 'UVMap'",
              f"{found}; skipped {skipped}")
        tree.nodes.remove(uv)
        geometry = tree.nodes.new("ShaderNodeNewGeometry")
        tree.links.new(geometry.outputs["Normal"], noise.inputs["Vector"])
        refused("the normal (Geometry Normal) into its Vector", "Vector from")
        tree.nodes.remove(geometry)
        # Through a Color Ramp: the layer's remap is Cycles' table of the ramp.
        ramp = make_ramp(tree)
        tree.links.new(noise.outputs["Fac"], ramp.inputs["Fac"])
        tree.links.new(ramp.outputs["Color"], bump.inputs["Height"])
        found, skipped, _ = operators.material_layers(tree, "UVMap", ob)
        points = found[0].get("remap") if len(found) == 1 else None
        worst = (max(abs(remap_at(points, i / 255)
                         - sum(w * c for w, c in zip(REMAP_LUMINANCE,
                                                     cycles_ramp(ramp.color_ramp, i / 255))))
                     for i in range(256)) if points else None)
        check("noise: a Noise Texture through a Color Ramp into the Bump makes a blender-noise "
              "layer with a remap",
              len(found) == 1 and found[0].get("function") == "blender-noise"
              and abs(found[0].get("amplitude", 0) - distance) < 1e-7
              and worst is not None and worst < REMAP_TOLERANCE,
              f"one blender-noise layer, amplitude {distance:.4g}, the ramp's luminance as its "
              "remap",
              f"{[{k: v for k, v in f.items() if k != 'remap'} for f in found]}; skipped "
              f"{skipped}; remap of {len(points or ())} points, max off {worst}")
        tree.nodes.remove(ramp)
    finally:
        tree.nodes.remove(noise)
        tree.links.new(tex.outputs["Color"], bump.inputs["Height"])
    # A volume layer made by hand, function Blender Noise: its inputs sent (no seed or
    # octaves, no mapping), and it bakes.
    checks.append(hand_made_check(
        settings, "noise", "Blender Noise",
        {"function": "blender-noise", "frequency": 5.0, "detail": 1.5, "roughness": 0.7,
         "distortion": 0.2, "amplitude": 0.02, "texture_dimensions": "4D", "w": 0.3},
        {"function": "blender-noise", "detail": 1.5, "roughness": 0.7, "distortion": 0.2,
         "dimensions": "4D", "w": 0.3},
        ("seed", "octaves", "mapping")))
    return checks


def make_musgrave(tree, inputs=None, musgrave_type="FBM"):
    """A Musgrave Texture node in `tree` (`musgrave_type`, 3D) with `inputs` (MUSGRAVE_INPUTS
    by default)."""
    musgrave = tree.nodes.new("ShaderNodeTexMusgrave")
    musgrave.musgrave_type, musgrave.musgrave_dimensions = musgrave_type, "3D"
    for name, value in (inputs or MUSGRAVE_INPUTS).items():
        musgrave.inputs[name].default_value = value
    return musgrave


MUSGRAVE_KEYS = {"frequency": "Scale", "detail": "Detail", "dimension": "Dimension",
                 "lacunarity": "Lacunarity"}  # the layer's settings -> the node's inputs


def musgrave_case(settings, ob, work):
    """The bump material's Height fed by a Musgrave Texture (MUSGRAVE_INPUTS) on the object's
    own coordinates through a Mapping node (MUSGRAVE_MAPPING), Distance MUSGRAVE_DISTANCE:
    texture_case "musgrave", its control without the layer's "dimension" and "lacunarity"."""
    return texture_case(settings, ob, work, "musgrave", make_musgrave, MUSGRAVE_KEYS,
                        MUSGRAVE_INPUTS, {"musgrave_type": "fbm"},
                        {"roughness", "distortion", "offset", "gain"}, MUSGRAVE_MAPPING,
                        MUSGRAVE_DISTANCE, ("dimension", "lacunarity"))


MUSGRAVE_RIDGED_KEYS = dict(MUSGRAVE_KEYS, musgrave_offset="Offset", gain="Gain")


def musgrave_ridged_case(settings, ob, work):
    """The bump material's Height fed by a Ridged Multifractal Musgrave Texture
    (MUSGRAVE_RIDGED_INPUTS) on the object's own coordinates through a Mapping node
    (MUSGRAVE_MAPPING), Distance MUSGRAVE_RIDGED_DISTANCE: texture_case "musgrave_ridged" (a
    "blender-musgrave" layer of type ridged-multifractal with its offset and gain), its control
    the layer left at fBM (without its "musgrave_type", "offset" and "gain")."""
    return texture_case(
        settings, ob, work, "musgrave_ridged",
        lambda tree: make_musgrave(tree, MUSGRAVE_RIDGED_INPUTS, "RIDGED_MULTIFRACTAL"),
        MUSGRAVE_RIDGED_KEYS, MUSGRAVE_RIDGED_INPUTS, {"musgrave_type": "ridged-multifractal"},
        {"roughness", "distortion"}, MUSGRAVE_MAPPING, MUSGRAVE_RIDGED_DISTANCE,
        ("musgrave_type", "offset", "gain"), function="blender-musgrave")


def texture_case(settings, ob, work, case, make, keys, inputs, enums, absent, mapping_values,
                 distance_value, control_keys, output="Fac", coordinates="Object",
                 function=None, placement=None):
    """The bump material's Height fed by the `output` of the procedural texture node make(tree)
    makes (`inputs`: its inputs -> values; `enums`: the layer settings its enum properties
    must give, as sent) on the object's own coordinates (the Texture Coordinate node's output
    `coordinates`: with "UV", the UV map's, which the layer must read with "coordinates": "uv"
    on the render UV map's set; with "Position", a Geometry node's world positions, which the
    layer must read through the object's matrix_world, the object placed as `placement`
    (location, rotation, scale) meanwhile) through a Mapping node (Point, `mapping_values`),
    Distance `distance_value`: Layers from Material must make one `function` (default
    "blender-CASE") volume layer of those settings (`keys`: the layer's settings -> the node's
    inputs, sent under the scene's keys, SETTING_KEYS) and that mapping, sending none of
    `absent`; then the add-on's tangent-normal bake
    (addon_CASE.npy), the same job without `control_keys` (addon_CASE_control.npy), Cycles'
    (cycles_CASE.npy, its mask cycles_CASE_mask.npy) and the add-on's bake of the layer at
    amplitude 0 (addon_CASE_flat.npy), the normals Cycles' lean off. The material is put back
    afterwards. Returns the manifest entry (result, the layer sent, checks)."""
    import bpy
    import numpy as np
    from sgbake_blender import operators, scene as addon_scene
    function = function or f"blender-{case}"
    on_uv, on_world = coordinates == "UV", coordinates == "Position"
    tree = ob.active_material.node_tree
    tex = next(n for n in tree.nodes if n.type == "TEX_IMAGE" and n.name != "bake_target")
    bump = next(n for n in tree.nodes if n.type == "BUMP")
    distance = bump.inputs["Distance"].default_value
    texture = make(tree)
    mapping = tree.nodes.new("ShaderNodeMapping")
    mapping.vector_type = "POINT"
    for name, value in zip(("Location", "Rotation", "Scale"), mapping_values):
        mapping.inputs[name].default_value = value
    coordinates_output = coordinates
    coordinates = tree.nodes.new("ShaderNodeNewGeometry" if on_world else "ShaderNodeTexCoord")
    placed = (tuple(ob.location), tuple(ob.rotation_euler), tuple(ob.scale))
    if placement is not None:
        ob.location, ob.rotation_euler, ob.scale = placement
        bpy.context.view_layer.update()
    world = [[ob.matrix_world[r][c] for c in range(4)] for r in range(3)]
    tree.links.new(coordinates.outputs[coordinates_output], mapping.inputs["Vector"])
    tree.links.new(mapping.outputs["Vector"], texture.inputs["Vector"])
    tree.links.new(texture.outputs[output], bump.inputs["Height"])
    bump.inputs["Distance"].default_value = distance_value
    entry = {"result": None, "checks": []}
    close = lambda a, b: abs(a - b) < 1e-6  # noqa: E731  (float32 properties)
    try:
        try:
            bpy.ops.object.sgbake_layers_from_material()
            layer = settings.layers[0] if len(settings.layers) == 1 else None
            sent = operators.BakeJob(bpy.context).scene["layers"][0] if layer else {}
        except RuntimeError as exc:
            layer, sent = None, {"error": str(exc).strip()}
        entry["layer"] = sent
        mapped = sent.get("mapping", {})
        entry["checks"].append({
            "name": f"{case}: Layers from Material makes one {function} volume of the "
                    "node's settings and its Mapping, sent so",
            "ok": (layer is not None and layer.type == "volume"
                   and layer.function == function
                   and close(layer.amplitude, distance_value)
                   and all(close(getattr(layer, key), inputs[name])
                           for key, name in keys.items())
                   and all(getattr(layer, key) == value for key, value in enums.items())
                   and sent.get("function") == function
                   and sent.get("gradient") == "bump-node"
                   and close(sent.get("amplitude", 0), distance_value)
                   and all(close(sent.get(addon_scene.SETTING_KEYS.get(key, key), -1),
                                 inputs[name]) for key, name in keys.items())
                   and all(sent.get(key) == value for key, value in enums.items())
                   and not ({"seed", "octaves", "step"} | set(absent)) & set(sent)
                   and bool(layer.coordinates_uv) == on_uv
                   and bool(layer.coordinates_world) == on_world
                   and (sent.get("coordinates"), "uv" in sent) == (("uv", True) if on_uv
                                                                   else (None, False))
                   and (all(abs(a - b) < 1e-6 for row, want in zip(mapped["matrix"], world)
                            for a, b in zip(row, want))
                        if on_world and len(mapped.get("matrix", ())) == 3
                        else not on_world and "matrix" not in mapped)
                   and "type" not in mapped
                   and all(close(a, b) for key, want in zip(("location", "rotation", "scale"),
                                                            mapping_values)
                           for a, b in zip(mapped.get(key, [9] * 3), want))),
            "expected": f"one {function} volume, {inputs}, {enums}, amplitude "
                        f"{distance_value}, bump-node, mapping {mapping_values}, none of "
                        f"{sorted(absent)}" + (", on the UV map's coordinates" if on_uv
                                               else f", matrix {world}" if on_world else ""),
            "message": f"{len(settings.layers)} layer(s); sent {sent}"})
        if layer is not None:
            entry["result"] = bake_against_cycles(settings, ob, work, case, control_keys)
            # The surface's own normals (the layer at amplitude 0), what the bump leans off.
            job = operators.BakeJob(bpy.context)
            for scene_of_tile in job.scenes.values():
                for sent_layer in scene_of_tile["layers"]:
                    sent_layer["amplitude"] = 0.0
            job.run()
            if job.error is None:
                flat, _ = job.finish()
                np.save(os.path.join(work, f"addon_{case}_flat.npy"), bc.image_array(flat))
    finally:
        for node in (mapping, coordinates, texture):
            tree.nodes.remove(node)
        tree.links.new(tex.outputs["Color"], bump.inputs["Height"])
        bump.inputs["Distance"].default_value = distance
        ob.location, ob.rotation_euler, ob.scale = placed
        bpy.context.view_layer.update()
    return entry


def musgrave_checks(settings, ob):
    """Layers from Material on Musgrave Textures of each type (each taken: its type in the
    scene's name, the Offset and Gain where the type uses them, a Gain fed by a node where it
    does not), of Dimensions 1D (its W sent), on those it does not take (a Lacunarity or a used
    Offset fed by a node: no layer, a reason), and volume layers made by hand with function
    Blender Musgrave.
    Returns check records like expect_error's."""
    import bpy
    from sgbake_blender import operators
    c = TextureChecks(ob, "musgrave")
    tree, tex, bump, checks, check, refused = c.tree, c.tex, c.bump, c.checks, c.check, c.refused
    musgrave = make_musgrave(tree)

    try:
        tree.links.new(musgrave.outputs["Fac"], bump.inputs["Height"])
        musgrave.inputs["Offset"].default_value = 0.8
        musgrave.inputs["Gain"].default_value = 1.9
        for blender_type, name, used in (
                ("FBM", "fbm", ()), ("MULTIFRACTAL", "multifractal", ()),
                ("RIDGED_MULTIFRACTAL", "ridged-multifractal", ("musgrave_offset", "gain")),
                ("HYBRID_MULTIFRACTAL", "hybrid-multifractal", ("musgrave_offset", "gain")),
                ("HETERO_TERRAIN", "hetero-terrain", ("musgrave_offset",))):
            musgrave.musgrave_type = blender_type
            found, skipped, _ = operators.material_layers(tree, "UVMap", ob)
            want = {"musgrave_offset": 0.8, "gain": 1.9}
            got = found[0] if len(found) == 1 else {}
            check(f"musgrave: type {blender_type} makes a {name} layer with "
                  f"{', '.join(used) or 'neither offset nor gain'}",
                  got.get("function") == "blender-musgrave" and got.get("musgrave_type") == name
                  and all(abs(got.get(key, -1) - want[key]) < 1e-6 for key in used)
                  and not (set(want) - set(used)) & set(got),
                  f"one blender-musgrave layer, musgrave_type {name}, "
                  f"{ {key: want[key] for key in used} }",
                  f"{found}; skipped {skipped}")
        # An input the type does not use may come from a node (Cycles reads none of it); one
        # it uses may not.
        feeder = tree.nodes.new("ShaderNodeTexNoise")
        tree.links.new(feeder.outputs["Fac"], musgrave.inputs["Gain"])
        found, skipped, _ = operators.material_layers(tree, "UVMap", ob)
        check("musgrave: a Hetero Terrain's Gain fed by another texture still makes a layer",
              len(found) == 1 and found[0].get("musgrave_type") == "hetero-terrain",
              "one hetero-terrain layer", f"{found}; skipped {skipped}")
        tree.nodes.remove(feeder)
        feeder = tree.nodes.new("ShaderNodeTexNoise")
        tree.links.new(feeder.outputs["Fac"], musgrave.inputs["Offset"])
        refused("a Hetero Terrain's Offset fed by another texture", "Offset from a node")
        tree.nodes.remove(feeder)
        musgrave.musgrave_type = "FBM"
        musgrave.musgrave_dimensions = "1D"
        musgrave.inputs["W"].default_value = -0.6
        found, skipped, _ = operators.material_layers(tree, "UVMap", ob)
        check("musgrave: Dimensions 1D makes a layer of its Dimensions and W",
              len(found) == 1 and found[0].get("texture_dimensions") == "1D"
              and abs(found[0].get("w", 1) + 0.6) < 1e-6,
              "one layer, texture_dimensions 1D, w -0.6", f"{found}; skipped {skipped}")
        musgrave.musgrave_dimensions = "3D"
        feeder = tree.nodes.new("ShaderNodeTexNoise")
        tree.links.new(feeder.outputs["Fac"], musgrave.inputs["Lacunarity"])
        refused("a Lacunarity fed by another texture", "Lacunarity from a node")
        tree.nodes.remove(feeder)
        found, skipped, _ = operators.material_layers(tree, "UVMap", ob)
        check("musgrave: the same node as fBM, 3D, its inputs constants makes a layer",
              len(found) == 1 and found[0].get("function") == "blender-musgrave"
              and found[0].get("coordinates_generated"),
              "one blender-musgrave layer on the Generated coordinates (Vector unlinked)",
              f"{found}; skipped {skipped}")
    finally:
        tree.nodes.remove(musgrave)
        tree.links.new(tex.outputs["Color"], bump.inputs["Height"])
    # A volume layer made by hand, function Blender Musgrave: its inputs sent (none of Blender
    # Noise's), and it bakes.
    checks.append(hand_made_check(
        settings, "musgrave", "Blender Musgrave",
        {"function": "blender-musgrave", "frequency": 4.0, "detail": 2.5, "dimension": 1.2,
         "lacunarity": 2.6, "amplitude": 0.01},
        {"function": "blender-musgrave", "musgrave_type": "fbm", "detail": 2.5, "dimension": 1.2,
         "lacunarity": 2.6},
        ("roughness", "distortion", "seed", "octaves", "mapping", "offset", "gain")))
    # Of type Hybrid Multifractal: its Offset and Gain sent too; of Hetero Terrain its Offset.
    checks.append(hand_made_check(
        settings, "musgrave", "Blender Musgrave (Hybrid Multifractal)",
        {"function": "blender-musgrave", "musgrave_type": "hybrid-multifractal", "detail": 3.0,
         "musgrave_offset": 0.6, "gain": 2.2, "amplitude": 0.01},
        {"function": "blender-musgrave", "musgrave_type": "hybrid-multifractal", "detail": 3.0,
         "offset": 0.6, "gain": 2.2},
        ("roughness", "distortion", "musgrave_offset")))
    checks.append(hand_made_check(
        settings, "musgrave", "Blender Musgrave (Hetero Terrain)",
        {"function": "blender-musgrave", "musgrave_type": "hetero-terrain",
         "musgrave_offset": -0.3, "gain": 2.2, "amplitude": 0.01},
        {"function": "blender-musgrave", "musgrave_type": "hetero-terrain", "offset": -0.3},
        ("gain", "musgrave_offset")))
    return checks


def make_wave(tree, inputs=None, node=None):
    """A Wave Texture node in `tree` with its properties `node` (WAVE_NODE by default) and
    `inputs` (WAVE_INPUTS by default)."""
    wave = tree.nodes.new("ShaderNodeTexWave")
    for prop, value in (node or WAVE_NODE).items():
        setattr(wave, prop, value)
    for name, value in (inputs or WAVE_INPUTS).items():
        wave.inputs[name].default_value = value
    return wave


WAVE_KEYS = {"frequency": "Scale", "distortion": "Distortion", "detail": "Detail",
             "detail_scale": "Detail Scale", "detail_roughness": "Detail Roughness",
             "phase": "Phase Offset"}  # the layer's settings -> the node's inputs


def wave_case(settings, ob, work):
    """The bump material's Height fed by a Wave Texture (WAVE_NODE, WAVE_INPUTS) on the object's
    own coordinates through a Mapping node (WAVE_MAPPING), Distance WAVE_DISTANCE:
    texture_case "wave", its enums WAVE_ENUMS, its control without the layer's "phase"."""
    return texture_case(settings, ob, work, "wave", make_wave, WAVE_KEYS, WAVE_INPUTS,
                        WAVE_ENUMS, {"roughness", "dimension", "lacunarity", "direction"},
                        WAVE_MAPPING, WAVE_DISTANCE, ("phase",))


def wave_checks(settings, ob):
    """Layers from Material on Wave Textures: Bands Diagonal Saw and Rings Z Triangle give the
    scene's names, the Color output the Fac's layer, a Phase Offset fed by a node no layer and
    a reason; and a volume layer made by hand with function Blender Wave. Returns check
    records like expect_error's."""
    import bpy
    from sgbake_blender import operators
    c = TextureChecks(ob, "wave")
    tree, tex, bump, checks, check, refused = c.tree, c.tex, c.bump, c.checks, c.check, c.refused
    wave = make_wave(tree)

    try:
        tree.links.new(wave.outputs["Fac"], bump.inputs["Height"])
        for node, names in ((("BANDS", "bands_direction", "DIAGONAL", "SAW"),
                             ("bands", "diagonal", "saw")),
                            (("RINGS", "rings_direction", "Z", "TRI"), ("rings", "z", "triangle"))):
            wave.wave_type, wave.wave_profile = node[0], node[3]
            setattr(wave, node[1], node[2])
            found, skipped, _ = operators.material_layers(tree, "UVMap", ob)
            made = {key: found[0].get(key) for key in WAVE_ENUMS} if len(found) == 1 else {}
            check(f"wave: {node[0].title()} {node[2].title()} {node[3].title()} gives the scene's "
                  "names", made == dict(zip(WAVE_ENUMS, names))
                  and found[0].get("function") == "blender-wave",
                  f"one blender-wave layer, {dict(zip(WAVE_ENUMS, names))}",
                  f"{found}; skipped {skipped}")
        tree.links.new(wave.outputs["Color"], bump.inputs["Height"])
        from_color, skipped, _ = operators.material_layers(tree, "UVMap", ob)
        check("wave: the Color output (Fac, Fac, Fac) gives the Fac's layer",
              len(from_color) == 1 and from_color == found,
              f"the Fac's layer {found}", f"{from_color}; skipped {skipped}")
        tree.links.new(wave.outputs["Fac"], bump.inputs["Height"])
        feeder = tree.nodes.new("ShaderNodeTexNoise")
        tree.links.new(feeder.outputs["Fac"], wave.inputs["Phase Offset"])
        found, skipped, _ = operators.material_layers(tree, "UVMap", ob)
        reason = "Phase Offset from a node"
        check("wave: a Phase Offset fed by another texture gives no layer and a reason",
              not found and any(f"'{bump.name}'" in note and reason in note
                                for note in skipped),
              f"no layer, '{bump.name}' skipped: ...{reason}...", f"{found}; skipped {skipped}")
        tree.nodes.remove(feeder)
    finally:
        tree.nodes.remove(wave)
        tree.links.new(tex.outputs["Color"], bump.inputs["Height"])
    # A volume layer made by hand, function Blender Wave: its settings sent (none of the other
    # functions'), and it bakes.
    checks.append(hand_made_check(
        settings, "wave", "Blender Wave",
        {"function": "blender-wave", "wave": "bands", "wave_direction": "diagonal",
         "profile": "triangle", "frequency": 4.0, "phase": 0.5, "distortion": 0.8,
         "detail": 1.5, "detail_scale": 2.0, "detail_roughness": 0.7, "amplitude": 0.01},
        {"function": "blender-wave", "wave": "bands", "wave_direction": "diagonal",
         "profile": "triangle", "frequency": 4.0, "phase": 0.5, "distortion": 0.8,
         "detail": 1.5, "detail_scale": 2.0, "detail_roughness": 0.7},
        ("roughness", "dimension", "lacunarity", "direction", "seed", "octaves", "mapping")))
    return checks


def make_voronoi(tree, inputs=None, feature=None):
    """A Voronoi Texture node in `tree` with its properties VORONOI_NODE (but its Feature Output
    `feature` if given) and `inputs` (VORONOI_INPUTS by default)."""
    voronoi = tree.nodes.new("ShaderNodeTexVoronoi")
    for prop, value in VORONOI_NODE.items():
        setattr(voronoi, prop, value)
    if feature is not None:
        voronoi.feature = feature
    for name, value in (inputs or VORONOI_INPUTS).items():
        voronoi.inputs[name].default_value = value
    return voronoi


VORONOI_KEYS = {"frequency": "Scale", "randomness": "Randomness",
                "exponent": "Exponent"}  # the layer's settings -> the node's inputs


def voronoi_case(settings, ob, work):
    """The bump material's Height fed by a Voronoi Texture's Distance (VORONOI_NODE,
    VORONOI_INPUTS) on the object's own coordinates through a Mapping node (VORONOI_MAPPING),
    Distance VORONOI_DISTANCE: texture_case "voronoi", its enums VORONOI_ENUMS, its control
    without the layer's "mapping"."""
    return texture_case(settings, ob, work, "voronoi", make_voronoi, VORONOI_KEYS,
                        VORONOI_INPUTS, VORONOI_ENUMS,
                        {"roughness", "distortion", "detail", "dimension", "lacunarity",
                         "direction", "phase", "wave"}, VORONOI_MAPPING, VORONOI_DISTANCE,
                        ("mapping",), output="Distance")


def voronoi_edge_case(settings, ob, work):
    """The bump material's Height fed by a Voronoi Texture's Distance to Edge
    (VORONOI_EDGE_INPUTS) on the object's own coordinates through a Mapping node
    (VORONOI_MAPPING), Distance VORONOI_EDGE_DISTANCE: texture_case "voronoi_edge" (a
    "blender-voronoi" layer of feature distance-to-edge, without a metric, exponent or
    smoothness), its control the layer left at F1 (without its "feature")."""
    return texture_case(
        settings, ob, work, "voronoi_edge",
        lambda tree: make_voronoi(tree, VORONOI_EDGE_INPUTS, "DISTANCE_TO_EDGE"),
        {"frequency": "Scale", "randomness": "Randomness"}, VORONOI_EDGE_INPUTS,
        {"feature": "distance-to-edge"},
        {"roughness", "distortion", "detail", "metric", "exponent", "smoothness"},
        VORONOI_MAPPING, VORONOI_EDGE_DISTANCE, ("feature",), output="Distance",
        function="blender-voronoi")


NOISE_KEYS = {"frequency": "Scale", "detail": "Detail", "roughness": "Roughness",
              "distortion": "Distortion"}


def noise_uv_case(settings, ob, work):
    """The bump material's Height fed by a Noise Texture (NOISE_INPUTS) on the UV map's
    coordinates (Texture Coordinate UV) through a Mapping node (NOISE_UV_MAPPING), Distance
    NOISE_UV_DISTANCE: texture_case "noise_uv", a blender-noise volume on "coordinates": "uv",
    its control the same layer on the object's coordinates (without "coordinates" and "uv")."""
    return texture_case(settings, ob, work, "noise_uv", make_noise, NOISE_KEYS, NOISE_INPUTS,
                        {}, {"dimension", "lacunarity", "randomness", "wave"}, NOISE_UV_MAPPING,
                        NOISE_UV_DISTANCE, ("coordinates", "uv"), coordinates="UV",
                        function="blender-noise")


def noise_world_case(settings, ob, work):
    """The bump material's Height fed by a Noise Texture (NOISE_INPUTS) on world positions (a
    Geometry node's Position) through a Mapping node (NOISE_MAPPING), Distance NOISE_DISTANCE,
    Suzanne placed as NOISE_WORLD_PLACEMENT (moved, turned, scaled): texture_case "noise_world", a blender-noise volume on
    coordinates ob.matrix_world, its control the same layer without its "mapping" (the
    object's own coordinates)."""
    return texture_case(settings, ob, work, "noise_world", make_noise, NOISE_KEYS, NOISE_INPUTS,
                        {}, {"dimension", "lacunarity", "randomness", "wave"}, NOISE_MAPPING,
                        NOISE_DISTANCE, ("mapping",), coordinates="Position",
                        function="blender-noise", placement=NOISE_WORLD_PLACEMENT)


def make_brick(tree):
    """A Brick Texture node in `tree` with BRICK_INPUTS and BRICK_PROPS."""
    brick = tree.nodes.new("ShaderNodeTexBrick")
    for name, value in BRICK_INPUTS.items():
        brick.inputs[name].default_value = value
    brick.offset, brick.offset_frequency = BRICK_PROPS["brick_offset"], BRICK_PROPS["offset_frequency"]
    brick.squash, brick.squash_frequency = BRICK_PROPS["squash"], BRICK_PROPS["squash_frequency"]
    return brick


def brick_case(settings, ob, work):
    """The bump material's Height fed by a Brick Texture's Fac (make_brick) on the object's own
    coordinates through a Mapping node (BRICK_MAPPING), Distance BRICK_DISTANCE: texture_case
    "brick", its properties as the layer's settings, its control without the layer's
    "mapping"."""
    keys = {"frequency": "Scale", "mortar_size": "Mortar Size", "mortar_smooth": "Mortar Smooth",
            "brick_width": "Brick Width", "row_height": "Row Height"}
    return texture_case(settings, ob, work, "brick", make_brick, keys, BRICK_INPUTS,
                        BRICK_PROPS, {"detail", "roughness", "randomness", "offset"},
                        BRICK_MAPPING, BRICK_DISTANCE, ("mapping",))


def make_gradient(tree):
    """A Gradient Texture node (Quadratic Sphere) in `tree`."""
    gradient = tree.nodes.new("ShaderNodeTexGradient")
    gradient.gradient_type = "QUADRATIC_SPHERE"
    return gradient


def gradient_case(settings, ob, work):
    """The bump material's Height fed by a Gradient Texture's Fac (make_gradient) on the
    object's own coordinates through a Mapping node (GRADIENT_MAPPING): texture_case
    "gradient", its type the layer's, no frequency sent, its control without the mapping."""
    return texture_case(settings, ob, work, "gradient", make_gradient, {}, {},
                        {"gradient_type": "quadratic-sphere"}, {"frequency", "detail", "depth"},
                        GRADIENT_MAPPING, GRADIENT_DISTANCE, ("mapping",))


def make_magic(tree):
    """A Magic Texture node in `tree` with MAGIC_INPUTS and Depth MAGIC_DEPTH."""
    magic = tree.nodes.new("ShaderNodeTexMagic")
    for name, value in MAGIC_INPUTS.items():
        magic.inputs[name].default_value = value
    magic.turbulence_depth = MAGIC_DEPTH
    return magic


def magic_case(settings, ob, work):
    """The bump material's Height fed by a Magic Texture's Fac (make_magic) on the object's own
    coordinates through a Mapping node (BRICK_MAPPING): texture_case "magic", its Depth as the
    layer's, its control without the mapping."""
    return texture_case(settings, ob, work, "magic", make_magic,
                        {"frequency": "Scale", "magic_distortion": "Distortion"}, MAGIC_INPUTS,
                        {"depth": MAGIC_DEPTH}, {"detail", "gradient_type", "roughness"},
                        BRICK_MAPPING, MAGIC_DISTANCE, ("mapping",))


def gradient_magic_checks(settings, ob):
    """Layers from Material on a Magic Texture it does not take (its Color output, a Scale fed
    by a node: no layer, a reason), and volume layers made by hand with function Blender
    Gradient (sent without a frequency) and Blender Magic. Returns check records."""
    c = TextureChecks(ob, "magic")
    magic = make_magic(c.tree)
    try:
        c.tree.links.new(magic.outputs["Color"], c.bump.inputs["Height"])
        c.refused("its Color output", "Color output")
        c.tree.links.new(magic.outputs["Fac"], c.bump.inputs["Height"])
        feeder = c.tree.nodes.new("ShaderNodeTexNoise")
        c.tree.links.new(feeder.outputs["Fac"], magic.inputs["Scale"])
        c.refused("a Scale fed by another texture", "Scale from a node")
        c.tree.nodes.remove(feeder)
    finally:
        c.tree.nodes.remove(magic)
        c.tree.links.new(c.tex.outputs["Color"], c.bump.inputs["Height"])
    return c.checks + [
        hand_made_check(settings, "gradient", "Blender Gradient",
                        {"function": "blender-gradient", "gradient_type": "radial",
                         "frequency": 3.0, "amplitude": 0.01},
                        {"function": "blender-gradient", "gradient_type": "radial"},
                        ("frequency", "depth", "distortion", "detail", "mapping")),
        hand_made_check(settings, "magic", "Blender Magic",
                        {"function": "blender-magic", "frequency": 2.0, "depth": 5,
                         "magic_distortion": 1.7, "amplitude": 0.01},
                        {"function": "blender-magic", "frequency": 2.0, "depth": 5,
                         "distortion": 1.7},
                        ("gradient_type", "detail", "roughness", "mapping")),
        # Left as they start, its settings are the node's defaults: Depth 2, Distortion 1.
        hand_made_check(settings, "magic", "Blender Magic (at its defaults)",
                        {"function": "blender-magic", "amplitude": 0.01},
                        {"function": "blender-magic", "depth": 2, "distortion": 1.0},
                        ("gradient_type", "detail", "roughness", "mapping"))]


def voronoi_checks(settings, ob):
    """Layers from Material on Voronoi Textures: Manhattan, Chebychev and Minkowski give the
    scene's metrics; F2, Smooth F1 and Distance to Edge the scene's features (Smooth F1 with
    its Smoothness, Distance to Edge without the metric and exponent); N-Sphere Radius and the
    Color output no layer and a reason; and volume layers made by hand with function Blender
    Voronoi. Returns check records like expect_error's."""
    import bpy
    from sgbake_blender import operators
    c = TextureChecks(ob, "voronoi")
    tree, tex, bump, checks, check, refused = c.tree, c.tex, c.bump, c.checks, c.check, c.refused
    voronoi = make_voronoi(tree)

    try:
        tree.links.new(voronoi.outputs["Distance"], bump.inputs["Height"])
        for distance, metric in (("MANHATTAN", "manhattan"), ("CHEBYCHEV", "chebyshev"),
                                 ("MINKOWSKI", "minkowski")):
            voronoi.distance = distance
            found, skipped, _ = operators.material_layers(tree, "UVMap", ob)
            check(f"voronoi: {distance.title()} gives the scene's metric {metric}",
                  len(found) == 1 and found[0].get("function") == "blender-voronoi"
                  and found[0].get("metric") == metric,
                  f"one blender-voronoi layer, metric {metric}", f"{found}; skipped {skipped}")
        voronoi.inputs["Smoothness"].default_value = 0.4
        for feature, name, want, unwanted in (
                ("F2", "f2", {"metric": "minkowski", "exponent": 0.5}, ("smoothness",)),
                ("SMOOTH_F1", "smooth-f1", {"metric": "minkowski", "smoothness": 0.4}, ()),
                ("DISTANCE_TO_EDGE", "distance-to-edge", {},
                 ("metric", "exponent", "smoothness"))):
            voronoi.feature = feature
            found, skipped, _ = operators.material_layers(tree, "UVMap", ob)
            layer = found[0] if len(found) == 1 else {}
            check(f"voronoi: Feature Output {feature} gives the scene's feature {name}",
                  layer.get("function") == "blender-voronoi" and layer.get("feature") == name
                  and all(layer.get(key) == value if isinstance(value, str)
                          else abs(layer.get(key, -1) - value) < 1e-6
                          for key, value in want.items())
                  and not set(unwanted) & set(layer),
                  f"one blender-voronoi layer, feature {name}, {want}, none of {unwanted}",
                  f"{found}; skipped {skipped}")
        voronoi.distance = "EUCLIDEAN"
        voronoi.feature = "N_SPHERE_RADIUS"
        tree.links.new(voronoi.outputs["Radius"], bump.inputs["Height"])
        refused("Feature Output N-Sphere Radius", "Radius output")
        voronoi.feature = "F1"
        tree.links.new(voronoi.outputs["Color"], bump.inputs["Height"])
        refused("the Color output", "Color output")
    finally:
        tree.nodes.remove(voronoi)
        tree.links.new(tex.outputs["Color"], bump.inputs["Height"])
    # A volume layer made by hand, function Blender Voronoi: its settings sent (none of the
    # other functions'), and it bakes.
    checks.append(hand_made_check(
        settings, "voronoi", "Blender Voronoi",
        {"function": "blender-voronoi", "metric": "minkowski", "frequency": 3.0,
         "randomness": 0.6, "exponent": 1.5, "amplitude": 0.01},
        {"function": "blender-voronoi", "metric": "minkowski", "frequency": 3.0,
         "randomness": 0.6, "exponent": 1.5},
        ("roughness", "detail", "distortion", "dimension", "lacunarity", "phase", "direction",
         "seed", "octaves", "mapping", "smoothness")))
    checks.append(hand_made_check(
        settings, "voronoi", "Blender Voronoi (Smooth F1)",
        {"function": "blender-voronoi", "feature": "smooth-f1", "smoothness": 0.3,
         "frequency": 3.0, "amplitude": 0.01},
        {"function": "blender-voronoi", "feature": "smooth-f1", "smoothness": 0.3,
         "frequency": 3.0},
        ("roughness", "detail", "distortion", "dimension", "lacunarity", "phase", "mapping")))
    return checks


def blender_make(work, library_path, sabotage):
    """Builds the scene, runs the add-on (see the module docstring), writes manifest.json."""
    import bpy
    os.environ.pop("SGBAKE_LIBRARY", None)  # the preferences' path is the one under test
    ob, height, distance = build_scene(work)
    prefs = enable_addon(library_path)
    settings = bpy.context.scene.sgbake
    from sgbake_blender import capi, library
    manifest = {"blender": bpy.app.version_string,
                "library": capi.version(library.get(bpy.context)),
                "size": SIZE, "distance": distance,
                "layers_from_material": layers_from_material(settings, distance)}
    layers = manifest["layers_from_material"]["layers"]
    manifest["scale"] = layers[0]["scale"] if layers else distance
    manifest["cases"] = bake_cases(settings, ob, work, sabotage)
    manifest["udim"] = udim_case(settings, ob, work, sabotage)
    manifest["options"] = options_case(settings, height, work)
    layers_from_material(settings, distance)  # the material's layer again, for what follows
    manifest["limit"] = limit_case(settings, ob, work, manifest["scale"])
    manifest["world"] = world_case(settings, ob, work, sabotage)
    manifest["materials"] = materials_case(settings, ob, height, work, sabotage)
    manifest["projector"] = projector_case(settings, ob, work)
    manifest["displacement"] = displacement_case(settings, ob, work)
    manifest["remap"] = remap_case(settings, ob, work)
    manifest["float_curve"] = float_curve_case(settings, ob, work)
    manifest["noise"] = noise_case(settings, ob, work)
    manifest["musgrave"] = musgrave_case(settings, ob, work)
    manifest["musgrave_ridged"] = musgrave_ridged_case(settings, ob, work)
    manifest["wave"] = wave_case(settings, ob, work)
    manifest["voronoi"] = voronoi_case(settings, ob, work)
    manifest["voronoi_edge"] = voronoi_edge_case(settings, ob, work)
    manifest["noise_uv"] = noise_uv_case(settings, ob, work)
    manifest["noise_world"] = noise_world_case(settings, ob, work)
    manifest["brick"] = brick_case(settings, ob, work)
    manifest["gradient"] = gradient_case(settings, ob, work)
    manifest["magic"] = magic_case(settings, ob, work)
    layers_from_material(settings, distance)  # the material's layer again, for what follows
    manifest["errors"] = (material_checks(settings, ob, distance) + remap_checks(ob, distance)
                          + noise_checks(settings, ob, distance)
                          + musgrave_checks(settings, ob)
                          + wave_checks(settings, ob)
                          + voronoi_checks(settings, ob)
                          + gradient_magic_checks(settings, ob)
                          + [hand_made_check(
                              settings, "brick", "Blender Brick",
                              {"function": "blender-brick", "frequency": 4.0,
                               "mortar_size": 0.05, "squash": 2.0, "offset_frequency": 3,
                               "amplitude": 0.01},
                              {"function": "blender-brick", "mortar_size": 0.05,
                               "mortar_smooth": 0.1, "squash": 2.0, "offset_frequency": 3,
                               "squash_frequency": 2},
                              ("detail", "randomness", "offset", "seed", "mapping"))]
                          + worker_thread_checks(settings, ob)
                          + error_reports(settings, prefs, height, work, library_path))
    with open(os.path.join(work, "manifest.json"), "w", encoding="ascii") as f:
        json.dump(manifest, f, indent=1)


def blender_compare(work):
    """Compares each addon_CASE.npy with cli_CASE.exr; writes results.json."""
    import numpy as np
    with open(os.path.join(work, "manifest.json"), encoding="ascii") as f:
        manifest = json.load(f)
    results = {}
    for case, entry in manifest["cases"].items():
        if entry["result"] != ["FINISHED"]:
            continue
        ours = np.load(os.path.join(work, f"addon_{case}.npy"))
        cli_path = os.path.join(work, f"cli_{case}.exr")
        if not os.path.exists(cli_path):
            results[case] = {"error": "no CLI output"}
            continue
        theirs = bc.load_raw(cli_path)
        if ours.shape != theirs.shape:
            results[case] = {"error": f"shapes differ: add-on {ours.shape}, CLI {theirs.shape}"}
            continue
        channels = 4 if entry["alpha"] else 3
        diff = np.abs(ours[..., :channels].astype(np.float64) - theirs[..., :channels])
        per_texel = diff.max(axis=-1)
        worst = np.unravel_index(int(per_texel.argmax()), per_texel.shape)
        covered = int(np.count_nonzero(theirs[..., 0] > 0.5)) if entry["map"] == "mask" else None
        results[case] = {
            "channels": channels,
            "max_abs": float(per_texel.max()),
            "worst_at": [int(worst[1]), int(worst[0])],  # (x, file row)
            "worst_values": [ours[worst][:channels].tolist(), theirs[worst][:channels].tolist()],
            "differing": int(np.count_nonzero(per_texel > 0)),
            "over_tolerance": int(np.count_nonzero(per_texel > TOLERANCE)),
            "exact": bool(np.array_equal(ours[..., :channels], theirs[..., :channels])),
            "texels": int(per_texel.size),
            "covered": covered,
        }
    results["extra"] = extra_comparisons(work, manifest)
    results["world"] = world_comparisons(work, manifest)
    results["materials"] = materials_comparisons(work)
    results["projector"] = against_cycles(work, "projector")
    results["displacement"] = against_cycles(work, "displacement")
    results["remap"] = against_cycles(work, "remap")
    results["float_curve"] = against_cycles(work, "float_curve")
    results["noise"] = against_cycles(work, "noise")
    results["noise_generated"] = against_cycles(work, "noise_generated")
    results["musgrave"] = against_cycles(work, "musgrave")
    results["musgrave_lean"] = lean_stats(work, "musgrave")
    results["musgrave_ridged"] = against_cycles(work, "musgrave_ridged")
    results["wave"] = against_cycles(work, "wave")
    results["wave_lean"] = lean_stats(work, "wave")
    results["voronoi"] = against_cycles(work, "voronoi")
    results["voronoi_lean"] = lean_stats(work, "voronoi")
    results["voronoi_edge"] = against_cycles(work, "voronoi_edge")
    results["noise_uv"] = against_cycles(work, "noise_uv")
    results["noise_world"] = against_cycles(work, "noise_world")
    results["brick"] = against_cycles(work, "brick")
    results["gradient"] = against_cycles(work, "gradient")
    results["magic"] = against_cycles(work, "magic")
    with open(os.path.join(work, "results.json"), "w", encoding="ascii") as f:
        json.dump(results, f, indent=1)


def difference(ours, theirs, channels):
    """Largest per-texel difference of two (H, W, 4) arrays over `channels` channels, and
    where it is."""
    import numpy as np
    if ours.shape != theirs.shape:
        return {"error": f"shapes differ: add-on {ours.shape}, CLI {theirs.shape}"}
    diff = np.abs(ours[..., :channels].astype(np.float64) - theirs[..., :channels])
    per_texel = diff.max(axis=-1)
    worst = np.unravel_index(int(per_texel.argmax()), per_texel.shape)
    return {"max_abs": float(per_texel.max()), "worst_at": [int(worst[1]), int(worst[0])],
            "texels": int(per_texel.size)}


def extra_comparisons(work, manifest):
    """The UDIM tiles (each add-on tile against the CLI's file of that tile; negative control:
    tile 1002 against the CLI's 1001) and the layer options (the add-on against the CLI's
    scene with the same keys; negative controls: against each scene without one key).
    Returns records {name, expect ("equal" or "differ"), max_abs, ...}."""
    import numpy as np

    def load(name):
        path = os.path.join(work, name)
        if not os.path.exists(path):
            return None
        return np.load(path) if name.endswith(".npy") else bc.load_raw(path)

    pairs = [(f"UDIM tile {t}", f"addon_udim.{t}.exr", f"cli_udim.{t}.exr", "equal",
              UDIM_TOLERANCE) for t in manifest["udim"]["tiles"]]
    pairs.append(("UDIM negative control: add-on tile 1002 vs CLI tile 1001",
                  "addon_udim.1002.exr", "cli_udim.1001.exr", "differ", TOLERANCE))
    for t in (1001, 1002):
        pairs.append((f"UDIM height image, tile {t}", f"addon_udim_in.{t}.exr",
                      f"cli_udim_in.{t}.exr", "equal", UDIM_TOLERANCE))
        pairs.append((f"UDIM height image negative control: tile {t} vs the swapped tiles",
                      f"addon_udim_in.{t}.exr", f"cli_udim_in_swapped.{t}.exr", "differ",
                      TOLERANCE))
    pairs.append(("exact limit surface vs CLI --subdivide limit", "addon_limit.npy",
                  "cli_limit.exr", "equal", TOLERANCE))
    pairs.append(("limit negative control: Blender's level-1 mesh vs CLI --subdivide limit",
                  "addon_limit_mesh.npy", "cli_limit.exr", "differ", TOLERANCE))
    for control in ("no_creases", "keep_boundaries"):
        pairs.append((f"limit negative control: exact limit surface vs CLI limit {control}",
                      "addon_limit.npy", f"cli_limit_{control}.exr", "differ", TOLERANCE))
    for name in manifest["options"]["scenes"]:
        pairs.append((f"layer options vs CLI {name}.json", "addon_options.npy",
                      f"cli_{name}.exr", "equal" if name == "options" else "differ", TOLERANCE))
    records = []
    for name, ours_file, theirs_file, expect, tolerance in pairs:
        record = {"name": name, "expect": expect, "files": [ours_file, theirs_file],
                  "tolerance": tolerance}
        ours, theirs = load(ours_file), load(theirs_file)
        if ours is None or theirs is None:
            record["error"] = f"missing {ours_file if ours is None else theirs_file}"
        else:
            record.update(difference(ours, theirs, 3))
        records.append(record)
    return records


def world_comparisons(work, manifest):
    """The transformed object's bakes (world_case) against Cycles': angle statistics between
    the decoded normals over the texels Cycles' mask covers, less one texel at island borders
    (as bake_compare.py), for the add-on's bake and for the negative control. Returns
    {map: {"addon": stats, "control": stats}} ({"error": ...} for a missing file)."""
    import numpy as np
    records = {}
    mask_path = os.path.join(work, "cycles_world_mask.npy")
    if not os.path.exists(mask_path):
        return {kind: {"error": "no Cycles mask"} for kind in manifest["world"]["maps"]}
    inner = bc.erode(np.load(mask_path)[..., 0] > 0.5, 1)
    for kind, space in manifest["world"]["maps"].items():
        files = {"addon": f"addon_world_{kind}.npy", "control": f"addon_world_{kind}_control.npy",
                 "cycles": f"cycles_world_{space}.npy"}
        missing = [f for f in files.values() if not os.path.exists(os.path.join(work, f))]
        if missing:
            records[kind] = {"error": f"missing {', '.join(missing)}"}
            continue
        cycles = bc.decode_normals(np.load(os.path.join(work, files["cycles"])))
        records[kind] = {}
        for which in ("addon", "control"):
            ours = bc.decode_normals(np.load(os.path.join(work, files[which])))
            records[kind][which] = bc.angle_stats(bc.angle_deg(ours, cycles)[inner])
    return records


def materials_comparisons(work):
    """The two-material object's bakes (materials_case) against Cycles' (against_cycles)."""
    return against_cycles(work, "materials")


def against_cycles(work, case):
    """A case's add-on bake and its control (addon_CASE.npy, addon_CASE_control.npy) against
    Cycles' (cycles_CASE.npy, mask cycles_CASE_mask.npy), as world_comparisons: {"addon":
    stats, "control": stats}, or {"error": ...} for a missing file."""
    import numpy as np
    files = {"addon": f"addon_{case}.npy", "control": f"addon_{case}_control.npy",
             "cycles": f"cycles_{case}.npy", "mask": f"cycles_{case}_mask.npy"}
    missing = [f for f in files.values() if not os.path.exists(os.path.join(work, f))]
    if missing:
        return {"error": f"missing {', '.join(missing)}"}
    inner = bc.erode(np.load(os.path.join(work, files["mask"]))[..., 0] > 0.5, 1)
    cycles = bc.decode_normals(np.load(os.path.join(work, files["cycles"])))
    return {which: bc.angle_stats(bc.angle_deg(
        bc.decode_normals(np.load(os.path.join(work, files[which]))), cycles)[inner])
        for which in ("addon", "control")}


def lean_stats(work, case):
    """How far Cycles' bumped normals (cycles_CASE.npy) lean off the surface's own
    (addon_CASE_flat.npy: the add-on's bake of the layer at amplitude 0; not +Z, where a face is
    flat-shaded), over the mask as against_cycles: angle_stats, or {"error": ...}."""
    import numpy as np
    files = {"flat": f"addon_{case}_flat.npy", "cycles": f"cycles_{case}.npy",
             "mask": f"cycles_{case}_mask.npy"}
    missing = [f for f in files.values() if not os.path.exists(os.path.join(work, f))]
    if missing:
        return {"error": f"missing {', '.join(missing)}"}
    inner = bc.erode(np.load(os.path.join(work, files["mask"]))[..., 0] > 0.5, 1)
    normals = {key: bc.decode_normals(np.load(os.path.join(work, files[key])))
               for key in ("flat", "cycles")}
    return bc.angle_stats(bc.angle_deg(normals["cycles"], normals["flat"])[inner])


def blender_main(argv):
    mode, work = argv[0], argv[1]
    if mode == "make":
        blender_make(work, argv[2], argv[3] == "sabotage")
    elif mode == "compare":
        blender_compare(work)
    else:
        raise SystemExit(f"unknown mode {mode}")


# ---------------------------------------------------------------------------------------------
# Driver


def run_cli(cli, work, manifest):
    """Bakes every case with the CLI; returns the failed command lines."""
    failed = []
    for case, entry in manifest["cases"].items():
        cmd = [cli, "bake", "--mesh", os.path.join(work, "mesh.obj"),
               "--height", os.path.join(work, "height.exr"),
               "--height-scale", repr(manifest["scale"]), "--height-gradient", "bump-node",
               "--filter", "bilinear",
               "--map", entry["map"], "--size", manifest["size"], "--margin", entry["margin"],
               "--padding", entry["padding"],
               "--samples", entry["samples"], "--bit-depth", 32, "--no-manifest",
               "-o", os.path.join(work, f"cli_{case}.exr")]
        if entry["map"] == "tangent-normal":
            cmd += ["--green", "opengl"]
        if entry["alpha"]:
            cmd.append("--alpha")
        proc = bc.run_tool(cmd, timeout=120)
        if proc is None or proc.returncode != 0:
            failed.append(" ".join(map(str, cmd)))
    for part in ("udim", "options", "limit"):
        for args in manifest[part]["cli"]:
            cmd = [cli] + [os.path.join(work, a) if a.endswith((".json", ".obj", ".exr"))
                           else a for a in args]
            proc = bc.run_tool(cmd, timeout=120)
            if proc is None or proc.returncode != 0:
                failed.append(" ".join(map(str, cmd)))
    return failed


def evaluate(manifest, results):
    """Prints the figures; returns a list of failures."""
    failures = []
    lfm = manifest["layers_from_material"]
    print(f"Layers from Material: {lfm['result']}, layers {lfm['layers']}")
    if "error" in lfm:
        failures.append(f"Layers from Material: {lfm['error']}")
    for case, entry in manifest["cases"].items():
        if entry["result"] != ["FINISHED"]:
            print(f"  {case:22s} the add-on's bake failed: {entry.get('error')}")
            failures.append(f"{case}: the add-on's bake returned {entry['result']}: "
                            f"{entry.get('error')}")
            continue
        if entry["image_size"] != [manifest["size"]] * 2:
            failures.append(f"{case}: image '{entry['image']}' is {entry['image_size']}, "
                            f"expected {manifest['size']}^2")
        r = results.get(case, {"error": "not compared"})
        if "error" in r:
            print(f"  {case:22s} {r['error']}")
            failures.append(f"{case}: {r['error']}")
            continue
        exact = entry["map"] == "mask"
        ok = r["exact"] if exact else r["max_abs"] <= TOLERANCE
        covered = f", {r['covered']} covered" if r["covered"] is not None else ""
        print(f"  {case:22s} max |add-on - CLI| = {r['max_abs']:.3g} over {r['channels']} "
              f"channels of {r['texels']} texels{covered}; {r['differing']} differ, "
              f"{r['over_tolerance']} by > {TOLERANCE:g} -> {'ok' if ok else 'FAIL'}")
        if not ok:
            failures.append(f"{case}: the add-on's image differs from the CLI's: max "
                            f"{r['max_abs']:.3g} at (x, row) {r['worst_at']}, add-on / CLI "
                            f"{r['worst_values']}" + (" (must be identical)" if exact else ""))
    for part in ("udim", "options"):
        entry = manifest[part]
        if entry["result"] != ["FINISHED"]:
            failures.append(f"{part}: the add-on's bake returned {entry['result']}")
    for surface, result in manifest["limit"]["result"].items():
        if result != ["FINISHED"]:
            failures.append(f"limit case, surface {surface}: the add-on's bake returned "
                            f"{result}")
    for r in results["extra"]:
        if "error" in r:
            print(f"  {r['name']}: {r['error']}")
            failures.append(f"{r['name']}: {r['error']}")
            continue
        equal, tolerance = r["expect"] == "equal", r["tolerance"]
        ok = (r["max_abs"] <= tolerance) if equal else (r["max_abs"] > tolerance)
        print(f"  {r['name']}: max |add-on - CLI| = {r['max_abs']:.3g} over {r['texels']} "
              f"texels (must {'be within' if equal else 'exceed'} {tolerance:g}) -> "
              f"{'ok' if ok else 'FAIL'}")
        if not ok:
            failures.append(f"{r['name']}: max {r['max_abs']:.3g} at (x, row) "
                            f"{r['worst_at']}, expected to "
                            f"{'be within' if equal else 'exceed'} {tolerance:g}")
    failures += evaluate_world(manifest["world"], results["world"])
    failures += evaluate_materials(manifest["materials"], results["materials"])
    failures += evaluate_case_against_cycles(
        "projector", "Box projection on an Empty's coordinates through a Mapping node "
        f"({manifest['projector'].get('layer')})", manifest["projector"], results["projector"],
        "with sgbake's own triplanar blend", PROJECTOR_MEDIAN_DEG, PROJECTOR_CONTROL_FACTOR)
    failures += evaluate_case_against_cycles(
        "displacement", "Displacement (Bump Only, object space, Suzanne stretched) with a Bump node on the "
        f"displaced normal ({manifest['displacement'].get('layers')})",
        manifest["displacement"], results["displacement"],
        "with the Bump added to the displacement", DISPLACEMENT_MEDIAN_DEG,
        DISPLACEMENT_CONTROL_FACTOR)
    failures += evaluate_case_against_cycles(
        "remap", "a Color Ramp (Ease, three coloured stops) and a clamped Math node (x "
        f"{REMAP_FACTOR:g}) on the height ({manifest['remap'].get('layer')})",
        manifest["remap"], results["remap"], "without the remap", REMAP_MEDIAN_DEG,
        REMAP_CONTROL_FACTOR, REMAP_P99_DEG)
    failures += evaluate_case_against_cycles(
        "float_curve", f"a Float Curve through {FLOAT_CURVE_POINTS} on the height "
        f"({manifest['float_curve'].get('layer')})", manifest["float_curve"],
        results["float_curve"], "without the remap", REMAP_MEDIAN_DEG, REMAP_CONTROL_FACTOR,
        REMAP_P99_DEG)
    noise = manifest["noise"]
    failures += evaluate_case_against_cycles(
        "noise", "a Noise Texture (3D, "
        + ", ".join(f"{k} {v:g}" for k, v in NOISE_INPUTS.items())
        + ") on object coordinates through a Mapping node (Point), Distance "
        f"{NOISE_DISTANCE:g}", noise, results["noise"], "without the layer's mapping",
        NOISE_MEDIAN_DEG, NOISE_CONTROL_FACTOR, NOISE_P99_DEG)
    failures += evaluate_case_against_cycles(
        "noise_generated", "the same Noise Texture, its Vector unlinked (Generated "
        f"coordinates), Suzanne turned and scaled {NOISE_PLACEMENT[2]}",
        {"result": noise.get("generated_result")}, results["noise_generated"],
        "without the layer's mapping (its own coordinates)", NOISE_MEDIAN_DEG,
        NOISE_CONTROL_FACTOR, NOISE_P99_DEG)
    failures += evaluate_case_against_cycles(
        "noise_world", "the Noise Texture on world positions (Geometry Position) through a "
        f"Mapping node (Point), Suzanne placed {NOISE_WORLD_PLACEMENT}", manifest["noise_world"],
        results["noise_world"], "without the layer's mapping (its own coordinates)",
        NOISE_MEDIAN_DEG, NOISE_CONTROL_FACTOR, NOISE_P99_DEG)
    failures += evaluate_case_against_cycles(
        "brick", "a Brick Texture's Fac (" + ", ".join(f"{k} {v:g}" for k, v in BRICK_INPUTS.items())
        + f", {BRICK_PROPS}) on object coordinates through a Mapping node (Point), Distance "
        f"{BRICK_DISTANCE:g}", manifest["brick"], results["brick"], "without the layer's mapping",
        NOISE_MEDIAN_DEG, NOISE_CONTROL_FACTOR, NOISE_P99_DEG)
    failures += evaluate_case_against_cycles(
        "gradient", "a Gradient Texture's Fac (Quadratic Sphere) on object coordinates through a "
        f"Mapping node (Point), Distance {GRADIENT_DISTANCE:g}", manifest["gradient"],
        results["gradient"], "without the layer's mapping", NOISE_MEDIAN_DEG,
        NOISE_CONTROL_FACTOR, NOISE_P99_DEG)
    failures += evaluate_case_against_cycles(
        "magic", "a Magic Texture's Fac (" + ", ".join(f"{k} {v:g}" for k, v in MAGIC_INPUTS.items())
        + f", Depth {MAGIC_DEPTH}) on object coordinates through a Mapping node (Point), Distance "
        f"{MAGIC_DISTANCE:g}", manifest["magic"], results["magic"], "without the layer's mapping",
        NOISE_MEDIAN_DEG, NOISE_CONTROL_FACTOR, NOISE_P99_DEG)
    failures += evaluate_case_against_cycles(
        "musgrave", "a Musgrave Texture (fBM, 3D, "
        + ", ".join(f"{k} {v:g}" for k, v in MUSGRAVE_INPUTS.items())
        + ") on object coordinates through a Mapping node (Point), Distance "
        f"{MUSGRAVE_DISTANCE:g}", manifest["musgrave"], results["musgrave"],
        "without the layer's dimension and lacunarity (2 and 2)", MUSGRAVE_MEDIAN_DEG,
        MUSGRAVE_CONTROL_FACTOR, MUSGRAVE_P99_DEG)
    failures += evaluate_lean("musgrave", results["musgrave_lean"], MUSGRAVE_LEAN_DEG)
    failures += evaluate_case_against_cycles(
        "musgrave_ridged", "a Musgrave Texture (Ridged Multifractal, 3D, "
        + ", ".join(f"{k} {v:g}" for k, v in MUSGRAVE_RIDGED_INPUTS.items())
        + ") on object coordinates through a Mapping node (Point), Distance "
        f"{MUSGRAVE_RIDGED_DISTANCE:g}", manifest["musgrave_ridged"],
        results["musgrave_ridged"], "the layer left at fBM (no type, offset, gain)",
        MUSGRAVE_MEDIAN_DEG, MUSGRAVE_CONTROL_FACTOR, MUSGRAVE_P99_DEG)
    failures += evaluate_case_against_cycles(
        "wave", "a Wave Texture (" + ", ".join(WAVE_ENUMS.values()) + ", "
        + ", ".join(f"{k} {v:g}" for k, v in WAVE_INPUTS.items())
        + ") on object coordinates through a Mapping node (Point), Distance "
        f"{WAVE_DISTANCE:g}", manifest["wave"], results["wave"],
        "without the layer's phase", WAVE_MEDIAN_DEG, WAVE_CONTROL_FACTOR, WAVE_P99_DEG)
    failures += evaluate_lean("wave", results["wave_lean"], WAVE_LEAN_DEG)
    failures += evaluate_case_against_cycles(
        "voronoi", "a Voronoi Texture's Distance (F1, 3D, euclidean, "
        + ", ".join(f"{k} {v:g}" for k, v in VORONOI_INPUTS.items())
        + ") on object coordinates through a Mapping node (Point), Distance "
        f"{VORONOI_DISTANCE:g}", manifest["voronoi"], results["voronoi"],
        "without the layer's mapping", VORONOI_MEDIAN_DEG, VORONOI_CONTROL_FACTOR,
        VORONOI_P99_DEG)
    failures += evaluate_lean("voronoi", results["voronoi_lean"], VORONOI_LEAN_DEG)
    failures += evaluate_case_against_cycles(
        "voronoi_edge", "a Voronoi Texture's Distance (Distance to Edge, 3D, "
        + ", ".join(f"{k} {v:g}" for k, v in VORONOI_EDGE_INPUTS.items())
        + ") on object coordinates through a Mapping node (Point), Distance "
        f"{VORONOI_EDGE_DISTANCE:g}", manifest["voronoi_edge"], results["voronoi_edge"],
        "the layer left at F1 (no feature)", VORONOI_MEDIAN_DEG, VORONOI_CONTROL_FACTOR,
        VORONOI_P99_DEG)
    failures += evaluate_case_against_cycles(
        "noise_uv", "the Noise Texture on the UV map's coordinates (Texture Coordinate UV) "
        f"through a Mapping node (Point), Distance {NOISE_UV_DISTANCE:g}", manifest["noise_uv"],
        results["noise_uv"], "the layer on object coordinates", NOISE_MEDIAN_DEG,
        NOISE_CONTROL_FACTOR, NOISE_P99_DEG)
    for check in (manifest["udim"]["checks"] + manifest["options"]["checks"]
                  + manifest["limit"]["checks"] + manifest["world"]["checks"]
                  + manifest["materials"]["checks"] + manifest["projector"]["checks"]
                  + manifest["displacement"]["checks"] + manifest["remap"]["checks"]
                  + manifest["float_curve"]["checks"]
                  + manifest["noise"]["checks"] + manifest["musgrave"]["checks"]
                  + manifest["musgrave_ridged"]["checks"]
                  + manifest["wave"]["checks"] + manifest["voronoi"]["checks"]
                  + manifest["voronoi_edge"]["checks"]
                  + manifest["noise_uv"]["checks"] + manifest["noise_world"]["checks"]
                  + manifest["brick"]["checks"] + manifest["gradient"]["checks"]
                  + manifest["magic"]["checks"]
                  + manifest["errors"]):
        print(f"  check, {check['name']}: {check['message']!r} -> "
              f"{'ok' if check['ok'] else 'FAIL'}")
        if not check["ok"]:
            failures.append(f"{check['name']}: expected an error report containing "
                            f"{check['expected']!r}, got {check['message']!r}")
    return failures


def evaluate_world(entry, results):
    """Prints the transformed object's angles to Cycles; returns failures: a median over
    WORLD_MEDIAN_DEG, or a negative control (no "transform") less than WORLD_CONTROL_FACTOR
    times worse."""
    failures = []
    print(f"  transformed Suzanne (scale {entry['scale']}, rotation {entry['rotation']}) vs "
          "Cycles:")
    for kind, result in entry["result"].items():
        if result != ["FINISHED"]:
            failures.append(f"world, {kind}: the add-on's bake returned {result}")
    for kind, r in results.items():
        if "error" in r:
            print(f"    {kind}: {r['error']}")
            failures.append(f"world, {kind}: {r['error']}")
            continue
        failures += judge_against_cycles(f"world, {kind}", f"{kind:15s} ", r["addon"],
                                         r["control"], "without the transform",
                                         WORLD_MEDIAN_DEG, WORLD_CONTROL_FACTOR)
    return failures


def evaluate_lean(case, lean, bar):
    """Prints how far Cycles' normals of `case` lean off the surface's (lean_stats); returns
    failures: a lean of `bar` degrees or more (the case's Distance is too large)."""
    if "error" in lean:
        return [f"{case}, lean: {lean['error']}"]
    ok = lean["max_deg"] < bar
    print(f"    Cycles' normals lean off the surface's: median {lean['median_deg']:.1f}, p99 "
          f"{lean['p99_deg']:.1f}, max {lean['max_deg']:.1f} deg -> {'ok' if ok else 'FAIL'}"
          f" (< {bar:g})")
    return [] if ok else [f"{case}: Cycles' normals lean up to {lean['max_deg']:.1f} deg off "
                          f"the surface's (bar {bar:g}: lower {case.upper()}_DISTANCE)"]


def judge_against_cycles(name, label, ours, control, control_what, bar, factor):
    """Prints the add-on's angles to Cycles (`ours`) and its negative control's; returns
    failures: a median over `bar`, or a control (`control_what`) less than `factor` times
    worse."""
    ok = ours["median_deg"] <= bar
    worse = control["median_deg"] >= factor * ours["median_deg"]
    print(f"    {label}median {ours['median_deg']:.3f}, p90 {ours['p90_deg']:.3f}, p99 "
          f"{ours['p99_deg']:.3f}, max {ours['max_deg']:.1f} deg over {ours['texels']} texels "
          f"-> {'ok' if ok else 'FAIL'} (median <= {bar}); {control_what}: median "
          f"{control['median_deg']:.3f}, p90 {control['p90_deg']:.3f}, p99 "
          f"{control['p99_deg']:.3f} deg -> {'ok' if worse else 'FAIL'} (must be >= "
          f"{factor:g} x)")
    failures = []
    if not ok:
        failures.append(f"{name}: median {ours['median_deg']:.3f} deg from Cycles (bar {bar})")
    if not worse:
        failures.append(f"{name} negative control: {control_what} the median is "
                        f"{control['median_deg']:.3f} deg, not {factor:g} x the add-on's "
                        f"{ours['median_deg']:.3f}")
    return failures


def evaluate_materials(entry, r):
    """Prints the two-material object's angles to Cycles; returns failures: a median over
    MATERIALS_MEDIAN_DEG, or a negative control (every layer on every face) less than
    MATERIALS_CONTROL_FACTOR times worse."""
    failures = []
    print(f"  Suzanne of two materials ({entry['faces'][0]} faces bumped, {entry['faces'][1]} "
          f"a Bump on a Normal Map), {entry['map']} vs Cycles:")
    if entry["result"] != ["FINISHED"]:
        failures.append(f"materials: the add-on's bake returned {entry['result']}")
    if "error" in r:
        print(f"    {r['error']}")
        return failures + [f"materials: {r['error']}"]
    failures += judge_against_cycles("materials", "", r["addon"], r["control"],
                                     "with every layer on every face", MATERIALS_MEDIAN_DEG,
                                     MATERIALS_CONTROL_FACTOR)
    worst = r["addon"]["max_deg"]
    print(f"    worst texel {worst:.1f} deg -> {'ok' if worst <= MATERIALS_MAX_DEG else 'FAIL'} "
          f"(<= {MATERIALS_MAX_DEG}: each texel takes the material of the triangle Blender's "
          f"nudged sample is in)")
    if worst > MATERIALS_MAX_DEG:
        failures.append(f"materials: a texel {worst:.1f} deg from Cycles (bar "
                        f"{MATERIALS_MAX_DEG}: is it on the other side of an edge?)")
    return failures


def evaluate_case_against_cycles(name, title, entry, r, control_what, bar, factor,
                                p99_bar=None):
    """Prints case `name`'s angles to Cycles under `title`; returns failures: its add-on bake
    not finished, a median over `bar` (a p99 over `p99_bar`, when given), or a control
    (`control_what`) less than `factor` times worse."""
    print(f"  {title} vs Cycles:")
    failures = []
    if entry["result"] != ["FINISHED"]:
        failures.append(f"{name}: the add-on's bake returned {entry['result']}")
    if "error" in r:
        print(f"    {r['error']}")
        return failures + [f"{name}: {r['error']}"]
    failures += judge_against_cycles(name, "", r["addon"], r["control"], control_what,
                                     bar, factor)
    if p99_bar is not None:
        p99 = r["addon"]["p99_deg"]
        print(f"    p99 {p99:.4f} deg -> {'ok' if p99 <= p99_bar else 'FAIL'} (<= {p99_bar})")
        if p99 > p99_bar:
            failures.append(f"{name}: p99 {p99:.4f} deg from Cycles (bar {p99_bar})")
    return failures


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cli", required=True, help="path to the sgbake executable")
    parser.add_argument("--library", required=True, help="path to libsgbake.so")
    parser.add_argument("--blender", default="blender", help="Blender executable")
    parser.add_argument("--keep", metavar="DIR", help="write every file here and keep it")
    parser.add_argument("--sabotage", action="store_true",
                        help="bake the add-on's normal maps with green DirectX (must fail)")
    args = parser.parse_args()

    blender = bc.blender_or_skip(args.blender, test="add-on")
    for path, what in ((args.cli, "sgbake_cli"), (args.library, "sgbake")):
        if not os.path.isfile(path):
            print(f"error: {path} is not a file (build {what} first)")
            return 2
    library = os.path.abspath(args.library)
    if bc.needs_asan_runtime(library):
        print(f"SKIP: {library} is built with AddressSanitizer; its runtime must be the first "
              "library of the process, so Blender cannot load it")
        return bc.SKIP

    def run_half(*half_args):
        return objio.run_blender_half(blender, os.path.abspath(__file__), list(half_args),
                                      timeout=150, tail=4000)

    with bc.work_dir(args.keep, "sgbake-addon-") as work:
        if not run_half("make", work, library, "sabotage" if args.sabotage else "honest"):
            return 1
        with open(os.path.join(work, "manifest.json"), encoding="ascii") as f:
            manifest = json.load(f)
        print(f"Blender {manifest['blender']}, libsgbake {manifest['library']}, Suzanne "
              f"{manifest['size']}^2, height scale {manifest['scale']!r}")
        failures = [f"command failed: {cmd}" for cmd in run_cli(args.cli, work, manifest)]
        if not run_half("compare", work):
            return 1
        with open(os.path.join(work, "results.json"), encoding="ascii") as f:
            results = json.load(f)
        failures += evaluate(manifest, results)
        if args.keep:
            print(f"files kept in {work}")
    return bc.report(failures)


if __name__ == "__main__":
    objio.run_script(blender_main, main)
