#!/usr/bin/env python3
"""Fails if a firmware ELF image contains f64 arithmetic.

The Cortex-M4F's FPU is single precision: every f64 operation the compiler cannot do with
integer bit tricks becomes a call into the soft-float routines of compiler-builtins
(__aeabi_dadd, __adddf3, __aeabi_d2f, ...), and libm's f64 functions are built from them. So
the image is free of f64 arithmetic exactly when none of those routines is linked in; this
lists every one that is.
"""
import re
import sys

from elf import functions

# The soft-float f64 routines of the ARM EABI and of compiler-builtins.
F64_ROUTINE = re.compile(
    r"^(__aeabi_(d[a-z0-9]+|[a-z0-9]+2d|cdcmp[a-z]*|cdrcmp[a-z]*)"
    r"|__(add|sub|mul|div|neg|pow[a-z]*)df3|__(eq|ne|lt|le|gt|ge|un|cmp)df2"
    r"|__(extendsfdf2|truncdfsf2|fix(uns)?df[sdt]i|float(un)?[sdt]idf))$"
)


def main():
    found = sorted({name for _, _, name in functions(sys.argv[1]) if F64_ROUTINE.match(name)})
    if found:
        print(f"f64 arithmetic in {sys.argv[1]}: {len(found)} soft-float routines linked:")
        for s in found:
            print(f"  {s}")
        sys.exit(1)
    print("no f64 arithmetic: no soft-float f64 routine is linked")


if __name__ == "__main__":
    main()
