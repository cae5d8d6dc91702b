#!/usr/bin/env python3
"""BlenderBakeOracle_<group>: sgbake's normal maps against Cycles' bakes of the same scenes.

    python3 tests/blender/bake_oracle.py --cli build/src/sgbake [--blender blender]
        [--keep DIR] [--group NAME | --cases NAME,...]
                 (a group of CASE_GROUPS below, one CTest test each; default: every case)
        [--sabotage green|scale|input|strength|normal-green]

1. bake_scene.py (inside Blender) builds each case (see its docstring: Suzanne subdivided
   once, smooth, 512^2; the same Suzanne with the Subdivision Surface modifier kept live, so
   that mesh.obj is the coarse mesh and every sgbake command below gets --subdivide 1 (the
   JSON scene "subdivision": {"level": 1}); a UV sphere, smooth, 256^2; a flat-shaded cube,
   512^2), gives it a
   Bump node fed by a procedural height image (32-bit float EXR, Non-Color, bilinear) with
   Distance = S, and bakes with Cycles (1 sample, denoising off, margin 0): NORMAL in OBJECT
   and in TANGENT space (+X +Y +Z) and an EMIT coverage mask. It writes mesh.obj (objio, exact
   floats), height.exr and Blender's bakes as raw float EXRs.
2. For each case this runs the sgbake CLI:
     sgbake convert --mesh mesh.obj --from object --to tangent blender_object.exr
                    --bit-depth 32 -o ours_convert.exr
     sgbake bake --mesh mesh.obj --height height.exr --height-scale S --filter bilinear
                 --map tangent-normal --size N --margin 0 --samples 1 --bit-depth 32
                 --no-manifest -o ours_bake.exr
     sgbake bake scene.json         (the same bake as a JSON scene -> ours_bake_json.exr)
     sgbake bake ... --height-scale 2S -o ours_bake_x2.exr   (negative control)
     sgbake bake ... --height-gradient bump-node -o ours_bake_bump_node.exr
     sgbake bake --mesh mesh.obj --map mask --size N --margin 0 -o ours_mask.exr
   A normal-map case (the nmap_* cases: no Bump node but a Normal Map node fed by normal.exr,
   a smooth procedural 512^2 float EXR whose normals lean up to 60 deg - 40 deg at Strength
   2 - from the surface normal, so that Cycles' valid-reflection guard bends a good part of
   them; tangent space on the UV sphere at Strength 1, 0.5 and 2 and on the flat cube at
   Strength 1 and 2, object space on the UV sphere; nmap_sphere_steep leans up to 150 deg, so
   that a third of its texels decode below the surface, which Cycles' guard keeps there or
   turns up on their own side (sgbake mirrored or clamped them: p99 102 deg off, now 0.18);
   256^2, see bake_scene.py) runs instead
     sgbake bake scene.json   (normal layer: normal.exr, space, strength, bilinear; outputs
                               tangent-normal -> ours_nmap_tangent.exr and object-normal ->
                               ours_nmap_object.exr; the same flags as above)
     sgbake bake --mesh mesh.obj --normal normal.exr --normal-space SPACE
                 --map tangent-normal ... -o ours_nmap_flags.exr   (Strength 1 cases only)
     sgbake bake scene_weak.json   (Strength x 0.9 -> ours_nmap_weak.exr, negative control)
   A chain case (chain_sphere, chain_suzanne: 512^2, a tangent-space map tilting up to 40 deg
   whose Normal Map node feeds the Normal input of a Bump node of Distance 0.1 fed by
   height.exr) has a second layer, the height with "base": "above", and skips the flags; its
   control scene_sum.json has "base": "surface" (-> ours_nmap_sum.exr).
3. bake_compare.py (inside Blender, as the EXR reader) measures the angles between our
   normals and Cycles' bake (tangent space; object space for ours_nmap_object.exr) over the
   covered texels minus a one-texel border.

The planar cases (planar_sphere, planar_sphere_backfacing: the height projected along z onto
object coordinates by Texture Coordinate Object into a Flat Image Texture) bake a scene with a
"planar" height layer instead (ours_bake.exr, ours_bake_x2.exr at twice the scale) and the mask;
its bump-node bake (ours_bake_bump_node.exr) is judged as (e); they have no convert, flags or
JSON checks. The Box cases (box_sphere, box_sphere_backfacing, box_stretch_sphere: Blender's Image
Texture Box projection with Blend 0.3 on object coordinates) bake a "triplanar" layer with
"projection": "box" the same way; their control ours_bake_blended.exr, sgbake's own triplanar
blend (seed 003), must fail both (b) and (e). box_mapped_sphere puts a Mapping node (Point: moved,
turned, unevenly scaled) between the coordinates and the texture, the layer's "mapping"; its
control ours_bake_unmapped.exr, the layer without it, must fail them too. box_strength_sphere
gives the Bump node a Strength of 0.4 (the layer's "strength"); its control
ours_bake_full_strength.exr, at Strength 1, must fail them too. sphere_wrap_sphere and
tube_wrap_sphere read the height by Blender's Sphere and Tube projections (after a Mapping node
that centres and turns them), a "planar" layer with "projection": "sphere" or "tube"; their
control ours_bake_swapped.exr, the other wrap, must fail them too, as must ours_nmap_swapped.exr
for the normal maps those projections read (sphere_nmap_sphere, tube_nmap_sphere_object). The
displacement cases (displacement_sphere, displacement_stretch_sphere, displacement_object_sphere:
a Displacement node into the Material Output's Displacement, Bump Only, instead of a Bump node)
are judged as the plain ones, the height layer's scale the node's Scale in its space
(--height-space, "height_space"); the object-space cases' control ours_bake_unscaled.exr (the
Scale in world units) must fail (b) and (e). ramp_sphere and clamp_suzanne reshape the height
before the Bump (a Color Ramp, Ease, coloured stops rising and falling; a Math node computing
2.5 h - 0.6 with Clamp): the height layer's "remap" holds the function's points (the ramp as
Cycles tabulates it, 256 entries, luminance of the colour), baked from scenes as the planar
cases are; their control ours_bake_unremapped.exr, the layer without it, must fail (b) and (e).
Measured with Cycles' slopes: median 0.0016-0.0017 deg, p99 0.0026-0.0029 deg (one Suzanne
texel 6.4 deg, its height on the clamp's corner); exact slopes median 0.40 and 0.70 deg; without
the remap 10.7 and 15.8 deg. noise_sphere and noise_stretch_suzanne (stretched and turned) bump
with Blender's Noise Texture (3D, on object coordinates through a Mapping node; Detail 2.5 and
Distortion 0.3, Detail 3 and Roughness 0.6): a "blender-noise" volume layer with that "mapping",
baked from scenes; their control ours_bake_unmapped.exr, the layer without its mapping, must
fail (b) and (e). Measured with Cycles' slopes: median 0.0016-0.0018 deg, p99 0.0019-0.0054
deg; exact slopes median 0.16 and 0.45 deg; without the mapping 3.7 and 4.1 deg.
noise_4d_suzanne does the same with the Noise Texture of Dimensions 4D (W 0.7, Distortion 0.4;
the layer's "dimensions" and "w"): median 0.0017 deg, p99 0.0033 deg (exact slopes 0.27 deg;
without the mapping 3.1 deg).
musgrave_sphere does the same with Blender's Musgrave Texture (fBM, Detail 2.5, Dimension 1.5,
Lacunarity 2.3), a "blender-musgrave" layer: median 0.0016 deg, p99 0.0018 deg (exact slopes
0.076 deg; without the mapping 3.6 deg); musgrave_ridged_sphere with its Ridged Multifractal
(Detail 3, Dimension 1.1, Lacunarity 2.2, Offset 0.9, Gain 1.8) and musgrave_hetero_suzanne
with its Hetero Terrain (Detail 2.5, Dimension 1.3, Lacunarity 2.1, Offset 0.4), the layer's
"musgrave_type", "offset" and "gain": median 0.0016 deg, p99 0.0017-0.0018 deg (exact slopes
median 0.076 and 0.026 deg, the ridges' kinks p99 2.2 deg; without the mapping 2.5 and 1.9
deg). wave_sphere (diagonal bands, sine, distorted by its noise) and wave_suzanne (spherical
rings, triangle) with Blender's Wave Texture, a "blender-wave" layer: median 0.0016 deg, p99
0.0020 deg (exact slopes median 0.14 and 0.010 deg, the triangle's folds p99 1.5 deg; without
the mapping 6.8 and 3.4 deg). voronoi_sphere (Euclidean, Randomness 0.8) and
voronoi_minkowski_suzanne (Minkowski 1.6) bump with Blender's Voronoi Texture's F1 Distance,
a "blender-voronoi" layer: median 0.0016 deg, p99 0.0019-0.0020 deg (exact slopes median 0.074
and 0.11 deg, p99 4.4 and 6.3 deg at the cells' borders, where Cycles' differences straddle two
points; without the mapping 5.8 and 6.9 deg). Its other Feature Outputs, the layer's "feature":
voronoi_edge_sphere (Distance to Edge), voronoi_f2_suzanne (F2, Euclidean) and
voronoi_smooth_sphere (Smooth F1, Smoothness 0.6): median 0.0016 deg, p99 0.0018-0.0020 deg
(exact slopes median 0.0016, 0.062 and 0.089 deg, p99 6.5, 6.7 and 0.36 deg: Distance to
Edge's slopes are constant between its creases, where its p99 lies; without the mapping 5.8,
5.6 and 4.3 deg).
brick_suzanne bumps with Blender's Brick Texture's Fac (wide smoothed mortar, rows moved and
squashed), a "blender-brick" layer: median 0.0016 deg, p99 0.0024 deg (exact slopes median 0.61
deg, p99 8.8 deg at the bricks' corners; without the mapping 9.0 deg).
gradient_suzanne bumps with Blender's Gradient Texture (Quadratic Sphere, mapped so that its
sphere holds Suzanne) and magic_sphere with its Magic Texture (Depth 3, Distortion 1.5), a
"blender-gradient" and a "blender-magic" layer, 256^2: median 0.0016 deg, p99 0.0019 and
0.0018 deg (exact slopes median 0.028 and 0.13 deg; without the mapping 2.8 and 1.9 deg).
noise_uv_suzanne and voronoi_uv_sphere read a Noise and a Voronoi Texture on the UV map's
coordinates (Texture Coordinate UV) through a Mapping node: a volume layer with "coordinates":
"uv"; their control ours_bake_on_object.exr, the same layer on the object's coordinates, must
fail (b) and (e). Measured with Cycles' slopes: median 0.0016-0.0017 deg, p99 0.0020-0.0036
deg; exact slopes median 0.12 and 0.037 deg; on object coordinates 7.4 and 8.3 deg.

Pass criteria, per case (Bump Distance = --height-scale; verified in bake_scene.py):
  (a) convert vs Blender's tangent bake: median <= 0.05 deg and 99th percentile <= 0.5 deg
      (both go through the same per-texel frame: only float rounding and the odd texel whose
      centre lies on a triangle edge differ; the same when sgbake subdivides the mesh itself,
      as it makes Blender's subdivided mesh); outside the islands the input is kept
      (|diff| <= 1e-6 at texels two or more texels away from any island);
  (b) bake vs Blender's tangent bake: median <= 1 deg (Cycles' Bump is a finite difference
      over about half a texel; sgbake differentiates the filtered height exactly); the JSON
      scene gives the same image (|diff| <= 1e-6); background (0.5, 0.5, 1) outside islands;
  (c) mask: at most 1 in 100,000 of Blender's covered texels differ (measured: none);
  (e) the bake with --height-gradient bump-node (the height read again where Cycles' Bump node
      reads it, docs/baker.md) vs Blender's tangent bake: median <= 0.01 deg, p99 <= 0.05 deg
      (measured median 0.0016-0.0017, p99 0.0018-0.0033 deg); the exact-slope bake (b) must
      FAIL these bars; a chain case (below) bakes its scene with the height's "gradient":
      "bump-node" too and is held to the same bars;
  negative controls: our maps with the green channel flipped, and the bake with twice the
  scale, must FAIL (a) / (b) - otherwise the comparison could not tell right from wrong.
Per normal-map case:
  (d) the tangent-normal bake vs Blender's tangent bake and the object-normal bake vs
      Blender's object bake: median <= 0.05 deg, 90th percentile <= 0.1 deg and 99th
      percentile <= 0.3 deg each (sgbake decodes as the Normal Map node does: measured
      median <= 0.005, p90 <= 0.009, p99 <= 0.026 deg, max 0.31 deg at a few texels by the
      sphere's poles and seam; the decode before it, with the unit normal, Strength as a
      scaled slope and no valid-reflection guard, was off by p90 5.8-9.9 deg on every case,
      and by medians 0.075 deg at Strength 1 on the sphere, 1.1-1.8 deg at Strength 0.5 and
      2); the --normal flags give the scene's image
      (|diff| <= 1e-6); background (0.5, 0.5, 1) outside the islands;
  negative controls: our tangent-normal map with green flipped, and the bake at 0.9 x
  Strength (medians 1.5-2.5 deg), must FAIL (d).
  A chain case's bars are the Bump node's finite-difference noise instead (CHAIN_*: median
  <= 0.5, p90 <= 1.5, p99 <= 3 deg; measured 0.22-0.35 / 0.93-1.0 / 1.8, as a plain bump
  of the sphere at 512^2 gives 0.22 / 0.91 / 1.79); its control with the bump's gradient
  added to the normal map's (medians 1.0-1.1, p90 3.1-3.4 deg) must FAIL too.
  Transformed cases (stretch_*: a UV sphere scaled (2, 1, 0.5), turned and moved, with the
  bump at 512^2, a tangent- and an object-space normal map; the flat cube scaled (3, 1, 0.4);
  the Suzanne chain scaled (0.6, 1.5, 1) and turned; see bake_scene.py): every command above
  also gets the object's matrix_world (--transform, "transform"), and the same bars hold,
  but a tighter p99 for the normal maps (STRETCH_NMAP_P99_DEG; the chain's,
  STRETCH_CHAIN_P99_DEG, is the unstretched one's), whose comments say why. Measured: convert
  median 0.010-0.012, p99 0.019-0.065 deg; bump medians 0.54 (sphere) and 0.59 deg (cube);
  normal maps median 0.0016-0.0017, p90 <= 0.0020, p99 <= 0.0021; the chain 0.34 / 1.19 /
  2.34. Their control, the same bake without the transform (in
  object space), must FAIL: medians 3.8 and 6.0 deg for the bumps, p90 11-17 deg for the
  normal maps, median 2.2 deg for the chain.
Prints one line per check with median, p99 (normal-map cases: p90 and p99), max and the
number of texels compared.

--sabotage makes sgbake produce a wrong answer on purpose, to see the test fail: `green` bakes
with --green directx, `scale` with 1.5 S, `input` hands convert Blender's tangent-space map
instead of the object-space one; for the normal-map cases `strength` gives the layer 0.8 x
its Strength and `normal-green` reads the tangent-space map with green flipped
("green": "directx", --normal-green directx). --keep DIR keeps every file for inspection.

Exit status: 0 pass, 1 fail (or a tool failed), 2 usage error, 77 Blender is not installed
(CTest: SKIP_RETURN_CODE 77). Takes ~18 s (Blender starts twice).
"""

