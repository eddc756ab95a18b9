#!/usr/bin/env python3
"""Fails if a firmware ELF image contains f64 arithmetic.

The Cortex-M4F's FPU is single precision: every f64 operation the compiler cannot do with
integer bit tricks becomes a call into the soft-float routines of compiler-builtins
(__aeabi_dadd, __adddf3, __aeabi_d2f, ...), and libm's f64 functions are built from them. So
the image is free of f64 arithmetic exactly when none of those routines is linked in; this
lists every one that is.
"""
import re
import struct
import sys

# The soft-float f64 routines of the ARM EABI and of compiler-builtins.
F64_ROUTINE = re.compile(
    r"^(__aeabi_(d[a-z0-9]+|[a-z0-9]+2d|cdcmp[a-z]*|cdrcmp[a-z]*)"
    r"|__(add|sub|mul|div|neg|pow[a-z]*)df3|__(eq|ne|lt|le|gt|ge|un|cmp)df2"
    r"|__(extendsfdf2|truncdfsf2|fix(uns)?df[sdt]i|float(un)?[sdt]idf))$"
)


def function_symbols(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != b"\x7fELF" or data[4] != 1:
        sys.exit(f"{path}: not a 32-bit ELF file")
    shoff, = struct.unpack_from("<I", data, 0x20)
    shentsize, shnum = struct.unpack_from("<HH", data, 0x2E)
    headers = [struct.unpack_from("<IIIIIIIIII", data, shoff + i * shentsize) for i in range(shnum)]
    for _, typ, _, _, off, size, link, _, _, entsize in headers:
        if typ != 2:  # SHT_SYMTAB
            continue
        strtab = headers[link][4]
        for i in range(size // entsize):
            name, _, _, info, _, _ = struct.unpack_from("<IIIBBH", data, off + i * entsize)
            if info & 0xF == 2:  # STT_FUNC
                end = data.index(b"\0", strtab + name)
                yield data[strtab + name:end].decode(errors="replace")


def main():
    found = sorted({s for s in function_symbols(sys.argv[1]) if F64_ROUTINE.match(s)})
    if found:
        print(f"f64 arithmetic in {sys.argv[1]}: {len(found)} soft-float routines linked:")
        for s in found:
            print(f"  {s}")
        sys.exit(1)
    print("no f64 arithmetic: no soft-float f64 routine is linked")


if __name__ == "__main__":
    main()
