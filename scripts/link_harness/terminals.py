#!/usr/bin/env python3
"""Real pixel terminals on this machine and over a shaped SSH link: kitty, xterm (sixel), mlterm.

For each terminal, door and place it opens the terminal (140x45 cells under Xvfb) on:
- `play`, `local`: `tidepool play ARGS` in the terminal itself;
- `serve`, `local`: `ssh` to a `tidepool serve` on this machine's loopback;
- `play`, `link`: `ssh -tt USER@FAR tidepool play ARGS`, the ssh client in the client network
  namespace, so everything crosses the shaped link (`ssh -t root@...` in the harness lab);
- `serve`, `link`: `ssh -tt` to `tidepool serve` in the far namespace (`-t` in the harness lab).
A `space` stone is dropped at 5 s (xdotool, through XTEST: xterm ignores synthetic key events);
the terminal's window is saved at each of --shots seconds (2, 6, 12, 30) as
OUT/TERMINAL-DOOR-PLACE[-TAG]-Ns.png; through util-linux `script -B -m advanced` both directions
between the terminal and its client are kept with their times, and the summary says when the
probe was answered and when the first picture (kitty `a=T`, a sixel image) arrived after it.

The link is lab.py's: two namespaces (--ns-prefix: PREFIXc, PREFIXs) joined by a veth pair
(--subnet: SUBNET.1, SUBNET.2), both ends `tc qdisc replace dev X root tbf rate 2mbit burst 32kbit
latency 400ms`. `--lab stock` (the default) is lab.py's stock configuration: no relay, Debian's
own sshd started plainly on port 22 of the far namespace (/etc/ssh/sshd_config as shipped:
`AcceptEnv LANG LC_*`, COLORTERM never arrives), the test user (--stock-user, made for the run
unless it exists) and the system's ssh client configuration. `--lab harness` is lab.py's lab
configuration instead (root, its sshd on 2222 taking COLORTERM, the relays adding the link's
round trip).

    sudo python3 scripts/link_harness/terminals.py --out docs/terminals/right-pictures
    sudo python3 scripts/link_harness/terminals.py --terminals kitty --doors serve --places link

kitty runs with LIBGL_ALWAYS_SOFTWARE=1 (Mesa's llvmpipe; --kitty-driver softpipe is slower:
kitty then answered the link's questions 1.5 s apart; llvmpipe draws a ghost status line under
kitty 0.26, scripts/kitty_ghost.sh). xterm runs as `xterm -ti vt340`
with 256 colour registers. Needs root, Debian's xvfb, kitty, xterm, mlterm, imagemagick,
xdotool, openssh-server and iproute2. Bounded by --timeout; everything it starts is stopped by
id and the namespaces are deleted at the end.
"""

import argparse
import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import time

from harness import LINKS
from lab import SERVE_PORT, STOCK_USER, Lab, stop

# Each terminal at 140x45 cells, at the top left of the screen (no window manager).
TERMINALS = {
    "kitty": lambda cmd, driver: [
        "env", "LIBGL_ALWAYS_SOFTWARE=1", f"GALLIUM_DRIVER={driver}",
        "kitty", "-o", "initial_window_width=140c", "-o", "initial_window_height=45c", "-o", "remember_window_size=no",
        *cmd,
    ],
    "xterm": lambda cmd, driver: [
        "xterm", "-ti", "vt340", "-xrm", "XTerm*numColorRegisters: 256", "-xrm", "XTerm*maxGraphicSize: 2000x2000",
        "-geometry", "140x45+0+0", "-e", *cmd,
    ],
    "mlterm": lambda cmd, driver: ["mlterm", "-g", "140x45+0+0", "-e", *cmd],
}
DOORS = ("play", "serve")
PLACES = ("local", "link")
# A loopback port of this run's range for the local `tidepool serve`.
LOCAL_SERVE_PORT = 27223


def local_ssh(lab, port):
    """OpenSSH's client for the `tidepool serve` on this machine's loopback: no config, this
    run's key, root, `-tt`."""
    cmd = ["ssh", "-F", "/dev/null", "-i", f"{lab.dir}/client_key", "-p", str(port)]
    cmd += ["-o", "IdentitiesOnly=yes", "-o", f"UserKnownHostsFile={lab.dir}/known_hosts", "-o", "StrictHostKeyChecking=no"]
    return cmd + ["-o", "LogLevel=ERROR", "-tt", "root@127.0.0.1"]