import json
import math
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.dont_write_bytecode = True  # keep __pycache__ out of the source tree
sys.path.insert(0, HERE)
import bake_common as bc  # noqa: E402  (needs the sys.path entry above)
import objio  # noqa: E402

CONVERT_MEDIAN_DEG = 0.05
CONVERT_P99_DEG = 0.5
BAKE_MEDIAN_DEG = 1.0
# Per-case p99 bars on (b), where the median alone cannot see what the case is about.
# sphere_backfacing: custom normals facing away from their triangles on 27 % of the texels,
# where Cycles shades from behind (gradient_detail::backFacingNormal): measured p99 5.4 deg,
# 176 deg shaded from the front.
# stretch_sphere_backfacing: the same sphere scaled (2, 1, 0.5) and turned, 512^2, where
# back-facing is decided in world space: measured p99 8.9 deg (median 0.57), 179.7 deg (median
# 1.5) shaded from the front.
BAKE_P99_DEG = {"sphere_backfacing": 10.0, "stretch_sphere_backfacing": 15.0}
# Heights read at positions (planar_sphere, planar_sphere_backfacing: the height projected along
# z onto object coordinates, Cycles' Texture Coordinate Object into a Flat Image Texture, 256^2):
# their slopes are taken along the triangle's plane and, from behind, keep their sign. Measured:
# front median 0.66, p90 1.30 deg; back-facing sphere median 0.75, p90 2.5, p99 91 deg (1271 of
# 58940 texels over 10 deg, where exact slopes and the Bump's differences part most). Projected
# onto the plane along N instead: back-facing median 2.4, p90 77 deg; with the slopes negated
# from behind as a UV height's: p90 111 deg.
BAKE_P90_DEG = {"planar_sphere_backfacing": 5.0, "box_sphere_backfacing": 5.0}
# With the Bump node's differences ("gradient": "bump-node"), (e) holds them too: median 0.0016,
# p99 0.0018 and 0.0021 deg (max 0.68 deg on the back-facing sphere; 56 texels over 10 deg
# before the guard dropped Cycles' root beyond 89.82 deg, BUMP_NODE_OVER_10_MAX).
# Blender's Box projection (box_*, Blend 0.3: one, two and three planes, each side's mirror):
# exact slopes median 0.76 / 0.75 / 0.67 deg (front, back-facing p90 under 5, stretched p99
# 4.8); bump-node median 0.0016 deg, p99 0.0018 / 0.0028 / 0.0023 deg (max 0.62 on the
# back-facing sphere, 49 texels over 10 deg before, as the planar one's). The stretched
# sphere's planes are picked by the world normal taken back to object space: by the object's
# own normal, p99 0.30 deg.
# Per-case bars on the worst texel of (b). suzanne_flat: its concave quads 162 and 163, which
# Cycles shades on the other diagonal's triangles (bake_detail::cyclesShadingTriangles):
# measured 2.3 deg, 117 deg on 48 texels when shaded on the baker's own triangles.
BAKE_MAX_DEG = {"suzanne_flat": 10.0}
# (e) "gradient": "bump-node" (--height-gradient bump-node) reads the heights again where Cycles'
# Bump node does when it bakes (half a texel along Cycles' orthonormals of Ng), so its bake is
# Cycles' to float rounding: measured median 0.0016, p99 0.0020-0.0024 deg on the sphere, Suzanne
# and the stretched sphere (max 2.6 deg at one Suzanne texel, column 257, row 492: not yet
# explained), where the analytic bake (b) is at
# medians 0.34-0.53 deg. That analytic bake is its negative control: it must fail these bars.
BUMP_NODE_MEDIAN_DEG = 0.01
BUMP_NODE_P99_DEG = 0.05
# Per-case bars on the number of texels of (e) more than 10 deg off, where the custom normals
# meet their triangles edge-on (the back-facing spheres): there the bake's incoming direction
# grazes the surface, and Cycles' guard drops a root beyond 89.82 deg from Ng for its other one
# (validReflectionNormal). Measured max 0.30-0.69 deg; with the nearest root instead 60 texels
# at 90 deg (sphere_backfacing), 58 up to 117 deg (stretch_sphere_backfacing), 56 and 49 on the
# planar and Box-projected ones. A single texel can still flip by 90 deg with Cycles' float
# (box_sphere_backfacing once, [166, 33], in a run of every case; 0.62 deg alone): at most 2.
# stretch_chain_suzanne: where the Bump node bumps the normal map's normal far below the
# surface, Cycles' closure keeps it there (a normal far below passes the guard); sgbake dropped
# the bump (no Gamma stands for it) until such a normal was handed on as it is (HandedNormal):
# measured max 3.8 deg (the Suzanne texel of case suzanne), 22 texels up to 142 deg before.
BUMP_NODE_OVER_10_MAX = {"sphere_backfacing": 2, "stretch_sphere_backfacing": 2,
                         "planar_sphere_backfacing": 2, "box_sphere_backfacing": 2,
                         "stretch_chain_suzanne": 2}
