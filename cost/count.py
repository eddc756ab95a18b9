#!/usr/bin/env python3
"""Counts the instructions servoplot's motion path costs on a Cortex-M4F and prints the table.

Builds the instruction-counting QEMU plugin (plugin/insn_count.c) and the harness (src/main.rs,
the firmware's release profile), runs the harness on QEMU's mps2-an386 (a Cortex-M4 with FPU),
and turns the instruction counts between the harness's marks into per-step figures.

    python3 count.py                    # every case: the table the README keeps
    python3 count.py --only circle      # cases whose name contains "circle"
    python3 count.py --only circle --profile   # and which functions the instructions went to
"""
import argparse
import os
import struct
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
TARGET = "thumbv7em-none-eabihf"
ELF = os.path.join(HERE, "..", "target", TARGET, "release", "servoplot-cost")
PLUGIN_SRC = os.path.join(HERE, "plugin", "insn_count.c")
PLUGIN = os.path.join(HERE, "..", "target", "cost", "insn_count.so")
QEMU = "qemu-system-arm"


def build():
    os.makedirs(os.path.dirname(PLUGIN), exist_ok=True)
    if not os.path.exists(PLUGIN) or os.path.getmtime(PLUGIN) < os.path.getmtime(PLUGIN_SRC):
        subprocess.run(["gcc", "-O2", "-Wall", "-shared", "-fPIC", "-o", PLUGIN, PLUGIN_SRC], check=True)
    subprocess.run(["cargo", "build", "--release", "--locked", "--quiet"], cwd=HERE, check=True)


def symbols(path):
    """(address, size, name) of every function in an ELF32 file, Thumb bit cleared."""
    with open(path, "rb") as f:
        data = f.read()
    shoff, = struct.unpack_from("<I", data, 0x20)
    shentsize, shnum = struct.unpack_from("<HH", data, 0x2E)
    headers = [struct.unpack_from("<IIIIIIIIII", data, shoff + i * shentsize) for i in range(shnum)]
    out = []
    for _, typ, _, _, off, size, link, _, _, entsize in headers:
        if typ != 2:  # SHT_SYMTAB
            continue
        strtab = headers[link][4]
        for i in range(size // entsize):
            name, value, sym_size, info, _, _ = struct.unpack_from("<IIIBBH", data, off + i * entsize)
            if info & 0xF == 2:  # STT_FUNC
                end = data.index(b"\0", strtab + name)
                out.append((value & ~1, sym_size, data[strtab + name:end].decode(errors="replace")))
    return out


def demangle(name):
    """Readable form of a legacy-mangled Rust name (`_ZN...E`); other names as they are."""
    if not name.startswith("_ZN"):
        return name
    parts, i = [], 3
    while i < len(name) and name[i].isdigit():
        j = i
        while name[j].isdigit():
            j += 1
        n = int(name[i:j])
        parts.append(name[j:j + n])
        i = j + n
    if parts and parts[-1].startswith("h") and len(parts[-1]) == 17:
        parts.pop()
    text = "::".join(parts)
    for code, char in (("$LT$", "<"), ("$GT$", ">"), ("$u20$", " "), ("$RF$", "&"), ("$C$", ","),
                       ("$u7b$", "{"), ("$u7d$", "}"), ("..", "::"), ("$u27$", "'"), ("$BP$", "*")):
        text = text.replace(code, char)
    return text


def run(only, profile):
    syms = symbols(ELF)
    mark = next(addr for addr, _, name in syms if name == "cost_mark")
    log = os.path.join(os.path.dirname(PLUGIN), "counts.txt")
    plugin = f"{PLUGIN},mark={mark:#x}" + (",profile=on" if profile else "")
    semihosting = f"enable=on,target=native,arg={only or '*'}"
    cmd = [QEMU, "-M", "mps2-an386", "-nographic", "-semihosting-config", semihosting, "-kernel", ELF,
           "-plugin", plugin, "-d", "plugin", "-D", log]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"the harness failed ({done.returncode}):\n{done.stdout}{done.stderr}")
    with open(log) as f:
        lines = f.read().splitlines()
    marks = [int(l.split()[1]) for l in lines if l.startswith("mark ")]
    results = [l.split() for l in done.stdout.splitlines() if l.startswith("result ")]
    if len(marks) != 2 * len(results) + 2:
        sys.exit(f"{len(marks)} marks for {len(results)} results:\n{done.stdout}")
    # The first two marks are back to back: what a pair of marks costs by itself.
    overhead = marks[1] - marks[0]
    # Lines of the same measure, case and method add up (the motion task reports every poll).
    measured = {}
    for k, (_, what, case, method, count) in enumerate(results):
        instructions = marks[2 * k + 3] - marks[2 * k + 2] - overhead
        total, steps = measured.get((case, method, what), (0, 0))
        measured[(case, method, what)] = (total + instructions, steps + int(count))
    blocks = [l.split() for l in lines if l.startswith("block ")]
    return measured, blocks, syms


def print_profile(blocks, syms):
    syms = sorted(syms)
    starts = [a for a, _, _ in syms]
    import bisect
    per_function = {}
    for _, addr, n, execs in blocks:
        a = int(addr, 16)
        i = bisect.bisect_right(starts, a) - 1
        name = demangle(syms[i][2]) if i >= 0 else "?"
        per_function[name] = per_function.get(name, 0) + int(n) * int(execs)
    total = sum(per_function.values())
    print(f"\nProfile (whole run, {total} instructions):\n")
    for name, count in sorted(per_function.items(), key=lambda kv: -kv[1])[:30]:
        print(f"{count:>12} {100 * count / total:5.1f}%  {name[:110]}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", help="run only the cases whose name contains this text")
    parser.add_argument("--profile", action="store_true", help="also print instructions per function")
    parser.add_argument("--no-build", action="store_true", help="use the harness and plugin as built")
    args = parser.parse_args()
    if not args.no_build:
        build()
    measured, blocks, syms = run(args.only, args.profile)
    cases = []
    for case, method, what in measured:
        if what != "pulse" and (case, method) not in cases:
            cases.append((case, method))
    print("| curve | method | setup (instructions) | steps | interp (instr/step) | + planner (instr/step) "
          "| + motion task (instr/step) |")
    print("|---|---|---:|---:|---:|---:|---:|")
    for case, method in cases:
        def per_step(what):
            if (case, method, what) not in measured:
                return ""
            n, steps = measured[(case, method, what)]
            return f"{n / max(steps, 1):.1f}"
        setup = measured.get((case, method, "setup"), (0, 0))[0]
        steps = measured.get((case, method, "interp"), (0, 0))[1]
        print(f"| {case} | {method} | {setup} | {steps} | {per_step('interp')} | {per_step('planner')} "
              f"| {per_step('task')} |")
    short, long_ = measured.get(("short", "both", "pulse")), measured.get(("long", "both", "pulse"))
    if short and long_:
        per_pulse = (long_[0] - short[0]) / (long_[1] - short[1])
        print(f"\nPulse path: {per_pulse:.1f} instructions per pulse (step timer interrupt, entry to return, "
              f"and the sleep loop around it)")
    if args.profile:
        print_profile(blocks, syms)


if __name__ == "__main__":
    main()
