#!/usr/bin/env python3
"""Counts what servoplot's motion path costs on a Cortex-M4F and prints the table.

Builds the counting QEMU plugin (plugin/insn_count.c) and the harness (src/main.rs, the
firmware's release profile), runs the harness on QEMU's mps2-an386 (a Cortex-M4 with FPU), and
turns what the plugin counts between the harness's marks into per-step figures: instructions,
exactly, and cycles on the STM32F407 from the Cortex-M4's instruction timings (see CYCLES).

    python3 count.py                    # every case: the table the README keeps
    python3 count.py --only circle      # cases whose name contains "circle"
    python3 count.py --only circle --profile   # and which functions the instructions went to
    python3 count.py --kinds            # and the kinds of instructions each case runs
    python3 count.py --check-model f407.txt    # fails if the simulator's model is out of date
    python3 count.py --write-model f407.txt    # writes it anew from what is counted
    python3 count.py --masked           # longest stretch with interrupts masked (shared state)
    python3 count.py --masked --image ELF --qemu-arg=-serial --qemu-arg=null   # any image
"""
import argparse
import bisect
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
# The ELF reader the firmware checks use.
sys.path.insert(0, os.path.join(HERE, "..", ".ci"))
from elf import functions  # noqa: E402
TARGET = "thumbv7em-none-eabihf"
ELF = os.path.join(HERE, "..", "target", TARGET, "release", "servoplot-cost")
PLUGIN_SRC = os.path.join(HERE, "plugin", "insn_count.c")
PLUGIN = os.path.join(HERE, "..", "target", "cost", "insn_count.so")
MASKED_SRC = os.path.join(HERE, "plugin", "masked.c")
MASKED_PLUGIN = os.path.join(HERE, "..", "target", "cost", "masked.so")
QEMU = "qemu-system-arm"

# The processor the counts are turned into time for: the STM32F407 at 168 MHz.
CLOCK_HZ = 168_000_000

# Cycles of each kind of instruction the plugin tells apart, on the Cortex-M4 with zero wait
# states: its Technical Reference Manual (r0p1), Table 3-1 and 3.3.2 (load and store timings),
# and Table 7-1 for the FPU.
CYCLES = {
    "alu": 1,          # data processing, moves, compares, shifts, bit fields, extends
    "mul": 1,          # MUL, MLA, MLS, SMULL, UMULL, SMLAL, UMLAL
    "div": 12,         # SDIV, UDIV: 2 to 12 by early termination; the most
    "load": 2,         # LDR, LDRB, LDRH, LDRSB, LDRSH
    "load_pipe": 1,    # the same right after a load: its address phase overlaps that load's data
    "load_pc": 2,      # LDR PC: 2, and the refill below
    "store": 1,        # STR with an immediate offset: its data phase overlaps what follows
    "store_reg": 2,    # STR with a register offset
    "pair": 3,         # LDRD, STRD: 1 + N
    "multi": 1,        # LDM, STM, PUSH, POP: 1 + N, the N words charged apart (WORD_CYCLES)
    "branch": 1,       # B, BL, BX, BLX, CBZ, CBNZ: 1, and a refill where taken
    "table": 2,        # TBB, TBH: 2, and a refill
    "it": 1,           # IT
    "it_folded": 0,    # IT right after a 16-bit instruction: folded into it
    "barrier": 1,      # DMB, DSB, ISB: 1 + B, B at its least (0; ISB's refill is counted)
    "system": 2,       # MRS, MSR, CPSIE, CPSID: 1 or 2, the most; WFI without its wait
    "fp": 1,           # VADD, VSUB, VMUL, VABS, VNEG, VCMP, VCVT, VMOV, VMRS
    "fp_mac": 3,       # VMLA, VMLS, VNMLA, VNMLS, VFMA, VFMS
    "fp_divsqrt": 14,  # VDIV, VSQRT
    "fp_load": 2,      # VLDR
    "fp_store": 2,     # VSTR
    "fp_multi": 1,     # VLDM, VSTM, VPUSH, VPOP: 1 + N words
    "other": 1,        # anything else (the run says which, if any)
}
# Each word an LDM, STM, PUSH, POP or their FPU forms move.
WORD_CYCLES = 1
# The pipeline's refill after a taken branch: 1 to 3 by the target's alignment and width, and
# whether the core speculated its address early (TRM, Table 3-1, P): the most.
REFILL_CYCLES = 3
# The STM32F407 runs from flash at 5 wait states at 168 MHz and 2.7-3.6 V (RM0090, Table 10),
# through the ART accelerator with prefetch and both caches on. Sequential code streams through
# the prefetch buffer; a taken branch whose target line is not in the 64-line instruction cache,
# and a load of a constant from flash not in the 8-line data cache, waits them out. The plugin
# models both caches (least recently used line out).
FLASH_WAIT_CYCLES = 5
# The step timer's interrupt runs once a pulse: entry 12 cycles (TRM 5.5.1, interrupt latency),
# return 10, which no instruction of the handler shows.
INTERRUPT_CYCLES = 12 + 10