SAME_IMAGE_ABS = 1e-6
BACKGROUND_ABS = 1e-4
NMAP_MEDIAN_DEG = 0.05
NMAP_P90_DEG = 0.1
NMAP_P99_DEG = 0.3
# Per-case bars on the worst texel of (d). nmap_suzanne_flat: flat Suzanne, where Cycles'
# MikkTSpace runs on its own split of quads 162 and 163 and welds a flat quad's two triangles
# where its float triangle normals are equal to the bit (computeLoopTriangleTangents): measured
# 0.002 deg; 5.3 deg with the baker's split, 0.76 with normals rounded otherwise.
NMAP_MAX_DEG = {"nmap_suzanne_flat": 0.05}
# A Bump node stacked on the Normal Map's output: Cycles' bump is a finite difference (see (b)),
# so the bars are the plain bump's noise at 512^2 (UV sphere: median 0.22, p90 0.91, p99 1.79
# deg) with room; adding the bump's gradient to the normal map's instead is off by medians
# 1.0-1.1, p90 3.1-3.4, p99 5.6-5.7 deg.
CHAIN_MEDIAN_DEG = 0.5
CHAIN_P90_DEG = 1.5
CHAIN_P99_DEG = 3.0
# A normal map on an unevenly scaled object (stretch_nmap_*): as on the others, measured median
# 0.0016-0.0017, p90 0.0018-0.0020, p99 0.0020-0.0021 deg (max 0.28-1.4 deg at single texels
# where the guard bends a grazing normal). The stretch turns some of the decoded normals below
# the surface: Cycles' guard bends those, seen from their own side, and sgbake must not shade
# their mirror image (the Γ of such a normal stands for it): with it, p99 was 0.26 tangent and
# 0.52 deg object, ~1 % of the texels, in stripes near the sphere's UV seam
# (NormalBelowSurface). Without the transform: p90 11-17 deg.
STRETCH_NMAP_P99_DEG = 0.05
# The chain on Suzanne scaled (0.6, 1.5, 1) and turned (stretch_chain_suzanne, 512^2): median and
# p90 within the chain bars (measured 0.34 / 1.19 tangent, 0.22 / 0.96 object); p99 2.3 tangent
# and 2.5 deg object, a little above the unstretched chains' 1.8 (the finite difference's noise).
# It was 3.3 and 6.0 deg while the normal map's output was guarded before the Bump node bumped it:
# in Blender 3.4 only the closure guards.
STRETCH_CHAIN_P99_DEG = 3.0
# Coverage: sgbake samples each texel where Blender does (its centre moved by (0.001, 0.002)
# texel), and every case's mask equals Blender's EMIT mask texel for texel. Left only as slack
# for Blender's single-precision scan conversion: 1 texel per 100,000 covered (the 512^2
# Suzanne: 1). Sampling the texel centre instead differed on 3 (Suzanne) and 2 (the cylinder).
MASK_MISMATCH_FRACTION = 1e-5
MASK_MISMATCH_SLACK = 0
SGBAKE_TIMEOUT = 120
# The cases in groups, one CTest test each (BlenderBakeOracle_<group>, `--group NAME`), so that
# ctest -j runs them side by side and each stays well within its time limit; DEFAULT_CASES is
# every group in turn.
CASE_GROUPS = {
    # Bumps from a height map on meshes of every kind, and Bumps chained on normal maps.
    "meshes": ("suzanne", "suzanne_live", "sphere", "cube_flat", "suzanne_flat",
               "cylinder_twist", "chain_sphere", "chain_suzanne"),
    # Normal Map nodes in tangent and object space.
    "normal_maps": ("nmap_sphere", "nmap_sphere_s05", "nmap_sphere_s2", "nmap_sphere_object",
                    "nmap_cube", "nmap_cube_s2", "nmap_suzanne", "nmap_suzanne_flat",
                    "nmap_sphere_steep"),
    # Objects scaled unevenly, turned and moved; normals facing away from their triangle.
    "stretched": ("stretch_sphere", "stretch_cube", "stretch_nmap_sphere",
                  "stretch_nmap_sphere_object", "stretch_chain_suzanne", "sphere_backfacing",
                  "nmap_sphere_backfacing", "stretch_sphere_backfacing",
                  "stretch_nmap_sphere_backfacing"),
    # Images projected onto object coordinates: Flat and Box.
    "projections": ("planar_sphere", "planar_sphere_backfacing", "box_sphere",
                    "box_sphere_backfacing", "box_stretch_sphere", "box_mapped_sphere",
                    "box_empty_sphere", "box_generated_sphere", "box_strength_sphere",
                    "box_nmap_sphere", "box_nmap_sphere_object", "flat_nmap_sphere",
                    "box_nmap_stretch_sphere"),
    # Images wrapped around object coordinates: Sphere and Tube.
    "wraps": ("sphere_wrap_sphere", "tube_wrap_sphere", "sphere_nmap_sphere",
              "tube_nmap_sphere_object", "sphere_wrap_stretch_sphere"),
    # Heights through the Material Output's Displacement, and reshaped before the Bump node.
    "displacement_remaps": ("displacement_sphere", "displacement_stretch_sphere",
                            "displacement_object_sphere", "displacement_object_stretch_sphere",
                            "ramp_sphere", "clamp_suzanne"),
    # Blender's procedural textures but Voronoi.
    "procedural": ("noise_sphere", "noise_stretch_suzanne", "noise_uv_suzanne",
                   "noise_4d_suzanne", "brick_suzanne",
                   "musgrave_sphere", "musgrave_ridged_sphere", "musgrave_hetero_suzanne",
                   "wave_sphere", "wave_suzanne", "gradient_suzanne", "magic_sphere"),
    # Blender's Voronoi Texture.
    "voronoi": ("voronoi_uv_sphere", "voronoi_sphere", "voronoi_minkowski_suzanne",
                "voronoi_edge_sphere", "voronoi_f2_suzanne", "voronoi_smooth_sphere"),
}
DEFAULT_CASES = tuple(case for group in CASE_GROUPS.values() for case in group)
# Blender's Sphere and Tube projections: their own wrap is the control of each other's
# (ours_bake_swapped, nmap_swapped: the Sphere read as the Tube and the other way round).
# Measured: heights with Cycles' slopes median 0.0016, p99 0.0018 deg (exact slopes median 0.09
# and 0.12 deg); on the stretched sphere, in world space, 0.0016 and 0.0022 deg; normal maps
# median 0.0014-0.0017, p99 <= 0.0020 deg; the other wrap 3.3-4.2 deg (heights), 6.6-19.9 deg
# (normal maps).
SWAPPED_WRAP = {"sphere": "tube", "tube": "sphere"}


