#!/usr/bin/env python3
"""Prints the flash and static RAM a firmware ELF image uses, from its section headers; with
--max-flash-kib N, fails when the flash used is above N KiB."""
import sys

from elf import sections

FLASH = (0x08000000, 1024 * 1024)
RAM = (0x20000000, 128 * 1024)


def main():
    flash = ram = 0
    for name, typ, flags, addr, size in sections(sys.argv[1]):
        if not flags & 0x2:  # SHF_ALLOC
            continue
        in_flash = FLASH[0] <= addr < FLASH[0] + FLASH[1]
        in_ram = RAM[0] <= addr < RAM[0] + RAM[1]
        if in_flash:
            flash += size
        if in_ram:
            ram += size
            if typ != 8:  # not NOBITS: .data's initial values are stored in flash too
                flash += size
    print(f"flash: {flash} bytes ({flash / FLASH[1]:.1%} of {FLASH[1] // 1024} KiB)")
    print(f"static RAM: {ram} bytes ({ram / RAM[1]:.1%} of {RAM[1] // 1024} KiB)")
    if len(sys.argv) == 4 and sys.argv[2] == "--max-flash-kib":
        limit = int(sys.argv[3]) * 1024
        if flash > limit:
            sys.exit(f"flash {flash} bytes is above the {limit // 1024} KiB budget")
        print(f"flash within the {limit // 1024} KiB budget")


if __name__ == "__main__":
    main()
