#!/usr/bin/env python3
"""The player over a real, shaped link: key -> effect, bytes at the terminal, frames.

Builds two network namespaces joined by a veth pair, shapes both ends with `tc ... tbf`, adds
round trip with a delaying relay (TCP, and UDP for mosh: `relay.py`), runs its own sshd in
the server namespace (its own config and host key, root with a key made for the run, a test
port) and drives the client (OpenSSH's `ssh`, or `mosh`) in a pseudo-terminal that it reads
as the terminal: a pyte screen, DA1 answered like a real terminal. For each row it presses a
key that changes the status line (`+`/`-`, the stone size) every ~1.5 s while the water is
busy and times how long until the status line shows it.

Needs root, Debian's iproute2, openssh-server, mosh and tmux, and pyte (see README.md).
Everything is torn down at the end (processes it started, by id; the namespaces; the
temporary folder); the run is bounded by --timeout. Traffic stays inside the namespaces it
makes.
"""

import argparse
import os
import pty
import re
import select
import shlex
import shutil
import signal
import statistics
import struct
import subprocess
import sys
import tempfile
import termios
import fcntl
import threading
import time

try:
    import pyte
except ImportError:
    sys.exit("link_harness: pyte is missing: pip install pyte")

HERE = os.path.dirname(os.path.abspath(__file__))
COLS, ROWS = 160, 48
DA1_QUESTION = b"\x1b[c"
DA1_ANSWER = b"\x1b[?62;22c"
SYNC_END = b"\x1b[?2026l"
# The link's two ends and their addresses (inside the namespaces this script makes).
CLIENT_IP, SERVER_IP, PREFIX = "10.213.0.1", "10.213.0.2", "30"
SSH_PORT, SERVE_PORT, MOSH_PORT = 2222, 2223, 60001
RELAY_SSH, RELAY_SERVE = 12222, 12223
LINKS = {
    "2mbit-20ms": ("2mbit", 250_000, 20),
    "2mbit-150ms": ("2mbit", 250_000, 150),
    "256kbit-300ms": ("256kbit", 32_000, 300),
}
MODES = ("ssh", "tmux", "mosh", "serve")
# A key whose effect has not shown after this long counts as never shown.
KEY_DEADLINE = 15.0


def run(cmd, check=True, **kw):
    """Runs a command to completion (bounded: 60 s)."""
    return subprocess.run(cmd, check=check, timeout=60, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, **kw)