# Blender's own limit per run (a group's bakes, or its comparison): above what any group needs
# on a loaded machine, so that the CTest test's limit decides, and a run by hand cannot hang.
BLENDER_TIMEOUT = 1200


def run_blender_script(blender, script, args):
    try:
        proc = objio.run_blender(blender, os.path.join(HERE, script), args,
                                 capture_output=True, text=True, timeout=BLENDER_TIMEOUT)
    except subprocess.TimeoutExpired:
        print(f"error: Blender running {script} took more than {BLENDER_TIMEOUT} s")
        return False
    if proc.returncode != 0:
        print(f"error: Blender running {script} exited with {proc.returncode}\n"
              f"{proc.stdout[-4000:]}\n{proc.stderr[-4000:]}")
        return False
    return True


def run_sgbake(cli, args, log):
    """Runs sgbake; returns True on success. Records the command in `log`."""
    cmd = [cli] + [str(a) for a in args]
    log.append(" ".join(cmd))
    proc = bc.run_tool(cmd, timeout=SGBAKE_TIMEOUT)
    return proc is not None and proc.returncode == 0


def transformed(entry):
    """Whether the case's object has a transform whose 3 x 3 part is not the identity."""
    rows = entry.get("transform")
    return rows is not None and any(rows[r][c] != (1.0 if r == c else 0.0)
                                    for r in range(3) for c in range(3))


def transform_flags(entry):
    """--transform with the case's matrix_world, row by row, when it has one."""
    if not transformed(entry):
        return []
    return ["--transform", ",".join(repr(float(v)) for row in entry["transform"] for v in row)]


def bake_layer_scenes(cli, entry, layers, green, common, failed, log):
    """Bakes each (name, layer) of `layers` from a scene of its own on the case's mesh (and its
    subdivision and transform) into name.exr, then the mask; returns `failed` with the command
    lines that failed added."""
    d, size = entry["dir"], entry["size"]
    p = lambda name: os.path.join(d, name)  # noqa: E731
    for name, layer in layers:
        scene = {"mesh": p("mesh.obj"), "subdivision": {"level": entry.get("subdivision", 0)},
                 "layers": [layer],
                 "outputs": [{"map": "tangent-normal", "file": p(name + ".exr"), "size": size,
                              "margin": 0, "samples": 1, "green": green, "bit_depth": 32}]}
        if transformed(entry):
            scene["transform"] = entry["transform"]
        if not bc.bake_scene_file(cli, d, name, scene):
            failed.append(f"sgbake bake {p(name + '.json')}")
    if not run_sgbake(cli, ["bake", "--mesh", p("mesh.obj"), "--map", "mask", "--size", size,
                            "-o", p("ours_mask.exr")] + common, log):
        failed.append(log[-1])
    return failed


