#!/usr/bin/env python3
"""The BlenderImageOrientation test: Blender reads sgbake's PNGs the right way up.

    python3 tests/blender/bake_orientation.py --cli build/src/sgbake [--blender blender]
        [--keep DIR] [--size 64] [--sabotage flip]

The scene is one quad in the plane z = 0 whose UVs cover only the rectangle
u in [0.1, 0.7], v in [0.2, 0.9] (asymmetric in u, in v and under transposition) and whose
corner normals are custom split normals proportional to (A (u - 0.4), B (v - 0.55), 1),
A = 0.9, B = -0.45: all four have the same length, so the interpolated (then normalised) normal
is exactly n(u, v) = normalize(A (u - 0.4), B (v - 0.55), 1) everywhere on the quad. R grows
to the right, G DEcreases upwards, at different rates.

1. Blender half `make` (this file inside Blender): builds the quad, writes it as plane.obj
   (objio, exact floats) and bakes it itself with Cycles (NORMAL, OBJECT space, +X +Y +Z,
   1 sample, margin 0) into blender_object.exr (raw float).
2. sgbake: `bake --mesh plane.obj --map object-normal --size N --margin 0 -o ours.png` and
   `bake --mesh plane.obj --map mask --size N --margin 0 -o ours_mask.png`.
3. Blender half `read` (inside Blender): loads ours.png, ours_mask.png (Non-Color) and
   blender_object.exr with bpy.data.images.load and dumps image.pixels (Blender's bottom-up
   rows, as is) to JSON.
4. Checks (plain python3, which decodes the PNGs itself with bake_common.read_png, zlib only):
   - file texel (x, r) == Blender's pixel (x, H - 1 - r), every channel, |diff| <= 1e-6
     (Blender's byte images read back as value / 255);
   - the mask is 1 exactly at the texels whose centre u = (x + 0.5) / N, v = 1 - (r + 0.5) / N
     lies in the UV rectangle and 0 elsewhere;
   - at those texels our RGB equals n(u, v) / 2 + 0.5 within half a quantisation step
     (+ 1e-4 for Blender's custom-normal encoding), and equals Blender's own bake within the
     same bound.
--sabotage flip hands the checks our image upside down, to see the test fail.

Exit status: 0 pass, 1 fail, 2 usage error, 77 Blender is not installed. Takes ~6 s.
"""

import json
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.dont_write_bytecode = True  # keep __pycache__ out of the source tree
sys.path.insert(0, HERE)
import bake_common as bc  # noqa: E402  (needs the sys.path entry above)
import objio  # noqa: E402

U0, U1, V0, V1 = 0.1, 0.7, 0.2, 0.9  # the quad's UV rectangle
UC, VC = (U0 + U1) / 2, (V0 + V1) / 2
A, B = 0.9, -0.45
NORMAL_ENCODING_TOL = 1e-4  # Blender stores custom normals compressed (measured: 2e-5)


def expected_normal(u, v):
    x, y, z = A * (u - UC), B * (v - VC), 1.0
    length = math.sqrt(x * x + y * y + z * z)
    return (x / length, y / length, z / length)


def inside(u, v):
    return U0 <= u <= U1 and V0 <= v <= V1


# ---------------------------------------------------------------------------------------------
# Blender halves