# The simulator's model (f407.txt): each kind of curve costs what its costliest case costs.
MODEL_KINDS = {
    "line": ["line0", "line30", "line45"],
    "arc": ["circle", "arc"],
    "ellipse": ["ellipse"],
    "sine": ["sine"],
    "function": ["gauss", "cubic", "sinx"],
}
MODEL_HEADER = """\
# The motion path's cost on the board, for the simulator's CPU model (`cargo sim --cpu f407`).
# Written by `python3 cost/count.py --write-model cost/f407.txt` from what is counted on QEMU's
# Cortex-M4F (mps2-an386); `.ci/run` checks that it still matches.
# Per step: the motion task all-in (interpolator, planner, task), the most costly case of each
# kind (in cycles). Per pulse: the step timer's interrupt. The figures are instructions; each
# `cycles_per_instruction` turns its kind's into cycles on the STM32F407 at 168 MHz (the
# Cortex-M4's instruction timings, flash at five wait states through the ART accelerator, and
# for the pulse the interrupt's entry and return: see count.py).
# A function: per step, plus per X step (where it evaluates the curve) `per_x_step` and
# `per_x_step_op` per operation of its expression. `build`: the drawing builder's walk per step,
# plus per X step of a sine or a function `per_x_step`, and for a function `per_x_step_op`.
"""
# How far the model may be from what is counted before --check-model fails. The same source
# built in another directory counts up to about 5 % apart on some cases (the builder's ellipse
# with diagonal steps: 56.5 and 58.9 instructions a step from two clones): the paths change the
# symbols' names, and with them the order LLVM visits functions in and what it inlines.
MODEL_TOLERANCE = 0.10

# The budgets (--check-budgets): instructions per step of the motion task all-in, by kind of
# curve, and per pulse.
STEP_BUDGETS = {"line": 200, "arc": 200, "ellipse": 200, "sine": 400, "function": 400}
PULSE_BUDGET = 150

# The longest stretch with interrupts masked (--masked), instructions: the step timer's interrupt
# waits at most this long, and must write SIGN within 2 us (336 cycles) of its update event
# (SIGN_LATENCY_US, src/board/stm32f407/step_timer.rs). 80 instructions take at most some 150
# cycles (at the 1.9 cycles per instruction of the costliest code counted); with the interrupt's
# entry (12 cycles and the vector's fetch) and the handler's instructions up to its last SIGN
# write (up to 55, some 110 cycles), under 300 cycles.
MASKED_BUDGET = 80
# The longest critical section (BASEPRI raised: every interrupt but the pulse interrupt held off,
# src/critical.rs), instructions: the host link's UART holds one received byte, and at 115200
# baud the next comes 87 us later; its interrupt waits for a section and for the time driver's
# (the only interrupt above it, at most a section's length too). 3,000 instructions take some
# 34 us at 1.9 cycles per instruction: two of them, back to back, still leave the byte room.
SECTION_BUDGET = 3_000
# The harness's cases --masked runs unless told otherwise: the shared state's operations.
MASKED_CASES = "shared"
# The critical-section crate's entry points, when the image has them out of line.
CRITICAL_SECTION_SYMBOLS = ("_critical_section_1_0_acquire", "_critical_section_1_0_release")


def build_plugin(source, plugin):
    os.makedirs(os.path.dirname(plugin), exist_ok=True)
    if not os.path.exists(plugin) or os.path.getmtime(plugin) < os.path.getmtime(source):
        subprocess.run(["gcc", "-O2", "-Wall", "-shared", "-fPIC", "-o", plugin, source], check=True)