def sgbake_case(cli, entry, sabotage, threads):
    """Runs every sgbake command of one case; returns a list of failed command lines."""
    d = entry["dir"]
    p = lambda name: os.path.join(d, name)  # noqa: E731
    scale, size = entry["scale"], entry["size"]
    # A displacement case's height layer: the Displacement node's Scale, in its space
    # (bake_scene.DISPLACEMENT: object space grows along the normal with the object's scale).
    height_space = entry.get("displacement", {}).get("space", "world")
    # 32-bit float EXRs (sgbake's default 16 = half floats moves convert's median from 0.0025 to
    # 0.016 deg on Suzanne, a third of the 0.05 deg budget), and
    # no .sgbake-manifest.json (it would let a re-run in a kept directory skip the bake).
    common = ["--margin", 0, "--samples", 1, "--bit-depth", 32, "--no-manifest"]
    # A case with a live Subdivision Surface modifier: mesh.obj is coarse, sgbake subdivides.
    subdivide = ["--subdivide", entry["subdivision"]] if entry.get("subdivision") else []
    common += subdivide
    if threads:
        common += ["--threads", threads]
    failed, log = [], []

    convert_input = p("blender_tangent.exr" if sabotage == "input" else "blender_object.exr")
    if not run_sgbake(cli, ["convert", "--mesh", p("mesh.obj"), "--from", "object", "--to",
                            "tangent", convert_input, "-o", p("ours_convert.exr"),
                            "--bit-depth", 32] + subdivide + transform_flags(entry)
                      + (["--threads", threads] if threads else []),
                      log):
        failed.append(log[-1])

    bake_scale = scale * (1.5 if sabotage == "scale" else 1.0)
    green = "directx" if sabotage == "green" else "opengl"
    if "planar" in entry:  # the height projected at positions: no flags for it, scenes only
        projection = entry["planar"]["projection"]
        box = projection == "box"
        bakes = [("ours_bake", bake_scale, "analytic"), ("ours_bake_x2", 2 * scale, "analytic"),
                 ("ours_bake_bump_node", bake_scale, "bump-node")]
        if box:
            bakes.append(("ours_bake_blended", bake_scale, "bump-node"))
        if projection in SWAPPED_WRAP:
            bakes.append(("ours_bake_swapped", bake_scale, "bump-node"))
        if "mapping" in entry["planar"]:
            bakes.append(("ours_bake_unmapped", bake_scale, "bump-node"))
        strength = entry["planar"].get("strength", 1.0)
        if strength != 1.0:
            bakes.append(("ours_bake_full_strength", bake_scale, "bump-node"))
        layers = []
        for name, layer_scale, gradient in bakes:
            layer = {"type": "planar", "image": p("height.exr"), "kind": "height", "axis": "z",
                     "scale": layer_scale, "filter": entry["filter"], "gradient": gradient}
            if "mapping" in entry["planar"] and name != "ours_bake_unmapped":
                layer["mapping"] = entry["planar"]["mapping"]
            if strength != 1.0 and name != "ours_bake_full_strength":
                layer["strength"] = strength
            if projection in SWAPPED_WRAP:  # Blender's Sphere and Tube; the control: swapped
                layer["projection"] = (SWAPPED_WRAP[projection] if name == "ours_bake_swapped"
                                       else projection)
            if box:  # Blender's Box projection; the control: sgbake's own triplanar blend
                del layer["axis"]
                layer["type"] = "triplanar"
                if name != "ours_bake_blended":
                    layer.update(projection="box", box_blend=entry["planar"]["blend"])
            layers.append((name, layer))
        return bake_layer_scenes(cli, entry, layers, green, common, failed, log)
    if "remap" in entry or "noise" in entry:  # scenes only
        # A height reshaped before the Bump (its layer's "remap"; the control without it), or
        # Blender's Noise Texture (a "blender-noise" volume; the control without its Mapping).
        control = ("ours_bake_unremapped" if "remap" in entry
                   else "ours_bake_on_object" if entry["noise"].get("coordinates") == "UV"
                   else "ours_bake_unmapped")
        layers = []
        for name, layer_scale, gradient, complete in (
                ("ours_bake", bake_scale, "analytic", True),
                ("ours_bake_x2", 2 * scale, "analytic", True),
                ("ours_bake_bump_node", bake_scale, "bump-node", True),
                (control, bake_scale, "bump-node", False)):
            if "noise" in entry:
                noise = entry["noise"]
                kind = noise.get("kind", "noise")
                layer = {"type": "volume", "amplitude": layer_scale,
                         "gradient": gradient, "function": "blender-" + kind}
                if kind != "gradient":  # (the Gradient Texture has no Scale)
                    layer["frequency"] = noise["scale"]
                if kind == "voronoi":  # Blender's names, lower case, "-" for "_"
                    layer["metric"] = noise["metric"].lower()
                    feature = noise.get("feature", "F1").lower().replace("_", "-")
                    if feature != "f1":
                        layer["feature"] = feature
                    if "smoothness" in noise:
                        layer["smoothness"] = noise["smoothness"]
                elif kind == "gradient":  # Blender's type, lower case, "-" for "_"
                    layer["gradient_type"] = noise["gradient_type"].lower().replace("_", "-")
                elif kind not in ("brick", "magic"):
                    layer["detail"] = noise["detail"]
                keys = {"noise": ("roughness", "distortion"), "voronoi": ("randomness", "exponent"),
                        "musgrave": ("dimension", "lacunarity"),
                        "brick": ("mortar_size", "mortar_smooth", "brick_width", "row_height",
                                  "brick_offset", "offset_frequency", "squash",
                                  "squash_frequency"),
                        "wave": ("distortion", "detail_scale", "detail_roughness", "phase"),
                        "gradient": (), "magic": ("depth", "distortion")}
                for key in keys[kind]:
                    layer[key] = noise[key]
                if "dimensions" in noise:  # (the Noise Texture's other Dimensions, and W)
                    layer["dimensions"] = noise["dimensions"]
                    if "w" in noise:
                        layer["w"] = noise["w"]
                if kind == "musgrave":  # Blender's type, lower case, "-" for "_"
                    layer["musgrave_type"] = noise.get("musgrave_type",
                                                       "FBM").lower().replace("_", "-")
                    layer.update((key, noise[key]) for key in ("offset", "gain") if key in noise)
                if kind == "wave":  # Blender's enum names, lower case ("SIN" is "sine")
                    layer.update(wave=noise["wave"].lower(),
                                 wave_direction=noise["direction"].lower(),
                                 profile={"SIN": "sine", "SAW": "saw",
                                          "TRI": "triangle"}[noise["profile"]])
                # On UV coordinates the control is the texture read at the object's positions
                # (through the same mapping), elsewhere the texture without its mapping.
                on_uv = noise.get("coordinates") == "UV"
                if complete or on_uv:
                    location, rotation, mapping_scale = noise["mapping"]
                    layer["mapping"] = {"location": location, "rotation": rotation,
                                        "scale": mapping_scale}
                if complete and on_uv:
                    layer["coordinates"] = "uv"
            else:
                layer = {"type": "height", "image": p("height.exr"), "scale": layer_scale,
                         "filter": entry["filter"], "gradient": gradient}
                if complete:
                    layer["remap"] = entry["remap"]
            layers.append((name, layer))
        return bake_layer_scenes(cli, entry, layers, green, common, failed, log)
    bake = ["bake", "--mesh", p("mesh.obj"), "--height", p("height.exr"), "--filter",
            entry["filter"], "--map", "tangent-normal", "--size", size, "--green", green] + common
    world_units = list(bake)  # (the control of an object-space displacement)
    if height_space == "object":
        bake += ["--height-space", "object"]
    # The control without the transform (not for heights in object units: on a uniformly
    # scaled object they bake the same without it, the control ours_bake_unscaled tells).
    if transformed(entry) and height_space == "world" and not run_sgbake(
            cli, bake + ["--height-scale", repr(bake_scale), "-o",
                         p("ours_bake_object_space.exr")], log):
        failed.append(log[-1])
    bake += transform_flags(entry)
    if not run_sgbake(cli, bake + ["--height-scale", repr(bake_scale), "-o", p("ours_bake.exr")],
                      log):
        failed.append(log[-1])
    if not run_sgbake(cli, bake + ["--height-scale", repr(2 * scale), "-o",
                                   p("ours_bake_x2.exr")], log):
        failed.append(log[-1])
    if not run_sgbake(cli, bake + ["--height-scale", repr(bake_scale), "--height-gradient",
                                   "bump-node", "-o", p("ours_bake_bump_node.exr")], log):
        failed.append(log[-1])
    if height_space == "object" and not run_sgbake(
            cli, world_units + transform_flags(entry)
            + ["--height-scale", repr(bake_scale), "--height-gradient", "bump-node", "-o",
               p("ours_bake_unscaled.exr")], log):
        failed.append(log[-1])  # the control: the object-space Scale taken in world units

    scene = {
        "mesh": p("mesh.obj"),
        "subdivision": {"level": entry.get("subdivision", 0)},
        "layers": [{"type": "height", "image": p("height.exr"), "scale": bake_scale,
                    "filter": entry["filter"], "uv": 0, "weight": 1.0,
                    "height_space": height_space}],
        "outputs": [{"map": "tangent-normal", "file": p("ours_bake_json.exr"), "size": size,
                     "margin": 0, "samples": 1, "green": green, "bit_depth": 32}],
    }
    if transformed(entry):
        scene["transform"] = entry["transform"]
    with open(p("scene.json"), "w", encoding="ascii") as f:
        json.dump(scene, f, indent=1)
    if not run_sgbake(cli, ["bake", p("scene.json"), "--no-manifest"]
                      + (["--threads", threads] if threads else []), log):
        failed.append(log[-1])

    if not run_sgbake(cli, ["bake", "--mesh", p("mesh.obj"), "--map", "mask", "--size", size,
                            "-o", p("ours_mask.exr")] + common, log):
        failed.append(log[-1])
    return failed


