"""The harness's terminal: a pseudo-terminal read by a pyte screen, DA1 answered at once.

The client (ssh, mosh) runs in a pseudo-terminal of 160x48; a reader thread timestamps every
chunk as it is read (and answers DA1 like a real terminal), a parser thread feeds a pyte screen
and records when each status line first showed, so a slow parser does not add latency.
"""

import fcntl
import os
import pty
import select
import signal
import struct
import termios
import threading
import time

import pyte

COLS, ROWS = 160, 48
DA1_QUESTION = b"\x1b[c"
DA1_ANSWER = b"\x1b[?62;22c"
# Device status (DSR 5): every VT100-compatible terminal answers "OK".
DSR_QUESTION = b"\x1b[5n"
DSR_ANSWER = b"\x1b[0n"
SYNC_END = b"\x1b[?2026l"


class Strings:
    """Drops the string sequences pyte does not know (APC: kitty's pictures; DCS: sixel; PM,
    SOS), which it would otherwise print as text, across chunk boundaries."""

    def __init__(self):
        self.inside = False
        self.carry = b""

    def strip(self, data):
        buf, out, i = self.carry + data, bytearray(), 0
        self.carry = b""
        while i < len(buf):
            if self.inside:
                end = buf.find(b"\x1b\\", i)
                if end < 0:
                    self.carry = b"\x1b" if buf.endswith(b"\x1b") else b""
                    return bytes(out)
                i, self.inside = end + 2, False
                continue
            esc = buf.find(b"\x1b", i)
            if esc < 0:
                out += buf[i:]
                break
            out += buf[i:esc]
            if esc + 1 == len(buf):
                self.carry = b"\x1b"
                break
            if buf[esc + 1] in b"_P^X":
                self.inside = True
            else:
                out += buf[esc : esc + 2]
            i = esc + 2
        return bytes(out)


class Screen:
    """A pyte screen fed from a parser thread: when each status line first showed, when the
    screen changed, when bytes arrived and synchronized frames ended. A reader (the subclass)
    appends `(time, bytes)` to `pending` and calls `arrived`."""

    def __init__(self, cols, rows, raw_path=None):
        self.screen = pyte.Screen(cols, rows)
        self.stream = pyte.ByteStream(self.screen)
        self.strings = Strings()
        self.lock = threading.Lock()
        # Held while the parser changes the screen, so a shot copies a whole parsed state.
        self.screen_lock = threading.Lock()
        # Every byte read, as read (--keep-logs), for ansi_view.py or a replay.
        self.raw = open(raw_path, "wb") if raw_path else None
        self.arrivals = []  # (time, bytes)
        self.statuses = []  # (time, text)
        self.changes = []  # times the screen changed
        self.sync_ends = []  # times a synchronized frame ended
        self.pending = []
        self.done = False
        self.tail = b""
        self.parser = threading.Thread(target=self.parse, daemon=True)
        self.parser.start()

    def arrived(self, now, data):
        """Bytes the terminal read at `now`; returns the answers owed to the questions among
        them (DA1 and DSR 5), in the order asked."""
        if self.raw:
            self.raw.write(data)
        window = self.tail + data
        found = []
        for question, answer in ((DA1_QUESTION, DA1_ANSWER), (DSR_QUESTION, DSR_ANSWER)):
            at = window.find(question, max(0, len(self.tail) - len(question) + 1))
            while at >= 0:
                found.append((at, answer))
                at = window.find(question, at + 1)
        questions = [answer for _, answer in sorted(found)]
        ends = window.count(SYNC_END) - self.tail.count(SYNC_END)
        self.tail = window[-8:]
        with self.lock:
            self.arrivals.append((now, len(data)))
            self.sync_ends.extend([now] * ends)
            self.pending.append((now, data))
        return questions

    def parse(self):
        last_status = ""
        while not self.done or self.pending:
            with self.lock:
                batch, self.pending = self.pending, []
            if not batch:
                time.sleep(0.002)
                continue
            for arrived, data in batch:
                with self.screen_lock:
                    self.stream.feed(self.strings.strip(data))
                    dirty = bool(self.screen.dirty)
                    self.screen.dirty.clear()
                    status = self.status_text() if dirty else last_status
                if dirty:
                    with self.lock:
                        self.changes.append(arrived)
                        if status != last_status:
                            self.statuses.append((arrived, status))
                    last_status = status

    def status_text(self):
        # The player's status line is its last row (tmux runs with its own status off).
        lines = self.screen.display
        return lines[-1] + "\n" + lines[-2]

    def copy_screen(self):
        """The screen as the parser last left it (plain tuples, see screen_shots.py)."""
        from screen_shots import copy_screen

        with self.screen_lock:
            return copy_screen(self.screen)

    def shown_since(self, text, since):
        with self.lock:
            for t, s in self.statuses:
                if t >= since and text in s:
                    return t
        return None


class Terminal(Screen):
    """A pseudo-terminal driven as a user's terminal: it answers DA1 at once, keeps a pyte
    screen, and records when each status line first appeared and when bytes arrived."""

    def __init__(self, cmd, env, raw_path=None):
        self.pid, self.fd = pty.fork()
        if self.pid == 0:
            try:
                os.execvpe(cmd[0], cmd, env)
            finally:
                os._exit(127)
        fcntl.ioctl(self.fd, termios.TIOCSWINSZ, struct.pack("HHHH", ROWS, COLS, 0, 0))
        super().__init__(COLS, ROWS, raw_path)
        self.reader = threading.Thread(target=self.read, daemon=True)
        self.reader.start()

    def read(self):
        while not self.done:
            ready, _, _ = select.select([self.fd], [], [], 0.1)
            if not ready:
                continue
            try:
                data = os.read(self.fd, 65536)
            except OSError:
                break
            if not data:
                break
            # Answer DA1 and DSR at once, as a terminal does once it has read the question.
            for answer in self.arrived(time.monotonic(), data):
                self.write(answer)
        self.done = True

    def write(self, data):
        try:
            os.write(self.fd, data)
        except OSError:
            pass

    def close(self):
        self.done = True
        try:
            os.kill(self.pid, signal.SIGTERM)
        except ProcessLookupError:
            pass
        for _ in range(30):
            if os.waitpid(self.pid, os.WNOHANG) != (0, 0):
                break
            time.sleep(0.1)
        else:
            try:
                os.kill(self.pid, signal.SIGKILL)
                os.waitpid(self.pid, 0)
            except (ProcessLookupError, ChildProcessError):
                pass
        self.reader.join(timeout=1)
        os.close(self.fd)
        if self.raw:
            self.raw.close()
