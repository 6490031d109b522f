#!/usr/bin/env python3
"""The player over a real, shaped link: key -> effect, bytes at the terminal, frames.

Builds two network namespaces joined by a veth pair, shapes both ends with `tc ... tbf`, adds
round trip with a delaying relay where a row asks for one (TCP, and UDP for mosh: `relay.py`),
and reaches the far namespace two ways (see README.md): the *lab* configuration (an sshd of its
own, root, port 2222, always behind the relay) and the *stock* configuration (Debian's sshd as
shipped on port 22, a test user, the multiplexer started by the ssh command). The client
(OpenSSH's `ssh`, or `mosh`) runs in a pseudo-terminal that the harness reads as the terminal (a
pyte screen, DA1 answered like a real terminal), or in a real kitty or xterm under Xvfb. For
each row it presses a key that changes the status line (`+`/`-`, the stone size) every ~1.5 s
while the water is busy and times how long until the status line shows it.

Needs root, Debian's iproute2, openssh-server, mosh, tmux and screen, and pyte (see README.md).
Everything is torn down at the end (processes it started, by id; the namespaces; the test user;
the temporary folder); the run is bounded by --timeout. Traffic stays inside the namespaces it
makes.
"""

import argparse
import os
import re
import shlex
import shutil
import signal
import statistics
import sys
import threading
import time

try:
    import pyte  # noqa: F401
except ImportError:
    sys.exit("link_harness: pyte is missing: pip install pyte")

from lab import MOSH_PORT, SERVE_PORT, Lab
from lab import run as run_command
from path_log import PathLog
from pty_terminal import COLS, ROWS, Terminal

HERE = os.path.dirname(os.path.abspath(__file__))
# name: (tc rate, capacity in bytes a second, round trip added by the relay in ms; 0: no relay)
LINKS = {
    "2mbit": ("2mbit", 250_000, 0),
    "2mbit-20ms": ("2mbit", 250_000, 20),
    "2mbit-150ms": ("2mbit", 250_000, 150),
    "256kbit": ("256kbit", 32_000, 0),
    "256kbit-300ms": ("256kbit", 32_000, 300),
}
CONFIGS = {
    # The harness's first rows: its own sshd, always behind the relay, a stone every 0.5 s in
    # the warm-up and one before each timed key.
    "lab": {"links": ("2mbit-20ms", "2mbit-150ms", "256kbit-300ms"), "modes": ("ssh", "tmux", "mosh", "serve")},
    # Issue 30's link as a user builds it: the stock sshd, no relay on the base row, a stone
    # every 50 ms all through the row.
    "stock": {
        "links": ("2mbit", "2mbit-20ms", "2mbit-150ms", "256kbit-300ms"),
        "modes": ("ssh", "screen", "tmux", "mosh", "serve", "kitty", "xterm", "tmux-passthrough", "tmux-attach", "screen-attach"),
        # The rows run unless --modes names others (the -attach rows: see attach_command).
        "default": ("ssh", "screen", "tmux", "mosh", "serve", "kitty", "xterm"),
    },
}
# The stock configuration's busy water: a stone this often, all through the row.
STOCK_STONES = 0.05
# A key whose effect has not shown after this long counts as never shown.
KEY_DEADLINE = 15.0


def lab_command(lab, mode, play_args):
    """The lab configuration's clients (its own sshd as root, the relay in front)."""
    tidepool = shlex.quote(lab.tidepool)
    play = f"{tidepool} play {play_args}"
    if mode == "ssh":
        return lab.ns(lab.client_ns, *lab.ssh_command(remote=play))
    if mode == "tmux":
        # A fresh tmux server on its own socket, its status line off, true colour passed on
        # (as the README's tmux paragraph asks); the pane runs the player.
        socket = f"tp-harness-{os.getpid()}"
        inner = (
            f"tmux -u -f /dev/null -L {socket} new-session -x {COLS} -y {ROWS} {shlex.quote(play)} \\; "
            "set status off \\; set -as terminal-features ',*:RGB'"
        )
        return lab.ns(lab.client_ns, *lab.ssh_command(remote=inner))
    if mode == "mosh":
        ssh = " ".join(shlex.quote(a) for a in lab.ssh_command(tty=False)[:-1])
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
        return lab.ns(lab.client_ns, *lab.ssh_command(port=SERVE_PORT))
    raise ValueError(mode)


