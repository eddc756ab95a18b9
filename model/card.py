#!/usr/bin/env python3
"""Plots a file from the microSD card on QEMU's mps2-an386, the Cortex-M4F model board.

The card is a FAT16 image holding model/plot.gcode (every kind of curve at the highest pulse
rate the README claims for it, `$205` set by the file itself), which QEMU loads into the model's
PSRAM; the model reads it a block at a time in the F407's time for the SPI transfer
(src/board/mps2_an386/card.rs). The keys are tapped on the model's third UART
(src/board/mps2_an386/keys.rs): the card mode, the file, and `#` once it is checked. Meanwhile
the host link asks `?` at 5 Hz and the LCD redraws the run screen: every task runs.

    python3 model/card.py                 # build, make the card, plot it, check it against the simulator
    python3 model/card.py --no-build      # use the image as built

It fails unless the plot starts and ends, every status report is well formed, no step-queue
underrun and no missed timer update is reported, the pulses and the final position are the
simulator's for the same card and keys, the plot kept its resume record on the card (written
at most once a second as it ran, cleared at its end, every write taken), the stack's peak stays
under half the stack and no task poll took 10 ms or more of the F407's time (`$I`).
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import run  # noqa: E402  (the model runner: QEMU's command, the host link, the monitor)

GCODE = os.path.join(HERE, "plot.gcode")
IMAGE = os.path.join(ROOT, "target", "model", "card.img")
# A 16 MiB FAT16 volume (mkfs.fat makes FAT12 below 16 MiB), as the README makes one.
IMAGE_KIB = 16384
# Where QEMU loads it: the model's PSRAM (src/board/mps2_an386/card.rs).
IMAGE_ADDR = 0x2100_0000
# From power-on: the card mode (the eleventh mode: ten times B, then #), its one file chosen.
KEYS_TO_CHECK = "BBBBBBBBBB##"
# Once checked, `#` plots it: tapped every few seconds of wall time until the plot runs (a `#`
# while the file is checked does nothing).
PLOT_TAP_PERIOD_S = 2.0
# The simulator's keys: the same, the last `#` once the check is done (it takes no time there).
SIM_KEYS = "B B B B B B B B B B # # wait:3000 #"
RUN_TIMEOUT_S = 900
LINE = re.compile(r"\|Ln:(\d+)")


def make_image():
    os.makedirs(os.path.dirname(IMAGE), exist_ok=True)
    if os.path.exists(IMAGE):
        os.remove(IMAGE)
    subprocess.run(["mkfs.fat", "-F", "16", "-C", IMAGE, str(IMAGE_KIB)], check=True, capture_output=True)
    subprocess.run(["mcopy", "-i", IMAGE, GCODE, "::plot.gcode"], check=True)


def simulate():
    """The simulator's pulses and final position for the same card and keys."""
    out_dir = os.path.join(ROOT, "target", "model", "sim-card")
    done = subprocess.run(["cargo", "run", "--release", "--locked", "--quiet", "--target", "host-tuple", "--",
                           "--sd", IMAGE, "--keys-text", SIM_KEYS, "--out", out_dir],
                          cwd=ROOT, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"the simulator failed:\n{done.stderr}")
    return run.sim_summary(done.stderr)


def plot(link, keys):
    """Taps the keys to the checked file, then `#` until it plots; `?` at 5 Hz until it ends.
    The status reports seen while it ran."""
    keys.sendall(KEYS_TO_CHECK.encode())
    end = time.time() + RUN_TIMEOUT_S
    started = False
    next_tap = time.time() + PLOT_TAP_PERIOD_S
    while time.time() < end:
        status = link.status_now()
        m = LINE.search(status)
        if not started:
            started = bool(m and int(m.group(1)) > 0)
            if not started and time.time() > next_tap:
                keys.sendall(b"#")
                next_tap = time.time() + PLOT_TAP_PERIOD_S
        elif not m and status.startswith("<Idle"):
            return status
        time.sleep(run.POLL_PERIOD_S)
    sys.exit(f"the card plot did not {'end' if started else 'start'} within {RUN_TIMEOUT_S} s")


def check():
    failures = []
    make_image()
    print(f"card: {IMAGE} with {os.path.relpath(GCODE, ROOT)}; simulator: --sd {os.path.relpath(IMAGE, ROOT)} "
          f"--keys-text \"{SIM_KEYS}\"")
    sim_pulses, sim_position = simulate()

    work = tempfile.mkdtemp(prefix="servoplot-model-card-")
    host_path, keys_path, mon_path = (os.path.join(work, n) for n in ("uart0", "uart2", "monitor"))
    defmt_path = os.path.join(ROOT, "target", "model", "defmt-card.bin")
    cmd = run.qemu_command("chardev:host", [
        "-serial", "chardev:keys",
        "-device", f"loader,file={IMAGE},addr={IMAGE_ADDR:#x},force-raw=on",
        "-chardev", f"socket,id=host,path={host_path},server=on,wait=on",
        "-chardev", f"socket,id=keys,path={keys_path},server=on,wait=off",
        "-monitor", f"unix:{mon_path},server=on,wait=off"])
    print("model: " + " ".join(cmd))
    log = open(defmt_path, "wb")
    qemu = subprocess.Popen(cmd, stdout=log, stderr=subprocess.PIPE)
    started = time.time()
    try:
        link = run.Link(run.connect(host_path))
        status = plot(link, run.connect(keys_path))
        _, info, pulses = run.finish(link, mon_path)
    finally:
        try:
            qemu.wait(timeout=10)
        except subprocess.TimeoutExpired:
            qemu.kill()
        log.close()
    stderr = qemu.stderr.read().decode(errors="replace")
    if stderr.strip():
        print(stderr)

    print(f"\nplotted from the card in {time.time() - started:.1f} s of wall time; "
          f"{len(link.statuses)} status reports")
    run.check_reports(link.statuses, failures)
    lines = [int(m.group(1)) for s in link.statuses for m in [LINE.search(s)] if m]
    print(f"lines reported in `|Ln:`: up to {max(lines, default=0)}")
    run.check_motion(pulses, status, sim_pulses, sim_position, failures)
    run.check_health(info, failures)
    text = run.decode_log(defmt_path)
    with open(os.path.join(ROOT, "target", "model", "defmt-card.txt"), "w") as f:
        f.write(text)
    for what, pattern in (("check", r"card file checked"), ("plot", r"card plot: all \d+ lines sent"),
                          ("resume record", r"resume record, kept [1-9]\d* times, cleared")):
        found = [l for l in text.splitlines() if re.search(pattern, l)]
        if not found:
            failures.append(f"the defmt log has no {what} line")
        else:
            print(f"defmt ({what}): {found[-1].strip()}")
    for line in text.splitlines():
        if "resume record not" in line:
            failures.append(f"a resume record was not written: {line.strip()}")
    if failures:
        print("\nthe model's card plot FAILED:\n  " + "\n  ".join(failures))
        sys.exit(1)
    print("\nthe model's card plot matches the simulator")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-build", action="store_true", help="use the image as built")
    args = parser.parse_args()
    if not args.no_build:
        run.build()
    check()


if __name__ == "__main__":
    main()
