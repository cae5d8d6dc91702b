#!/usr/bin/env python3
"""Compares the sgbake CLI's tangent frames with Blender's on every case of a case directory.

    python3 tests/blender/compare_tangents.py --cli build/src/sgbake --cases CASE_DIR
        [--tolerance-deg 0.05] [--threads N] [--out-dir DIR] [--only NAME ...]

CASE_DIR is what make_tangent_cases.py wrote (NAME.obj, NAME.tangents.csv, cases.json). For
each case this runs `sgbake tangents NAME.obj -o OUT_DIR/NAME.sgbake.csv` and checks, corner by
corner, in the CSV's order (face order, then each face's corner order):
  - the rows name the same (face, corner) as the reference;
  - the angle between the two tangents, atan2(|a x b|, a . b), is at most --tolerance-deg;
  - sgbake's tangent is unit (| |t| - 1 | <= 1e-4; Blender's are unit to ~1.5e-7);
  - the bitangent signs are identical.
It prints one line per case (corners, worst angle and where, sign mismatches) and, for a failing
case, the first few offending corners. Exit status: 0 all cases pass, 1 some case fails (or the
CLI failed on it), 2 the command line or the case directory is unusable.

Plain Python 3 only (no numpy), so it runs with whatever `python3` is first on PATH.
"""

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

sys.dont_write_bytecode = True  # keep __pycache__ out of the source tree
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import objio  # noqa: E402  (needs the sys.path entry above)

UNIT_TOLERANCE = 1e-4  # how far from unit length an sgbake tangent may be
MAX_REPORTED = 8       # offending corners listed per failing case


def angle_deg(a, b):
    """Angle between two 3-vectors in degrees, accurate for tiny angles (unlike acos)."""
    cx = a[1] * b[2] - a[2] * b[1]
    cy = a[2] * b[0] - a[0] * b[2]
    cz = a[0] * b[1] - a[1] * b[0]
    return math.degrees(math.atan2(math.sqrt(cx * cx + cy * cy + cz * cz),
                                   a[0] * b[0] + a[1] * b[1] + a[2] * b[2]))


def list_cases(case_dir):
    """Case names from cases.json, or from the *.obj files when there is no manifest."""
    manifest = os.path.join(case_dir, "cases.json")
    if os.path.exists(manifest):
        with open(manifest, encoding="ascii") as f:
            return [entry["name"] for entry in json.load(f)]
    return sorted(name[:-4] for name in os.listdir(case_dir) if name.endswith(".obj"))


def compare_rows(reference, ours, tolerance_deg):
    """Compares two tangent tables. Returns (worst angle, its (face, corner), sign mismatches,
    list of problem descriptions). A row-count or numbering mismatch is itself a problem."""
    problems = []
    if len(ours) != len(reference):
        problems.append(f"sgbake wrote {len(ours)} rows, Blender {len(reference)}")
    worst, worst_at, sign_mismatches = 0.0, None, 0
    for row, (ref, got) in enumerate(zip(reference, ours)):
        face, corner, ref_t, ref_s = ref
        got_face, got_corner, got_t, got_s = got
        where = f"row {row + 1} face {face} corner {corner}"
        if (got_face, got_corner) != (face, corner):
            problems.append(f"{where}: sgbake's row is face {got_face} corner {got_corner}")
            continue
        angle = angle_deg(ref_t, got_t)
        length = math.sqrt(sum(x * x for x in got_t))
        if angle > worst or worst_at is None:
            worst, worst_at = angle, (face, corner)
        detail = (f"blender t=({ref_t[0]:.6f}, {ref_t[1]:.6f}, {ref_t[2]:.6f}) s={ref_s:+.0f}, "
                  f"sgbake t=({got_t[0]:.6f}, {got_t[1]:.6f}, {got_t[2]:.6f}) s={got_s:+.0f}")
        if got_s != ref_s:
            sign_mismatches += 1
            problems.append(f"{where}: sign differs; {detail}")
        elif angle > tolerance_deg:
            problems.append(f"{where}: angle {angle:.4f} deg > {tolerance_deg} deg; {detail}")
        elif abs(length - 1.0) > UNIT_TOLERANCE:
            problems.append(f"{where}: sgbake tangent has length {length:.6f}; {detail}")
    return worst, worst_at, sign_mismatches, problems


