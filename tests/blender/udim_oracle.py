#!/usr/bin/env python3
"""The BlenderUdimOracle test: a bake from a UDIM height image against Cycles' bake of it.

    python3 tests/blender/udim_oracle.py --cli build/src/sgbake [--blender blender]
        [--keep DIR] [--sabotage swap]

1. Inside Blender (this file, re-run by objio.run_blender): a smooth UV sphere whose faces
   right of u = 0.5 are moved one tile right, so its UVs lie in tiles 1001 and 1002; a tiled
   height image of two different height fields (height.1001.exr, height.1002.exr: 32-bit
   float, Non-Color, h in R = G = B) feeds the Bump node of bake_scene.make_material
   (Distance = SCALE, bilinear, Repeat); Cycles bakes NORMAL in tangent space into a tiled
   32-bit float target with the same two tiles (1 sample, margin 0), saved as
   blender.1001.exr and blender.1002.exr. mesh.obj is the sphere (objio, exact floats).
2. sgbake bakes the scene {"layers": [{"type": "height", "image": "height.<UDIM>.exr",
   "scale": SCALE, "filter": "bilinear"}], "outputs": tangent-normal and mask, "<UDIM>"}.
3. Back in Blender (as the EXR reader), per tile, the angles between our normals and Cycles'
   over the texels both cover, minus a one-texel border.

Pass: in each tile, median <= 1 deg (Cycles' Bump is a finite difference over about half a
texel, as in BlenderBakeOracle), and the bake with "gradient": "bump-node" (the heights' slopes
as that finite difference takes them) median <= 0.01 deg, p99 <= 0.05 deg; negative control: the bake with the two tile files swapped
must differ by a median of more than 5 deg in each tile. --sabotage swap runs sgbake on the
swapped tiles, to see the test fail.

Exit status: 0 pass, 1 fail, 2 usage error, 77 Blender is not installed. Takes ~5 s.
"""

import json
import os
import shutil
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.dont_write_bytecode = True  # keep __pycache__ out of the source tree
sys.path.insert(0, HERE)
import bake_common as bc  # noqa: E402  (needs the sys.path entry above)
import objio  # noqa: E402

SCALE = 0.1
SIZE = 256          # bake size of each tile
HEIGHT_SIZE = 256   # size of each height tile
TILES = (1001, 1002)
MEDIAN_LIMIT_DEG = 1.0
# The same bake with the heights' slopes as Cycles' Bump node takes them ("gradient":
# "bump-node"): Cycles' bake to float rounding, as in BlenderBakeOracle (e).
BUMP_NODE_MEDIAN_DEG = 0.01
BUMP_NODE_P99_DEG = 0.05
CONTROL_MIN_DEG = 5.0
RESULT_TAG = "UDIM_ORACLE_RESULT "


# ---- Inside Blender ------------------------------------------------------------------------

