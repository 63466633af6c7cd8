"""defmt over RTT: reads the firmware's RTT up-channel 0 from emulated RAM (as a debug probe
does) and pipes the bytes to `defmt-print`, which decodes them with the image's symbols into
a log file."""

import subprocess
import struct

from elftools.elf.elffile import ELFFile


def symbol_address(elf_path: str, name: str):
    with open(elf_path, "rb") as f:
        symtab = ELFFile(f).get_section_by_name(".symtab")
        for sym in symtab.get_symbol_by_name(name) or []:
            return sym["st_value"]
    return None


class RttReader:
    def __init__(self, elf_path: str, defmt_print: str, log_path: str):
        self.block = symbol_address(elf_path, "_SEGGER_RTT")
        if self.block is None:
            raise RuntimeError(f"{elf_path}: no _SEGGER_RTT symbol: is it a defmt-rtt image?")
        self.log = open(log_path, "ab")
        self.decoder = subprocess.Popen(
            [defmt_print, "-e", elf_path, "stdin"],
            stdin=subprocess.PIPE, stdout=self.log, stderr=subprocess.STDOUT)
        self.bytes_read = 0

    def poll(self, mem):
        """Moves whatever the firmware has written since the last poll to the decoder."""
        try:
            ident = bytes(mem.read(self.block, 16))
        except Exception:
            return
        if not ident.startswith(b"SEGGER RTT"):
            return  # not initialised yet (before the first defmt log call)
        up = self.block + 24
        buf, size, wr, rd = struct.unpack("<4I", bytes(mem.read(up + 4, 16)))
        if wr == rd or size == 0:
            return
        if wr > rd:
            data = bytes(mem.read(buf + rd, wr - rd))
        else:
            data = bytes(mem.read(buf + rd, size - rd)) + bytes(mem.read(buf, wr))
        mem.write(up + 16, struct.pack("<I", wr))
        self.bytes_read += len(data)
        try:
            self.decoder.stdin.write(data)
            self.decoder.stdin.flush()
        except BrokenPipeError:
            pass

    def close(self):
        try:
            self.decoder.stdin.close()
        except BrokenPipeError:
            pass
        self.decoder.wait(timeout=10)
        self.log.close()