def build():
    build_plugin(PLUGIN_SRC, PLUGIN)
    build_plugin(MASKED_SRC, MASKED_PLUGIN)
    subprocess.run(["cargo", "build", "--release", "--locked", "--quiet"], cwd=HERE, check=True)


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


class Counts:
    """What the plugin counted over a stretch of the run: instructions, each kind, the words of
    multiple transfers, taken branches and misses of the flash caches."""

    def __init__(self, kinds, values):
        self.kinds = kinds
        self.values = values

    def __sub__(self, other):
        return Counts(self.kinds, [a - b for a, b in zip(self.values, other.values)])

    def __add__(self, other):
        return Counts(self.kinds, [a + b for a, b in zip(self.values, other.values)])

    @property
    def instructions(self):
        return self.values[0]

    def kind(self, name):
        return self.values[1 + self.kinds.index(name)]

    @property
    def words(self):
        return self.values[-4]

    @property
    def taken(self):
        return self.values[-3]

    @property
    def misses(self):
        return self.values[-2] + self.values[-1]

    def cycles(self):
        base = sum(CYCLES[k] * self.kind(k) for k in self.kinds)
        return base + WORD_CYCLES * self.words + REFILL_CYCLES * self.taken + FLASH_WAIT_CYCLES * self.misses


def run(only, profile):
    syms = functions(ELF)
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
    kinds = next(l.split()[1:] for l in lines if l.startswith("kinds "))
    unknown = [kind for kind in kinds if kind not in CYCLES]
    if unknown:
        sys.exit(f"no cycles for the plugin's kinds {unknown}")
    for l in lines:
        if l.startswith("unknown "):
            print(f"note: `{l.split()[1]}` is not a kind the plugin knows: charged {CYCLES['other']} cycle")
    marks = [Counts(kinds, [int(v) for v in l.split()[1:]]) for l in lines if l.startswith("mark ")]
    results = [l.split() for l in done.stdout.splitlines() if l.startswith("result ")]
    if len(marks) != 2 * len(results) + 2:
        sys.exit(f"{len(marks)} marks for {len(results)} results:\n{done.stdout}")
    # The first two marks are back to back: what a pair of marks costs by itself.
    overhead = marks[1] - marks[0]
    # Lines of the same measure, case and method add up (the motion task reports every poll).
    measured = {}
    # The builder's slices also count one by one: the longest of each case.
    longest = {}
    for k, (_, what, case, method, count) in enumerate(results):
        counts = marks[2 * k + 3] - marks[2 * k + 2] - overhead
        total, steps = measured.get((case, method, what), (Counts(kinds, [0] * len(counts.values)), 0))
        measured[(case, method, what)] = (total + counts, steps + int(count))
        if what == "slice" and ((case, method) not in longest or counts.cycles() > longest[(case, method)].cycles()):
            longest[(case, method)] = counts
    blocks = [l.split() for l in lines if l.startswith("block ")]
    return measured, blocks, syms, (done.stdout, longest)


def print_profile(blocks, syms):
    syms = sorted(syms)
    starts = [a for a, _, _ in syms]
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


class Pulse:
    """The pulse path, per pulse: the difference of two runs of different lengths."""

    def __init__(self, measured):
        short, long_ = measured.get(("short", "both", "pulse")), measured.get(("long", "both", "pulse"))
        self.counts = None
        if short and long_:
            self.n = long_[1] - short[1]
            self.counts = long_[0] - short[0]

    def instructions(self):
        return self.counts.instructions / self.n

    def cycles(self):
        return self.counts.cycles() / self.n + INTERRUPT_CYCLES


def model_from(measured, pulse):
    """The simulator's model file from the counts, or None if a case is missing."""
    if pulse.counts is None:
        return None
    lines = [MODEL_HEADER + f"clock_hz {CLOCK_HZ}"]
    lines.append(f"pulse {round(pulse.instructions())}")
    lines.append(f"pulse cycles_per_instruction {pulse.cycles() / pulse.instructions():.2f}")
    for kind, cases in MODEL_KINDS.items():
        if kind == "function":
            # Fitted by the size of the expression: see build_model.
            continue
        for method in ("classic", "diagonal"):
            costs = [measured[(c, method, "task")] for c in cases if (c, method, "task") in measured]
            if len(costs) != len(cases):
                return None
            counts, steps = max(costs, key=lambda cs: cs[0].cycles() / cs[1])
            lines.append(f"{kind} {method} {round(counts.instructions / steps)}")
            lines.append(f"{kind} {method} cycles_per_instruction {counts.cycles() / counts.instructions:.2f}")
    return "\n".join(lines) + "\n"