def build(out_dir):
    """Step 1 of the docstring."""
    import bpy
    import numpy as np
    import bake_scene
    bc.reset_scene()
    bc.setup_cycles(bpy.context.scene)
    bpy.ops.mesh.primitive_uv_sphere_add(segments=32, ring_count=16, radius=1.0, calc_uvs=True)
    ob = bpy.context.object
    bc.set_smooth(ob, True)
    me = ob.data
    uv = me.uv_layers.active.data
    for poly in me.polygons:
        centre = sum(uv[li].uv.x for li in poly.loop_indices) / poly.loop_total
        if centre > 0.5:
            for li in poly.loop_indices:
                uv[li].uv.x += 1.0
    me.calc_normals_split()
    objio.write_obj(os.path.join(out_dir, "mesh.obj"), objio.mesh_arrays(me),
                    comment=f"UDIM oracle sphere (Blender {bpy.app.version_string})")

    first = bake_scene.height_field(HEIGHT_SIZE)
    second = np.roll(first[::-1], HEIGHT_SIZE // 3, axis=1) * 0.8 + 0.1  # another field
    for tile, field in zip(TILES, (first, second)):
        img = bc.new_float_image(f"height {tile}", HEIGHT_SIZE, HEIGHT_SIZE, field)
        bc.save_exr(img, os.path.join(out_dir, f"height.{tile}.exr"))
        bpy.data.images.remove(img)
        blank = bc.new_float_image(f"target {tile}", SIZE, SIZE)
        bc.save_exr(blank, os.path.join(out_dir, f"target.{tile}.exr"), verify=False)
        bpy.data.images.remove(blank)
    height = bc.load_tiled(os.path.join(out_dir, "height.<UDIM>.exr"), TILES)
    target = bc.load_tiled(os.path.join(out_dir, "target.<UDIM>.exr"), TILES)
    mat, node = bake_scene.make_material(height, SCALE)
    me.materials.clear()
    me.materials.append(mat)
    bake_scene.bake_pass(ob, mat, node, target, "tangent", 0)
    target.filepath_raw = os.path.join(out_dir, "blender.<UDIM>.exr")
    target.file_format = "OPEN_EXR"
    target.use_half_precision = False
    target.save()
    for tile in TILES:
        if not os.path.isfile(os.path.join(out_dir, f"blender.{tile}.exr")):
            raise RuntimeError(f"Blender did not save tile {tile} of its bake")


def compare(out_dir, prefix):
    """Step 3: per tile, angle statistics of PREFIX.TILE.exr against blender.TILE.exr."""
    import numpy as np
    result = {}
    for tile in TILES:
        ours = bc.load_raw(os.path.join(out_dir, f"{prefix}.{tile}.exr"))
        ref = bc.load_raw(os.path.join(out_dir, f"blender.{tile}.exr"))
        mask = bc.load_raw(os.path.join(out_dir, f"mask.{tile}.exr"))[..., 0] > 0.999
        covered = np.abs(ref[..., :3]).sum(axis=-1) > 0  # Cycles leaves other texels at 0
        region = bc.erode(mask & covered, 1)
        angles = bc.angle_deg(bc.decode_normals(ours), bc.decode_normals(ref))[region]
        result[str(tile)] = bc.angle_stats(angles)
    return result


def blender_main(argv):
    command, out_dir = argv[0], argv[1]
    if command == "build":
        build(out_dir)
        print(RESULT_TAG + "{}", flush=True)
    else:
        print(RESULT_TAG + json.dumps({p: compare(out_dir, p) for p in argv[2:]}), flush=True)


# ---- The driver ----------------------------------------------------------------------------

def run_blender(blender, args):
    """Runs this file in Blender; returns the JSON after RESULT_TAG, or None (output shown)."""
    return objio.run_blender_result(blender, os.path.abspath(__file__), args, RESULT_TAG)


def bake(cli, out_dir, heights, prefix, gradient="analytic"):
    """Bakes PREFIX.<UDIM>.exr and mask.<UDIM>.exr from the tiles HEIGHTS.<UDIM>.exr, the
    heights' slopes taken by `gradient`."""
    scene = {
        "mesh": "mesh.obj",
        "layers": [{"type": "height", "image": heights + ".<UDIM>.exr", "scale": SCALE,
                    "filter": "bilinear", "gradient": gradient}],
        "outputs": [
            {"map": "tangent-normal", "file": prefix + ".<UDIM>.exr", "size": SIZE,
             "margin": 0, "bit_depth": 32},
            {"map": "mask", "file": "mask.<UDIM>.exr", "size": SIZE, "margin": 0,
             "bit_depth": 32}]}
    return bc.bake_scene_file(cli, out_dir, prefix, scene)


def main():
    parser = bc.oracle_parser(__doc__, blender_help=None)
    parser.add_argument("--sabotage", choices=["swap"], help="bake from swapped tiles")
    args = parser.parse_args()
    blender = bc.blender_or_skip(args.blender)
    bc.require_executable(args.cli, "error: --cli {} is not an executable file")

    with bc.work_dir(args.keep, "sgbake_udim_oracle_") as out_dir:
        if run_blender(blender, ["build", out_dir]) is None:
            return 1
        # The negative control's tiles: each file holds the other tile's heights.
        for tile, other in zip(TILES, reversed(TILES)):
            shutil.copyfile(os.path.join(out_dir, f"height.{other}.exr"),
                            os.path.join(out_dir, f"swapped.{tile}.exr"))
        heights = "swapped" if args.sabotage else "height"
        if not (bake(args.cli, out_dir, heights, "ours")
                and bake(args.cli, out_dir, heights, "ours_bump_node", "bump-node")
                and bake(args.cli, out_dir, "height" if args.sabotage else "swapped",
                         "control")):
            return 1
        stats = run_blender(blender, ["compare", out_dir, "ours", "ours_bump_node", "control"])
        if stats is None:
            return 1
        passed = [bc.judge_against_control(
            f"tile {tile}", stats["ours"][str(tile)], stats["control"][str(tile)],
            MEDIAN_LIMIT_DEG, CONTROL_MIN_DEG, "swapped tiles") for tile in TILES]
        passed += [bc.judge_against_control(
            f"tile {tile}, bump-node slopes", stats["ours_bump_node"][str(tile)],
            stats["control"][str(tile)], BUMP_NODE_MEDIAN_DEG, CONTROL_MIN_DEG, "swapped tiles",
            p99_limit=BUMP_NODE_P99_DEG) for tile in TILES]
        failed = not all(passed)
        print("FAILED" if failed else "PASSED")
        return 1 if failed else 0


if __name__ == "__main__":
    objio.run_script(blender_main, main)
