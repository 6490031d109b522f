"""The harness's link: two network namespaces, a shaped veth pair, sshd, `tidepool serve`, relays.

Two ways to reach the far namespace (see README.md):
- the *lab* configuration (the harness's first rows): an sshd of its own, its own config and
  host key, root admitted with a key made for the run, port 2222, `AcceptEnv COLORTERM`, always
  behind the delaying relay;
- the *stock* configuration (issue 30, the link as a user builds it): Debian's own sshd started
  plainly (`ip netns exec NS /usr/sbin/sshd`: /etc/ssh/sshd_config as shipped, PAM, privilege
  separation, port 22), a test user made for the run, and the relay only where a round trip is
  added (the base rows go straight to the shaped veth).

Everything the lab starts is stopped by `close`, by process id: its own children, then whatever
still runs inside its two namespaces (sshd's daemon, the user's sessions, tmux's and screen's
servers, mosh-server), then the namespaces are deleted (which removes the veth pair), the test
user too, and the temporary folder.
"""

import os
import pwd
import shutil
import signal
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
# The lab configuration's ports inside the server namespace, and the relays' on the client
# namespace's loopback (offsets from --port-base).
LAB_SSH_PORT, SERVE_PORT, MOSH_PORT = 2222, 2223, 60001
RELAY_LAB_SSH, RELAY_SERVE, RELAY_STOCK_SSH = 22, 23, 24
STOCK_SSH_PORT = 22
# The test user of the stock configuration (made for the run unless it exists).
STOCK_USER = "tplink"


def run(cmd, check=True, timeout=60, **kw):
    """Runs a command to completion (bounded: 60 s)."""
    return subprocess.run(cmd, check=check, timeout=timeout, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, **kw)


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