def stock_command(lab, mode, play_args):
    """The stock configuration's clients: the commands of issue 30, `tidepool` being the binary
    measured (`ssh -tt host "..."` with the system's client config, the test user)."""
    play = f"{shlex.quote(lab.tidepool)} play {play_args}".rstrip()
    remote = {
        "ssh": play,
        "kitty": play,
        "xterm": play,
        "screen": f"screen -S x -c /dev/null env COLORTERM=truecolor {play}",
        "tmux": (
            f"tmux -f /dev/null -L x new-session -x {COLS} -y {ROWS} {shlex.quote(play)} \\; "
            "set status off \\; set -as terminal-features ',*:RGB'"
        ),
    }
    # The same tmux with its passthrough allowed (off by default since tmux 3.3).
    remote["tmux-passthrough"] = remote["tmux"] + " \\; set -g allow-passthrough on"
    if mode == "serve":
        return lab.ns(lab.client_ns, *lab.ssh_command(port=SERVE_PORT, stock=True))
    if mode == "mosh":
        # `mosh host -- tidepool play` over the stock sshd (its ssh the system's client with the
        # test user's key); mosh-server on the lab's UDP port, which the UDP relay forwards
        # where a round trip is added.
        *ssh, host = lab.ssh_command(stock=True, tty=False)
        ssh_text = " ".join(shlex.quote(a) for a in ssh)
        return lab.ns(lab.client_ns, "mosh", f"--ssh={ssh_text}", f"--port={MOSH_PORT}", "--predict=never", host, "--", *shlex.split(play))
    if mode.endswith("-attach"):
        attach = {"tmux-attach": "tmux -L x attach", "screen-attach": "screen -r x"}[mode]
        return lab.ns(lab.client_ns, *lab.ssh_command(remote=attach, stock=True))
    return lab.ns(lab.client_ns, *lab.ssh_command(remote=remote[mode], stock=True))


def attach_first(lab, mode, play_args):
    """The -attach rows: another SSH connection (still open, idle, as a second terminal of the
    user's would be) starts the multiplexer detached with the player in it; the row's terminal
    then attaches from its own connection. The player's SSH_CONNECTION names the first one."""
    play = f"{shlex.quote(lab.tidepool)} play {play_args}".rstrip()
    start = {
        "tmux-attach": (
            f"tmux -f /dev/null -L x new-session -d -x {COLS} -y {ROWS} {shlex.quote(play)} \\; "
            "set status off \\; set -as terminal-features ',*:RGB'"
        ),
        "screen-attach": f"screen -dmS x -c /dev/null env COLORTERM=truecolor {play}",
    }[mode]
    return lab.start(lab.ns(lab.client_ns, *lab.ssh_command(remote=f"{start}; sleep 600", stock=True, tty=False)), "first connection")


def run_text(cmd):
    return run_command(cmd, check=False).stdout


def percentile(values, p):
    values = sorted(values)
    return values[round((len(values) - 1) * p)]


# Shots (--shots): after the warm-up, one stone, then the screen copied this often for this long;
# the PNG is the copy SHOT_PNG_AT seconds after the stone.
SHOT_INTERVAL, SHOT_SECONDS, SHOT_PNG_AT = 0.2, 5.0, 3.0


def take_shots(term, directory, name):
    """One stone, then copies of the screen every SHOT_INTERVAL s for SHOT_SECONDS s (painted
    after the row, so the painting does not compete with the terminal's reader); a real
    terminal's window is saved once, SHOT_PNG_AT s after the stone."""
    term.write(b" ")
    stone = time.monotonic()
    frames = []
    for i in range(int(SHOT_SECONDS / SHOT_INTERVAL) + 1):
        time.sleep(max(0.0, stone + i * SHOT_INTERVAL - time.monotonic()))
        if hasattr(term, "screenshot"):
            if abs(i * SHOT_INTERVAL - SHOT_PNG_AT) < 1e-6:
                path = os.path.join(directory, f"{name}.png")
                term.screenshot(path)
                print(f"  shot: {path}", file=sys.stderr, flush=True)
            continue
        frames.append(term.copy_screen())
    return frames


