#!/usr/bin/env python3
"""Runs the servoplot firmware on QEMU's mps2-an386, the Cortex-M4F model board.

The image is the firmware's own (its tasks, executors, priorities, stack and statics), built for
the model's UART, timers and memory (`src/board/mps2_an386`). QEMU counts time in instructions
(`-icount`), and the model's clock turns them into the STM32F407's time.

    python3 model/run.py                  # build, boot, stream model/plot.gcode, check it against the simulator
    python3 model/run.py --gcode FILE     # another G-code file
    python3 model/run.py --pty            # boot and serve the host link on a pseudo-terminal for a sender

A check streams the file over the model's UART as a character-counting sender does, with `?`
polls at 5 Hz and a feed hold and resume part way, and runs the same file through the simulator
(`cargo sim --serial FILE`). It fails unless every line is answered as the simulator answers it,
every status report is well formed, the pulses the model's step timer emitted and the final
position are the simulator's, no step-queue underrun and no missed timer update is reported,
the stack's peak (`$I`) stays under half the stack, no task poll took 10 ms or more of its own work
(the motion task's polls that preempted it not counted; `$I` gives both), no stretch
with interrupts masked is over its budget (the cost runner's masked plugin follows the whole
run: `cost/count.py --masked`), and the firmware's defmt log, decoded with defmt-print, has its
boot, settings and job lines.
"""
import argparse
import os
import re
import socket
import subprocess
import sys
import tempfile
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(ROOT, ".ci"))
sys.path.insert(0, os.path.join(ROOT, "cost"))
from elf import functions, objects  # noqa: E402
import count  # noqa: E402  (the cost runner: its masked-stretch plugin and report)

TARGET = "thumbv7em-none-eabihf"
BIN = "servoplot-mps2-an386"
ELF = os.path.join(ROOT, "target", TARGET, "release", BIN)
GCODE = os.path.join(HERE, "plot.gcode")
QEMU = "qemu-system-arm"
# Each instruction takes 2^4 ns of QEMU's virtual time; the model's clock is built on it
# (src/board/mps2_an386/clock.rs). Idle time is skipped.
ICOUNT = "shift=4,sleep=off"

# What a character-counting sender may keep unanswered (GRBL's receive buffer, `$I`'s [OPT:]).
RX_WINDOW_BYTES = 128
# How often the sender asks `?`, s.
POLL_PERIOD_S = 0.2
# The feed hold comes after this share of the file's lines, and the resume once it holds.
HOLD_AT = 0.4
# Limits of the check.
POLL_MAX_US = 10_000
STACK_MAX_SHARE = 0.5
# Longest a run may take, s of wall time.
RUN_TIMEOUT_S = 600

STATUS = re.compile(r"^<(Idle|Run|Hold:[01]|Jog|Alarm|Door:[0-3]|Check|Home|Sleep)(\|[A-Za-z]+:[^|>]*)*>$")


def build():
    subprocess.run(["cargo", "build", "--release", "--locked", "--features", "mps2-an386", "--bin", BIN],
                   cwd=ROOT, check=True)


def qemu_command(serial, extra=()):
    return [QEMU, "-M", "mps2-an386", "-display", "none", "-icount", ICOUNT,
            "-semihosting-config", "enable=on,target=native", "-kernel", ELF,
            "-serial", serial, "-serial", "null", *extra]


class Link:
    """The host side of the model's UART: lines in, answers and status reports out."""

    def __init__(self, sock):
        self.sock = sock
        self.answers = []
        self.statuses = []
        self.answered = threading.Semaphore(0)
        self.lock = threading.Lock()
        self.closed = False
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        pending = b""
        while True:
            try:
                data = self.sock.recv(4096)
            except OSError:
                data = b""
            if not data:
                self.closed = True
                self.answered.release()
                return
            pending += data
            while b"\n" in pending:
                line, pending = pending.split(b"\n", 1)
                text = line.decode(errors="replace").rstrip("\r")
                with self.lock:
                    if text.startswith("<"):
                        self.statuses.append(text)
                    else:
                        self.answers.append(text)
                if text == "ok" or text.startswith("error:"):
                    self.answered.release()

    def send(self, data):
        self.sock.sendall(data)

    def last_status(self):
        with self.lock:
            return self.statuses[-1] if self.statuses else ""

    def status_now(self, timeout_s=5.0):
        """Asks `?` and waits for the answer."""
        with self.lock:
            seen = len(self.statuses)
        self.send(b"?")
        end = time.time() + timeout_s
        while time.time() < end:
            with self.lock:
                if len(self.statuses) > seen:
                    return self.statuses[-1]
            time.sleep(0.005)
        raise SystemExit("the model answered no `?`")


