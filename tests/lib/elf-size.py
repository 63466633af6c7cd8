#!/usr/bin/env python3
"""Flash and static RAM of a 32-bit ARM ELF image, from its section headers (no binutils needed).

flash = every allocated section with contents (vector table, text, rodata, .data's load image)
ram   = every allocated section that lives in RAM: .data, .bss, .uninit (the stack is not static)

Usage: elf-size.py ELF [--max-flash-kib N] [--max-ram-kib N]; prints one line and exits 1 when a
budget is exceeded.
"""
import struct
import sys

SHF_ALLOC = 0x2
SHT_NOBITS = 8
RAM_START, RAM_END = 0x2000_0000, 0x4000_0000


def sections(path):
    data = open(path, "rb").read()
    if data[:4] != b"\x7fELF" or data[4] != 1:
        raise SystemExit(f"{path}: not a 32-bit ELF")
    shoff, = struct.unpack_from("<I", data, 0x20)
    shentsize, shnum, shstrndx = struct.unpack_from("<HHH", data, 0x2E)
    headers = [struct.unpack_from("<IIIIIIIIII", data, shoff + i * shentsize) for i in range(shnum)]
    strtab_off = headers[shstrndx][4]
    for name_off, typ, flags, addr, _off, size, *_ in headers:
        end = data.index(b"\0", strtab_off + name_off)
        yield data[strtab_off + name_off:end].decode(), typ, flags, addr, size


def main():
    args = sys.argv[1:]
    path = args[0]
    max_flash = float(args[args.index("--max-flash-kib") + 1]) if "--max-flash-kib" in args else None
    max_ram = float(args[args.index("--max-ram-kib") + 1]) if "--max-ram-kib" in args else None
    flash = ram = 0
    for name, typ, flags, addr, size in sections(path):
        if not flags & SHF_ALLOC or size == 0:
            continue
        in_ram = RAM_START <= addr < RAM_END
        if typ != SHT_NOBITS:
            flash += size  # .data counts here too: its initial values are stored in flash
        if in_ram:
            ram += size
    ok = (max_flash is None or flash <= max_flash * 1024) and (max_ram is None or ram <= max_ram * 1024)
    budget = ""
    if max_flash is not None or max_ram is not None:
        budget = f" (budget {max_flash:g} KiB flash, {max_ram:g} KiB RAM: {'ok' if ok else 'EXCEEDED'})"
    print(f"{path}: flash {flash} B ({flash / 1024:.1f} KiB), static RAM {ram} B ({ram / 1024:.1f} KiB){budget}")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