def blender_make(out_dir, size):
    import bpy
    bc.reset_scene()
    bc.setup_cycles(bpy.context.scene, samples=1)
    # Positions: u -> x in [-1.2, 1.2], v -> y in [-1.4, 1.4] (the UV rectangle scaled by 4).
    uvs = [(U0, V0), (U1, V0), (U1, V1), (U0, V1)]
    verts = [((u - UC) * 4.0, (v - VC) * 4.0, 0.0) for u, v in uvs]
    me = bpy.data.meshes.new("plane")
    me.from_pydata(verts, [], [(0, 1, 2, 3)])
    uv_layer = me.uv_layers.new(name="UVMap")
    for loop in me.loops:
        uv_layer.data[loop.index].uv = uvs[loop.vertex_index]
    me.polygons.foreach_set("use_smooth", [True])
    me.use_auto_smooth = True
    me.normals_split_custom_set([expected_normal(*uvs[loop.vertex_index]) for loop in me.loops])
    me.update()
    ob = bpy.data.objects.new("plane", me)
    bpy.context.scene.collection.objects.link(ob)
    me.calc_normals_split()
    objio.write_obj(os.path.join(out_dir, "plane.obj"), objio.mesh_arrays(me),
                    comment="orientation test quad (tests/blender/bake_orientation.py)")

    mat = bpy.data.materials.new("plain")
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    target = nodes.new("ShaderNodeTexImage")
    image = bc.new_float_image("blender_object", size, size)
    target.image = image
    nodes.active = target
    me.materials.append(mat)
    bpy.ops.object.select_all(action="DESELECT")
    ob.select_set(True)
    bpy.context.view_layer.objects.active = ob
    result = bpy.ops.object.bake(type="NORMAL", normal_space="OBJECT", normal_r="POS_X",
                                 normal_g="POS_Y", normal_b="POS_Z", margin=0, use_clear=False,
                                 target="IMAGE_TEXTURES", save_mode="INTERNAL")
    if result != {"FINISHED"}:
        raise RuntimeError(f"bake returned {result}")
    bc.save_exr(image, os.path.join(out_dir, "blender_object.exr"))


def blender_read(out_dir, names):
    """Dumps image.pixels of each file exactly as Blender holds them (bottom row first)."""
    import bpy
    dump = {}
    for name in names:
        img = bpy.data.images.load(os.path.join(out_dir, name), check_existing=False)
        img.colorspace_settings.name = "Non-Color"
        w, h = img.size
        dump[name] = {"width": w, "height": h, "channels": img.channels,
                      "is_float": img.is_float, "pixels": list(img.pixels)}
    with open(os.path.join(out_dir, "blender_pixels.json"), "w", encoding="ascii") as f:
        json.dump(dump, f)


def blender_main(argv):
    mode, out_dir = argv[0], argv[1]
    if mode == "make":
        blender_make(out_dir, int(argv[2]))
    elif mode == "read":
        blender_read(out_dir, argv[2:])
    else:
        raise SystemExit(f"unknown mode {mode}")


# ---------------------------------------------------------------------------------------------
# Driver


def blender_pixel(dump, x, row):
    """Blender's pixel for FILE row `row`: image.pixels is bottom row first."""
    w, h = dump["width"], dump["height"]
    y = h - 1 - row
    start = (y * w + x) * 4
    return dump["pixels"][start:start + 4]