def stream(link, lines):
    """Character counting: as many lines in flight as GRBL's receive buffer holds; `?` at 5 Hz;
    a feed hold part way, resumed once the machine holds."""
    in_flight = []
    next_poll = time.time()
    hold_line = int(len(lines) * HOLD_AT)
    held = False
    for k, line in enumerate(lines):
        data = (line + "\n").encode()
        while sum(in_flight) + len(data) > RX_WINDOW_BYTES:
            if not link.answered.acquire(timeout=POLL_PERIOD_S):
                if time.time() > next_poll:
                    link.send(b"?")
                    next_poll = time.time() + POLL_PERIOD_S
                continue
            if link.closed:
                raise SystemExit("the model closed its UART")
            in_flight.pop(0)
        link.send(data)
        in_flight.append(len(data))
        if time.time() > next_poll:
            link.send(b"?")
            next_poll = time.time() + POLL_PERIOD_S
        if k == hold_line and not held:
            held = True
            link.send(b"!")
            end = time.time() + 30
            while not link.status_now().startswith("<Hold:0"):
                if time.time() > end:
                    raise SystemExit("the feed hold never held")
                time.sleep(0.05)
            link.send(b"~")
    while in_flight:
        if link.answered.acquire(timeout=POLL_PERIOD_S):
            if link.closed:
                raise SystemExit("the model closed its UART")
            in_flight.pop(0)
        elif time.time() > next_poll:
            link.send(b"?")
            next_poll = time.time() + POLL_PERIOD_S


def monitor(path, command):
    """One command to QEMU's monitor; its answer."""
    with socket.socket(socket.AF_UNIX) as s:
        s.connect(path)
        s.settimeout(5)
        out = b""
        while not out.endswith(b"(qemu) "):
            out += s.recv(4096)
        s.sendall(command.encode() + b"\n")
        out = b""
        while not out.endswith(b"(qemu) "):
            chunk = s.recv(4096)
            if not chunk:
                break
            out += chunk
        return out.decode(errors="replace")


def read_words(mon, address, count):
    text = monitor(mon, f"xp /{count}wu {address:#x}")
    values = re.findall(r":\s*((?:\d+\s*)+)", text)
    return [int(v) for v in " ".join(values).split()][:count]


def symbol(name):
    found = [(a, s) for a, s, n in objects(ELF) if name in n]
    if len(found) != 1:
        sys.exit(f"{name}: {len(found)} symbols in {ELF}")
    return found[0]


def finish(link, mon_path):
    """At the end of a run: the answers so far, the `$I` answer's lines (the stack's peak, the
    longest poll) and the pulses the model emitted (`PULSES_EMITTED`, read through the
    monitor); then QEMU quits."""
    with link.lock:
        before = list(link.answers)
    link.send(b"$I\n")
    link.answered.acquire(timeout=10)
    with link.lock:
        info = link.answers[len(before):]
    address, _ = symbol("PULSES_EMITTED")
    pulses = read_words(mon_path, address, 4)
    monitor(mon_path, "quit")
    return before, info, pulses


def simulate(path):
    """The simulator's answers, pulses and final position for the same file."""
    out_dir = os.path.join(ROOT, "target", "model", "sim")
    done = subprocess.run(["cargo", "run", "--release", "--locked", "--quiet", "--target", "host-tuple", "--",
                           "--serial", path, "--out", out_dir], cwd=ROOT, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"the simulator failed:\n{done.stderr}")
    # The answers on standard output, the summary on standard error.
    lines = [l for l in done.stdout.splitlines() if l.strip() and not l.startswith("<")]
    return (lines, *sim_summary(done.stderr))


