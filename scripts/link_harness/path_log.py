"""What the player could see of its path, logged beside each row (`--keep-logs`).

Once the player runs in the server namespace: its environment's path variables (`SSH_CONNECTION`,
`SSH_TTY`, `TMUX`, `STY`, `TERM`, `COLORTERM`) and its ancestors' names, which is what its path
detection reads. Then every 100 ms: the send queue (`tx_queue` of /proc/net/tcp, what the player
reads inside a multiplexer) of every established connection to the SSH and serve ports, the
bytes the player has written (`wchar` of /proc/PID/io) and sshd's session process's bytes read
and written (its `rchar` less its `wchar` grows while sshd holds output the socket has not
taken: its channel buffer, which the socket's queue cannot show); every 500 ms `ss -tmi` for
the connection (its send buffer, bytes not yet sent).
"""

import re
import subprocess
import threading
import time

SAMPLE = 0.1
SS_EVERY = 5
PATH_VARS = ("SSH_CONNECTION", "SSH_CLIENT", "SSH_TTY", "TMUX", "STY", "ZELLIJ", "TERM", "COLORTERM")


def read(path, binary=False):
    try:
        with open(path, "rb" if binary else "r", errors=None if binary else "replace") as f:
            return f.read()
    except (FileNotFoundError, ProcessLookupError, PermissionError):
        return b"" if binary else ""


def io_counts(pid):
    text = read(f"/proc/{pid}/io")
    fields = dict(line.split(": ") for line in text.splitlines() if ": " in line)
    return int(fields.get("rchar", 0)), int(fields.get("wchar", 0))


def ancestors(pid):
    names = []
    for _ in range(16):
        stat = read(f"/proc/{pid}/stat")
        if not stat:
            break
        names.append(stat[stat.index("(") + 1 : stat.rindex(")")])
        pid = int(stat.rsplit(")", 1)[1].split()[1])
        if pid <= 1:
            break
    return names


def established(table, ports):
    """(local port, remote, tx_queue) of the established sockets on `ports`."""
    rows = []
    for line in table.splitlines()[1:]:
        cols = line.split()
        if len(cols) < 5 or cols[3] != "01":
            continue
        port = int(cols[1].split(":")[1], 16)
        if port in ports:
            rows.append((port, cols[2], int(cols[4].split(":")[0], 16)))
    return rows


class PathLog:
    """Samples the server namespace while a row runs; `stop` returns a one-line summary.
    `candidates` (tmux and screen rows, `--candidates`): every 500 ms also what else a program
    inside the multiplexer could read, as the test user: tmux's count of bytes written to its
    client (`#{client_written}`), whether sshd's session process lets it read its byte counts
    (`/proc/PID/io`), and that process's resident memory (`/proc/PID/status`, which anyone
    reads: it grows with sshd's buffer)."""

    def __init__(self, lab, path, ports, candidates=None):
        self.lab, self.path, self.ports = lab, path, set(ports)
        self.candidates = candidates
        self.out = open(path, "w")
        self.out.write("time,tx_queues,player_wchar,sshd_rchar,sshd_wchar,ss\n")
        self.done = False
        self.player = None
        self.sshd = None
        self.seen = ""
        self.queues = []
        self.thread = threading.Thread(target=self.run, daemon=True)
        self.thread.start()

    def find(self):
        for pid in self.lab.namespace_pids(self.lab.server_ns):
            cmdline = read(f"/proc/{pid}/cmdline").replace("\0", " ")
            comm = read(f"/proc/{pid}/comm").strip()
            if self.player is None and comm == "tidepool" and " play" in cmdline:
                self.player = pid
                env = dict(v.split("=", 1) for v in read(f"/proc/{pid}/environ").split("\0") if "=" in v)
                seen = " ".join(f"{k}={env[k]!r}" for k in PATH_VARS if k in env)
                self.seen = f"player {pid}: {seen or 'no path variables'}; ancestors {' < '.join(ancestors(pid)[1:])}"
                self.out.write(f"# {self.seen}\n")
            if self.sshd is None and comm == "sshd" and "@" in cmdline:
                self.sshd = pid
                self.out.write(f"# sshd session {pid}: {cmdline.strip()}\n")

    def run(self):
        # serve runs in the server namespace: its /proc/PID/net/tcp is that namespace's table.
        anchor = self.lab.serve.pid
        count = 0
        while not self.done:
            now = time.monotonic()
            if self.player is None or self.sshd is None:
                self.find()
            table = read(f"/proc/{anchor}/net/tcp") if anchor else ""
            queues = established(table, self.ports)
            if queues:
                self.queues.append(max(q for _, _, q in queues))
            player = io_counts(self.player)[1] if self.player else 0
            sshd = io_counts(self.sshd) if self.sshd else (0, 0)
            ss = ""
            if count % SS_EVERY == 0:
                ss = self.ss()
                if self.candidates:
                    ss += " " + self.candidate_sample()
            count += 1
            qtext = " ".join(f"{p}>{r}:{q}" for p, r, q in queues)
            self.out.write(f"{now:.3f},{qtext},{player},{sshd[0]},{sshd[1]},{ss}\n")
            time.sleep(max(0.0, now + SAMPLE - time.monotonic()))

    def candidate_sample(self):
        user = ["runuser", "-u", self.lab.stock_user, "--"]
        out = []
        if self.candidates.startswith("tmux"):
            written = subprocess.run(self.lab.ns(self.lab.server_ns, *user, "tmux", "-L", "x", "list-clients", "-F", "#{client_written}"), timeout=5, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True).stdout.split()
            out.append(f"client_written:{'/'.join(written) or '-'}")
        if self.sshd:
            io = subprocess.run([*user, "cat", f"/proc/{self.sshd}/io"], timeout=5, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True).stdout
            out.append("io_as_user:" + ("readable" if "rchar" in io else io.strip().split(":")[-1].strip().replace(" ", "_")))
            rss = re.search(r"VmRSS:\s+(\d+)", read(f"/proc/{self.sshd}/status"))
            out.append(f"sshd_rss_kB:{rss.group(1) if rss else '-'}")
        return " ".join(out)

    def ss(self):
        try:
            out = subprocess.run(self.lab.ns(self.lab.server_ns, "ss", "-tmiH", "state", "established"), timeout=5, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True).stdout
        except subprocess.TimeoutExpired:
            return ""
        keep = []
        for m in re.finditer(r"skmem:\(([^)]*)\)|notsent:(\d+)|delivery_rate (\S+)|\brtt:(\S+)", out):
            keep.append(m.group(0).replace(",", ";"))
        return " ".join(keep)

    def stop(self):
        self.done = True
        self.thread.join(timeout=2)
        self.out.close()
        queue = ""
        if self.queues:
            q = sorted(self.queues)
            queue = f"; sshd's socket queue median {q[len(q) // 2] / 1e3:.0f} kB, max {q[-1] / 1e3:.0f} kB"
        return (self.seen or "player not found") + queue