def sgbake_nmap_case(cli, entry, sabotage, threads):
    """Runs the sgbake commands of a normal-map case (entry["normal_map"]); returns a list of
    failed command lines."""
    d = entry["dir"]
    p = lambda name: os.path.join(d, name)  # noqa: E731
    nmap, size = entry["normal_map"], entry["size"]
    common = ["--margin", 0, "--samples", 1, "--bit-depth", 32, "--no-manifest"]
    if threads:
        common += ["--threads", threads]
    failed, log = [], []
    strength = nmap["strength"] * (0.8 if sabotage == "strength" else 1.0)
    map_green = "directx" if sabotage == "normal-green" else "opengl"
    green = "directx" if sabotage == "green" else "opengl"

    projected = "planar" in entry  # read by one of Blender's projections, not the UV map

    def scene_file(name, layer_strength, outputs, base="above", transform=True,
                   gradient="analytic", through_uvs=False, projection=None):
        projection = projection or (entry["planar"]["projection"] if projected else None)
        layer = {"type": "normal", "image": p("normal.exr"), "space": nmap["space"],
                 "strength": layer_strength, "filter": "bilinear", "uv": 0, "weight": 1.0}
        if projected and not through_uvs:
            layer = {"type": "triplanar", "image": p("normal.exr"),
                     "kind": f"{nmap['space']}-normal", "scale": layer_strength,
                     "projection": "box", "box_blend": entry["planar"]["blend"],
                     "filter": "bilinear", "weight": 1.0}
            if entry["planar"]["projection"] != "box":  # Flat, Sphere, Tube: single lookups
                del layer["box_blend"]
                layer.update(type="planar", projection=projection)
            if "mapping" in entry["planar"]:
                layer["mapping"] = entry["planar"]["mapping"]
        if nmap["space"] == "tangent":
            layer["green"] = map_green
        layers = [layer]
        if "bump" in nmap:  # the Bump node on the Normal Map's output
            layers.append({"type": "height", "image": p("height.exr"), "scale": nmap["bump"],
                           "filter": "bilinear", "base": base, "gradient": gradient})
        scene = {"mesh": p("mesh.obj"), "layers": layers, "outputs": []}
        if transform and transformed(entry):
            scene["transform"] = entry["transform"]
        for kind, file in outputs:
            out = {"map": kind, "file": p(file), "size": size, "margin": 0, "samples": 1,
                   "bit_depth": 32}
            if kind == "tangent-normal":
                out["green"] = green
            scene["outputs"].append(out)
        with open(p(name), "w", encoding="ascii") as f:
            json.dump(scene, f, indent=1)
        return ["bake", p(name), "--no-manifest"] + (["--threads", threads] if threads else [])

    for args in (scene_file("scene.json", strength,
                            [("tangent-normal", "ours_nmap_tangent.exr"),
                             ("object-normal", "ours_nmap_object.exr")]),
                 scene_file("scene_weak.json", 0.9 * strength,
                            [("tangent-normal", "ours_nmap_weak.exr")])):
        if not run_sgbake(cli, args, log):
            failed.append(log[-1])
    if projected and not run_sgbake(  # the control: the same map read through the UV map
            cli, scene_file("scene_uv.json", strength, [("tangent-normal", "ours_nmap_uv.exr")],
                            through_uvs=True), log):
        failed.append(log[-1])
    if projected and entry["planar"]["projection"] in SWAPPED_WRAP and not run_sgbake(
            cli, scene_file("scene_swapped.json", strength,  # the control: the other wrap
                            [("tangent-normal", "ours_nmap_swapped.exr")],
                            projection=SWAPPED_WRAP[entry["planar"]["projection"]]), log):
        failed.append(log[-1])
    if transformed(entry) and not run_sgbake(
            cli, scene_file("scene_object_space.json", strength,
                            [("tangent-normal", "ours_nmap_object_space.exr")],
                            transform=False), log):
        failed.append(log[-1])
    if "bump" in nmap and not run_sgbake(
            cli, scene_file("scene_sum.json", strength, [("tangent-normal", "ours_nmap_sum.exr")],
                            base="surface"), log):
        failed.append(log[-1])
    if "bump" in nmap and not run_sgbake(
            cli, scene_file("scene_bump_node.json", strength,
                            [("tangent-normal", "ours_nmap_bump_node.exr")],
                            gradient="bump-node"), log):
        failed.append(log[-1])
    if nmap["strength"] == 1.0 and "bump" not in nmap and not projected:
        # (the flags have no Strength, chain or projection)
        flags = ["bake", "--mesh", p("mesh.obj"), "--normal", p("normal.exr"), "--normal-space",
                 nmap["space"], "--map", "tangent-normal", "--size", size, "--green", green,
                 "-o", p("ours_nmap_flags.exr")] + common + transform_flags(entry)
        if nmap["space"] == "tangent":
            flags += ["--normal-green", map_green]
        if not run_sgbake(cli, flags, log):
            failed.append(log[-1])
    return failed


def fmt(stats):
    if not stats or stats.get("median_deg") is None:
        return "no texels"
    return (f"median {stats['median_deg']:.4f} deg, p99 {stats['p99_deg']:.4f} deg, "
            f"max {stats['max_deg']:.3f} deg, {stats['texels']} texels")


def fmt_nmap(stats):
    if not stats or stats.get("median_deg") is None:
        return "no texels"
    return (f"median {stats['median_deg']:.4f}, p90 {stats['p90_deg']:.4f}, "
            f"p99 {stats['p99_deg']:.4f}, max {stats['max_deg']:.3f} deg, "
            f"{stats['texels']} texels")


def passes_convert(s):
    return s["median_deg"] <= CONVERT_MEDIAN_DEG and s["p99_deg"] <= CONVERT_P99_DEG


def passes_bake(s, case=None):
    return (s["median_deg"] <= BAKE_MEDIAN_DEG
            and s["p90_deg"] <= BAKE_P90_DEG.get(case, math.inf)
            and s["p99_deg"] <= BAKE_P99_DEG.get(case, math.inf)
            and s["max_deg"] <= BAKE_MAX_DEG.get(case, math.inf))


def passes_bump_node(s, case=None):
    return (s["median_deg"] <= BUMP_NODE_MEDIAN_DEG and s["p99_deg"] <= BUMP_NODE_P99_DEG
            and s.get("over_10_deg", 0) <= BUMP_NODE_OVER_10_MAX.get(case, math.inf))