class Lab:
    """The namespaces, the shaped veth pair, the sshds, serve, the relays; torn down by `close`.

    `names` makes the namespaces `NAMESc` and `NAMESs` (and the veth ends); `subnet` is the
    first three octets of the veth's /24 (`.1` the client, `.2` the server); `port_base` the
    relays' ports on the client's loopback; `stock_user` the stock configuration's test user.
    """

    def __init__(self, tidepool, lifetime, names=None, subnet="10.213.0", port_base=12200, stock_user=STOCK_USER):
        names = names or f"tp{os.getpid()}"
        self.client_ns, self.server_ns = f"{names}c", f"{names}s"
        self.veth_client, self.veth_server = self.client_ns[:15], self.server_ns[:15]
        self.client_ip, self.server_ip = f"{subnet}.1", f"{subnet}.2"
        self.port_base = port_base
        self.dir = tempfile.mkdtemp(prefix="link-harness-")
        os.chmod(self.dir, 0o755)
        self.tidepool = tidepool
        self.lifetime = lifetime
        self.procs = []  # (Popen, description)
        self.relays = []
        self.made_namespaces = False
        self.stock_user = stock_user
        self.made_user = False
        self.stock_uid = None
        self.rtt_ms = 0

    def ns(self, name, *cmd):
        return ["ip", "netns", "exec", name, *cmd]

    def port(self, offset):
        return self.port_base + offset

    def setup(self, lab_sshd=True, stock_sshd=False, congestion=None):
        for ns in (self.client_ns, self.server_ns):
            if os.path.exists(f"/run/netns/{ns}"):
                raise RuntimeError(f"the namespace {ns} exists already (another run, or one not cleaned up): ip netns del {ns}")
        for ns in (self.client_ns, self.server_ns):
            run(["ip", "netns", "add", ns])
            self.made_namespaces = True
        run(["ip", "link", "add", self.veth_client, "type", "veth", "peer", "name", self.veth_server])
        run(["ip", "link", "set", self.veth_client, "netns", self.client_ns])
        run(["ip", "link", "set", self.veth_server, "netns", self.server_ns])
        for ns, dev, ip in ((self.client_ns, self.veth_client, self.client_ip), (self.server_ns, self.veth_server, self.server_ip)):
            run(self.ns(ns, "ip", "addr", "add", f"{ip}/24", "dev", dev))
            run(self.ns(ns, "ip", "link", "set", dev, "up"))
            run(self.ns(ns, "ip", "link", "set", "lo", "up"))
            if congestion:
                # TCP's congestion control in this namespace only (a new namespace takes the
                # machine's default: BBR or CUBIC change how much the sockets hold).
                run(self.ns(ns, "sysctl", "-q", "-w", f"net.ipv4.tcp_congestion_control={congestion}"))
        # Keys made for this run: the lab sshd's host key, the client's key; serve makes its own.
        for name in ("host_key", "client_key"):
            run(["ssh-keygen", "-q", "-t", "ed25519", "-N", "", "-f", f"{self.dir}/{name}"])
        os.makedirs("/run/sshd", exist_ok=True)
        if lab_sshd:
            self.start_lab_sshd()
        if stock_sshd:
            self.start_stock_sshd()
        serve = [self.tidepool, "serve", "--listen", f"{self.server_ip}:{SERVE_PORT}", "--host-key", f"{self.dir}/serve_key"]
        self.serve = self.start(self.ns(self.server_ns, *serve), "tidepool serve")
        self.wait_for_log("tidepool_serve", "listening on")

    def wait_for_log(self, name, word, seconds=20):
        deadline = time.monotonic() + seconds
        while word not in read_text(f"{self.dir}/{name}.log"):
            if time.monotonic() > deadline:
                raise RuntimeError(f"{name} did not start: {read_text(f'{self.dir}/{name}.log')[-300:]}")
            time.sleep(0.05)

    def start_lab_sshd(self):
        shutil.copy(f"{self.dir}/client_key.pub", f"{self.dir}/authorized_keys")
        with open(f"{self.dir}/sshd_config", "w") as f:
            f.write(
                f"""Port {LAB_SSH_PORT}
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
        self.wait_for_log("sshd", "Server listening")

    def start_stock_sshd(self):
        """Debian's sshd as shipped, on port 22 of the server namespace, and the test user."""
        for path in ("/etc/ssh/ssh_host_ed25519_key", "/etc/ssh/sshd_config"):
            if not os.path.exists(path):
                raise RuntimeError(f"{path} is missing: apt-get install -y openssh-server")
        try:
            user = pwd.getpwnam(self.stock_user)
        except KeyError:
            run(["useradd", "--create-home", "--shell", "/bin/bash", self.stock_user])
            self.made_user = True
            user = pwd.getpwnam(self.stock_user)
        self.stock_uid = user.pw_uid
        ssh_dir = os.path.join(user.pw_dir, ".ssh")
        os.makedirs(ssh_dir, exist_ok=True)
        keys = os.path.join(ssh_dir, "authorized_keys")
        shutil.copy(f"{self.dir}/client_key.pub", keys)
        for path, mode in ((ssh_dir, 0o700), (keys, 0o600)):
            os.chown(path, user.pw_uid, user.pw_gid)
            os.chmod(path, mode)
        # Daemonizes, as a user starts it; its pid is found in the namespace.
        run(self.ns(self.server_ns, "/usr/sbin/sshd"))
        deadline = time.monotonic() + 20
        while f":{STOCK_SSH_PORT:04X} " not in self.server_sockets(listening=True):
            if time.monotonic() > deadline:
                raise RuntimeError("the stock sshd did not start listening on port 22")
            time.sleep(0.05)

    def server_sockets(self, listening=False):
        """The server namespace's TCP table (/proc/net/tcp as seen there)."""
        out = run(self.ns(self.server_ns, "cat", "/proc/net/tcp"), check=False).stdout
        if listening:
            return "\n".join(line for line in out.splitlines() if line.split()[3:4] == ["0A"])
        return out

    def start(self, cmd, what, quiet=False, **kw):
        # A new log for each start (relays are restarted for every link); `quiet`: no output kept.
        log = f"{self.dir}/{what.replace(' ', '_')}.log"
        open(log, "w").close()
        out = subprocess.DEVNULL if quiet else open(log, "ab")
        proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=out, stderr=subprocess.STDOUT, **kw)
        self.procs.append((proc, what))
        return proc

    def shape(self, rate, rtt_ms):
        """Shapes both ends to `rate`; with `rtt_ms` > 0 relays add that round trip in front."""
        for ns, dev in ((self.client_ns, self.veth_client), (self.server_ns, self.veth_server)):
            run(self.ns(ns, "tc", "qdisc", "replace", "dev", dev, "root", "tbf", "rate", rate, "burst", "32kbit", "latency", "400ms"))
        for proc, _ in self.relays:
            stop(proc)
        self.relays = []
        self.rtt_ms = rtt_ms
        if rtt_ms <= 0:
            return
        relay = [sys.executable, f"{HERE}/relay.py"]
        routes = (
            ("tcp", RELAY_LAB_SSH, LAB_SSH_PORT),
            ("tcp", RELAY_SERVE, SERVE_PORT),
            ("tcp", RELAY_STOCK_SSH, STOCK_SSH_PORT),
        )
        for kind, offset, target in routes:
            port = self.port(offset)
            cmd = self.ns(self.client_ns, *relay, kind, "127.0.0.1", str(port), self.server_ip, str(target), str(rtt_ms), str(self.lifetime))
            self.relays.append((self.start(cmd, f"relay {kind} {port}"), f"relay_{kind}_{port}"))
        cmd = self.ns(self.client_ns, *relay, "udp", "127.0.0.1", str(MOSH_PORT), self.server_ip, str(MOSH_PORT), str(rtt_ms), str(self.lifetime))
        self.relays.append((self.start(cmd, f"relay udp {MOSH_PORT}"), f"relay_udp_{MOSH_PORT}"))
        # Each relay says when it listens (Python starts slowly on a loaded machine).
        deadline = time.monotonic() + 20
        for proc, name in self.relays:
            while "listening" not in read_text(f"{self.dir}/{name}.log"):
                if proc.poll() is not None or time.monotonic() > deadline:
                    raise RuntimeError(f"the relay {name} did not start: {read_text(f'{self.dir}/{name}.log')[-300:]}")
                time.sleep(0.05)

    def route(self, target_port, relay_offset):
        """Where the client connects for `target_port`: the relay when a round trip is added,
        else the server itself across the shaped veth."""
        if self.rtt_ms > 0:
            return "127.0.0.1", self.port(relay_offset)
        return self.server_ip, target_port

    def ssh_command(self, port=None, remote=None, tty=True, stock=False, user=None):
        """OpenSSH's client for the lab sshd (`stock` False: no config, root, the relay) or the
        stock one (the system's client config, the test user, `-tt`). `port` overrides the
        target (serve's port)."""
        if stock:
            host, target = self.route(port or STOCK_SSH_PORT, RELAY_SERVE if port == SERVE_PORT else RELAY_STOCK_SSH)
            cmd = ["ssh", "-i", f"{self.dir}/client_key", "-p", str(target)]
            cmd += ["-o", "IdentitiesOnly=yes", "-o", f"UserKnownHostsFile={self.dir}/known_hosts", "-o", "StrictHostKeyChecking=no"]
            cmd += ["-o", "LogLevel=ERROR"]
            cmd += ["-tt"] if tty else []
            cmd += [f"{user or self.stock_user}@{host}"]
            return cmd + ([remote] if remote else [])
        host, target = self.route(port or LAB_SSH_PORT, RELAY_SERVE if port == SERVE_PORT else RELAY_LAB_SSH)
        cmd = ["ssh", "-F", "/dev/null", "-i", f"{self.dir}/client_key", "-p", str(target)]
        cmd += ["-o", "IdentitiesOnly=yes", "-o", f"UserKnownHostsFile={self.dir}/known_hosts", "-o", "StrictHostKeyChecking=no"]
        cmd += ["-o", "LogLevel=ERROR", "-o", "SendEnv=COLORTERM"]
        cmd += ["-t"] if tty else []
        cmd += [f"root@{host}"]
        if remote:
            cmd += ["--", remote]
        return cmd

    def namespace_pids(self, ns):
        return [int(p) for p in run(["ip", "netns", "pids", ns], check=False).stdout.split() if p.isdigit()]

    def stop_sessions(self):
        """Ends what a row left in the server namespace besides the servers the lab started
        (the users' sessions, tmux's and screen's servers, mosh-server), by process id; sshd's
        listener and serve stay."""
        keep = {proc.pid for proc, _ in self.procs}
        listener = self.stock_listener()
        for sig in (signal.SIGTERM, signal.SIGKILL):
            left = False
            for pid in self.namespace_pids(self.server_ns):
                if pid in keep or pid == listener:
                    continue
                try:
                    os.kill(pid, sig)
                    left = True
                except ProcessLookupError:
                    pass
            if not left:
                return
            time.sleep(0.3)

    def stock_listener(self):
        """The stock sshd's listening process (`sshd: /usr/sbin/sshd [listener]`), if any."""
        for pid in self.namespace_pids(self.server_ns):
            if "[listener]" in read_text(f"/proc/{pid}/cmdline").replace("\0", " "):
                return pid
        return None

    def close(self):
        for proc, _ in reversed(self.procs):
            stop(proc)
        # Whatever still runs inside the namespaces was started there by this run (the stock
        # sshd daemon and its sessions, mosh-server, tmux's and screen's servers): end it by id.
        if self.made_namespaces:
            for sig in (signal.SIGTERM, signal.SIGKILL):
                for ns in (self.client_ns, self.server_ns):
                    for pid in self.namespace_pids(ns):
                        try:
                            os.kill(pid, sig)
                        except ProcessLookupError:
                            pass
                time.sleep(0.3)
            for ns in (self.client_ns, self.server_ns):
                run(["ip", "netns", "del", ns], check=False)
        if self.stock_uid is not None:
            # tmux's and screen's sockets of the user, outside its home.
            for path in (f"/tmp/tmux-{self.stock_uid}", f"/run/screen/S-{self.stock_user}"):
                shutil.rmtree(path, ignore_errors=True)
        if self.made_user:
            run(["userdel", "--remove", self.stock_user], check=False)
        shutil.rmtree(self.dir, ignore_errors=True)
