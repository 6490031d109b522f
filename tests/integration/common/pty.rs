//! Runs the `tidepool` binary in a real pseudo-terminal and collects everything it writes.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use portable_pty::{Child, CommandBuilder, ExitStatus, MasterPty, PtySize, native_pty_system};
use tidepool::testing::TerminalModel;

/// The primary device attributes question the player asks after frames, and a VT220-like
/// answer (as xterm gives).
const DA1_QUESTION: &[u8] = b"\x1b[c";
pub const DA1_ANSWER: &[u8] = b"\x1b[?62;22c";

/// A player running in a pty.
pub struct Player {
    pub child: Box<dyn Child + Send + Sync>,
    pub master: Box<dyn MasterPty + Send>,
    /// The keyboard side, shared with the reader thread (which answers the player's device
    /// attributes questions, as a terminal does).
    writer: Arc<Mutex<Box<dyn Write + Send>>>,
    output: Arc<Mutex<Vec<u8>>>,
    /// The reader saw the end of the output (every end of the pty closed: the player exited).
    drained: Arc<AtomicBool>,
    pub dir: PathBuf,
    pub cols: u16,
    pub rows: u16,
}

/// A fresh empty folder under the target directory.
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

impl Player {
    /// Starts `tidepool ARGS` in a `cols x rows` pty, in folder `dir`, with truecolor and no SSH.
    pub fn spawn(dir: &Path, cols: u16, rows: u16, args: &[&str], env: &[(&str, &str)]) -> Player {
        Player::spawn_answering(dir, cols, rows, args, env, |_| Some(DA1_ANSWER.to_vec()))
    }

    /// [`Player::spawn`] with a scripted terminal: `answer(n)` gives the bytes written when the
    /// `n`-th device attributes question (0-based; the graphics probe's is the first) is seen,
    /// `None` for silence. A probe's other questions go before its DA1, so the answer to it
    /// carries the answers to them (a terminal answers in order).
    pub fn spawn_answering(
        dir: &Path,
        cols: u16,
        rows: u16,
        args: &[&str],
        env: &[(&str, &str)],
        answer: impl Fn(usize) -> Option<Vec<u8>> + Send + 'static,
    ) -> Player {
        let mut asked = 0;
        // The last two bytes of the previous read: a question may straddle two reads (and
        // two bytes cannot hold a whole one, so none is counted twice).
        let mut tail: Vec<u8> = Vec::new();
        Player::spawn_responding(dir, cols, rows, args, env, move |chunk| {
            tail.extend_from_slice(chunk);
            let questions = tail.windows(3).filter(|w| *w == DA1_QUESTION).count();
            tail.drain(..tail.len().saturating_sub(2));
            let mut out = Vec::new();
            for _ in 0..questions {
                if let Some(bytes) = answer(asked) {
                    out.extend_from_slice(&bytes);
                }
                asked += 1;
            }
            out
        })
    }

    /// [`Player::spawn`] with a fake terminal ([`super::fake_terminal`]) answering everything
    /// the player asks, as that terminal would; the fake also keeps the pictures it took.
    pub fn spawn_fake(
        dir: &Path,
        args: &[&str],
        env: &[(&str, &str)],
        fake: Arc<Mutex<super::fake_terminal::FakeTerminal>>,
    ) -> Player {
        let (cols, rows) = {
            let f = fake.lock().unwrap();
            (f.screen.cols() as u16, f.screen.rows() as u16)
        };
        Player::spawn_responding(dir, cols, rows, args, env, move |chunk| fake.lock().unwrap().feed(chunk))
    }

    /// [`Player::spawn`] with `respond` given every chunk the player writes, returning the
    /// terminal's answers (written back at once).
    pub fn spawn_responding(
        dir: &Path,
        cols: u16,
        rows: u16,
        args: &[&str],
        env: &[(&str, &str)],
        mut respond: impl FnMut(&[u8]) -> Vec<u8> + Send + 'static,
    ) -> Player {
        let pty = native_pty_system();
        let pair = pty.openpty(PtySize { rows, cols, pixel_width: 0, pixel_height: 0 }).unwrap();
        let mut cmd = CommandBuilder::new(env!("CARGO_BIN_EXE_tidepool"));
        cmd.args(args);
        cmd.cwd(dir);
        cmd.env("TERM", "xterm-256color");
        cmd.env("COLORTERM", "truecolor");
        cmd.env_remove("SSH_CONNECTION");
        cmd.env_remove("TIDEPOOL_TEST_PANIC");
        // The probe reads these; the test's terminal is none of them.
        for name in ["TMUX", "SSH_TTY", "TERM_PROGRAM"] {
            cmd.env_remove(name);
        }
        for (k, v) in env {
            cmd.env(k, v);
        }
        let child = pair.slave.spawn_command(cmd).unwrap();
        drop(pair.slave);
        let mut reader = pair.master.try_clone_reader().unwrap();
        let writer = Arc::new(Mutex::new(pair.master.take_writer().unwrap()));
        let answers = Arc::clone(&writer);
        let output = Arc::new(Mutex::new(Vec::new()));
        let sink = Arc::clone(&output);
        let drained = Arc::new(AtomicBool::new(false));
        let done = Arc::clone(&drained);
        std::thread::spawn(move || {
            let mut buf = [0u8; 65536];
            while let Ok(n) = reader.read(&mut buf) {
                if n == 0 {
                    break;
                }
                sink.lock().unwrap().extend_from_slice(&buf[..n]);
                let bytes = respond(&buf[..n]);
                if !bytes.is_empty() {
                    let mut w = answers.lock().unwrap();
                    let _ = w.write_all(&bytes).and_then(|()| w.flush());
                }
            }
            done.store(true, Ordering::SeqCst);
        });
        Player { child, master: pair.master, writer, output, drained, dir: dir.to_owned(), cols, rows }
    }