def passes_nmap(s, chain=False, stretched=False, case=None):
    if s["max_deg"] > NMAP_MAX_DEG.get(case, math.inf):
        return False
    if chain:
        return (s["median_deg"] <= CHAIN_MEDIAN_DEG and s["p90_deg"] <= CHAIN_P90_DEG
                and s["p99_deg"] <= (STRETCH_CHAIN_P99_DEG if stretched else CHAIN_P99_DEG))
    return (s["median_deg"] <= NMAP_MEDIAN_DEG and s["p90_deg"] <= NMAP_P90_DEG
            and s["p99_deg"] <= (STRETCH_NMAP_P99_DEG if stretched else NMAP_P99_DEG))


def evaluate_nmap(name, r, nmap, stretched_case=False):
    """Prints the figures of a normal-map case; returns a list of failure descriptions."""
    fails = []
    chain = "bump" in nmap
    stretched = stretched_case
    print(f"case {name}: {r['size'][1]}x{r['size'][0]}, {nmap['space']}-space normal map "
          f"(tilts up to {nmap['tilt_deg']:g} deg), Strength {nmap['strength']:g}"
          + ((f", read by the Box projection with Blend {nmap['box']:g}"
              if nmap["projection"] == "box"
              else f", read by the {nmap['projection'].title()} projection")
             if "projection" in nmap else "")
          + (f", then a Bump node of Distance {nmap['bump']:g} on its output" if chain else "")
          + f", {r['covered']} covered texels, {r['compared']} compared; Blender's tangent bake "
          f"tilt from +Z: {fmt_nmap(r['tilt'])}")
    bars = (f"(median <= {CHAIN_MEDIAN_DEG}, p90 <= {CHAIN_P90_DEG}, p99 <= "
            f"{STRETCH_CHAIN_P99_DEG if stretched else CHAIN_P99_DEG})"
            if chain else
            f"(median <= {NMAP_MEDIAN_DEG}, p90 <= {NMAP_P90_DEG}, p99 <= "
            f"{STRETCH_NMAP_P99_DEG if stretched else NMAP_P99_DEG}"
            + (f", max <= {NMAP_MAX_DEG[name]}" if name in NMAP_MAX_DEG else "") + ")")
    for key, what in (("nmap_tangent", "tangent-normal vs Blender tangent"),
                      ("nmap_object", "object-normal vs Blender object ")):
        if key not in r or "error" in r[key]:
            fails.append(f"{name}: {what.strip()}: " + (r[key]["error"] if key in r
                                                         else "no output to compare"))
            continue
        s = r[key]
        ok = passes_nmap(s, chain, stretched, name)
        print(f"  (d) {what}: {fmt_nmap(s)} worst at (x, row) {s.get('worst_at')} -> "
              f"{'ok' if ok else 'FAIL'} {bars}")
        if not ok:
            fails.append(f"{name}: {what.strip()}: {fmt_nmap(s)}")
        if key == "nmap_tangent":
            if s["outside_max_abs"] > BACKGROUND_ABS:
                fails.append(f"{name}: normal-map bake background is not (0.5, 0.5, 1) outside "
                             f"the islands (max |diff| {s['outside_max_abs']:.3g})")
            print(f"      control, green flipped:            {fmt_nmap(s['flipped_green'])}")
            if passes_nmap(s["flipped_green"], chain, stretched):
                fails.append(f"{name}: negative control: the normal-map bake with green "
                             f"flipped still passes")
    if chain and "nmap_bump_node" in r:
        s = r["nmap_bump_node"]
        ok = "error" not in s and passes_bump_node(s, name)
        print(f"  (e) bump-node chain vs Blender:         {fmt_nmap(s)} -> "
              f"{'ok' if ok else 'FAIL'} (median <= {BUMP_NODE_MEDIAN_DEG}, p99 <= "
              f"{BUMP_NODE_P99_DEG}"
              + (f", texels over 10 deg: {s.get('over_10_deg')} <= {BUMP_NODE_OVER_10_MAX[name]})"
                 if name in BUMP_NODE_OVER_10_MAX else ")"))
        if not ok:
            fails.append(f"{name}: the bump-node chain differs from Blender's: {fmt_nmap(s)}")
        if passes_bump_node(r["nmap_tangent"]):
            fails.append(f"{name}: negative control: the analytic chain passes the bump-node "
                         f"bars")
    elif chain:
        fails.append(f"{name}: no bump-node chain bake to compare")
    if chain:
        negative_control(name, r, "nmap_sum", "bump added, not stacked:  ",
                         "the bake with the bump added to the normal map's gradient", chain,
                         fails, stretched)
    if nmap.get("projection") in SWAPPED_WRAP:
        negative_control(name, r, "nmap_swapped", "the other wrap:           ",
                         "the bake of the map read by the other wrap", chain, fails, stretched)
    if "projection" in nmap:
        negative_control(name, r, "nmap_uv", "read through the UV map:  ",
                         "the bake of the map read through the UV map", chain, fails, stretched)
    elif nmap["strength"] == 1.0 and not chain:
        s = r.get("nmap_flags")
        same = s.get("json_vs_flags_max_abs") if s else None
        if s is None or "error" in s:
            fails.append(f"{name}: no --normal flags bake to compare")
        else:
            print(f"  (d) --normal flags bake:                {fmt_nmap(s)}; "
                  f"max |JSON - flags| = {same}")
        if same is None or same > SAME_IMAGE_ABS:
            fails.append(f"{name}: the JSON scene and the --normal flags give different images "
                         f"(max |diff| {same})")
    negative_control(name, r, "nmap_weak", "0.9 x Strength:           ",
                     "the bake at 0.9 x Strength", chain, fails, stretched)
    if stretched:
        negative_control(name, r, "nmap_object_space", "without transform:        ",
                         "the bake without the object's transform", chain, fails, stretched)
    return fails


def negative_control(name, r, key, label, what, chain, fails, stretched=False):
    """Prints the figures of control bake r[key] and appends to `fails` when it is missing or
    passes the bars (then the comparison could not tell right from wrong)."""
    s = r.get(key)
    if s is None or "error" in s:
        fails.append(f"{name}: no control bake ({what}) to compare")
        return
    print(f"      control, {label}{fmt_nmap(s)}")
    if passes_nmap(s, chain, stretched):
        fails.append(f"{name}: negative control: {what} still passes ({fmt_nmap(s)})")


