#!/usr/bin/env python3
"""The BlenderTangentOracle test: Blender makes the cases, sgbake must reproduce its tangents.

    python3 tests/blender/run_tangent_oracle.py --cli build/src/sgbake
        [--blender blender] [--keep DIR] [compare_tangents.py options...]

1. Runs make_tangent_cases.py inside Blender (headless, factory settings) to write the case
   meshes and Blender's reference tangents into a temporary directory (or --keep DIR, which is
   left in place for inspection).
2. Runs compare_tangents.py on them with the given sgbake CLI; any other option
   (--tolerance-deg, --threads, --only) is passed on to it.

Exit status: 0 pass, 1 fail, 2 usage error, 77 Blender is not installed (CTest counts that
as skipped via SKIP_RETURN_CODE 77). Takes ~10 s: Blender starts once for all cases.
"""

import argparse
import os
import shutil
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.dont_write_bytecode = True  # keep __pycache__ out of the source tree
sys.path.insert(0, HERE)
import compare_tangents  # noqa: E402  (needs the sys.path entry above)
import objio  # noqa: E402

SKIP = 77


def make_cases(blender, out_dir):
    """Runs the case generator in Blender; returns True on success (prints Blender's output
    on failure)."""
    proc = objio.run_blender(blender, os.path.join(HERE, "make_tangent_cases.py"), [out_dir],
                             capture_output=True, text=True)
    if proc.returncode != 0:
        print(f"error: `{' '.join(proc.args)}` exited with {proc.returncode}\n"
              f"{proc.stdout[-4000:]}\n{proc.stderr[-4000:]}")
        return False
    for line in proc.stdout.splitlines():
        if line.startswith("case "):
            print("blender " + line)
    return True


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cli", required=True, help="path to the sgbake executable")
    parser.add_argument("--blender", default="blender",
                        help="Blender executable (default: `blender` on PATH)")
    parser.add_argument("--keep", metavar="DIR", help="write the cases here and keep them")
    args, rest = parser.parse_known_args()

    blender = shutil.which(args.blender)
    if blender is None:
        print(f"SKIP: {args.blender} is not on PATH; the Blender oracle test needs Blender")
        return SKIP

    if not (os.path.isfile(args.cli) and os.access(args.cli, os.X_OK)):
        print(f"error: {args.cli} is not an executable file (build sgbake_cli first)")
        return 2

    if args.keep:
        os.makedirs(args.keep, exist_ok=True)
        if not make_cases(blender, args.keep):
            return 1
        return compare_tangents.main(["--cli", args.cli, "--cases", args.keep,
                                      "--out-dir", args.keep] + rest)
    with tempfile.TemporaryDirectory(prefix="sgbake-oracle-") as tmp:
        if not make_cases(blender, tmp):
            return 1
        return compare_tangents.main(["--cli", args.cli, "--cases", tmp] + rest)


if __name__ == "__main__":
    sys.exit(main())
