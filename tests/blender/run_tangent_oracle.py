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

import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.dont_write_bytecode = True  # keep __pycache__ out of the source tree
sys.path.insert(0, HERE)
import bake_common as bc  # noqa: E402  (needs the sys.path entry above)
import compare_tangents  # noqa: E402
import objio  # noqa: E402


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
    parser = bc.oracle_parser(
        __doc__, blender_help="Blender executable (default: `blender` on PATH)",
        keep_help="write the cases here and keep them")
    args, rest = parser.parse_known_args()
    blender = bc.blender_or_skip(args.blender)
    bc.require_executable(args.cli)

    with bc.work_dir(args.keep, "sgbake-oracle-") as work:
        if not make_cases(blender, work):
            return 1
        # With --keep, sgbake's CSVs are kept beside the cases (else compare_tangents writes
        # them in a temporary directory of its own).
        out_dir = ["--out-dir", work] if args.keep else []
        return compare_tangents.main(["--cli", args.cli, "--cases", work] + out_dir + rest)


if __name__ == "__main__":
    sys.exit(main())