def save_shots(frames, directory, name):
    import screen_shots

    png = os.path.join(directory, f"{name}.png")
    gif = os.path.join(directory, f"{name}.gif")
    screen_shots.save_png(frames[round(SHOT_PNG_AT / SHOT_INTERVAL)], png)
    screen_shots.save_gif(frames, gif, SHOT_INTERVAL)
    return png, gif


class Stones(threading.Thread):
    """Busy water for the stock rows: a stone every STOCK_STONES seconds until stopped."""

    def __init__(self, term):
        super().__init__(daemon=True)
        self.term, self.done = term, False

    def run(self):
        start = time.monotonic()
        i = 0
        while not self.done:
            self.term.write(b" ")
            i += 1
            time.sleep(max(0.0, start + i * STOCK_STONES - time.monotonic()))


def redraw(lab, mode):
    """Makes the multiplexer redraw its whole screen, as it does on attach, on a resize and (tmux)
    after a client whose output backed up: a burst of a screenful the player did not send."""
    user = ["runuser", "-u", lab.stock_user, "--"]
    if mode.startswith("tmux"):
        clients = run_text(lab.ns(lab.server_ns, *user, "tmux", "-L", "x", "list-clients", "-F", "#{client_name}")).split()
        for client in clients[:4]:
            run_text(lab.ns(lab.server_ns, *user, "tmux", "-L", "x", "refresh-client", "-t", client))
    elif mode.startswith("screen"):
        run_text(lab.ns(lab.server_ns, *user, "screen", "-S", "x", "-X", "redisplay"))


def open_terminal(lab, config, mode, args, raw, display):
    env = dict(os.environ, TERM="xterm-256color", COLORTERM="truecolor", LANG="C.UTF-8", LC_ALL="C.UTF-8")
    for var in ("TMUX", "STY", "SSH_CONNECTION", "SSH_TTY", "SSH_CLIENT"):
        env.pop(var, None)
    if config == "lab":
        return Terminal(lab_command(lab, mode, args.play_args), env, raw)
    cmd = stock_command(lab, mode, args.stock_play_args)
    if mode in ("kitty", "xterm"):
        from real_terminal import TappedTerminal

        return TappedTerminal(mode, cmd, display, lab.dir, raw, driver=args.kitty_driver)
    return Terminal(cmd, env, raw)