def sim_summary(stderr):
    """The pulses and the final position the simulator's summary gives."""
    summary = stderr.partition("pulses: ")[2]
    m = re.match(r"X (\d+) forward, (\d+) back; Y (\d+) forward, (\d+) back", summary)
    p = re.search(r"final position: X (-?[\d.]+) mm, Y (-?[\d.]+) mm", summary)
    if not m or not p:
        sys.exit(f"cannot read the simulator's summary:\n{summary}")
    return [int(v) for v in m.groups()], (float(p.group(1)), float(p.group(2)))


def connect(path):
    """The client end of one of QEMU's Unix sockets, once QEMU has made it."""
    for _ in range(500):
        if os.path.exists(path):
            break
        time.sleep(0.01)
    sock = socket.socket(socket.AF_UNIX)
    sock.connect(path)
    return sock


def check_reports(statuses, failures):
    """Every status report well formed, and none counting an underrun or a missed update."""
    bad = [s for s in statuses if not STATUS.match(s)]
    if bad:
        failures.append(f"malformed status report: {bad[0]!r}")
    for field, what in (("Un:", "step-queue underruns"), ("Mu:", "missed timer updates")):
        counted = [s for s in statuses if "|" + field in s]
        if counted:
            failures.append(f"{what}: {counted[-1]}")


def check_motion(pulses, status, sim_pulses, sim_position, failures):
    """The model's pulses and final position (from its last status report) are the simulator's."""
    print(f"pulses: model X {pulses[0]} forward, {pulses[1]} back; Y {pulses[2]} forward, {pulses[3]} back")
    print(f"        simulator X {sim_pulses[0]} forward, {sim_pulses[1]} back; Y {sim_pulses[2]} forward, "
          f"{sim_pulses[3]} back")
    if pulses != sim_pulses:
        failures.append("the model's pulses are not the simulator's")
    m = re.search(r"MPos:(-?[\d.]+),(-?[\d.]+)", status)
    position = (float(m.group(1)), float(m.group(2))) if m else None
    print(f"final position: model {position}, simulator {sim_position}")
    if position != sim_position:
        failures.append("the model's final position is not the simulator's")


def check_health(info, failures):
    """`$I`'s stack peak under half the stack, and no task poll of 10 ms or more of its own."""
    stack = next((re.match(r"\[STACK:(\d+),(\d+)\]", l) for l in info if l.startswith("[STACK:")), None)
    poll = next((re.match(r"\[POLL:(\d+),(\d+)\]", l) for l in info if l.startswith("[POLL:")), None)
    if not stack or not poll:
        failures.append(f"`$I` gave no stack or poll figure: {info}")
        return
    peak, size, poll_us = int(stack.group(1)), int(stack.group(2)), int(poll.group(1))
    print(f"stack: {peak} of {size} bytes at most ({peak / size:.0%}); longest task poll: "
          f"{poll_us / 1000:.2f} ms of the F407's time, {int(poll.group(2)) / 1000:.2f} ms with the "
          f"motion task's polls that preempted it")
    if peak > STACK_MAX_SHARE * size:
        failures.append(f"the stack's peak is over {STACK_MAX_SHARE:.0%} of the stack")
    if poll_us >= POLL_MAX_US:
        failures.append(f"a task poll took {poll_us} us, {POLL_MAX_US} at most")


def decode_log(defmt_path):
    done = subprocess.run(["defmt-print", "-e", ELF], stdin=open(defmt_path, "rb"), capture_output=True, text=True)
    return done.stdout + done.stderr