class Lab:
    """The namespaces, the shaped veth pair, sshd, relays; torn down by `close`.

    `prefix` names the namespaces (PREFIXc, PREFIXs; default tpc/tps and this process's id),
    `subnet` their addresses (SUBNET.1 and SUBNET.2). `stock`: Debian's own sshd configuration
    (/etc/ssh/sshd_config: port 22, `AcceptEnv LANG LC_*` only, PAM), read after four lines
    that only say where this run's keys and pid file are, instead of the harness's own
    (port 2222, `AcceptEnv COLORTERM`)."""

    def __init__(self, tidepool, lifetime, prefix=None, subnet=None, stock=False):
        tag = str(os.getpid())
        self.client_ns, self.server_ns = (f"{prefix}c", f"{prefix}s") if prefix else (f"tpc{tag}", f"tps{tag}")
        self.veth_client, self.veth_server = self.client_ns[:15], self.server_ns[:15]
        self.client_ip, self.server_ip = (f"{subnet}.1", f"{subnet}.2") if subnet else (CLIENT_IP, SERVER_IP)
        self.stock = stock
        self.ssh_port = 22 if stock else SSH_PORT
        self.dir = tempfile.mkdtemp(prefix="link-harness-")
        self.tidepool = tidepool
        self.lifetime = lifetime
        self.procs = []  # (Popen, description)
        self.relays = []
        self.made_namespaces = False

    def ns(self, name, *cmd):
        return ["ip", "netns", "exec", name, *cmd]

    def setup(self):
        for ns in (self.client_ns, self.server_ns):
            run(["ip", "netns", "add", ns])
        self.made_namespaces = True
        run(["ip", "link", "add", self.veth_client, "type", "veth", "peer", "name", self.veth_server])
        run(["ip", "link", "set", self.veth_client, "netns", self.client_ns])
        run(["ip", "link", "set", self.veth_server, "netns", self.server_ns])
        for ns, dev, ip in ((self.client_ns, self.veth_client, self.client_ip), (self.server_ns, self.veth_server, self.server_ip)):
            run(self.ns(ns, "ip", "addr", "add", f"{ip}/{PREFIX}", "dev", dev))
            run(self.ns(ns, "ip", "link", "set", dev, "up"))
            run(self.ns(ns, "ip", "link", "set", "lo", "up"))
        # Keys made for this run: sshd's host key, the client's key, serve's host key.
        for name in ("host_key", "client_key"):
            run(["ssh-keygen", "-q", "-t", "ed25519", "-N", "", "-f", f"{self.dir}/{name}"])
        shutil.copy(f"{self.dir}/client_key.pub", f"{self.dir}/authorized_keys")
        os.makedirs("/run/sshd", exist_ok=True)
        with open(f"{self.dir}/sshd_config", "w") as f:
            # sshd takes the first value it reads of each keyword: these four, then Debian's.
            stock = f"""HostKey {self.dir}/host_key
PidFile {self.dir}/sshd.pid
AuthorizedKeysFile {self.dir}/authorized_keys
StrictModes no
Include /etc/ssh/sshd_config
"""
            f.write(stock if self.stock else
                f"""Port {SSH_PORT}
ListenAddress {self.server_ip}
HostKey {self.dir}/host_key
PidFile {self.dir}/sshd.pid
AuthorizedKeysFile {self.dir}/authorized_keys
PermitRootLogin prohibit-password
PasswordAuthentication no
KbdInteractiveAuthentication no
UsePAM no
StrictModes no
AcceptEnv LANG LC_* COLORTERM
PrintMotd no
PrintLastLog no
"""
            )
        run(["/usr/sbin/sshd", "-t", "-f", f"{self.dir}/sshd_config"])
        self.start(self.ns(self.server_ns, "/usr/sbin/sshd", "-D", "-e", "-f", f"{self.dir}/sshd_config"), "sshd")
        serve = [self.tidepool, "serve", "--listen", f"{self.server_ip}:{SERVE_PORT}", "--host-key", f"{self.dir}/serve_key"]
        self.start(self.ns(self.server_ns, *serve), "tidepool serve")
        deadline = time.monotonic() + 20
        for name, word in (("sshd", "Server listening"), ("tidepool_serve", "listening on")):
            while word not in read_text(f"{self.dir}/{name}.log"):
                if time.monotonic() > deadline:
                    raise RuntimeError(f"{name} did not start: {read_text(f'{self.dir}/{name}.log')[-300:]}")
                time.sleep(0.05)

    def start(self, cmd, what, **kw):
        # A new log for each start (relays are restarted for every link).
        open(f"{self.dir}/{what.replace(' ', '_')}.log", "w").close()
        proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=open(f"{self.dir}/{what.replace(' ', '_')}.log", "ab"), stderr=subprocess.STDOUT, **kw)
        self.procs.append((proc, what))
        return proc

    def shape(self, rate, rtt_ms):
        """Shapes both ends to `rate` and puts relays with `rtt_ms` of round trip in front
        (`rtt_ms` None: no relays, the plain shaped link)."""
        for ns, dev in ((self.client_ns, self.veth_client), (self.server_ns, self.veth_server)):
            run(self.ns(ns, "tc", "qdisc", "replace", "dev", dev, "root", "tbf", "rate", rate, "burst", "32kbit", "latency", "400ms"))
        if rtt_ms is None:
            return
        for proc, _ in self.relays:
            stop(proc)
        self.relays = []
        relay = [sys.executable, f"{HERE}/relay.py"]
        for kind, port, target in (("tcp", RELAY_SSH, SSH_PORT), ("tcp", RELAY_SERVE, SERVE_PORT), ("udp", MOSH_PORT, MOSH_PORT)):
            cmd = self.ns(self.client_ns, *relay, kind, "127.0.0.1", str(port), self.server_ip, str(target), str(rtt_ms), str(self.lifetime))
            self.relays.append((self.start(cmd, f"relay {kind} {port}"), f"relay_{kind}_{port}"))
        # Each relay says when it listens (Python starts slowly on a loaded machine).
        deadline = time.monotonic() + 20
        for proc, name in self.relays:
            while "listening" not in read_text(f"{self.dir}/{name}.log"):
                if proc.poll() is not None or time.monotonic() > deadline:
                    raise RuntimeError(f"the relay {name} did not start: {read_text(f'{self.dir}/{name}.log')[-300:]}")
                time.sleep(0.05)

    def ssh_command(self, port, remote=None, tty=True, host="127.0.0.1", send_env=True):
        """The ssh client's command: to `host` (the relay on 127.0.0.1 by default), `-tt` for a
        pty whatever its input; `send_env`: COLORTERM too (the harness's own sshd takes it;
        OpenSSH sends nothing by default and Debian's sshd takes only LANG/LC_*)."""
        cmd = ["ssh", "-F", "/dev/null", "-i", f"{self.dir}/client_key", "-p", str(port)]
        cmd += ["-o", "IdentitiesOnly=yes", "-o", f"UserKnownHostsFile={self.dir}/known_hosts", "-o", "StrictHostKeyChecking=no"]
        cmd += ["-o", "LogLevel=ERROR"] + (["-o", "SendEnv=COLORTERM"] if send_env else [])
        cmd += ["-tt"] if tty else []
        cmd += [f"root@{host}"]
        if remote:
            cmd += ["--", remote]
        return cmd

    def close(self):
        for proc, _ in reversed(self.procs):
            stop(proc)
        # Whatever still runs inside the namespaces was started there by this run (mosh-server
        # detaches from its parent, tmux's server too): end it by id.
        if self.made_namespaces:
            for ns in (self.client_ns, self.server_ns):
                pids = run(["ip", "netns", "pids", ns], check=False).stdout.split()
                for pid in pids:
                    try:
                        os.kill(int(pid), signal.SIGTERM)
                    except (ProcessLookupError, ValueError):
                        pass
            time.sleep(0.3)
            for ns in (self.client_ns, self.server_ns):
                for pid in run(["ip", "netns", "pids", ns], check=False).stdout.split():
                    try:
                        os.kill(int(pid), signal.SIGKILL)
                    except (ProcessLookupError, ValueError):
                        pass
                run(["ip", "netns", "del", ns], check=False)
        shutil.rmtree(self.dir, ignore_errors=True)