def check(work, size, sabotage):
    problems = []
    with open(os.path.join(work, "blender_pixels.json"), encoding="ascii") as f:
        dumps = json.load(f)
    images = {}
    for name in ("ours.png", "ours_mask.png"):
        w, h, channels, depth, rows = bc.read_png(os.path.join(work, name))
        if (w, h) != (size, size):
            problems.append(f"{name} is {w}x{h}, expected {size}x{size}")
            return problems
        if sabotage == "flip":
            rows = rows[::-1]
        images[name] = (channels, depth, rows)
        print(f"{name}: {w}x{h}, {channels} channels, {depth}-bit")

    # 1. Blender's reading of our file: texel (x, r) of the file is Blender's (x, H-1-r).
    for name, (channels, depth, rows) in images.items():
        dump = dumps[name]
        worst = 0.0
        for r in range(size):
            for x in range(size):
                ours = rows[r][x]
                theirs = blender_pixel(dump, x, r)
                # Grey PNGs come back as RGB = grey; compare the channels the file has.
                ref = theirs[:3] if channels >= 3 else theirs[:1]
                worst = max(worst, max(abs(a - b) for a, b in zip(ours[:len(ref)], ref)))
        print(f"{name}: max |file texel (x, r) - Blender pixel (x, H-1-r)| = {worst:.3g}")
        if worst > 1e-6:
            problems.append(f"{name}: Blender reads the file differently (max diff {worst:.3g})"
                            " - rows flipped or channels swapped?")

    # 2. Coverage: the mask is exactly the UV rectangle.
    _, _, mask_rows = images["ours_mask.png"]
    wrong_cover = []
    for r in range(size):
        for x in range(size):
            u, v = (x + 0.5) / size, 1.0 - (r + 0.5) / size
            want = 1.0 if inside(u, v) else 0.0
            if abs(mask_rows[r][x][0] - want) > 1e-6:
                wrong_cover.append((x, r, mask_rows[r][x][0], want))
    print(f"ours_mask.png: {len(wrong_cover)} texels differ from the UV rectangle "
          f"u [{U0}, {U1}] x v [{V0}, {V1}]")
    if wrong_cover:
        problems.append(f"mask: {len(wrong_cover)} texels wrong, e.g. (x, r, ours, expected) "
                        f"{wrong_cover[:4]}")

    # 3. Values at the covered texels: the analytic normal and Blender's own bake.
    channels, depth, rows = images["ours.png"]
    tolerance = 0.5 / (2 ** depth - 1) + NORMAL_ENCODING_TOL + 1e-6
    blender_bake = dumps["blender_object.exr"]
    worst_analytic, worst_blender, worst_at, count = 0.0, 0.0, None, 0
    for r in range(size):
        for x in range(size):
            u, v = (x + 0.5) / size, 1.0 - (r + 0.5) / size
            if not inside(u, v):
                continue
            count += 1
            want = [c / 2 + 0.5 for c in expected_normal(u, v)]
            ours = rows[r][x][:3]
            theirs = blender_pixel(blender_bake, x, r)[:3]
            d_analytic = max(abs(a - b) for a, b in zip(ours, want))
            d_blender = max(abs(a - b) for a, b in zip(ours, theirs))
            if d_analytic > worst_analytic:
                worst_analytic, worst_at = d_analytic, (x, r, ours, want)
            worst_blender = max(worst_blender, d_blender)
    print(f"ours.png: {count} covered texels; max |ours - n(u,v)/2+0.5| = {worst_analytic:.5f}, "
          f"max |ours - Blender's bake| = {worst_blender:.5f} (tolerance {tolerance:.5f})")
    if worst_analytic > tolerance:
        problems.append(f"object normals differ from n(u, v) by {worst_analytic:.4f}; worst "
                        f"(x, r, ours, expected) = {worst_at}")
    if worst_blender > tolerance:
        problems.append(f"object normals differ from Blender's own bake by {worst_blender:.4f}")
    return problems


def main():
    parser = bc.oracle_parser(__doc__)
    parser.add_argument("--size", type=int, default=64)
    parser.add_argument("--sabotage", choices=("flip",), help="check our image upside down")
    args = parser.parse_args()

    blender = bc.blender_or_skip(args.blender)
    bc.require_executable(args.cli)
    if not bc.cli_has_command(args.cli, "bake"):
        print(f"FAIL: `{args.cli} --help` lists no `bake` command")
        return 1

    def run_half(*half_args):
        return objio.run_blender_half(blender, os.path.abspath(__file__), list(half_args),
                                      timeout=120)

    with bc.work_dir(args.keep, "sgbake-orientation-") as work:
        if not run_half("make", work, str(args.size)):
            return 1
        mesh = os.path.join(work, "plane.obj")
        for kind, name in (("object-normal", "ours.png"), ("mask", "ours_mask.png")):
            proc = bc.run_tool([args.cli, "bake", "--mesh", mesh, "--map", kind, "--size",
                                args.size, "--margin", 0, "--samples", 1, "--no-manifest", "-o",
                                os.path.join(work, name)], timeout=60)
            if proc is None or proc.returncode != 0:
                return 1
        if not run_half("read", work, "ours.png", "ours_mask.png", "blender_object.exr"):
            return 1
        problems = check(work, args.size, args.sabotage)
        if args.keep:
            print(f"files kept in {work}")
    if problems:
        print("FAIL:\n  " + "\n  ".join(problems))
        return 1
    print("PASS")
    return 0


if __name__ == "__main__":
    objio.run_script(blender_main, main)
