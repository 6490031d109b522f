"""Rows read by a real terminal emulator under Xvfb (kitty, xterm): the terminal reads the link
and answers the player's questions itself; `tap.py` between it and the ssh client timestamps
both directions and types the harness's keys; the harness follows the tap's log with the same
pyte screen as its own terminal (pictures' APC and DCS strings dropped), so a row's figures mean
the same as the pyte rows': when the status line's bytes reached the terminal.
"""

import os
import shutil
import subprocess
import threading
import time

from lab import HERE, stop
from pty_terminal import Screen
from tap import RECORD

TERMINALS = {
    # kitty with Mesa's softpipe (llvmpipe draws a ghost status line: scripts/kitty_ghost.sh),
    # 960x640; xterm as a VT340 (sixel) with 256 colour registers, 120x40.
    "kitty": lambda cmd, driver="softpipe": [
        "env", "LIBGL_ALWAYS_SOFTWARE=1", f"GALLIUM_DRIVER={driver}",
        "kitty", "-o", "initial_window_width=960", "-o", "initial_window_height=640", "-o", "remember_window_size=no",
        *cmd,
    ],
    "xterm": lambda cmd, driver=None: [
        "xterm", "-ti", "vt340", "-xrm", "XTerm*numColorRegisters: 256", "-xrm", "XTerm*maxGraphicSize: 2000x2000",
        "-geometry", "120x40+0+0", "-e", *cmd,
    ],
}
# The part of the 1600x1000 root window each terminal's window covers (no window manager).
CROPS = {"kitty": "960x640+0+0", "xterm": "730x530+0+0"}


class Display:
    """One Xvfb for the run, started on first use, stopped by `close`."""

    def __init__(self, display):
        self.display = display
        self.proc = None

    def env(self):
        if self.proc is None:
            for tool in ("Xvfb", "kitty", "xterm", "import"):
                if not shutil.which(tool):
                    raise RuntimeError(f"{tool} is missing: apt-get install -y xvfb kitty xterm imagemagick")
            if os.path.exists(f"/tmp/.X11-unix/X{self.display.lstrip(':')}"):
                raise RuntimeError(f"the X display {self.display} is taken: choose another with --display")
            self.proc = subprocess.Popen(["Xvfb", self.display, "-screen", "0", "1600x1000x24"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            time.sleep(2)
        env = dict(os.environ, DISPLAY=self.display)
        for var in ("TMUX", "STY", "SSH_CONNECTION", "SSH_TTY", "KITTY_WINDOW_ID", "TERM_PROGRAM", "COLORTERM"):
            env.pop(var, None)
        return env

    def close(self):
        if self.proc:
            stop(self.proc)


class TappedTerminal(Screen):
    """A real terminal running `cmd` through the tap; keys go in through the tap's FIFO."""

    def __init__(self, name, cmd, display, folder, raw_path=None, driver="softpipe"):
        self.name = name
        self.log_path = os.path.join(folder, f"tap-{name}.log")
        self.fifo_path = os.path.join(folder, f"tap-{name}.fifo")
        for path in (self.log_path, self.fifo_path):
            if os.path.exists(path):
                os.remove(path)
        os.mkfifo(self.fifo_path)
        tap = ["python3", os.path.join(HERE, "tap.py"), self.log_path, self.fifo_path, "--", *cmd]
        self.env = display.env()
        self.output = open(os.path.join(folder, f"{name}.out"), "wb")
        self.proc = subprocess.Popen(TERMINALS[name](tap, driver), env=self.env, stdin=subprocess.DEVNULL, stdout=self.output, stderr=subprocess.STDOUT)
        # The log's header says the terminal's size.
        deadline = time.monotonic() + 30
        while True:
            try:
                with open(self.log_path, "rb") as f:
                    header = f.readline()
                if header.endswith(b"\n"):
                    break
            except FileNotFoundError:
                pass
            if time.monotonic() > deadline or self.proc.poll() is not None:
                raise RuntimeError(f"{name} did not start the tap")
            time.sleep(0.05)
        cols, rows = (int(v) for v in header.split())
        self.size = (cols, rows)
        self.fifo = os.open(self.fifo_path, os.O_WRONLY | os.O_NONBLOCK)
        super().__init__(cols, rows, raw_path)
        self.follower = threading.Thread(target=self.follow, args=(len(header),), daemon=True)
        self.follower.start()

    def follow(self, offset):
        """Follows the tap's log: the terminal's output records, with the tap's times."""
        with open(self.log_path, "rb") as f:
            f.seek(offset)
            buf = b""
            while not self.done:
                chunk = f.read(65536)
                if not chunk:
                    time.sleep(0.002)
                    continue
                buf += chunk
                while len(buf) >= RECORD.size:
                    t, kind, n = RECORD.unpack_from(buf)
                    if len(buf) < RECORD.size + n:
                        break
                    data = buf[RECORD.size : RECORD.size + n]
                    buf = buf[RECORD.size + n :]
                    if kind == b"O":
                        self.arrived(t, data)

    def write(self, data):
        try:
            os.write(self.fifo, data)
        except OSError:
            pass

    def screenshot(self, path):
        subprocess.run(["import", "-window", "root", "-crop", CROPS[self.name], "+repage", path], env=self.env, check=False, timeout=30)

    def close(self):
        stop(self.proc)
        self.done = True
        os.close(self.fifo)
        self.output.close()
        self.follower.join(timeout=2)
        if self.raw:
            self.raw.close()