def read_text(path):
    try:
        with open(path, errors="replace") as f:
            return f.read()
    except FileNotFoundError:
        return ""


def stop(proc):
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=3)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(timeout=3)


class Terminal:
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
        self.screen = pyte.Screen(COLS, ROWS)
        self.stream = pyte.ByteStream(self.screen)
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
        self.reader = threading.Thread(target=self.read, daemon=True)
        self.parser = threading.Thread(target=self.parse, daemon=True)
        self.reader.start()
        self.parser.start()

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
            now = time.monotonic()
            if self.raw:
                self.raw.write(data)
            # Answer DA1 at once, as a terminal does once it has read the question.
            window = self.tail + data
            questions = window.count(DA1_QUESTION) - self.tail.count(DA1_QUESTION)
            for _ in range(questions):
                self.write(DA1_ANSWER)
            ends = window.count(SYNC_END) - self.tail.count(SYNC_END)
            self.tail = window[-8:]
            with self.lock:
                self.arrivals.append((now, len(data)))
                self.sync_ends.extend([now] * ends)
                self.pending.append((now, data))
        self.done = True

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
                    self.stream.feed(data)
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

    def write(self, data):
        try:
            os.write(self.fd, data)
        except OSError:
            pass

    def shown_since(self, text, since):
        with self.lock:
            for t, s in self.statuses:
                if t >= since and text in s:
                    return t
        return None

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


