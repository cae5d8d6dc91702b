#!/usr/bin/env python3
"""The BlenderSwizzleOracle test: normal maps baked with a Swizzle against Cycles' bake with it.

    python3 tests/blender/swizzle_oracle.py --cli build/src/sgbake [--blender blender]
        [--keep DIR] [--sabotage]

1. Blender (bake_scene.py, case nmap_suzanne: Suzanne with a 40 deg tangent-space normal map,
   256^2) bakes NORMAL in tangent and in object space with the bake's Swizzle set to
   SWIZZLE_BLENDER (every channel moved, two negated), plus the coverage mask.
2. sgbake bakes the same scene's tangent-normal and object-normal maps with
   "swizzle": SWIZZLE ("ours"), and without it ("control").
3. Back in Blender (as the EXR reader), the angles between our maps and Cycles', both read as
   if they were +X+Y+Z (a swizzle that differs turns the vectors; the same one keeps their
   angles), over the covered texels minus a one-texel border.

Pass: in each space, median <= 0.05 deg and p99 <= 0.5 deg (the normal-map bars of
BlenderBakeOracle: the same bake without a swizzle agrees to ~0.002 deg); negative control:
the unswizzled maps must differ by a median of more than 30 deg. --sabotage bakes "ours" with
the swizzle's G negated, to see the test fail.

Exit status: 0 pass, 1 fail, 2 usage error, 77 Blender is not installed. Takes ~10 s.
"""

import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.dont_write_bytecode = True  # keep __pycache__ out of the source tree
sys.path.insert(0, HERE)
import bake_common as bc  # noqa: E402  (needs the sys.path entry above)
import objio  # noqa: E402

CASE = "nmap_suzanne"
SWIZZLE_BLENDER = "NEG_Z,POS_X,NEG_Y"
SWIZZLE = "-Z+X-Y"  # the same, as sgbake writes it
SABOTAGED = "-Z-X-Y"
MEDIAN_LIMIT_DEG = 0.05
P99_LIMIT_DEG = 0.5
CONTROL_MIN_DEG = 30.0
SPACES = ("tangent", "object")
RESULT_TAG = "SWIZZLE_ORACLE_RESULT "


# ---- Inside Blender: the comparison ---------------------------------------------------------

def compare(case_dir, prefix):
    """Angle statistics of PREFIX_SPACE.exr against blender_SPACE.exr, per space (step 3)."""
    mask = bc.load_raw(os.path.join(case_dir, "blender_mask.exr"))[..., 0] > 0.5
    region = bc.erode(mask, 1)
    result = {}
    for space in SPACES:
        ours = bc.load_raw(os.path.join(case_dir, f"{prefix}_{space}.exr"))
        ref = bc.load_raw(os.path.join(case_dir, f"blender_{space}.exr"))
        angles = bc.angle_deg(bc.decode_normals(ours), bc.decode_normals(ref))[region]
        result[space] = bc.angle_stats(angles)
    return result


def blender_main(argv):
    case_dir = argv[0]
    print(RESULT_TAG + json.dumps({p: compare(case_dir, p) for p in argv[1:]}), flush=True)


# ---- The driver ------------------------------------------------------------------------------

def bake(cli, case_dir, prefix, swizzle):
    """sgbake's PREFIX_tangent.exr and PREFIX_object.exr of the case, channels `swizzle`."""
    entry_path = os.path.join(case_dir, "..", "cases.json")
    with open(entry_path, encoding="ascii") as f:
        entry = next(e for e in json.load(f) if e["name"] == CASE)
    nmap = entry["normal_map"]
    outputs = []
    for space in SPACES:
        out = {"map": f"{space}-normal", "file": f"{prefix}_{space}.exr", "size": entry["size"],
               "margin": 0, "bit_depth": 32}
        if swizzle:
            out["swizzle"] = swizzle
        outputs.append(out)
    scene = {"mesh": "mesh.obj",
             "layers": [{"type": "normal", "image": "normal.exr", "space": nmap["space"],
                         "strength": nmap["strength"], "filter": "bilinear"}],
             "outputs": outputs}
    return bc.bake_scene_file(cli, case_dir, prefix, scene)


def main():
    parser = bc.oracle_parser(__doc__, blender_help=None)
    parser.add_argument("--sabotage", action="store_true",
                        help=f"bake ours with {SABOTAGED} instead of {SWIZZLE}")
    args = parser.parse_args()
    blender = bc.blender_or_skip(args.blender)
    bc.require_executable(args.cli, "error: --cli {} is not an executable file")

    with bc.work_dir(args.keep, "sgbake_swizzle_oracle_") as out_dir:
        if not objio.run_blender_half(
                blender, os.path.join(HERE, "bake_scene.py"),
                [out_dir, "--cases", CASE, "--swizzle", SWIZZLE_BLENDER], timeout=300):
            return 1
        case_dir = os.path.join(out_dir, CASE)
        if not (bake(args.cli, case_dir, "ours", SABOTAGED if args.sabotage else SWIZZLE)
                and bake(args.cli, case_dir, "control", None)):
            return 1
        stats = objio.run_blender_result(blender, os.path.abspath(__file__),
                                         [case_dir, "ours", "control"], RESULT_TAG)
        if stats is None:
            return 1
        passed = [bc.judge_against_control(
            f"{space} space, swizzle {SWIZZLE_BLENDER}", stats["ours"][space],
            stats["control"][space], MEDIAN_LIMIT_DEG, CONTROL_MIN_DEG, "without the swizzle",
            p99_limit=P99_LIMIT_DEG) for space in SPACES]
        failed = not all(passed)
        print("FAILED" if failed else "PASSED")
        return 1 if failed else 0


if __name__ == "__main__":
    objio.run_script(blender_main, main)