# The builder, and a function's cost by the size of its expression (`src/build.rs`): the cases
# each figure of the model is fitted to. The motion task and the builder cost `s` per step and,
# for sines and functions, `c` per X step (where the curve is evaluated), a function's `c` being
# `c0 + c1 * ops`; each fit is by least squares over its cases. An operation costs what it
# costs in the usual mix (arithmetic, sin, cos, exp, sqrt, small powers): a function whose
# operations are mostly sines costs up to a fifth more than the model says, one of mostly
# arithmetic a fifth less. b-fn-heavy, all general powers, costs three times as much per
# operation: it is counted for the longest slice, not fitted. Each fit's cycles per instruction
# are those of its cases together.
MOTION_FUNCTION_CASES = ["gauss", "cubic", "sinx", "m-fn3", "m-fn10", "m-fn18", "m-fn30"]
BUILD_KINDS = {
    "arc": ["b-circle", "b-arc"],
    "ellipse": ["b-ellipse"],
    "sine": ["b-sine-flat", "b-sine", "b-sine-steep"],
    "function": ["b-fn3", "b-fn6", "b-fn9", "b-fn-steep", "b-fn18", "b-fn30"],
}
# The front ends' slice (src/motion/drawing/builder.rs, BUILD_SLICE_STEPS), and the longest a slice may
# take on the board.
BUILD_SLICE_STEPS = 1536
BUILD_SLICE_BUDGET_MS = 2.0


def least_squares(rows, values):
    """The x minimising |rows·x - values|: the normal equations, by elimination."""
    n = len(rows[0])
    a = [[sum(r[i] * r[j] for r in rows) for j in range(n)] + [sum(r[i] * v for r, v in zip(rows, values))]
         for i in range(n)]
    for i in range(n):
        p = max(range(i, n), key=lambda k: abs(a[k][i]))
        a[i], a[p] = a[p], a[i]
        for k in range(n):
            if k != i and a[i][i]:
                f = a[k][i] / a[i][i]
                a[k] = [x - f * y for x, y in zip(a[k], a[i])]
    return [a[i][n] / a[i][i] if a[i][i] else 0.0 for i in range(n)]


def walked(output):
    """The build cases' and the motion task's function cases' X steps and expression sizes."""
    facts = {}
    for line in output.splitlines():
        words = line.split()
        if words[:1] == ["walked"]:
            _, case, method, kind, x_steps, ops = words
            facts[(case, method)] = (kind, int(x_steps), int(ops))
        elif words[:1] == ["motion"]:
            _, case, method, x_steps, ops = words
            facts[(case, method)] = ("function", int(x_steps), int(ops))
    return facts


def cycles_per_instruction(counts):
    """Cycles per instruction over `counts`, a list of Counts."""
    return sum(c.cycles() for c in counts) / sum(c.instructions for c in counts)