def client_command(lab, mode, play_args):
    tidepool = shlex.quote(lab.tidepool)
    play = f"{tidepool} play {play_args}"
    if mode == "ssh":
        return lab.ns(lab.client_ns, *lab.ssh_command(RELAY_SSH, play))
    if mode == "tmux":
        # A fresh tmux server on its own socket, its status line off, true colour passed on
        # (as the README's tmux paragraph asks); the pane runs the player.
        socket = f"tp-harness-{os.getpid()}"
        inner = (
            f"tmux -u -f /dev/null -L {socket} new-session -x {COLS} -y {ROWS} {shlex.quote(play)} \\; "
            "set status off \\; set -as terminal-features ',*:RGB'"
        )
        return lab.ns(lab.client_ns, *lab.ssh_command(RELAY_SSH, inner))
    if mode == "mosh":
        ssh = " ".join(shlex.quote(a) for a in lab.ssh_command(RELAY_SSH, tty=False)[:-1])
        return lab.ns(
            lab.client_ns,
            "mosh",
            f"--ssh={ssh}",
            f"--port={MOSH_PORT}",
            "--predict=never",
            "root@127.0.0.1",
            "--",
            *shlex.split(play),
        )
    if mode == "serve":
        return lab.ns(lab.client_ns, *lab.ssh_command(RELAY_SERVE))
    raise ValueError(mode)


def percentile(values, p):
    values = sorted(values)
    return values[round((len(values) - 1) * p)]


# Shots (--shots): after the warm-up, one stone, then the screen copied this often for this long;
# the PNG is the copy SHOT_PNG_AT seconds after the stone.
SHOT_INTERVAL, SHOT_SECONDS, SHOT_PNG_AT = 0.2, 5.0, 3.0


def take_shots(term):
    """One stone, then copies of the screen every SHOT_INTERVAL s for SHOT_SECONDS s (painted
    after the row, so the painting does not compete with the terminal's reader)."""
    term.write(b" ")
    stone = time.monotonic()
    frames = []
    for i in range(int(SHOT_SECONDS / SHOT_INTERVAL) + 1):
        time.sleep(max(0.0, stone + i * SHOT_INTERVAL - time.monotonic()))
        frames.append(term.copy_screen())
    return frames


def save_shots(frames, directory, name):
    import screen_shots

    png = os.path.join(directory, f"{name}.png")
    gif = os.path.join(directory, f"{name}.gif")
    screen_shots.save_png(frames[round(SHOT_PNG_AT / SHOT_INTERVAL)], png)
    screen_shots.save_gif(frames, gif, SHOT_INTERVAL)
    return png, gif


