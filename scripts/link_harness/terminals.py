#!/usr/bin/env python3
"""Real pixel terminals over the harness's shaped link (issue 22): kitty and xterm (sixel).

Builds the harness's lab (two namespaces, the tbf-shaped veth pair, the delaying relay, its own
sshd: see README.md), starts Xvfb on a display of its own, and for each terminal opens it on
`ssh -t host tidepool play --graphics auto ARGS`, the ssh client running in the client
namespace, so everything the player sends crosses the shaped link. After --seconds (8) the
screen is saved (`import -window root`, cropped to the terminal's window) as OUT/TERMINAL-over-LINK[-TAG].png and the
terminal is closed.

    sudo python3 scripts/link_harness/terminals.py --out docs/terminals
    sudo python3 scripts/link_harness/terminals.py --terminals xterm --link 256kbit-300ms --out /tmp/t

kitty runs with LIBGL_ALWAYS_SOFTWARE=1 and GALLIUM_DRIVER=softpipe: Mesa's llvmpipe draws a
ghost status line under kitty (scripts/kitty_ghost.sh; a kitty/Mesa matter, not tidepool's).
xterm runs as `xterm -ti vt340` with 256 colour registers, as scripts/real_terminals.sh does.
Needs root, what harness.py needs, and Debian's xvfb, kitty, xterm and imagemagick. Bounded by
--timeout; everything it starts is stopped by id and the namespaces are deleted at the end.
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
from lab import Lab, stop
from real_terminal import CROPS, TERMINALS

def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--tidepool", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "target", "release", "tidepool"))
    parser.add_argument("--link", default="2mbit-20ms", help=f"one of {', '.join(LINKS)} (default 2mbit-20ms)")
    parser.add_argument("--terminals", default="kitty,xterm", help="of kitty, xterm (default both)")
    parser.add_argument("--play-args", default="--graphics auto --seed 5", help="arguments for `tidepool play` (default: --graphics auto --seed 5)")
    parser.add_argument("--seconds", type=float, default=8.0, help="how long each terminal plays before its screenshot (default 8, at most 120)")
    parser.add_argument("--out", default="target/terminals_over_link", help="where the screenshots go")
    parser.add_argument("--tag", default="", help="appended to the screenshots' names")
    parser.add_argument("--kitty-driver", default="softpipe", choices=("softpipe", "llvmpipe"), help="Mesa's software driver under kitty (default softpipe: llvmpipe draws kitty's ghost status line)")
    parser.add_argument("--logs", metavar="DIR", help="keep each terminal's own output as DIR/TERMINAL-over-LINK[-TAG].log, and both directions between it and ssh (util-linux script -B, advanced timing) as .raw and .timing")
    parser.add_argument("--display", default=":79", help="the Xvfb display to start (default :79)")
    parser.add_argument("--timeout", type=float, default=300.0, help="the whole run ends after this many seconds (default 300)")
    parser.add_argument("--names", help="the namespaces are NAMESc and NAMESs (default tp<pid>)")
    parser.add_argument("--subnet", default="10.213.0", help="the veth pair's /24, three octets (default 10.213.0)")
    args = parser.parse_args()
    if os.geteuid() != 0:
        sys.exit("terminals.py: needs root (network namespaces, tc, sshd)")
    if args.link not in LINKS:
        sys.exit(f"terminals.py: unknown link {args.link!r}: one of {', '.join(LINKS)}")
    names = args.terminals.split(",")
    for name in names:
        if name not in TERMINALS:
            sys.exit(f"terminals.py: unknown terminal {name!r}: one of {', '.join(TERMINALS)}")
    if args.tag and not re.fullmatch(r"[A-Za-z0-9_.-]{1,40}", args.tag):
        sys.exit("terminals.py: --tag takes letters, digits, '.', '_' and '-' (at most 40)")
    if not re.fullmatch(r":[0-9]{1,4}", args.display):
        sys.exit("terminals.py: --display takes an X display such as :79")
    if not 1 <= args.seconds <= 120:
        sys.exit("terminals.py: --seconds must be between 1 and 120")
    for tool in ("Xvfb", "import", *names):
        if not shutil.which(tool):
            sys.exit(f"terminals.py: {tool} is missing: apt-get install -y xvfb kitty xterm imagemagick")
    tidepool = os.path.abspath(args.tidepool)
    if not os.access(tidepool, os.X_OK):
        sys.exit(f"terminals.py: no tidepool binary at {tidepool}: cargo build --release, or --tidepool PATH")
    for directory in (args.out, args.logs):
        if directory:
            os.makedirs(directory, exist_ok=True)
    tag = f"-{args.tag}" if args.tag else ""

    def out_of_time(*_):
        raise TimeoutError(f"the run took longer than --timeout {args.timeout:.0f} s")

    signal.signal(signal.SIGALRM, out_of_time)
    signal.signal(signal.SIGTERM, out_of_time)
    signal.alarm(int(args.timeout))
    lab = Lab(tidepool, args.timeout, names=args.names, subnet=args.subnet)
    xvfb = None
    try:
        lab.setup()
        rate, _, rtt = LINKS[args.link]
        lab.shape(rate, rtt)
        xvfb = subprocess.Popen(["Xvfb", args.display, "-screen", "0", "1600x1000x24"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(2)
        env = dict(os.environ, DISPLAY=args.display)
        for var in ("TMUX", "SSH_CONNECTION", "SSH_TTY", "KITTY_WINDOW_ID", "TERM_PROGRAM"):
            env.pop(var, None)
        play = f"{shlex.quote(tidepool)} play {args.play_args}"
        ssh = lab.ns(lab.client_ns, *lab.ssh_command(remote=play))
        for name in names:
            shot = os.path.join(args.out, f"{name}-over-{args.link}{tag}.png")
            log = open(os.path.join(args.logs or lab.dir, f"{name}-over-{args.link}{tag}.log"), "wb")
            client = ssh
            if args.logs:
                # What reaches the terminal, with timings (util-linux `script`), for a later look.
                base = os.path.join(args.logs, f"{name}-over-{args.link}{tag}")
                # Both directions (-B) with advanced timing: the terminal's answers are in it too.
                client = ["script", "-q", "-f", "-m", "advanced", "-T", f"{base}.timing", "-B", f"{base}.raw", "-c", shlex.join(ssh)]
            term = subprocess.Popen(TERMINALS[name](client, args.kitty_driver), env=env, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT)
            time.sleep(args.seconds)
            subprocess.run(["import", "-window", "root", "-crop", CROPS[name], "+repage", shot], env=env, check=False, timeout=30)
            print(f"{name}: {shot}", flush=True)
            stop(term)
            log.close()
            # The remote player ends with its ssh session; give sshd a moment to reap it.
            time.sleep(1)
        print(f"load average: {os.getloadavg()[0]:.2f} ({os.cpu_count()} cores)")
    finally:
        signal.alarm(0)
        if xvfb:
            stop(xvfb)
        lab.close()


if __name__ == "__main__":
    main()