def run_case(cli, case_dir, out_dir, name, tolerance_deg, threads):
    """Runs the CLI on one case and compares. Returns True when the case passes."""
    mesh = os.path.join(case_dir, name + ".obj")
    out = os.path.join(out_dir, name + ".sgbake.csv")
    cmd = [cli, "tangents", mesh, "-o", out]
    if threads is not None:
        cmd += ["--threads", str(threads)]
    start = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    seconds = time.perf_counter() - start
    if proc.returncode != 0:
        print(f"FAIL {name}: `{' '.join(cmd)}` exited with {proc.returncode}\n"
              f"  stderr: {proc.stderr.strip()[:2000]}")
        return False
    try:
        reference = objio.read_tangent_csv(os.path.join(case_dir, name + ".tangents.csv"))
        ours = objio.read_tangent_csv(out)
    except (OSError, ValueError) as e:
        print(f"FAIL {name}: {e}")
        return False
    worst, worst_at, sign_mismatches, problems = compare_rows(reference, ours, tolerance_deg)
    at = "face %d corner %d" % worst_at if worst_at else "-"
    status = "FAIL" if problems else "ok  "
    print(f"{status} {name:<20} corners {len(reference):6d}  worst angle {worst:.5f} deg "
          f"({at})  sign mismatches {sign_mismatches}  cli {seconds:.2f} s")
    for line in problems[:MAX_REPORTED]:
        print("     " + line)
    if len(problems) > MAX_REPORTED:
        print(f"     ... and {len(problems) - MAX_REPORTED} more problems")
    return not problems


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cli", required=True, help="path to the sgbake executable")
    parser.add_argument("--cases", required=True, help="directory made by make_tangent_cases.py")
    parser.add_argument("--tolerance-deg", type=float, default=0.05,
                        help="largest allowed angle between tangents (default 0.05)")
    parser.add_argument("--threads", type=int, help="pass --threads N to the CLI")
    parser.add_argument("--out-dir", help="where to keep sgbake's CSVs (default: a temp dir)")
    parser.add_argument("--only", nargs="+", metavar="NAME", help="compare only these cases")
    args = parser.parse_args(argv)

    if not os.path.isfile(args.cli) or not os.access(args.cli, os.X_OK):
        print(f"error: {args.cli} is not an executable file", file=sys.stderr)
        return 2
    try:
        names = list_cases(args.cases)
    except (OSError, ValueError, KeyError) as e:
        print(f"error: cannot list the cases in {args.cases}: {e}", file=sys.stderr)
        return 2
    if args.only:
        names = [n for n in names if n in set(args.only)]
    if not names:
        print(f"error: no cases in {args.cases}", file=sys.stderr)
        return 2

    with tempfile.TemporaryDirectory(prefix="sgbake-tangents-") as tmp:
        out_dir = args.out_dir or tmp
        os.makedirs(out_dir, exist_ok=True)
        failed = [name for name in names
                  if not run_case(args.cli, args.cases, out_dir, name, args.tolerance_deg,
                                  args.threads)]
    if failed:
        print(f"FAILED: {len(failed)} of {len(names)} cases differ from Blender "
              f"(tolerance {args.tolerance_deg} deg, identical signs): {', '.join(failed)}")
        return 1
    print(f"PASSED: all {len(names)} cases agree with Blender within {args.tolerance_deg} deg "
          "with identical signs")
    return 0


if __name__ == "__main__":
    sys.exit(main())
