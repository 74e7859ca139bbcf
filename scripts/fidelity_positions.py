#!/usr/bin/env python3
"""Issue 9's cut-fidelity matrix at several positions of its strokes.

The matrix (test/unit/cutting/test_cut_fidelity.cpp) cuts 40 fixed strokes: the thigh and four
TetGen livers x vertical / 45-degree blades x straight / curved paths x 0.2 / 3 mm steps. How a
stroke scores depends on where it meets the mesh, and the cutter was tuned on exactly those
strokes (docs/DESIGN.md section 12, "How much of the matrix is where the strokes meet the
mesh"). This runs the matrix unshifted and with every stroke moved (STC_FIDELITY_SHIFT) by
+-D mm along its path and across its blade plane, and prints per position and in all: strokes
within the two-sided Hausdorff tolerance, the summed excess over it, the least opening on the
lesser side, the least share of the sweep covered by open faces, and the least share walled on
the lesser side (swept points whose line along the blade normal meets an open face of that side
within the tolerance) with how many strokes are walled under 90 %.

usage: scripts/fidelity_positions.py BINARY [--shift D] [--guard DEG]
  BINARY: the core unit tests (build-core/tissue_core_unit, or devel/lib/.../tissue_core_unit)
  --shift D: the shift in mm (default 0.5); --guard DEG: the shape guard (STC_FIDELITY_GUARD)
Two gtest processes run at a time (the coarse meshes with the thigh, the fine livers); about 20
minutes on a 2-core machine.
"""
import os
import re
import subprocess
import sys

LINE = re.compile(
    r"FIDELITY (\S+) (.*?): swept ([\d.e+-]+) cm2, opened ([\d.e+-]+) / ([\d.e+-]+) cm2 "
    r"\(([\d.e+-]+) % the lesser side; ([\d.e+-]+) % of the swept area.*?"
    r"; ([\d.e+-]+) x tolerance; faces ([\d.e+-]+) x\)")
WALLED = re.compile(r", walled ([\d.e+-]+) / ([\d.e+-]+) %")
GROUPS = ["CutFidelity.ThighMatrix:CutFidelity.*Coarse*",
          "CutFidelity.Liver2Fine:CutFidelity.LiverBoundaryFine"]


def run(binary, shift, guard):
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", STC_FIDELITY_SHIFT=shift)
    if guard is not None:
        env["STC_FIDELITY_GUARD"] = guard
    procs = [subprocess.Popen([binary, "--gtest_filter=" + g], env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True) for g in GROUPS]
    rows = []
    for p in procs:
        out, _ = p.communicate()
        for line in out.splitlines():
            m = LINE.match(line)
            if m and "path border" not in line:
                w = WALLED.search(line)
                walled = min(float(w.group(1)), float(w.group(2))) if w else float("nan")
                rows.append((m.group(1), m.group(2), float(m.group(6)), float(m.group(7)),
                             float(m.group(8)), walled))
    return rows


def main(argv):
    if len(argv) < 2 or argv[1].startswith("-"):
        print("usage: scripts/fidelity_positions.py BINARY [--shift D] [--guard DEG]",
              file=sys.stderr)
        return 2
    binary, d, guard = argv[1], 0.5, None
    args = argv[2:]
    while args:
        key = args.pop(0)
        if key == "--shift" and args:
            d = float(args.pop(0))
        elif key == "--guard" and args:
            guard = args.pop(0)
        else:
            print(f"fidelity_positions: unknown argument '{key}'", file=sys.stderr)
            return 2
    positions = [(0, 0), (d, d), (-d, -d), (d, -d), (-d, d)]
    total_within = total_rows = 0
    total_excess = 0.0
    print(f"{'shift (along, aside) mm':>24} {'within':>8} {'excess':>8} {'least opened %':>15}"
          f" {'least covered %':>16} {'least walled %':>15} {'walled < 90 %':>14}")
    for along, aside in positions:
        rows = run(binary, f"{along} {aside}", guard)
        if len(rows) != 40:
            print(f"fidelity_positions: {len(rows)} strokes measured at ({along}, {aside}), "
                  "expected 40", file=sys.stderr)
            return 1
        within = sum(1 for r in rows if r[4] <= 1.0)
        excess = sum(max(0.0, r[4] - 1.0) for r in rows)
        total_within += within
        total_rows += len(rows)
        total_excess += excess
        print(f"{f'({along:+g}, {aside:+g})':>24} {within:>5}/{len(rows)} {excess:8.2f}"
              f" {min(r[2] for r in rows):15.1f} {min(r[3] for r in rows):16.1f}"
              f" {min(r[5] for r in rows):15.1f} {sum(1 for r in rows if r[5] < 90):14d}")
    print(f"{'all positions':>24} {total_within:>4}/{total_rows} {total_excess:8.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