def check(args):
    failures = []
    with open(args.gcode) as f:
        lines = [l.rstrip("\r\n") for l in f]
    print(f"simulator: {args.gcode}")
    sim_answers, sim_pulses, sim_position = simulate(args.gcode)

    work = tempfile.mkdtemp(prefix="servoplot-model-")
    sock_path, mon_path = os.path.join(work, "uart0"), os.path.join(work, "monitor")
    defmt_path = os.path.join(ROOT, "target", "model", "defmt.bin")
    os.makedirs(os.path.dirname(defmt_path), exist_ok=True)
    masked_log = os.path.join(ROOT, "target", "model", "masked.txt")
    plugin = ["-plugin", count.masked_plugin_args(ELF), "-d", "plugin", "-D", masked_log]
    cmd = qemu_command("chardev:host", plugin + args.qemu_arg) + [
        "-chardev", f"socket,id=host,path={sock_path},server=on,wait=on",
        "-monitor", f"unix:{mon_path},server=on,wait=off"]
    print("model: " + " ".join(cmd))
    log = open(defmt_path, "wb")
    qemu = subprocess.Popen(cmd, stdout=log, stderr=subprocess.PIPE)
    started = time.time()
    try:
        link = Link(connect(sock_path))
        stream(link, lines)
        # At rest: the final position and the status fields.
        end = time.time() + 60
        status = link.status_now()
        while not status.startswith("<Idle"):
            if time.time() > end:
                failures.append(f"not at rest after the last line: {status}")
                break
            time.sleep(0.05)
            status = link.status_now()
        answers, info, pulses = finish(link, mon_path)
    finally:
        try:
            qemu.wait(timeout=10)
        except subprocess.TimeoutExpired:
            qemu.kill()
        log.close()
    elapsed = time.time() - started
    stderr = qemu.stderr.read().decode(errors="replace")
    if stderr.strip():
        print(stderr)

    model_answers = [a for a in answers if a.strip()]
    print(f"\n{len(lines)} lines streamed in {elapsed:.1f} s of wall time; {len(model_answers)} answers, "
          f"{len(link.statuses)} status reports")
    if model_answers != sim_answers:
        for k, (a, b) in enumerate(zip(model_answers, sim_answers)):
            if a != b:
                failures.append(f"answer {k + 1}: the model says {a!r}, the simulator {b!r}")
                break
        else:
            failures.append(f"{len(model_answers)} answers from the model, {len(sim_answers)} from the simulator")
    check_reports(link.statuses, failures)
    check_motion(pulses, status, sim_pulses, sim_position, failures)
    check_health(info, failures)

    print()
    stretches, notes = count.read_masked_log(masked_log, sorted(functions(ELF)))
    try:
        count.print_masked(stretches, notes, sorted(functions(ELF)), True)
    except SystemExit as over:
        failures.append(str(over))
    print()

    text = decode_log(defmt_path)
    with open(os.path.join(ROOT, "target", "model", "defmt.txt"), "w") as f:
        f.write(text)
    for what, pattern in (("boot", r"servoplot \S+ on mps2-an386"), ("settings", r"settings loaded"),
                          ("job", r"job planned to"), ("health", r"longest poll")):
        found = [l for l in text.splitlines() if re.search(pattern, l)]
        if not found:
            failures.append(f"the defmt log has no {what} line")
        else:
            print(f"defmt ({what}, {len(found)}): {found[-1].strip()}")
    if failures:
        print("\nthe model run FAILED:\n  " + "\n  ".join(failures))
        sys.exit(1)
    print("\nthe model run matches the simulator")


def serve_pty():
    cmd = qemu_command("pty")
    print("model: " + " ".join(cmd), file=sys.stderr)
    qemu = subprocess.Popen(cmd, stdout=subprocess.PIPE)
    # QEMU names the pseudo-terminal on its standard output; the defmt log follows there.
    line = qemu.stdout.readline().decode(errors="replace").strip()
    print(f"{line}: connect a sender or a terminal to it; Ctrl-C ends", file=sys.stderr)
    printer = subprocess.Popen(["defmt-print", "-e", ELF], stdin=subprocess.PIPE)

    def forward():
        while chunk := qemu.stdout.read1(4096):
            printer.stdin.write(chunk)
            printer.stdin.flush()
        printer.stdin.close()

    threading.Thread(target=forward, daemon=True).start()
    try:
        qemu.wait()
    except KeyboardInterrupt:
        qemu.terminate()
        qemu.wait()
    printer.wait()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--gcode", default=GCODE, help="the G-code file to stream (default: model/plot.gcode)")
    parser.add_argument("--pty", action="store_true", help="serve the host link on a pseudo-terminal instead")
    parser.add_argument("--no-build", action="store_true", help="use the image as built")
    parser.add_argument("--qemu-arg", action="append", default=[],
                        help="one more argument for QEMU (a plugin, say: --qemu-arg=-plugin --qemu-arg=FILE)")
    args = parser.parse_args()
    if not args.no_build:
        build()
    if args.pty:
        serve_pty()
    else:
        check(args)


if __name__ == "__main__":
    main()
