#!/usr/bin/env python3
"""The BlenderMarginOracle test: `--padding adjacent-faces` against Blender's Adjacent Faces margin.

    python3 tests/blender/margin_oracle.py --cli build/src/sgbake [--blender blender]
        [--keep DIR] [--sabotage extend]

1. Inside Blender (this file, re-run by objio.run_blender): bake_scene builds the flat cube
   (cross-shaped UV layout: every island edge is a seam) and Suzanne (seams, mesh boundaries
   round the eyes), with Bump Distance 0, and Cycles bakes NORMAL in object space, 256^2,
   margin MARGIN of type ADJACENT_FACES, Blender's default (blender_object.exr).
2. sgbake bakes `--map object-normal --margin MARGIN` with `--padding adjacent-faces` (ours)
   and `--padding extend` (the control), and `--map mask --margin 0` (which texels the
   islands cover).
3. Back in Blender (as the EXR reader), over the margin texels (uncovered, written by Blender
   and by both of ours): the largest |difference| of the three channels per texel, as median,
   90th percentile and the fraction within 0.01; and which texels each side wrote.

Pass, per case: ours median <= 0.005 and at least 60 % of the texels within 0.01; the texels
written by only one side at most 15 % of Blender's margin; the control's median at least 10x
ours and above 0.02 (an Extend margin must be told apart). Where Blender's choice is arbitrary
(beyond an island's corner where three faces meet; see adjacentFacesMargin in bake.hpp) the
values differ, hence percentiles rather than every texel. --sabotage extend bakes ours with
`--padding extend`, to see the test fail.

Exit status: 0 pass, 1 fail, 2 usage error, 77 Blender is not installed. Takes ~5 s.
"""

import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.dont_write_bytecode = True  # keep __pycache__ out of the source tree
sys.path.insert(0, HERE)
import bake_common as bc  # noqa: E402  (needs the sys.path entry above)
import objio  # noqa: E402

CASES = ("cube_flat", "suzanne")
SIZE = 256
MARGIN = 8
MEDIAN_LIMIT = 0.005
CLOSE = 0.01
CLOSE_FRACTION = 0.6
ONE_SIDED_LIMIT = 0.15
CONTROL_FACTOR = 10.0
CONTROL_MIN = 0.02
RESULT_TAG = "MARGIN_ORACLE_RESULT "


# ---- Inside Blender ------------------------------------------------------------------------

def build(out_dir):
    """Step 1 of the docstring."""
    import bpy
    import bake_scene
    bc.setup_cycles(bpy.context.scene)
    for name in CASES:
        bake_scene.build_case(name, os.path.join(out_dir, name), size=SIZE, passes=("object",),
                              margin=MARGIN, margin_type="ADJACENT_FACES", scale=0.0,
                              height_size=16)


def compare(out_dir):
    """Step 3: per case, statistics of ours and the control over the margin texels."""
    import numpy as np
    result = {}
    for name in CASES:
        case = os.path.join(out_dir, name)
        ref = bc.load_raw(os.path.join(case, "blender_object.exr"))[..., :3]
        covered = bc.load_raw(os.path.join(case, "mask.exr"))[..., 0] > 0.5
        blender = (np.abs(ref).sum(axis=-1) > 0) & ~covered  # Cycles leaves the rest at 0
        entry = {}
        for prefix in ("ours", "control"):
            image = bc.load_raw(os.path.join(case, prefix + ".exr"))[..., :3]
            written = (np.abs(image).sum(axis=-1) > 0) & ~covered
            entry[prefix + "_written"] = written
            entry[prefix] = image
        both = blender & entry["ours_written"] & entry["control_written"]
        stats = {"margin_texels": int(blender.sum()), "compared": int(both.sum()),
                 "one_sided": int((blender ^ entry["ours_written"]).sum())}
        for prefix in ("ours", "control"):
            diff = np.abs(entry[prefix] - ref).max(axis=-1)[both]
            stats[prefix] = {"median": float(np.median(diff)),
                             "p90": float(np.percentile(diff, 90)),
                             "close": float(np.mean(diff <= CLOSE))}
        result[name] = stats
    return result


def blender_main(argv):
    command, out_dir = argv[0], argv[1]
    if command == "build":
        build(out_dir)
        print(RESULT_TAG + "{}", flush=True)
    else:
        print(RESULT_TAG + json.dumps(compare(out_dir)), flush=True)


# ---- The driver ----------------------------------------------------------------------------

def run_blender(blender, args):
    """Runs this file in Blender; returns the JSON after RESULT_TAG, or None (output shown)."""
    return objio.run_blender_result(blender, os.path.abspath(__file__), args, RESULT_TAG)


def bake(cli, case, padding, out, kind="object-normal", margin=MARGIN):
    """`sgbake bake` of CASE/mesh.obj into CASE/OUT; whether it succeeded."""
    proc = bc.run_tool([cli, "bake", "--mesh", os.path.join(case, "mesh.obj"), "--map", kind,
                        "--size", str(SIZE), "--margin", str(margin), "--padding", padding,
                        "--bit-depth", "32", "--no-manifest", "-o", os.path.join(case, out)])
    return proc is not None and proc.returncode == 0


def main():
    parser = bc.oracle_parser(__doc__, blender_help=None)
    parser.add_argument("--sabotage", choices=["extend"], help="bake ours with Extend")
    args = parser.parse_args()
    blender = bc.blender_or_skip(args.blender)
    bc.require_executable(args.cli, "error: --cli {} is not an executable file")

    with bc.work_dir(args.keep, "sgbake_margin_oracle_") as out_dir:
        if run_blender(blender, ["build", out_dir]) is None:
            return 1
        ours = "extend" if args.sabotage else "adjacent-faces"
        for name in CASES:
            case = os.path.join(out_dir, name)
            if not (bake(args.cli, case, ours, "ours.exr")
                    and bake(args.cli, case, "extend", "control.exr")
                    and bake(args.cli, case, "extend", "mask.exr", kind="mask", margin=0)):
                return 1
        stats = run_blender(blender, ["compare", out_dir])
        if stats is None:
            return 1
        failed = False
        for name in CASES:
            s = stats[name]
            ours, control = s["ours"], s["control"]
            one_sided = s["one_sided"] / max(s["margin_texels"], 1)
            ok = (s["compared"] > 1000 and ours["median"] <= MEDIAN_LIMIT
                  and ours["close"] >= CLOSE_FRACTION and one_sided <= ONE_SIDED_LIMIT)
            told = (control["median"] >= CONTROL_FACTOR * ours["median"]
                    and control["median"] > CONTROL_MIN)
            failed |= not (ok and told)
            print(f"{name}: {'ok  ' if ok else 'FAIL'} adjacent faces vs Blender over "
                  f"{s['compared']} margin texels: median {ours['median']:.2e} (limit "
                  f"{MEDIAN_LIMIT}), p90 {ours['p90']:.2e}, {100 * ours['close']:.1f} % within "
                  f"{CLOSE} (at least {100 * CLOSE_FRACTION:.0f} %), written by one side only "
                  f"{100 * one_sided:.1f} % of Blender's {s['margin_texels']} (at most "
                  f"{100 * ONE_SIDED_LIMIT:.0f} %); {'ok  ' if told else 'FAIL'} Extend control "
                  f"median {control['median']:.3f} (must exceed {CONTROL_FACTOR:g}x ours and "
                  f"{CONTROL_MIN})")
        print("FAILED" if failed else "PASSED")
        return 1 if failed else 0


if __name__ == "__main__":
    objio.run_script(blender_main, main)