def measure(lab, config, mode, capacity, args, display, name):
    keep = args.keep_logs
    raw = os.path.join(keep, f"{name}.raw") if keep else None
    ports = (22, 2222, SERVE_PORT)
    candidates = mode if args.candidates and mode.startswith(("tmux", "screen")) else None
    path_log = PathLog(lab, os.path.join(keep or lab.dir, f"{name}.path.csv"), ports, candidates)
    first = attach_first(lab, mode, args.stock_play_args) if mode.endswith("-attach") else None
    # Another flow on the link (--cross-traffic): a bulk download over its own SSH connection.
    bulk = None
    if args.cross_traffic and config == "stock":
        remote = "head -c 200000000 /dev/zero"
        bulk = lab.start(lab.ns(lab.client_ns, *lab.ssh_command(remote=remote, stock=True, tty=False)), "bulk flow", quiet=True)
    if first:
        time.sleep(3)
    term = open_terminal(lab, config, mode, args, raw, display)
    stones = Stones(term) if config == "stock" else None
    shot_frames = None
    try:
        start = time.monotonic()
        if stones:
            stones.start()
        # Busy water in the lab rows: a stone every half second besides the rain and the breeze.
        redraws = sorted(args.redraw_at or [])
        while time.monotonic() - start < args.warm_up:
            if not stones:
                term.write(b" ")
            time.sleep(0.5)
            while redraws and time.monotonic() - start >= redraws[0] and config == "stock":
                redraws.pop(0)
                redraw(lab, mode)
        if args.shots:
            shot_frames = take_shots(term, args.shots, name)
        measuring = time.monotonic()
        latencies, missed = [], 0
        keys = []  # (pressed, shown or None), CLOCK_MONOTONIC: the clock the player's Instant reads
        size_up = True
        for _ in range(args.presses):
            if not stones:
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
            keys.append((at, shown))
            if shown:
                latencies.append(shown - at)
                size_up = not size_up
            else:
                missed += 1
            time.sleep(max(0.0, at + 1.5 - time.monotonic()))
            if not stones:
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
        if keep:
            with open(os.path.join(keep, f"{name}.keys.csv"), "w") as f:
                f.write("pressed,shown,ms\n")
                for at, shown in keys:
                    f.write(f"{at:.4f},{shown or 0:.4f},{(shown - at) * 1e3 if shown else -1:.0f}\n")
        seconds = end - measuring
        gaps = [b - a for a, b in zip([measuring] + changes, changes + [end])]
        frames = len(syncs) if syncs else bursts(changes)
        said = re.search(r"(\d+) fps \u00b7 ([\d.]+ [kMG]?B/s)", status)
        # The hint stands apart at the line's right end (after a run of spaces).
        hint = re.search(r"\s{2,}(\S[^\n]*--bandwidth[^\n]*?)\s*$", status.split("\n")[0])
        return {
            "latencies": latencies,
            "missed": missed,
            "bytes_per_s": received / seconds,
            "capacity": capacity,
            "fps": frames / seconds,
            "fps_from": "sync" if syncs else "bursts",
            "stall": max(gaps) if gaps else seconds,
            "player_says": (f"{said.group(1)} fps, {said.group(2)}" if said else "-") + (f"; {hint.group(1).strip()}" if hint else ""),
            "status": status,
            "unparsed": unparsed,
        }
    finally:
        if stones:
            stones.done = True
            stones.join(timeout=1)
        term.write(b"q")
        time.sleep(0.3)
        term.close()
        print(f"  {name}: {path_log.stop()}", file=sys.stderr, flush=True)
        for proc in (first, bulk):
            if proc:
                from lab import stop

                stop(proc)
        # A multiplexer's server outlives its client when the player did not quit: end it.
        lab.stop_sessions()
        if shot_frames:
            for path in save_shots(shot_frames, args.shots, name):
                print(f"  shot: {path}", file=sys.stderr, flush=True)


def bursts(changes, gap=0.010):
    """Screen updates separated by at least `gap` of quiet (for streams without frame marks)."""
    count, last = 0, None
    for t in changes:
        if last is None or t - last >= gap:
            count += 1
        last = t
    return count


def row_text(config, link, mode, r):
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
        f"| {config:<5} | {link:<14} | {mode:<6} | {latency.replace(' ms ', ' ms | ')}{missed} | "
        f"{r['bytes_per_s'] / 1e3:6.1f} kB/s of {r['capacity'] / 1e3:.0f} ({used:3.0f} %) | "
        f"{r['fps']:5.1f} ({r['fps_from']}) | {r['stall'] * 1e3:6.0f} ms | {r['player_says']} |"
    )