def build_model(measured, facts):
    """The builder's figures and the motion task's function figures, by method: name -> value;
    None if a case is missing."""
    out = {}
    for method in ("classic", "diagonal"):
        rows, values, counted = [], [], []
        for case in MOTION_FUNCTION_CASES:
            if (case, method, "task") not in measured or (case, method) not in facts:
                return None
            counts, steps = measured[(case, method, "task")]
            _, x_steps, ops = facts[(case, method)]
            rows.append([steps, x_steps, x_steps * ops])
            values.append(counts.instructions)
            counted.append(counts)
        x = least_squares(rows, values)
        out[f"function {method}"], out[f"function {method} per_x_step"] = x[0], x[1]
        out[f"function {method} per_x_step_op"] = x[2]
        out[f"function {method} cycles_per_instruction"] = cycles_per_instruction(counted)
        for kind, cases in BUILD_KINDS.items():
            rows, values, counted = [], [], []
            for case in cases:
                if (case, method, "slice") not in measured or (case, method) not in facts:
                    return None
                counts, steps = measured[(case, method, "slice")]
                _, x_steps, ops = facts[(case, method)]
                rows.append({"sine": [steps, x_steps], "function": [steps, x_steps, x_steps * ops]}.get(kind, [steps]))
                values.append(counts.instructions)
                counted.append(counts)
            cpi = cycles_per_instruction(counted)
            if kind in ("arc", "ellipse"):
                out[f"build {kind} {method}"] = max(v / r[0] for r, v in zip(rows, values))
                out[f"build {kind} {method} cycles_per_instruction"] = cpi
                continue
            x = least_squares(rows, values)
            out[f"build {kind} {method}"], out[f"build {kind} {method} per_x_step"] = x[0], x[1]
            if kind == "function":
                out[f"build function {method} per_x_step_op"] = x[2]
            out[f"build {kind} {method} cycles_per_instruction"] = cpi
    return out


def build_model_lines(figures):
    """The model's lines for `figures`: the motion task's function figures, then the builder's."""
    order = [n for n in figures if n.startswith("function ")] + [n for n in figures if n.startswith("build ")]
    def value(name):
        v = figures[name]
        if name.endswith(" cycles_per_instruction"):
            return f"{v:.2f}"
        return f"{v:.1f}" if v < 10 else f"{round(v)}"

    return [f"{n} {value(n)}" for n in order]


def print_functions(measured, facts, figures):
    """The motion task's functions: their cost per step, and what the model makes of it."""
    rows = [(c, m) for c in MOTION_FUNCTION_CASES for m in ("classic", "diagonal") if (c, m, "task") in measured]
    if not rows or not figures:
        return
    print("\nThe motion task's functions, by the size of their expressions:\n")
    print("| case | method | steps | X steps | ops | instr/step | model (instr/step) |")
    print("|---|---|---:|---:|---:|---:|---:|")
    for case, method in rows:
        counts, steps = measured[(case, method, "task")]
        n = counts.instructions
        _, x_steps, ops = facts.get((case, method), ("?", 0, 0))
        c = figures[f"function {method} per_x_step"] + figures[f"function {method} per_x_step_op"] * ops
        model = (figures[f"function {method}"] * steps + c * x_steps) / steps
        print(f"| {case} | {method} | {steps} | {x_steps} | {ops} | {n / steps:.1f} | {model:.1f} |")


