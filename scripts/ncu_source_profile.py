#!/usr/bin/env python3
"""Attributes Nsight Compute's per-instruction counts of one kernel to envgi's source files.

ncu's source page (`ncu -i REPORT --page source --csv --print-source sass`) gives, per SASS
instruction, the warp instructions executed and the warp-stall samples by reason, but without
line information in the CSV. This script disassembles the same binary with `nvdisasm -g` (build
it with CMAKE_CUDA_FLAGS=-lineinfo, which leaves the code unchanged), pairs the two instruction
by instruction, and prints per source file: static instructions, instructions executed at least
once, and shares of executed instructions and of stall samples; then the stall reasons, and the
hot code's footprint in 128-byte lines (what the instruction cache must hold).

Needs cuobjdump and nvdisasm (the CUDA toolkit; the device machine has them).

  ncu -k regex:regenKernel -s 5 -c 1 --section SourceCounters -o rep BIN --no-cpu --frames 8
  ncu -i rep.ncu-rep --page source --csv --print-source sass > src.csv
  scripts/ncu_source_profile.py BIN src.csv --kernel regenKernel --arch sm_90
"""
import argparse
import collections
import csv
import gzip
import os
import re
import subprocess
import sys
import tempfile


def disassemble(binary, kernel, arch):
    """[(address, opcode, (file, line))] of the kernel's instructions, in order."""
    with tempfile.TemporaryDirectory() as d:
        subprocess.run(["cuobjdump", "-xelf", arch, os.path.abspath(binary)], cwd=d, check=True,
                       stdout=subprocess.DEVNULL)
        instructions = []
        for cubin in sorted(os.listdir(d)):
            text = subprocess.run(["nvdisasm", "-g", os.path.join(d, cubin)], check=True,
                                  capture_output=True, text=True).stdout
            m = re.search(r"\.text\.(\S*" + re.escape(kernel) + r"\S*):", text)
            if not m:
                continue
            end = text.find(".section", m.end())
            where = ("?", 0)
            for line in text[m.end():end if end > 0 else None].split("\n"):
                f = re.search(r'//## File "([^"]+)", line (\d+)', line)
                if f:
                    path = f.group(1)
                    for cut in ("/src/", "/include/"):
                        path = path.split(cut)[-1]
                    where = (path, int(f.group(2)))
                    continue
                i = re.search(r"/\*([0-9a-f]{4,})\*/\s+(?:@!?U?P\w+\s+)?([A-Z][A-Z0-9_.]*)", line)
                if i:
                    instructions.append((int(i.group(1), 16), i.group(2), where))
            return instructions
    sys.exit(f"no kernel matching {kernel!r} for {arch} in {binary}")


def number(s):
    try:
        return float(s)
    except ValueError:
        return 0.0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("binary")
    ap.add_argument("csv", help="ncu's source page as CSV (may be gzipped)")
    ap.add_argument("--kernel", default="regenKernel")
    ap.add_argument("--arch", default="sm_90")
    ap.add_argument("--top", type=int, default=25)
    a = ap.parse_args()

    instructions = disassemble(a.binary, a.kernel, a.arch)
    if all(where[0] == "?" for _, _, where in instructions):
        print("note: the binary has no line information; rebuild with CMAKE_CUDA_FLAGS=-lineinfo", file=sys.stderr)
    opener = gzip.open if a.csv.endswith(".gz") else open
    with opener(a.csv, "rt") as f:
        rows = list(csv.reader(f))
    header = next(r for r in rows if r and r[0] == "Address")
    data = rows[rows.index(header) + 1:]
    if len(data) != len(instructions):
        sys.exit(f"{len(data)} rows in the CSV against {len(instructions)} instructions in the binary: "
                 "not the same build, or not the same kernel")
    col = {h: i for i, h in enumerate(header)}
    executed_col, samples_col = col["Instructions Executed"], col["Warp Stall Sampling (All Samples)"]
    stall_cols = [h for h in header if h.startswith("stall_") and "Not Issued" not in h]

    per_file = collections.defaultdict(collections.Counter)
    stalls = collections.Counter()
    lines = collections.Counter()
    for row, (address, _, (path, _)) in zip(data, instructions):
        e, s = number(row[executed_col]), number(row[samples_col])
        c = per_file[path]
        c["static"] += 1
        c["executed"] += e
        c["samples"] += s
        if e > 0:
            c["hot"] += 1
            lines[address // 128] += e
        for h in stall_cols:
            stalls[h] += number(row[col[h]])
    executed = sum(c["executed"] for c in per_file.values()) or 1
    samples = sum(c["samples"] for c in per_file.values()) or 1

    hot = sum(c["hot"] for c in per_file.values())
    print(f"{len(instructions)} instructions, {hot} executed at least once; "
          f"{executed:.4g} warp instructions executed, {samples:.0f} stall samples")
    print("stall reasons: " + ", ".join(f"{k[6:]} {v / samples * 100:.1f}%" for k, v in stalls.most_common(8)))
    ranked = sorted(lines.values(), reverse=True)
    for share in (0.9, 0.99):
        total, n = 0.0, 0
        for v in ranked:
            total += v
            n += 1
            if total >= share * executed:
                break
        print(f"128-byte lines holding {share * 100:.0f}% of executed instructions: {n} ({n * 128 / 1024:.0f} KB)")
    print(f"\n{'file':40s} {'static':>7s} {'hot':>6s} {'exec %':>7s} {'stall %':>8s}")
    for path, c in sorted(per_file.items(), key=lambda x: -x[1]["samples"])[:a.top]:
        print(f"{path:40s} {c['static']:7d} {c['hot']:6d} {c['executed'] / executed * 100:7.1f} "
              f"{c['samples'] / samples * 100:8.1f}")


if __name__ == "__main__":
    main()