def evaluate(name, r, planar=False):
    """Prints the figures of one case; returns a list of failure descriptions. (A case with a
    live modifier, which sgbake subdivides itself, is held to the same bars: its subdivided
    mesh is Blender's, float for float, BlenderSubdivisionOracle.) A planar case, or a remapped
    one, has only the bake (a scene), its 2x control and the mask."""
    fails = []
    print(f"case {name}: {r['size'][1]}x{r['size'][0]}, {r['covered']} covered texels, "
          f"{r['compared']} compared; bump tilt from +Z: {fmt(r['tilt'])}")

    def missing(key, what):
        if key not in r:
            fails.append(f"{name}: no {what} output to compare")
            return True
        if "error" in r[key]:
            fails.append(f"{name}: {what}: {r[key]['error']}")
            return True
        return False

    def judge(label, s, ok, bars, problem):
        """Prints a check's line; a failed check appends `problem` with the figures."""
        print(f"  {label} {fmt(s)} worst at (x, row) {s.get('worst_at')} -> "
              f"{'ok' if ok else 'FAIL'} {bars}")
        if not ok:
            fails.append(f"{name}: {problem}: {fmt(s)}")

    if not planar and not missing("convert", "convert"):
        s = r["convert"]
        judge("(a) convert vs Blender tangent:", s, passes_convert(s),
              f"(median <= {CONVERT_MEDIAN_DEG}, p99 <= {CONVERT_P99_DEG})",
              "convert differs from Blender's tangent bake")
        if s["outside_max_abs"] > SAME_IMAGE_ABS:
            fails.append(f"{name}: convert changed texels outside the islands "
                         f"(max |diff| {s['outside_max_abs']:.3g})")
        if passes_convert(s["flipped_green"]):
            fails.append(f"{name}: negative control: convert with green flipped still passes "
                         f"({fmt(s['flipped_green'])})")
    if not missing("bake", "bake"):
        s = r["bake"]
        p99_bar = f", p90 <= {BAKE_P90_DEG[name]}" if name in BAKE_P90_DEG else ""
        p99_bar += f", p99 <= {BAKE_P99_DEG[name]}" if name in BAKE_P99_DEG else ""
        p99_bar += f", max <= {BAKE_MAX_DEG[name]}" if name in BAKE_MAX_DEG else ""
        judge("(b) bake vs Blender tangent:   ", s, passes_bake(s, name),
              f"(median <= {BAKE_MEDIAN_DEG}{p99_bar})", "bake differs from Blender's tangent bake")
        if s["outside_max_abs"] > BACKGROUND_ABS:
            fails.append(f"{name}: bake background is not (0.5, 0.5, 1) outside the islands "
                         f"(max |diff| {s['outside_max_abs']:.3g})")
        print(f"      control, green flipped:     {fmt(s['flipped_green'])}")
        if passes_bake(s["flipped_green"], name):
            fails.append(f"{name}: negative control: bake with green flipped still passes")
    if not planar and not missing("bake_json", "JSON-scene bake"):
        s = r["bake_json"]
        same = s.get("json_vs_flags_max_abs")
        print(f"  (b) JSON scene bake:            {fmt(s)}; max |JSON - flags| = {same}")
        if not passes_bake(s, name):
            fails.append(f"{name}: JSON-scene bake differs from Blender's: {fmt(s)}")
        if same is None or same > SAME_IMAGE_ABS:
            fails.append(f"{name}: the JSON scene and the flags give different images "
                         f"(max |diff| {same})")
    if not missing("bake_bump_node", "bump-node bake"):
        s = r["bake_bump_node"]
        max_bar = (f", texels over 10 deg: {s.get('over_10_deg')} <= {BUMP_NODE_OVER_10_MAX[name]}"
                   if name in BUMP_NODE_OVER_10_MAX else "")
        judge("(e) bump-node bake vs Blender: ", s, passes_bump_node(s, name),
              f"(median <= {BUMP_NODE_MEDIAN_DEG}, p99 <= {BUMP_NODE_P99_DEG}{max_bar})",
              "the bump-node bake differs from Blender's")
        if "bake" in r and "error" not in r["bake"] and passes_bump_node(r["bake"]):
            fails.append(f"{name}: negative control: the analytic bake passes the bump-node "
                         f"bars ({fmt(r['bake'])})")
    for key, label, what in (("bake_blended", "sgbake's blend:   ",
                              "sgbake's own triplanar blend instead of Blender's Box"),
                             ("bake_unmapped", "without Mapping:  ", "its Mapping node left out"),
                             ("bake_on_object", "object coords:    ",
                              "the texture read at the object's coordinates, not the UV map's"),
                             ("bake_swapped", "the other wrap:   ",
                              "the Sphere and Tube projections swapped"),
                             ("bake_unscaled", "Scale in world:   ",
                              "the object-space Displacement's Scale taken in world units"),
                             ("bake_full_strength", "Strength 1:       ",
                              "the Bump's Strength left out"),
                             ("bake_unremapped", "without remap:    ",
                              "the Color Ramp or clamp before the Bump left out")):
        if key not in r:
            continue
        s = r[key]
        print(f"      control, {label} {fmt(s)}")
        if "error" in s or passes_bump_node(s) or passes_bake(s, name):
            fails.append(f"{name}: negative control: the bake with {what} still passes "
                         f"({fmt(s)})")
    if not missing("bake_x2", "2x-scale bake"):
        s = r["bake_x2"]
        print(f"      control, scale x2:          {fmt(s)}")
        if passes_bake(s):
            fails.append(f"{name}: negative control: the bake with twice the scale still passes"
                         f" ({fmt(s)})")
    if "bake_object_space" in r:
        s = r["bake_object_space"]
        print(f"      control, without transform: {fmt(s)}")
        if "error" in s or passes_bake(s):
            fails.append(f"{name}: negative control: the bake without the object's transform "
                         f"still passes ({fmt(s)})")
    if not missing("mask", "mask"):
        m = r["mask"]
        limit = max(MASK_MISMATCH_SLACK, int(MASK_MISMATCH_FRACTION * m["covered"]))
        ok = m["mismatched"] <= limit
        print(f"  (c) mask vs Blender EMIT:       {m['mismatched']} texels differ "
              f"({m['ours_only']} only ours, {m['blender_only']} only Blender's) of "
              f"{m['covered']} -> {'ok' if ok else 'FAIL'} (<= {limit:.0f})")
        if not ok:
            fails.append(f"{name}: coverage differs on {m['mismatched']} texels")
    return fails


def main():
    parser = bc.oracle_parser(__doc__)
    parser.add_argument("--cases", help="comma-separated case names (default: every case)")
    parser.add_argument("--group", choices=tuple(CASE_GROUPS),
                        help="the cases of one group (see CASE_GROUPS)")
    parser.add_argument("--threads", type=int, help="pass --threads N to sgbake")
    parser.add_argument("--sabotage", choices=("green", "scale", "input", "strength",
                                               "normal-green"),
                        help="make sgbake answer wrongly on purpose (the test must fail)")
    args = parser.parse_args()
    if args.cases and args.group:
        parser.error("--cases and --group exclude each other")
    if not args.cases:
        args.cases = ",".join(CASE_GROUPS[args.group] if args.group else DEFAULT_CASES)

    blender = bc.blender_or_skip(args.blender)
    bc.require_executable(args.cli)
    for command in ("bake", "convert"):
        if not bc.cli_has_command(args.cli, command):
            print(f"FAIL: `{args.cli} --help` lists no `{command}` command")
            return 1

    with bc.work_dir(args.keep, "sgbake-bake-oracle-") as work:
        if not run_blender_script(blender, "bake_scene.py", [work, "--cases", args.cases]):
            return 1
        with open(os.path.join(work, "cases.json"), encoding="ascii") as f:
            entries = json.load(f)
        failures = []
        for entry in entries:
            run = sgbake_nmap_case if "normal_map" in entry else sgbake_case
            for cmd in run(args.cli, entry, args.sabotage, args.threads):
                failures.append(f"{entry['name']}: command failed: {cmd}")
        if not run_blender_script(blender, "bake_compare.py", [work]):
            return 1
        with open(os.path.join(work, "results.json"), encoding="ascii") as f:
            results = json.load(f)
        for entry in entries:
            layer = (f"{entry['normal_map']['space']} normal map, Strength "
                     f"{entry['normal_map']['strength']:g}" if "normal_map" in entry
                     else f"scale {entry['scale']}")
            print(f"blender: {entry['name']}: {entry['faces']} faces, {layer}, "
                  f"bakes {', '.join(f'{k} {v:.2f} s' for k, v in entry['bake_s'].items())}")
        for entry in entries:
            if "normal_map" in entry:
                nmap = dict(entry["normal_map"])
                if "planar" in entry:
                    nmap["projection"] = entry["planar"]["projection"]
                    nmap["box"] = entry["planar"]["blend"]
                failures += evaluate_nmap(entry["name"], results[entry["name"]], nmap,
                                          transformed(entry))
            else:
                failures += evaluate(entry["name"], results[entry["name"]],
                                     "planar" in entry or "remap" in entry or "noise" in entry)
        if args.keep:
            print(f"files kept in {work}")
    return bc.report(failures)


if __name__ == "__main__":
    sys.exit(main())