def print_builds(measured, facts, figures, longest):
    """The builder's cost per case, what the model makes of it, and its longest slice; returns the
    longest slice of all, ms on the F407."""
    rows = [(c, m) for (c, m, what) in measured if what == "slice"]
    if not rows:
        return None
    print(f"\nThe builder, walking each case in slices of {BUILD_SLICE_STEPS} steps' worth:\n")
    print("| case | method | steps | X steps | ops | instr/step | instr/X step | model (instr/step) "
          "| longest slice (instructions) | (ms) |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    worst = 0.0
    for case, method in rows:
        counts, steps = measured[(case, method, "slice")]
        n = counts.instructions
        kind, x_steps, ops = facts.get((case, method), ("?", 0, 0))
        model = ""
        if figures:
            s = figures.get(f"build {kind} {method}", 0.0)
            c = (figures.get(f"build {kind} {method} per_x_step", 0.0)
                 + figures.get(f"build {kind} {method} per_x_step_op", 0.0) * ops)
            model = f"{(s * steps + c * x_steps) / steps:.1f}"
        per_x = f"{n / x_steps:.0f}" if x_steps else ""
        slice_counts = longest.get((case, method))
        slice_n = slice_counts.instructions if slice_counts else 0
        slice_ms = slice_counts.cycles() / CLOCK_HZ * 1000 if slice_counts else 0.0
        worst = max(worst, slice_ms)
        print(f"| {case} | {method} | {steps} | {x_steps} | {ops} | {n / steps:.1f} | {per_x} | {model} "
              f"| {slice_n} | {slice_ms:.2f} |")
    print(f"\nLongest slice: {worst:.2f} ms on the F407 (budget {BUILD_SLICE_BUDGET_MS} ms).")
    return worst


def figures(text):
    """The numbers of a model file, by name."""
    out = {}
    for line in text.splitlines():
        words = line.split()
        if words and not words[0].startswith("#"):
            out[" ".join(words[:-1])] = float(words[-1])
    return out


def check_model(path, model):
    if model is None:
        sys.exit("--check-model needs every case: run without --only")
    with open(path) as f:
        kept = figures(f.read())
    counted = figures(model)
    stale = [f"{name}: {kept.get(name)} kept, {value:g} counted" for name, value in counted.items()
             if name not in kept or abs(kept[name] - value) > MODEL_TOLERANCE * value]
    if stale:
        sys.exit(f"{path} is out of date (update it with --write-model):\n  " + "\n  ".join(stale))
    print(f"\n{path} matches the counts (within {MODEL_TOLERANCE:.0%})")


def check_budgets(measured, pulse):
    over = []
    for kind, cases in MODEL_KINDS.items():
        for case in cases:
            for method in ("classic", "diagonal"):
                if (case, method, "task") not in measured:
                    continue
                counts, steps = measured[(case, method, "task")]
                if counts.instructions / steps > STEP_BUDGETS[kind]:
                    over.append(f"{case} {method}: {counts.instructions / steps:.1f} instructions per step, "
                                f"budget {STEP_BUDGETS[kind]}")
    if pulse.counts is not None and pulse.instructions() > PULSE_BUDGET:
        over.append(f"pulse path: {pulse.instructions():.1f} instructions per pulse, budget {PULSE_BUDGET}")
    if over:
        sys.exit("over budget:\n  " + "\n  ".join(over))
    print(f"\nevery case within its budget (per step: {STEP_BUDGETS}; per pulse: {PULSE_BUDGET})")


def name_of(addr, syms):
    """`function+offset` for a code address, from the image's function symbols."""
    if addr >= 0xFFFF_FFFF:
        return "?"
    starts = [a for a, _, _ in syms]
    i = bisect.bisect_right(starts, addr) - 1
    if i < 0:
        return f"{addr:#x}"
    start, _, name = syms[i]
    return f"{demangle(name)}+{addr - start:#x}"


def build_masked_plugin():
    """The masked plugin, built if its source is newer; its path."""
    build_plugin(MASKED_SRC, MASKED_PLUGIN)
    return MASKED_PLUGIN


def masked_plugin_args(elf):
    """The plugin argument for QEMU's -plugin, with `elf`'s critical-section entry points where
    it has them."""
    by_name = {name: addr for addr, _, name in functions(elf)}
    plugin = build_masked_plugin()
    for arg, name in zip(("acquire", "release"), CRITICAL_SECTION_SYMBOLS):
        if name in by_name:
            plugin += f",{arg}={by_name[name]:#x}"
    return plugin


def read_masked_log(log, syms):
    """The stretches the plugin wrote to `log`, by kind, and notes on what it could not pair."""
    stretches, notes = {}, []
    with open(log) as f:
        for line in f.read().splitlines():
            words = line.split()
            if words[:1] == ["stretch"]:
                kind, begin, call, longest, count = words[1], int(words[2], 16), int(words[3], 16), int(words[4]), \
                    int(words[5])
                stretches.setdefault(kind, []).append((longest, count, begin, call))
            elif words[:1] == ["open"]:
                notes.append(f"still masked at exit: {words[1]} from {name_of(int(words[2], 16), syms)}, "
                             f"{words[3]} instructions")
            elif words[:1] == ["unmatched-msr"] and words[1] != "0":
                notes.append(f"{words[1]} `msr primask`/`msr basepri` without a saved value: taken as cleared there")
            elif words[:1] == ["saved"] and words[1:] != ["0", "0"]:
                notes.append(f"{words[1]} saved PRIMASK/BASEPRI values never written back ({words[2]} dropped): "
                             "the stretches may be paired wrongly")
            elif words[:1] == ["sites-full"]:
                notes.append("more places than the plugin keeps: some stretches were not recorded")
    return stretches, notes


def masked_run(elf, semihosting_arg, qemu_args):
    """Runs `elf` on mps2-an386 under the masked plugin; the stretches it found, by kind."""
    syms = sorted(functions(elf))
    log = os.path.join(os.path.dirname(MASKED_PLUGIN), "masked.txt")
    semihosting = "enable=on,target=native" + (f",arg={semihosting_arg}" if semihosting_arg else "")
    cmd = [QEMU, "-M", "mps2-an386", "-nographic", "-semihosting-config", semihosting, "-kernel", elf,
           "-plugin", masked_plugin_args(elf), "-d", "plugin", "-D", log] + qemu_args
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"{elf} failed ({done.returncode}):\n{done.stdout}{done.stderr}")
    stretches, notes = read_masked_log(log, syms)
    return stretches, notes, syms