def measure(lab, mode, capacity, play_args, presses, warm_up, shots=None, keep=None, name=""):
    env = dict(os.environ, TERM="xterm-256color", COLORTERM="truecolor", LANG="C.UTF-8", LC_ALL="C.UTF-8")
    env.pop("TMUX", None)
    env.pop("SSH_CONNECTION", None)
    raw = os.path.join(keep, f"{name}.raw") if keep else None
    term = Terminal(client_command(lab, mode, play_args), env, raw)
    shot_frames = None
    try:
        start = time.monotonic()
        # Busy water: a stone every half second besides the rain and the breeze.
        while time.monotonic() - start < warm_up:
            term.write(b" ")
            time.sleep(0.5)
        if shots:
            shot_frames = take_shots(term)
        measuring = time.monotonic()
        with term.lock:
            bytes_before = sum(n for _, n in term.arrivals)
        latencies, missed = [], 0
        size_up = True
        for _ in range(presses):
            term.write(b" ")
            time.sleep(0.25)
            key, text = (b"+", "stone 4") if size_up else (b"-", "stone 3")
            at = time.monotonic()
            term.write(key)
            deadline = at + KEY_DEADLINE
            shown = None
            while time.monotonic() < deadline:
                shown = term.shown_since(text, at)
                if shown:
                    break
                time.sleep(0.005)
            if shown:
                latencies.append(shown - at)
                size_up = not size_up
            else:
                missed += 1
            next_press = at + 1.5
            time.sleep(max(0.0, next_press - time.monotonic()))
            term.write(b" ")
        end = time.monotonic()
        with term.lock:
            received = sum(n for t, n in term.arrivals if t >= measuring) if term.arrivals else 0
            changes = [t for t in term.changes if t >= measuring]
            syncs = [t for t in term.sync_ends if t >= measuring]
            status = term.statuses[-1][1] if term.statuses else ""
            # Bytes read but not yet parsed: the emulator's lag (it must keep up for the
            # timings to mean anything).
            unparsed = sum(len(d) for _, d in term.pending)
        seconds = end - measuring
        gaps = [b - a for a, b in zip([measuring] + changes, changes + [end])]
        frames = len(syncs) if syncs else bursts(changes)
        said = re.search(r"(\d+) fps \u00b7 ([\d.]+ [kMG]?B/s)", status)
        return {
            "latencies": latencies,
            "missed": missed,
            "bytes_per_s": received / seconds,
            "capacity": capacity,
            "fps": frames / seconds,
            "fps_from": "sync" if syncs else "bursts",
            "stall": max(gaps) if gaps else seconds,
            "player_says": f"{said.group(1)} fps, {said.group(2)}" if said else "-",
            "unparsed": unparsed,
        }
    finally:
        term.write(b"q")
        time.sleep(0.3)
        term.close()
        if shot_frames:
            for path in save_shots(shot_frames, shots, name):
                print(f"  shot: {path}", file=sys.stderr, flush=True)


def bursts(changes, gap=0.010):
    """Screen updates separated by at least `gap` of quiet (for streams without frame marks)."""
    count, last = 0, None
    for t in changes:
        if last is None or t - last >= gap:
            count += 1
        last = t
    return count


