#!/usr/bin/env python3
"""A tap between a real terminal and the command it runs: every byte both ways, timestamped.

    tap.py LOG FIFO -- COMMAND...

Runs COMMAND (the ssh client) in a pseudo-terminal of the terminal's own size and copies bytes
both ways: what the terminal sends (its answers, typed keys) to the command, what the command
prints to the terminal. Bytes written to FIFO (by the harness: the busy stones and the timed
keys) go to the command as if typed. Each chunk is logged to LOG as it passes, with the time it
passed (CLOCK_MONOTONIC, the harness's clock too): a header line `cols rows`, then records of
`<d c I` (time, kind `O` output / `I` the terminal's input / `K` injected keys, length) and the
bytes. The output is written to the terminal before its record, so a slow terminal (it reads
what it draws) slows the tap's reading as it would slow ssh's.

Exits when the command does; bounded by the command's own end (the harness stops it).
"""

import fcntl
import os
import pty
import select
import signal
import struct
import sys
import termios
import time

RECORD = struct.Struct("<dcI")


def main():
    if len(sys.argv) < 5 or sys.argv[3] != "--":
        sys.exit("usage: tap.py LOG FIFO -- COMMAND...")
    log_path, fifo_path, cmd = sys.argv[1], sys.argv[2], sys.argv[4:]
    size = fcntl.ioctl(0, termios.TIOCGWINSZ, b"\0" * 8)
    rows, cols = struct.unpack("HHHH", size)[:2]
    pid, fd = pty.fork()
    if pid == 0:
        os.execvp(cmd[0], cmd)
    fcntl.ioctl(fd, termios.TIOCSWINSZ, size)
    saved = termios.tcgetattr(0)
    raw = termios.tcgetattr(0)
    # Raw: the terminal's bytes pass untouched (answers, Ctrl keys).
    raw[0] = 0
    raw[1] = 0
    raw[3] = 0
    raw[6][termios.VMIN], raw[6][termios.VTIME] = 1, 0
    termios.tcsetattr(0, termios.TCSANOW, raw)
    # Read-write: no end of file while the harness has not opened it yet.
    fifo = os.open(fifo_path, os.O_RDWR | os.O_NONBLOCK)
    log = open(log_path, "wb", buffering=0)
    log.write(f"{cols} {rows}\n".encode())

    def record(kind, data):
        # One unbuffered write a record: the harness follows the log as it grows.
        log.write(RECORD.pack(time.monotonic(), kind, len(data)) + data)

    signal.signal(signal.SIGTERM, lambda *_: (_ for _ in ()).throw(SystemExit(0)))
    try:
        while True:
            ready, _, _ = select.select([fd, 0, fifo], [], [], 1.0)
            if fd in ready:
                try:
                    data = os.read(fd, 65536)
                except OSError:
                    break
                if not data:
                    break
                write_all(1, data)
                record(b"O", data)
            if 0 in ready:
                data = os.read(0, 4096)
                if data:
                    write_all(fd, data)
                    record(b"I", data)
            if fifo in ready:
                data = os.read(fifo, 4096)
                if data:
                    write_all(fd, data)
                    record(b"K", data)
    finally:
        termios.tcsetattr(0, termios.TCSANOW, saved)
        log.close()
        try:
            os.kill(pid, signal.SIGTERM)
        except ProcessLookupError:
            pass


def write_all(fd, data):
    while data:
        data = data[os.write(fd, data) :]


def read_log(path):
    """The log's size and records: ((cols, rows), [(time, kind, bytes), ...])."""
    with open(path, "rb") as f:
        header = f.readline().split()
        size = (int(header[0]), int(header[1]))
        data = f.read()
    records, at = [], 0
    while at + RECORD.size <= len(data):
        t, kind, n = RECORD.unpack_from(data, at)
        at += RECORD.size
        records.append((t, kind.decode(), data[at : at + n]))
        at += n
    return size, records


if __name__ == "__main__":
    main()