def print_masked(stretches, notes, syms, check):
    """The longest stretches of each kind and where they began; fails over a budget if `check`:
    "primask" stretches hold off every interrupt, the pulse interrupt too (MASKED_BUDGET);
    "basepri" ones, the critical sections, every interrupt but it (SECTION_BUDGET)."""
    print(f"Longest stretches with interrupts masked, instructions on a Cortex-M4F (budgets: all masked "
          f"{MASKED_BUDGET}, all but the pulse interrupt {SECTION_BUDGET}):\n")
    print("| kind | longest | stretches | began at | called from |")
    print("|---|---:|---:|---|---|")
    over, summary = [], []
    for kind, budget in (("primask", MASKED_BUDGET), ("basepri", SECTION_BUDGET), ("section", None)):
        found = sorted(stretches.get(kind, []), reverse=True)
        for n, count, begin, call in found[:8]:
            print(f"| {kind} | {n} | {count} | {name_of(begin, syms)} | {name_of(call, syms)} |")
        longest = found[0][0] if found else 0
        if budget is not None:
            summary.append(f"longest {kind} stretch: {longest} instructions (budget {budget})")
            if longest > budget:
                over.append(f"a {kind} stretch of {longest} instructions, budget {budget}")
    print()
    for line in summary:
        print(line)
    for note in notes:
        print(f"\n{note}")
    if not stretches:
        sys.exit("no masked stretch seen: is this the image that was meant?")
    if check and over:
        sys.exit("over budget: " + "; ".join(over))


# The kinds the --kinds table shows, as shares of the instructions; the rest are "other".
KIND_GROUPS = [
    ("ALU", ["alu", "it", "it_folded"]),
    ("loads", ["load", "load_pipe", "load_pc", "pair"]),
    ("stores", ["store", "store_reg"]),
    ("multiple", ["multi"]),
    ("branches", ["branch", "table"]),
    ("MUL", ["mul"]),
    ("DIV", ["div"]),
    ("FPU", ["fp", "fp_mac", "fp_load", "fp_store", "fp_multi"]),
    ("VDIV/VSQRT", ["fp_divsqrt"]),
]