def parse_args():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--tidepool", default=os.path.join(HERE, "..", "..", "target", "release", "tidepool"), help="the binary to measure (default: this checkout's target/release/tidepool)")
    parser.add_argument("--config", default="lab,stock", help="configurations to run, of lab, stock (default both)")
    parser.add_argument("--links", help=f"links to run, of {', '.join(LINKS)} (default: each configuration's own)")
    parser.add_argument("--modes", help="clients to run (default: each configuration's own: lab ssh,tmux,mosh,serve; stock ssh,screen,tmux,mosh,serve,kitty,xterm)")
    parser.add_argument("--presses", type=int, default=12, help="status-line keys timed per row (default 12)")
    parser.add_argument("--warm-up", type=float, default=6.0, help="seconds of busy water before timing (default 6)")
    parser.add_argument("--play-args", default="--seed 5 --color truecolor", help="arguments for `tidepool play` in the lab rows (default: --seed 5 --color truecolor)")
    parser.add_argument(
        "--kitty-driver",
        default="softpipe",
        choices=("softpipe", "llvmpipe"),
        help="Mesa's software driver under the kitty rows (default softpipe: its screenshots are right, "
        "llvmpipe draws a ghost status line, scripts/kitty_ghost.sh; llvmpipe is what LIBGL_ALWAYS_SOFTWARE=1 "
        "picks and what issue 27 measured, and draws a frame several times faster)",
    )
    parser.add_argument("--stock-play-args", default="", help="arguments for `tidepool play` in the stock rows (default none: the issue's commands)")
    parser.add_argument("--timeout", type=float, default=1200.0, help="the whole run ends after this many seconds (default 1200)")
    parser.add_argument("--shots", metavar="DIR", help="after each row's warm-up: a stone, then the screen as a PNG 3 s later and a 5 s GIF, as DIR/MODE-LINK[-TAG].png/.gif (needs pillow)")
    parser.add_argument("--shot-tag", default="", help="appended to the shots' names (e.g. before, after)")
    parser.add_argument("--keep-logs", metavar="DIR", help="keep every byte the terminal read (DIR/MODE-LINK[-TAG].raw), what the player could see of its path (.path.csv) and the run's sshd, serve and relay logs (DIR/logs-TAG/)")
    parser.add_argument("--names", help="the namespaces are NAMESc and NAMESs (default tp<pid>)")
    parser.add_argument("--subnet", default="10.213.0", help="the veth pair's /24, three octets (default 10.213.0)")
    parser.add_argument("--port-base", type=int, default=12200, help="the relays listen on the client namespace's loopback from this port (default 12200)")
    parser.add_argument("--display", default=":79", help="the Xvfb display of the kitty and xterm rows (default :79)")
    parser.add_argument("--redraw-at", type=float, action="append", help="stock tmux and screen rows: make the multiplexer redraw its whole screen this many seconds into the warm-up (tmux refresh-client, screen redisplay; repeatable)")
    parser.add_argument("--cross-traffic", action="store_true", help="stock rows: another flow on the link, a bulk download over a second SSH connection all through the row")
    parser.add_argument("--candidates", action="store_true", help="tmux and screen rows: also log what else a program inside could read (tmux's #{client_written}, sshd's /proc/PID/io and memory) in the .path.csv")
    parser.add_argument("--congestion", help="TCP congestion control inside the two namespaces (default: the machine's, e.g. bbr; cubic is Linux's own default)")
    parser.add_argument("--stock-user", default="tplink", help="the stock configuration's test user, made for the run if missing (default tplink)")
    return parser.parse_args()


def check(args):
    """The rows to run, [(config, link, mode)], after checking the arguments and the tools."""
    if os.geteuid() != 0:
        sys.exit("link_harness: needs root (network namespaces, tc, sshd)")
    configs = args.config.split(",")
    for config in configs:
        if config not in CONFIGS:
            sys.exit(f"link_harness: unknown configuration {config!r}: one of {', '.join(CONFIGS)}")
    rows = []
    for link in LINKS:
        for config in configs:
            links = args.links.split(",") if args.links else CONFIGS[config]["links"]
            modes = args.modes.split(",") if args.modes else CONFIGS[config].get("default", CONFIGS[config]["modes"])
            for name in links:
                if name not in LINKS:
                    sys.exit(f"link_harness: unknown link {name!r}: one of {', '.join(LINKS)}")
            for mode in modes:
                if mode not in CONFIGS[config]["modes"]:
                    if args.modes and not any(mode in CONFIGS[c]["modes"] for c in configs):
                        sys.exit(f"link_harness: unknown client {mode!r} for {args.config}")
                    continue
                if link in links and not (config == "lab" and LINKS[link][2] == 0):
                    rows.append((config, link, mode))
    if not rows:
        sys.exit("link_harness: no rows: the lab configuration needs a link with a round trip (e.g. 2mbit-20ms)")
    tools = ["ip", "tc", "ssh", "ssh-keygen"]
    tools += ["mosh", "mosh-server"] if any(m == "mosh" for _, _, m in rows) else []
    tools += [m for _, _, m in rows if m in ("tmux", "screen", "kitty", "xterm")]
    for tool in tools:
        if not shutil.which(tool):
            sys.exit(f"link_harness: {tool} is missing: apt-get install -y openssh-server mosh tmux screen iproute2 (kitty, xterm: with xvfb)")
    if not os.path.exists("/usr/sbin/sshd"):
        sys.exit("link_harness: /usr/sbin/sshd is missing: apt-get install -y openssh-server")
    if not re.fullmatch(r"\d{1,3}\.\d{1,3}\.\d{1,3}", args.subnet):
        sys.exit("link_harness: --subnet takes three octets, e.g. 10.213.0")
    if args.names and not re.fullmatch(r"[a-z][a-z0-9]{0,12}", args.names):
        sys.exit("link_harness: --names takes lower-case letters and digits (at most 13)")
    if not re.fullmatch(r":[0-9]{1,4}", args.display):
        sys.exit("link_harness: --display takes an X display such as :79")
    if not 1024 <= args.port_base <= 65000:
        sys.exit("link_harness: --port-base must be between 1024 and 65000")
    if args.congestion and not re.fullmatch(r"[a-z0-9_]{1,16}", args.congestion):
        sys.exit("link_harness: --congestion takes a congestion control's name, e.g. cubic")
    if not re.fullmatch(r"[a-z][a-z0-9]{0,15}", args.stock_user):
        sys.exit("link_harness: --stock-user takes a user name of lower-case letters and digits")
    if args.shots:
        try:
            import PIL  # noqa: F401
        except ImportError:
            sys.exit("link_harness: --shots needs pillow: pip install pillow")
    if args.shot_tag and not re.fullmatch(r"[A-Za-z0-9_.-]{1,40}", args.shot_tag):
        sys.exit("link_harness: --shot-tag takes letters, digits, '.', '_' and '-' (at most 40)")
    return rows


def main():
    args = parse_args()
    rows = check(args)
    tidepool = os.path.abspath(args.tidepool)
    if not os.access(tidepool, os.X_OK):
        sys.exit(f"link_harness: no tidepool binary at {tidepool}: cargo build --release, or --tidepool PATH")
    for directory in (args.shots, args.keep_logs):
        if directory:
            os.makedirs(directory, exist_ok=True)
    tag = f"-{args.shot_tag}" if args.shot_tag else ""

    def out_of_time(*_):
        raise TimeoutError(f"the run took longer than --timeout {args.timeout:.0f} s")

    signal.signal(signal.SIGALRM, out_of_time)
    signal.signal(signal.SIGTERM, out_of_time)
    signal.alarm(int(args.timeout))
    lab = Lab(tidepool, args.timeout, names=args.names, subnet=args.subnet, port_base=args.port_base, stock_user=args.stock_user)
    display = None
    try:
        from real_terminal import Display

        display = Display(args.display)
        configs = {c for c, _, _ in rows}
        lab.setup(lab_sshd="lab" in configs, stock_sshd="stock" in configs, congestion=args.congestion)
        load_before = os.getloadavg()
        congestion = run_text(lab.ns(lab.server_ns, "sysctl", "-n", "net.ipv4.tcp_congestion_control")).strip()
        print(f"TCP congestion control in the namespaces: {congestion}")
        print(f"tidepool: {tidepool}\nlab play args: {args.play_args}; stock play args: {args.stock_play_args or '(none)'}; {args.presses} presses per row after {args.warm_up:.0f} s of busy water")
        print("| config | link | client | key->effect median | p90 | reached the terminal | fps | longest stall | the player's status says |")
        print("|---|---|---|---|---|---|---|---|---|")
        shaped = None
        for config, link, mode in rows:
            rate, capacity, rtt = LINKS[link]
            if shaped != link:
                lab.shape(rate, rtt)
                shaped = link
            result = measure(lab, config, mode, capacity, args, display, f"{config}-{mode}-{link}{tag}")
            print(row_text(config, link, mode, result), flush=True)
        load_after = os.getloadavg()
        print(f"load average before: {load_before[0]:.2f}, after: {load_after[0]:.2f} ({os.cpu_count()} cores)")
    finally:
        signal.alarm(0)
        if args.keep_logs:
            shutil.copytree(lab.dir, os.path.join(args.keep_logs, f"logs{tag or '-run'}"), ignore=shutil.ignore_patterns("*key*", "authorized_keys", "known_hosts", "*.fifo"), dirs_exist_ok=True)
        if display:
            display.close()
        lab.close()


if __name__ == "__main__":
    main()