    /// Types bytes into the terminal.
    pub fn send(&mut self, bytes: &[u8]) {
        let mut w = self.writer.lock().unwrap();
        w.write_all(bytes).unwrap();
        w.flush().unwrap();
    }

    /// Everything written so far.
    pub fn output(&self) -> Vec<u8> {
        self.output.lock().unwrap().clone()
    }

    /// How many bytes were written so far.
    pub fn len(&self) -> usize {
        self.output.lock().unwrap().len()
    }

    /// Waits until the output from `from` on contains `needle`; returns where it ends.
    pub fn wait_for(&self, needle: &[u8], from: usize, timeout: Duration) -> usize {
        let deadline = Instant::now() + timeout;
        loop {
            let out = self.output();
            if let Some(i) = find(&out[from.min(out.len())..], needle) {
                return from + i + needle.len();
            }
            assert!(Instant::now() < deadline, "no {:?} within {timeout:?}", String::from_utf8_lossy(needle));
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    /// The screen the output so far draws (raw mode: a line feed keeps the column).
    pub fn screen(&self) -> TerminalModel {
        let mut s = TerminalModel::new(self.cols.into(), self.rows.into());
        s.lf_returns = false;
        s.feed(&self.output());
        s
    }

    /// Waits until `ready` holds for the screen the output draws (polled; `what` names it in the
    /// failure). A readiness signal, never an assertion on time: the bound is only for a hang.
    pub fn wait_until(&self, what: &str, timeout: Duration, ready: impl Fn(&TerminalModel) -> bool) {
        let deadline = Instant::now() + timeout;
        loop {
            if ready(&self.screen()) {
                return;
            }
            assert!(Instant::now() < deadline, "never {what} within {timeout:?}");
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    /// Waits until the screen's last row contains `text`.
    pub fn wait_for_status(&self, text: &str, timeout: Duration) {
        let deadline = Instant::now() + timeout;
        loop {
            let s = self.screen();
            if s.row_text(s.rows() - 1).contains(text) {
                return;
            }
            assert!(Instant::now() < deadline, "status never said {text:?}: {:?}", s.row_text(s.rows() - 1));
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    /// Waits for the process to end.
    pub fn wait_exit(&mut self, timeout: Duration) -> ExitStatus {
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(status) = self.child.try_wait().unwrap() {
                // The reader sees the end once the process and its pty ends are gone; the
                // last bytes are collected by then. (Only a grandchild holding the pty would
                // keep it open; then give up waiting at the deadline.)
                while !self.drained.load(Ordering::SeqCst) && Instant::now() < deadline {
                    std::thread::sleep(Duration::from_millis(5));
                }
                return status;
            }
            if Instant::now() > deadline {
                let _ = self.child.kill();
                panic!("the player did not exit within {timeout:?}");
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    /// Sends a signal to the player.
    pub fn signal(&self, name: &str) {
        let pid = self.child.process_id().unwrap().to_string();
        let ok = std::process::Command::new("kill").args([&format!("-{name}"), &pid]).status().unwrap();
        assert!(ok.success());
    }

    /// The pty's mode as `stty -a` prints it.
    pub fn stty(&self) -> String {
        let tty = self.master.tty_name().expect("the pty has a name");
        let out = std::process::Command::new("stty").arg("-F").arg(&tty).arg("-a").output().unwrap();
        String::from_utf8_lossy(&out.stdout).into_owned()
    }
}

impl Drop for Player {
    fn drop(&mut self) {
        let _ = self.child.kill();
    }
}

/// Where `needle` first occurs in `haystack`.
pub fn find(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).position(|w| w == needle)
}

/// Where `needle` last occurs in `haystack`.
pub fn rfind(haystack: &[u8], needle: &[u8]) -> Option<usize> {
    haystack.windows(needle.len()).rposition(|w| w == needle)
}

/// Whether `stty -a` output shows a cooked terminal (canonical mode with echo).
pub fn cooked(stty: &str) -> bool {
    let words: Vec<&str> = stty.split_whitespace().collect();
    words.contains(&"icanon") && words.contains(&"echo")
}