def window_box(env, pid):
    """The terminal's window (WIDTH, HEIGHT, X, Y), found by its process id."""
    for _ in range(50):
        found = subprocess.run(["xdotool", "search", "--onlyvisible", "--pid", str(pid)], env=env, capture_output=True, text=True, timeout=10)
        if found.stdout.split():
            wid = found.stdout.split()[0]
            shell = subprocess.run(["xdotool", "getwindowgeometry", "--shell", wid], env=env, capture_output=True, text=True, timeout=10).stdout
            g = dict(line.split("=", 1) for line in shell.split() if "=" in line)
            return wid, (int(g["WIDTH"]), int(g["HEIGHT"]), int(g["X"]), int(g["Y"]))
        time.sleep(0.1)
    return None, None


def first_picture(raw_path, timing_path):
    """From `script -B -m advanced` logs: seconds from start to the probe's answer (the first
    DA1 reply the terminal sent), and from that answer to the first picture's bytes (kitty
    `a=T`, a sixel image `ESC P ... q`) the terminal received; None where not seen."""
    try:
        raw = open(raw_path, "rb").read()
        lines = open(timing_path).read().split("\n")
    except FileNotFoundError:
        return None, None
    # The log starts with script's own line ("Script started on ..."), not in the timing.
    at, pos, answered, picture = 0.0, raw.find(b"\n") + 1, None, None
    seen_in, seen_out = b"", b""
    for line in lines:
        parts = line.split()
        if len(parts) < 3 or parts[0] not in ("I", "O"):
            continue
        at += float(parts[1])
        size = int(parts[2])
        chunk = raw[pos:pos + size]
        pos += size
        if parts[0] == "I":
            seen_in += chunk
            if answered is None and re.search(rb"\x1b\[\?[0-9;]*c", seen_in):
                answered = at
        else:
            seen_out = seen_out[-64:] + chunk
            if answered is not None and picture is None and (b"\x1b_Ga=T" in seen_out or re.search(rb"\x1bP[0-9;]*q", seen_out)):
                picture = at - answered
    return answered, picture


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--tidepool", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "target", "release", "tidepool"))
    parser.add_argument("--link", default="2mbit-20ms", help=f"the link's rate, of {', '.join(LINKS)} (default 2mbit-20ms; the stock lab adds no round trip)")
    parser.add_argument("--lab", default="stock", choices=("stock", "harness"), help="stock: Debian's sshd on port 22, the test user, no relay (default); harness: lab.py's own sshd as root, and relays")
    parser.add_argument("--stock-user", default=STOCK_USER, help=f"the stock lab's test user, made for the run if missing (default {STOCK_USER})")
    parser.add_argument("--ns-prefix", default="p27", help="the namespaces' names: PREFIXc, PREFIXs (default p27)")
    parser.add_argument("--subnet", default="10.227.0", help="the veth pair's /24: SUBNET.1, SUBNET.2 (default 10.227.0)")
    parser.add_argument("--terminals", default="kitty,xterm,mlterm", help="of kitty, xterm, mlterm (default all)")
    parser.add_argument("--doors", default="play,serve", help="of play, serve (default both)")
    parser.add_argument("--places", default="local,link", help="of local, link (default both)")
    parser.add_argument("--play-args", default="--seed 5", help="arguments for `tidepool play` (default: --seed 5)")
    parser.add_argument("--shots", default="2,6,12,30", help="seconds after the terminal opens at which its window is saved (default 2,6,12,30; at most 120)")
    parser.add_argument("--out", default="target/terminals", help="where the screenshots and logs go")
    parser.add_argument("--tag", default="", help="appended to the files' names")
    parser.add_argument("--kitty-driver", default="llvmpipe", choices=("softpipe", "llvmpipe"), help="Mesa's software driver under kitty (default llvmpipe, what LIBGL_ALWAYS_SOFTWARE=1 picks; softpipe is slower and draws no ghost line)")
    parser.add_argument("--display", default=":271", help="the Xvfb display to start (default :271)")
    parser.add_argument("--timeout", type=float, default=1200.0, help="the whole run ends after this many seconds (default 1200)")
    args = parser.parse_args()
    if os.geteuid() != 0:
        sys.exit("terminals.py: needs root (network namespaces, tc, sshd)")
    if args.link not in LINKS:
        sys.exit(f"terminals.py: unknown link {args.link!r}: one of {', '.join(LINKS)}")
    lists = {}
    for what, value, allowed in (("terminal", args.terminals, TERMINALS), ("door", args.doors, DOORS), ("place", args.places, PLACES)):
        lists[what] = value.split(",")
        for name in lists[what]:
            if name not in allowed:
                sys.exit(f"terminals.py: unknown {what} {name!r}: one of {', '.join(allowed)}")
    try:
        shots = sorted(float(s) for s in args.shots.split(","))
    except ValueError:
        sys.exit("terminals.py: --shots takes seconds separated by commas, such as 2,6,12,30")
    if not shots or shots[0] < 0.5 or shots[-1] > 120:
        sys.exit("terminals.py: --shots must be between 0.5 and 120 seconds")
    if args.tag and not re.fullmatch(r"[A-Za-z0-9_.-]{1,40}", args.tag):
        sys.exit("terminals.py: --tag takes letters, digits, '.', '_' and '-' (at most 40)")
    if not re.fullmatch(r":[0-9]{1,4}", args.display):
        sys.exit("terminals.py: --display takes an X display such as :271")
    if not re.fullmatch(r"[a-z][a-z0-9]{0,15}", args.stock_user):
        sys.exit("terminals.py: --stock-user takes a user name of lower-case letters and digits (at most 16)")
    if not re.fullmatch(r"[a-z0-9]{1,8}", args.ns_prefix) or not re.fullmatch(r"10\.[0-9]{1,3}\.[0-9]{1,3}", args.subnet):
        sys.exit("terminals.py: --ns-prefix takes up to 8 letters or digits, --subnet three octets such as 10.227.0")
    for tool in ("Xvfb", "import", "convert", "xdotool", "script", "ssh", *lists["terminal"]):
        if not shutil.which(tool):
            sys.exit(f"terminals.py: {tool} is missing: apt-get install -y xvfb kitty xterm mlterm imagemagick xdotool openssh-client")
    tidepool = os.path.abspath(args.tidepool)
    if not os.access(tidepool, os.X_OK):
        sys.exit(f"terminals.py: no tidepool binary at {tidepool}: cargo build --release, or --tidepool PATH")
    os.makedirs(args.out, exist_ok=True)
    tag = f"-{args.tag}" if args.tag else ""

    def out_of_time(*_):
        raise TimeoutError(f"the run took longer than --timeout {args.timeout:.0f} s")

    signal.signal(signal.SIGALRM, out_of_time)
    signal.signal(signal.SIGTERM, out_of_time)
    signal.alarm(int(args.timeout))
    stock = args.lab == "stock"
    lab = Lab(tidepool, args.timeout, names=args.ns_prefix, subnet=args.subnet, stock_user=args.stock_user)
    xvfb = local_serve = None
    summary = []
    try:
        if "link" in lists["place"]:
            lab.setup(lab_sshd=not stock, stock_sshd=stock)
            rate, _, rtt = LINKS[args.link]
            # The stock lab goes straight to the shaped veth (no relay, no added round trip).
            lab.shape(rate, 0 if stock else rtt)
        else:
            for name in ("client_key",):
                subprocess.run(["ssh-keygen", "-q", "-t", "ed25519", "-N", "", "-f", f"{lab.dir}/{name}"], check=True, timeout=30)
        if "serve" in lists["door"] and "local" in lists["place"]:
            local_serve = subprocess.Popen(
                [tidepool, "serve", "--listen", f"127.0.0.1:{LOCAL_SERVE_PORT}", "--host-key", f"{lab.dir}/local_serve_key"],
                stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=open(f"{lab.dir}/local_serve.log", "wb"))
        # -noreset: Xvfb resets when its last client leaves, and a terminal opened during the
        # reset cannot open the display (xterm, then kitty, failed so between two runs).
        xvfb = subprocess.Popen(["Xvfb", args.display, "-noreset", "-screen", "0", "1600x1000x24"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(2)
        env = dict(os.environ, DISPLAY=args.display)
        for var in ("TMUX", "SSH_CONNECTION", "SSH_TTY", "SSH_CLIENT", "KITTY_WINDOW_ID", "TERM_PROGRAM", "COLORTERM"):
            env.pop(var, None)
        play = f"{shlex.quote(tidepool)} play {args.play_args}"
        for name in lists["terminal"]:
            for door in lists["door"]:
                for place in lists["place"]:
                    if place == "local" and door == "play":
                        client = ["sh", "-c", play]
                    elif place == "local":
                        client = local_ssh(lab, LOCAL_SERVE_PORT)
                    elif door == "play":
                        client = lab.ns(lab.client_ns, *lab.ssh_command(remote=play, stock=stock))
                    else:
                        client = lab.ns(lab.client_ns, *lab.ssh_command(port=SERVE_PORT, stock=stock))
                    base = os.path.join(args.out, f"{name}-{door}-{place}{tag}")
                    # Both directions (-B) with their times: the probe's answers and the pictures.
                    recorded = ["script", "-q", "-f", "-m", "advanced", "-T", f"{base}.timing", "-B", f"{base}.raw", "-c", shlex.join(client)]
                    for stale in (f"{base}.timing", f"{base}.raw"):
                        if os.path.exists(stale):
                            os.remove(stale)
                    log = open(f"{base}.log", "wb")
                    term = subprocess.Popen(TERMINALS[name](recorded, args.kitty_driver), env=env, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT)
                    opened = time.monotonic()
                    # When the terminal started `script` (it creates its logs at once): the
                    # probe's and the picture's times below count from there, the shots from
                    # `opened`, and a terminal slow to start (kitty under load) separates them.
                    started = None
                    while started is None and time.monotonic() < opened + 30 and term.poll() is None:
                        if os.path.exists(f"{base}.timing"):
                            started = time.monotonic() - opened
                        else:
                            time.sleep(0.01)
                    wid, box = window_box(env, term.pid)
                    stone = False
                    for t in shots:
                        if not stone and t > 5:
                            time.sleep(max(0.0, opened + 5 - time.monotonic()))
                            if wid:
                                subprocess.run(["xdotool", "windowfocus", "--sync", wid], env=env, timeout=10, check=False)
                            subprocess.run(["xdotool", "key", "space"], env=env, timeout=10, check=False)
                            stone = True
                        time.sleep(max(0.0, opened + t - time.monotonic()))
                        shot = f"{base}-{t:g}s.png"
                        crop = ["-crop", "{}x{}+{}+{}".format(*box), "+repage"] if box else []
                        subprocess.run(["import", "-window", "root", *crop, shot], env=env, check=False, timeout=30)
                    subprocess.run(["xdotool", "key", "q"], env=env, timeout=10, check=False)
                    time.sleep(1)
                    stop(term)
                    log.close()
                    answered, picture = first_picture(f"{base}.raw", f"{base}.timing")
                    line = (f"{name} {door} {place}: "
                            f"{'script never started, ' if started is None else f'started {started:.2f} s after the terminal opened, '}probe answered at "
                            f"{'-' if answered is None else f'{answered:.2f} s'}, first picture "
                            f"{'never' if picture is None else f'{picture:.2f} s after it'}")
                    summary.append(line)
                    print(line, flush=True)
                    # The remote player ends with its ssh session; give sshd a moment to reap it,
                    # then end by id whatever of the row still runs in the far namespace.
                    time.sleep(1)
                    if place == "link":
                        lab.stop_sessions()
        load = os.getloadavg()
        print(f"load average: {load[0]:.2f} {load[1]:.2f} {load[2]:.2f} ({os.cpu_count()} cores)")
        with open(os.path.join(args.out, f"summary{tag}.txt"), "w") as f:
            f.write("\n".join(summary) + f"\nload average: {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}\n")
    finally:
        signal.alarm(0)
        for proc in (xvfb, local_serve):
            if proc:
                stop(proc)
        lab.close()


if __name__ == "__main__":
    main()
