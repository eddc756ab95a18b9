#!/usr/bin/env python3
"""Fails if a function of a firmware image reserves more than a stack frame's budget.

Reads the image's disassembly (llvm-objdump) and, for every function, the stack it reserves in
one instruction (`sub sp, #N`, `sub.w sp, sp, #N`, `subw sp, sp, #N`): a value built on the stack
and moved shows up here, as the 50 KB planner once did. Prints the largest frames.

    python3 .ci/frames.py IMAGE [--max-bytes 4096] [--show 8]
"""
import argparse
import re
import shutil
import subprocess
import sys

SUB_SP = re.compile(r"\bsubw?(?:\.w)?\s+sp,\s*(?:sp,\s*)?#(0x[0-9a-f]+|\d+)")
FUNCTION = re.compile(r"^[0-9a-f]+ <(.*)>:$")


def objdump():
    for name in ("llvm-objdump", "rust-objdump"):
        if shutil.which(name):
            return name
    # rustup's llvm-tools component keeps it with the toolchain.
    sysroot = subprocess.run(["rustc", "--print", "sysroot"], capture_output=True, text=True).stdout.strip()
    found = subprocess.run(["find", sysroot, "-name", "llvm-objdump", "-type", "f"], capture_output=True, text=True)
    if found.stdout.strip():
        return found.stdout.split()[0]
    sys.exit("no llvm-objdump: `rustup component add llvm-tools`")


def frames(image):
    out = subprocess.run([objdump(), "-d", "--no-show-raw-insn", "-C", image], capture_output=True, text=True,
                         check=True).stdout
    largest = {}
    function = "?"
    for line in out.splitlines():
        m = FUNCTION.match(line)
        if m:
            function = m.group(1)
            continue
        m = SUB_SP.search(line)
        if m:
            largest[function] = max(largest.get(function, 0), int(m.group(1), 0))
    return sorted(largest.items(), key=lambda kv: -kv[1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("image")
    parser.add_argument("--max-bytes", type=int, default=4096, help="the largest frame allowed")
    parser.add_argument("--show", type=int, default=5, help="how many of the largest frames to print")
    args = parser.parse_args()
    found = frames(args.image)
    print(f"largest stack frames of {args.image}:")
    for name, size in found[:args.show]:
        print(f"  {size:>6} B  {name[:110]}")
    over = [(n, s) for n, s in found if s > args.max_bytes]
    if over:
        sys.exit(f"{len(over)} function(s) reserve more than {args.max_bytes} B of stack")
    print(f"no frame over {args.max_bytes} B")


if __name__ == "__main__":
    main()