def row_text(link, mode, r):
    lat = r["latencies"]
    if lat:
        median, p90 = statistics.median(lat) * 1e3, percentile(lat, 0.9) * 1e3
        latency = f"{median:7.0f} ms {p90:7.0f} ms"
    else:
        latency = f"{'never':>10} {'':>10}"
    missed = f" ({r['missed']} never shown)" if r["missed"] else ""
    if r["unparsed"] > 100_000:
        missed += f" (the emulator lagged {r['unparsed'] / 1e3:.0f} kB)"
    used = r["bytes_per_s"] / r["capacity"] * 100
    return (
        f"| {link:<14} | {mode:<6} | {latency.replace(' ms ', ' ms | ')}{missed} | "
        f"{r['bytes_per_s'] / 1e3:6.1f} kB/s of {r['capacity'] / 1e3:.0f} ({used:3.0f} %) | "
        f"{r['fps']:5.1f} ({r['fps_from']}) | {r['stall'] * 1e3:6.0f} ms | {r['player_says']} |"
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--tidepool", default=os.path.join(HERE, "..", "..", "target", "release", "tidepool"), help="the binary to measure (default: this checkout's target/release/tidepool)")
    parser.add_argument("--links", default=",".join(LINKS), help=f"links to run, of {', '.join(LINKS)}")
    parser.add_argument("--modes", default=",".join(MODES), help=f"modes to run, of {', '.join(MODES)}")
    parser.add_argument("--presses", type=int, default=12, help="status-line keys timed per row (default 12)")
    parser.add_argument("--warm-up", type=float, default=6.0, help="seconds of busy water before timing (default 6)")
    parser.add_argument("--play-args", default="--seed 5 --color truecolor", help="arguments for `tidepool play` (default: --seed 5 --color truecolor)")
    parser.add_argument("--timeout", type=float, default=1200.0, help="the whole run ends after this many seconds (default 1200)")
    parser.add_argument("--shots", metavar="DIR", help="after each row's warm-up: a stone, then the screen as a PNG 3 s later and a 5 s GIF, as DIR/MODE-LINK[-TAG].png/.gif (needs pillow)")
    parser.add_argument("--shot-tag", default="", help="appended to the shots' names (e.g. before, after)")
    parser.add_argument("--keep-logs", metavar="DIR", help="keep every byte the terminal read (DIR/MODE-LINK[-TAG].raw) and the run's sshd, serve and relay logs (DIR/logs-TAG/)")
    args = parser.parse_args()
    if os.geteuid() != 0:
        sys.exit("link_harness: needs root (network namespaces, tc, sshd)")
    for tool in ("ip", "tc", "ssh", "ssh-keygen", "mosh", "mosh-server", "tmux"):
        if not shutil.which(tool):
            sys.exit(f"link_harness: {tool} is missing: apt-get install -y openssh-server mosh tmux iproute2")
    if not os.path.exists("/usr/sbin/sshd"):
        sys.exit("link_harness: /usr/sbin/sshd is missing: apt-get install -y openssh-server")
    tidepool = os.path.abspath(args.tidepool)
    if not os.access(tidepool, os.X_OK):
        sys.exit(f"link_harness: no tidepool binary at {tidepool}: cargo build --release, or --tidepool PATH")
    links = args.links.split(",")
    modes = args.modes.split(",")
    for name in links:
        if name not in LINKS:
            sys.exit(f"link_harness: unknown link {name!r}: one of {', '.join(LINKS)}")
    for mode in modes:
        if mode not in MODES:
            sys.exit(f"link_harness: unknown mode {mode!r}: one of {', '.join(MODES)}")

    def out_of_time(*_):
        raise TimeoutError(f"the run took longer than --timeout {args.timeout:.0f} s")

    for directory in (args.shots, args.keep_logs):
        if directory:
            os.makedirs(directory, exist_ok=True)
    if args.shots:
        try:
            import PIL  # noqa: F401
        except ImportError:
            sys.exit("link_harness: --shots needs pillow: pip install pillow")
    if args.shot_tag and not re.fullmatch(r"[A-Za-z0-9_.-]{1,40}", args.shot_tag):
        sys.exit("link_harness: --shot-tag takes letters, digits, '.', '_' and '-' (at most 40)")
    tag = f"-{args.shot_tag}" if args.shot_tag else ""

    signal.signal(signal.SIGALRM, out_of_time)
    signal.signal(signal.SIGTERM, out_of_time)
    signal.alarm(int(args.timeout))
    lab = Lab(tidepool, args.timeout)
    rows = []
    try:
        lab.setup()
        load_before = os.getloadavg()
        print(f"tidepool: {tidepool}\nplay args: {args.play_args}; {args.presses} presses per row after {args.warm_up:.0f} s of busy water")
        print("| link | client | key->effect median | p90 | reached the terminal | fps | longest stall | the player's status says |")
        print("|---|---|---|---|---|---|---|---|")
        for name in links:
            rate, capacity, rtt = LINKS[name]
            lab.shape(rate, rtt)
            for mode in modes:
                result = measure(lab, mode, capacity, args.play_args, args.presses, args.warm_up, args.shots, args.keep_logs, f"{mode}-{name}{tag}")
                line = row_text(name, mode, result)
                rows.append(line)
                print(line, flush=True)
        load_after = os.getloadavg()
        print(f"load average before: {load_before[0]:.2f}, after: {load_after[0]:.2f} ({os.cpu_count()} cores)")
    finally:
        signal.alarm(0)
        if args.keep_logs:
            shutil.copytree(lab.dir, os.path.join(args.keep_logs, f"logs{tag or '-run'}"), ignore=shutil.ignore_patterns("*key*", "authorized_keys", "known_hosts"), dirs_exist_ok=True)
        lab.close()


if __name__ == "__main__":
    main()