def print_kinds(rows):
    """Per case: the share of each group of kinds, the branches taken and the cache misses."""
    names = [name for name, _ in KIND_GROUPS]
    print("\n| case | " + " | ".join(names) + " | taken branches | flash cache misses | cycles per instruction |")
    print("|---|" + "---:|" * (len(names) + 3))
    for label, counts in rows:
        n = counts.instructions
        shares = [sum(counts.kind(k) for k in kinds) / n for _, kinds in KIND_GROUPS]
        cells = " | ".join(f"{100 * s:.1f} %" for s in shares)
        # The pulse path's are the difference of two runs: a cache may start the longer one
        # warmer, so its misses may come out a hair below none.
        misses = max(counts.misses, 0)
        print(f"| {label} | {cells} | {100 * counts.taken / n:.1f} % | {100 * misses / n:.2f} % "
              f"| {counts.cycles() / n:.2f} |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", help="run only the cases whose name contains this text")
    parser.add_argument("--profile", action="store_true", help="also print instructions per function")
    parser.add_argument("--kinds", action="store_true", help="also print the kinds of instructions per case")
    parser.add_argument("--no-build", action="store_true", help="use the harness and plugin as built")
    parser.add_argument("--write-model", metavar="FILE", help="write the simulator's CPU model from the counts")
    parser.add_argument("--check-model", metavar="FILE", help="fail if the simulator's CPU model is out of date")
    parser.add_argument("--check-budgets", action="store_true", help="fail if a case is over its budget")
    parser.add_argument("--masked", action="store_true",
                        help="print the longest stretch with interrupts masked instead (the harness's shared-state "
                             "operations, or --only's cases, or --image)")
    parser.add_argument("--image", help="with --masked: run this mps2-an386 image instead of the harness")
    parser.add_argument("--qemu-arg", action="append", default=[], help="with --masked --image: one more QEMU argument")
    args = parser.parse_args()
    if args.masked:
        if args.image:
            build_plugin(MASKED_SRC, MASKED_PLUGIN)
            found = masked_run(args.image, None, args.qemu_arg)
        else:
            if not args.no_build:
                build()
            found = masked_run(ELF, args.only or MASKED_CASES, [])
        print_masked(*found, args.check_budgets)
        return
    if not args.no_build:
        build()
    measured, blocks, syms, output = run(args.only, args.profile)
    cases = []
    for case, method, what in measured:
        if what == "interp" and (case, method) not in cases:
            cases.append((case, method))

    def per_step(case, method, what):
        if (case, method, what) not in measured:
            return None
        counts, steps = measured[(case, method, what)]
        return counts.instructions / max(steps, 1)

    pulse = Pulse(measured)

    def khz(cycles):
        return f"{CLOCK_HZ / cycles / 1000:.0f}"

    print("Instructions on a Cortex-M4F, counted; cycles on the STM32F407 from the Cortex-M4's "
          "instruction timings, step rates at 168 MHz.\n")
    print("| curve | method | setup (instructions) | steps | interpolator (instr/step) | + planner (instr/step) "
          "| + motion task (instr/step) | cycles/step (per instruction) | motion task alone tops out at (kHz) "
          "| with the pulses too (kHz) |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    kind_rows = []
    for case, method in cases:
        fmt = lambda v: "" if v is None else f"{v:.1f}"
        task = measured.get((case, method, "task"))
        setup = measured.get((case, method, "setup"), (None, 0))[0]
        steps = measured.get((case, method, "interp"), (None, 0))[1]
        cycles = task[0].cycles() / task[1] if task else None
        alone = khz(cycles) if cycles else ""
        both = khz(cycles + pulse.cycles()) if cycles and pulse.counts else ""
        cpi = f"{cycles:.0f} ({task[0].cycles() / task[0].instructions:.2f})" if task else ""
        print(f"| {case} | {method} | {setup.instructions if setup else ''} | {steps} "
              f"| {fmt(per_step(case, method, 'interp'))} | {fmt(per_step(case, method, 'planner'))} "
              f"| {fmt(per_step(case, method, 'task'))} | {cpi} | {alone} | {both} |")
        if task:
            kind_rows.append((f"{case} {method}", task[0]))
    if pulse.counts is not None:
        print(f"\nPulse path: {pulse.instructions():.1f} instructions per pulse (the step timer's interrupt, entry to "
              f"return, with the sleep around it), {pulse.cycles():.0f} cycles with the interrupt's entry and "
              f"return ({pulse.cycles() / pulse.instructions():.2f} per instruction, "
              f"{1e6 * pulse.cycles() / CLOCK_HZ:.2f} µs); alone it tops out at {khz(pulse.cycles())} kHz.")
        kind_rows.append(("pulse path", pulse.counts))
    if args.kinds:
        print_kinds(kind_rows)
    model = model_from(measured, pulse)
    output, longest = output
    facts = walked(output)
    figures = build_model(measured, facts)
    print_functions(measured, facts, figures)
    slice_ms = print_builds(measured, facts, figures, longest)
    model = model_from(measured, pulse)
    if model is not None and figures is not None:
        model += "\n".join(build_model_lines(figures)) + "\n"
    else:
        model = None
    if args.write_model:
        with open(args.write_model, "w") as f:
            f.write(model)
        print(f"\nwrote {args.write_model}")
    if args.check_model:
        check_model(args.check_model, model)
    if args.check_budgets:
        check_budgets(measured, pulse)
        if slice_ms is not None and slice_ms > BUILD_SLICE_BUDGET_MS:
            sys.exit(f"a slice of the builder takes {slice_ms:.2f} ms, budget {BUILD_SLICE_BUDGET_MS} ms")
        print(f"every slice of the builder within its budget ({BUILD_SLICE_BUDGET_MS} ms)")
    if args.profile:
        print_profile(blocks, syms)


if __name__ == "__main__":
    main()
