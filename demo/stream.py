#!/usr/bin/env python3
"""Stream a G-code file to a GRBL 1.1 port, as a character-counting sender does.

    python3 demo/stream.py demo/demo.gcode /dev/pts/3      # the simulator's `--pty` port
    python3 demo/stream.py drawing.gcode /dev/ttyUSB0      # the board's USB-serial adapter

Keeps as many lines in flight as the plotter's 128-byte receive buffer holds, sending the next
as each `ok` or `error:N` frees its bytes; asks `?` once a second; once every line is answered,
waits for the machine to come to rest and prints how long the job took. Python 3's standard
library only: the port is set to raw 115200 8N1 with termios (a pseudo-terminal takes any rate).
Exits 1 if any line was answered with an error or the machine ended in an alarm.
"""

import argparse
import os
import select
import sys
import termios
import time
import tty

RX_BUFFER_BYTES = 128
BAUD = termios.B115200
STATUS_INTERVAL_S = 1.0
ANSWER_TIMEOUT_S = 30.0


class Port:
    """A serial port read line by line, with a deadline."""

    def __init__(self, path):
        self.fd = os.open(path, os.O_RDWR | os.O_NOCTTY)
        tty.setraw(self.fd)
        mode = termios.tcgetattr(self.fd)
        mode[4] = mode[5] = BAUD
        termios.tcsetattr(self.fd, termios.TCSANOW, mode)
        self.pending = b""
        self.last_status = None

    def send(self, data):
        os.write(self.fd, data)

    def line(self, timeout_s):
        """The next line, without its line end; None if none came in `timeout_s`."""
        deadline = time.monotonic() + timeout_s
        while b"\n" not in self.pending:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([self.fd], [], [], left)[0]:
                return None
            self.pending += os.read(self.fd, 4096)
        line, self.pending = self.pending.split(b"\n", 1)
        return line.decode(errors="replace").strip()

    def answer(self, next_status):
        """The next `ok` or `error:N`, asking `?` when `next_status` (a list of one time) is due;
        other lines are printed."""
        deadline = time.monotonic() + ANSWER_TIMEOUT_S
        while time.monotonic() < deadline:
            if time.monotonic() >= next_status[0]:
                self.send(b"?")
                next_status[0] += STATUS_INTERVAL_S
            line = self.line(max(0.0, min(next_status[0], deadline) - time.monotonic()))
            if line is None or line == "":
                continue
            if line.startswith("<"):
                self.last_status = line
            if line == "ok" or line.startswith("error:"):
                return line
            print("   ", line)
        sys.exit(f"no answer within {ANSWER_TIMEOUT_S:.0f} s")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("gcode", help="the G-code file")
    parser.add_argument("port", help="the port's path")
    args = parser.parse_args()
    with open(args.gcode) as f:
        # `;` comments and blank lines stay here; `(...)` is left to the plotter, whose `$F`
        # expressions have parentheses.
        lines = [l.split(";", 1)[0].strip() for l in f]
    lines = [l for l in lines if l]
    port = Port(args.port)
    port.line(0.5)  # a banner waiting in the port, if any
    start = time.monotonic()
    next_status = [start]
    in_flight, errors = [], 0
    for n, line in enumerate(lines, 1):
        data = (line + "\n").encode()
        while in_flight and sum(in_flight) + len(data) > RX_BUFFER_BYTES:
            answer = port.answer(next_status)
            in_flight.pop(0)
            errors += answer.startswith("error:")
            print(f"  {answer}")
        port.send(data)
        in_flight.append(len(data))
        print(f"{n}: {line}")
    while in_flight:
        answer = port.answer(next_status)
        in_flight.pop(0)
        errors += answer.startswith("error:")
        print(f"  {answer}")
    # Every line answered; the motion may still run. Wait for the machine to rest.
    while True:
        port.send(b"?")
        status = port.line(ANSWER_TIMEOUT_S)
        if status is None:
            sys.exit("no status report")
        if status.startswith("<Idle") or status.startswith("<Alarm"):
            break
        if status.startswith("<"):
            print("   ", status)
        time.sleep(STATUS_INTERVAL_S)
    print(status)
    print(f"{len(lines)} lines, {errors} errors, {time.monotonic() - start:.1f} s")
    sys.exit(1 if errors or status.startswith("<Alarm") else 0)


if __name__ == "__main__":
    main()
