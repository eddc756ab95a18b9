"""Reads what the checks need from a 32-bit little-endian ELF file: its sections and its
function and data symbols. Used by size.py, no_f64.py, the cost runner (cost/count.py) and the
model board's runner (model/run.py)."""
import struct
import sys

SHT_SYMTAB = 2
STT_OBJECT = 1
STT_FUNC = 2


def _read(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != b"\x7fELF" or data[4] != 1:
        sys.exit(f"{path}: not a 32-bit ELF file")
    shoff, = struct.unpack_from("<I", data, 0x20)
    shentsize, shnum, shstrndx = struct.unpack_from("<HHH", data, 0x2E)
    headers = [struct.unpack_from("<IIIIIIIIII", data, shoff + i * shentsize) for i in range(shnum)]
    return data, headers, shstrndx


def _name(data, table_offset, name):
    end = data.index(b"\0", table_offset + name)
    return data[table_offset + name:end].decode(errors="replace")


def sections(path):
    """(name, type, flags, address, size) of every section."""
    data, headers, shstrndx = _read(path)
    strtab = headers[shstrndx][4]
    return [(_name(data, strtab, name), typ, flags, addr, size) for name, typ, flags, addr, _, size, *_ in headers]


def _symbols(path, kind):
    data, headers, _ = _read(path)
    out = []
    for _, typ, _, _, off, size, link, _, _, entsize in headers:
        if typ != SHT_SYMTAB:
            continue
        strtab = headers[link][4]
        for i in range(size // entsize):
            name, value, sym_size, info, _, _ = struct.unpack_from("<IIIBBH", data, off + i * entsize)
            if info & 0xF == kind:
                out.append((value & ~1 if kind == STT_FUNC else value, sym_size, _name(data, strtab, name)))
    return out


def functions(path):
    """(address, size, name) of every function symbol, Thumb bit cleared."""
    return _symbols(path, STT_FUNC)


def objects(path):
    """(address, size, name) of every data symbol (statics)."""
    return _symbols(path, STT_OBJECT)
