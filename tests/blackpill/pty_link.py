"""USART2 bridged to a pseudo-terminal: `bowl send PTY ...` and `bowl monitor PTY` talk to the
emulated board as to a real one through a USB-serial adapter."""

import errno
import os
import tty


class PtyLink:
    def __init__(self, symlink: str = None):
        self.master, self.slave = os.openpty()
        # Raw, no echo: what the board sends must never come back to it as input.
        tty.setraw(self.slave)
        os.set_blocking(self.master, False)
        os.set_blocking(self.slave, False)
        self.path = os.ttyname(self.slave)
        self.symlink = symlink
        if symlink:
            if os.path.lexists(symlink):
                os.unlink(symlink)
            os.symlink(self.path, symlink)
        self.dropped = 0

    def send(self, data: bytes):
        try:
            os.write(self.master, data)
        except OSError as e:
            if e.errno not in (errno.EAGAIN, errno.EIO):
                raise
            # Nobody reading and the pty buffer full: drop the oldest bytes, as a real
            # adapter with no terminal attached loses them, so that whoever opens the port
            # next reads current frames.
            try:
                self.dropped += len(os.read(self.slave, 65536))
                os.write(self.master, data)
            except OSError:
                self.dropped += len(data)

    def receive(self) -> bytes:
        try:
            return os.read(self.master, 4096)
        except OSError as e:
            if e.errno in (errno.EAGAIN, errno.EIO):
                return b""
            raise

    def close(self):
        if self.symlink and os.path.islink(self.symlink):
            os.unlink(self.symlink)
        os.close(self.master)
        os.close(self.slave)
