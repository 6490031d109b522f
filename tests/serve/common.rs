//! Helpers: the real `tidepool serve` binary on a free loopback port with short timeouts and
//! a host key in a temporary folder, and an in-process russh client.
#![allow(dead_code)]

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use russh::client::{self, Handle};
use russh::keys::{HashAlg, PrivateKey, PrivateKeyWithHashAlg, PublicKeyOrCertificate};
use russh::{Channel, ChannelMsg};

/// Guard against a hang in a test (not a performance bound).
pub const HANG_GUARD: Duration = Duration::from_secs(30);
/// Synchronized output begins every frame the server sends.
pub const SYNC_BEGIN: &[u8] = b"\x1b[?2026h";
/// The device-attributes question, and the answer a VT220-class terminal gives.
pub const DA1_QUESTION: &[u8] = b"\x1b[c";
pub const DA1_ANSWER: &[u8] = b"\x1b[?62;22c";

/// Flags that make a test server quick and quiet: short timeouts, still water, no rain.
pub const TEST_FLAGS: &[&str] = &["--rain", "0", "--breeze", "0", "--handshake-timeout-ms", "5000"];

/// A running `tidepool serve`.
pub struct Server {
    pub child: Child,
    pub port: u16,
    /// The host key's directory when the server made its own: removed when the server is
    /// dropped (after the process is killed), so runs leave no keys behind in /tmp.
    own_dir: Option<tempfile::TempDir>,
    /// Everything the server wrote to standard error so far, line by line.
    pub log: Arc<Mutex<Vec<String>>>,
    pub first_line: String,
}

impl Server {
    /// Starts the server with `args` added to `--listen 127.0.0.1:0 --host-key DIR/host_key`.
    pub fn start(args: &[&str]) -> Server {
        Server::start_env(args, &[])
    }

    /// As [`Server::start`], with `env` added to the server's environment.
    pub fn start_env(args: &[&str], env: &[(&str, &str)]) -> Server {
        let dir = tempfile::tempdir().unwrap();
        let mut server = Server::start_in_env(dir.path(), args, env);
        server.own_dir = Some(dir);
        server
    }

    /// As [`Server::start`], with the host key in `dir`.
    pub fn start_in(dir: &Path, args: &[&str]) -> Server {
        Server::start_in_env(dir, args, &[])
    }

    /// As [`Server::start_in`], with `env` added to the server's environment.
    pub fn start_in_env(dir: &Path, args: &[&str], env: &[(&str, &str)]) -> Server {
        let key = dir.join("host_key");
        let mut child = Command::new(env!("CARGO_BIN_EXE_tidepool"))
            .envs(env.iter().copied())
            .args(["serve", "--listen", "127.0.0.1:0", "--host-key"])
            .arg(&key)
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("tidepool serve starts");
        let log = Arc::new(Mutex::new(Vec::new()));
        let sink = log.clone();
        let stderr = child.stderr.take().unwrap();
        std::thread::spawn(move || {
            for line in BufReader::new(stderr).lines().map_while(Result::ok) {
                sink.lock().unwrap().push(line);
            }
        });
        let mut out = BufReader::new(child.stdout.take().unwrap());
        let mut first_line = String::new();
        out.read_line(&mut first_line).unwrap();
        let mut second = String::new();
        out.read_line(&mut second).unwrap();
        let port = second
            .split("ssh -p ")
            .nth(1)
            .and_then(|r| r.split_whitespace().next())
            .and_then(|p| p.parse().ok())
            .unwrap_or_else(|| panic!("no port in {first_line:?} {second:?}; log {:?}", log.lock().unwrap()));
        Server { child, port, own_dir: None, log, first_line }
    }

    /// Sends `signal` and waits for the exit status.
    pub fn stop(mut self, signal: i32) -> (Option<i32>, Vec<String>) {
        unsafe_kill(self.child.id(), signal);
        let status = wait_with_guard(&mut self.child);
        // Let the stderr thread read the last lines.
        std::thread::sleep(Duration::from_millis(100));
        let log = self.log.lock().unwrap().clone();
        (status, log)
    }

    /// Waits (bounded) for a log line containing `needle`, and returns it. Async, so the
    /// test's own SSH clients keep running meanwhile.
    pub async fn wait_for_log(&self, needle: &str) -> String {
        let until = std::time::Instant::now() + HANG_GUARD;
        while std::time::Instant::now() < until {
            if let Some(line) = self.log.lock().unwrap().iter().find(|l| l.contains(needle)) {
                return line.clone();
            }
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
        panic!("no log line with {needle:?}: {:?}", self.log.lock().unwrap());
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn unsafe_kill(pid: u32, signal: i32) {
    let ok = Command::new("kill").arg(format!("-{signal}")).arg(pid.to_string()).status().unwrap();
    assert!(ok.success());
}

fn wait_with_guard(child: &mut Child) -> Option<i32> {
    let until = std::time::Instant::now() + HANG_GUARD;
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return status.code();
        }
        assert!(std::time::Instant::now() < until, "the server did not exit");
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// Client handler that accepts any host key and records its SHA256 fingerprint.
#[derive(Clone, Default)]
pub struct TestClient {
    pub server_fingerprint: Arc<Mutex<Option<String>>>,
}

impl client::Handler for TestClient {
    type Error = russh::Error;

    async fn check_server_key(&mut self, key: &PublicKeyOrCertificate) -> Result<bool, Self::Error> {
        if let PublicKeyOrCertificate::PublicKey { key, .. } = key {
            *self.server_fingerprint.lock().unwrap() = Some(key.fingerprint(HashAlg::Sha256).to_string());
        }
        Ok(true)
    }
}

/// Client config; `window` and `buffer` shrink the client's buffering (stall tests).
pub fn client_config(window: u32, buffer: usize) -> Arc<client::Config> {
    Arc::new(client::Config { window_size: window, channel_buffer_size: buffer, ..client::Config::default() })
}

/// Connects without authenticating.
pub async fn connect(port: u16) -> (Handle<TestClient>, TestClient) {
    connect_with(port, client_config(2 * 1024 * 1024, 100)).await
}

pub async fn connect_with(port: u16, config: Arc<client::Config>) -> (Handle<TestClient>, TestClient) {
    let handler = TestClient::default();
    let handle = client::connect(config, ("127.0.0.1", port), handler.clone()).await.expect("connect");
    (handle, handler)
}

/// Connects and authenticates with "none".
pub async fn connect_none(port: u16) -> Handle<TestClient> {
    let (mut h, _) = connect(port).await;
    assert!(h.authenticate_none("player").await.unwrap().success(), "none auth refused");
    h
}

/// Authenticates with a public key.
pub async fn auth_key(h: &mut Handle<TestClient>, key: &PrivateKey) -> bool {
    h.authenticate_publickey("player", PrivateKeyWithHashAlg::new(Arc::new(key.clone()), None)).await.unwrap().success()
}

/// Waits for the reply to a request sent with want_reply = true (skipping data).
pub async fn reply(ch: &mut Channel<client::Msg>) -> ChannelMsg {
    loop {
        let msg = tokio::time::timeout(HANG_GUARD, ch.wait()).await.expect("reply in time").expect("channel open");
        match msg {
            ChannelMsg::Success | ChannelMsg::Failure | ChannelMsg::Close | ChannelMsg::Eof => return msg,
            _ => continue,
        }
    }
}

/// Opens a session with a pty and a shell; returns the channel.
pub async fn open_shell(h: &Handle<TestClient>, term: &str, cols: u32, rows: u32) -> Channel<client::Msg> {
    let mut ch = h.channel_open_session().await.expect("session channel");
    ch.request_pty(true, term, cols, rows, 0, 0, &[]).await.unwrap();
    assert!(matches!(reply(&mut ch).await, ChannelMsg::Success), "pty-req refused");
    ch.request_shell(true).await.unwrap();
    assert!(matches!(reply(&mut ch).await, ChannelMsg::Success), "shell refused");
    ch
}

/// A player's terminal: the channel and a terminal model fed with everything it received.
pub struct Term {
    pub ch: Channel<client::Msg>,
    pub screen: tidepool::testing::TerminalModel,
    pub frames: usize,
    pub raw: Vec<u8>,
    /// How it answers device-attributes questions.
    pub answers: Answers,
    /// Device-attributes questions seen so far.
    pub questions: usize,
}

/// How a test terminal answers the server's questions.
#[derive(Clone, Copy, Debug)]
pub enum Answers {
    /// Every device-attributes question as a VT220-class text terminal does.
    Text,
    /// The first (the graphics probe's) with these bytes (a kitty or sixel terminal's answers,
    /// its DA1 last), later ones as text.
    Probe(&'static [u8]),
    /// Never: a terminal that answers nothing.
    Silent,
}

impl Term {
    pub fn new(ch: Channel<client::Msg>, cols: usize, rows: usize) -> Term {
        let mut screen = tidepool::testing::TerminalModel::new(cols, rows);
        // The client's terminal is raw (ssh sets it so) and the server has no pty: a line feed
        // moves down only.
        screen.lf_returns = false;
        Term { ch, screen, frames: 0, raw: Vec::new(), answers: Answers::Text, questions: 0 }
    }

    /// A terminal that answers as `answers` says.
    pub fn answering(ch: Channel<client::Msg>, cols: usize, rows: usize, answers: Answers) -> Term {
        Term { answers, ..Term::new(ch, cols, rows) }
    }

    /// Reads until `done` says so (bounded by [`HANG_GUARD`]).
    pub async fn read_until(&mut self, mut done: impl FnMut(&Term) -> bool) {
        let result = tokio::time::timeout(HANG_GUARD, async {
            while !done(self) {
                match self.ch.wait().await {
                    Some(ChannelMsg::Data { data }) => {
                        self.frames += data.windows(SYNC_BEGIN.len()).filter(|w| *w == SYNC_BEGIN).count();
                        self.screen.feed(&data);
                        self.raw.extend_from_slice(&data);
                        // A terminal answers device-attributes questions once it has read what
                        // came before them (the server's link control and probe ask them).
                        let questions = data.windows(DA1_QUESTION.len()).filter(|w| *w == DA1_QUESTION).count();
                        for _ in 0..questions {
                            let answer = match (self.answers, self.questions) {
                                (Answers::Silent, _) => None,
                                (Answers::Probe(probe), 0) => Some(probe),
                                _ => Some(DA1_ANSWER),
                            };
                            self.questions += 1;
                            if let Some(answer) = answer {
                                let _ = self.ch.data(answer).await;
                            }
                        }
                    }
                    Some(_) => {}
                    None => return false,
                }
            }
            true
        })
        .await;
        assert_eq!(result, Ok(true), "status line: {:?}", self.status());
    }

    /// Reads until the status line contains `needle`.
    pub async fn read_until_status(&mut self, needle: &str) {
        let needle = needle.to_string();
        self.read_until(|t| t.status().contains(&needle)).await;
    }

    /// Reads `n` more frames.
    pub async fn read_frames(&mut self, n: usize) {
        let until = self.frames + n;
        self.read_until(|t| t.frames >= until).await;
    }

    /// Reads until every pixel of the picture rows shows a colour (the first frame may come
    /// in parts when the byte budget is small).
    pub async fn read_until_painted(&mut self) {
        let (cols, rows) = (self.screen.cols(), self.screen.rows());
        self.read_until(|t| (0..2 * (rows - 1)).all(|y| (0..cols).all(|x| t.screen.pixel(x, y).is_some()))).await;
    }

    /// The last row's text.
    pub fn status(&self) -> String {
        self.screen.row_text(self.screen.rows() - 1)
    }
}

/// Reads until the channel closes; returns all data and the exit status (if any).
pub async fn read_to_close(ch: &mut Channel<client::Msg>) -> (Vec<u8>, Option<u32>) {
    let mut seen = Vec::new();
    let mut status = None;
    tokio::time::timeout(HANG_GUARD, async {
        while let Some(msg) = ch.wait().await {
            match msg {
                ChannelMsg::Data { data } => seen.extend_from_slice(&data),
                ChannelMsg::ExitStatus { exit_status } => status = Some(exit_status),
                ChannelMsg::Close => break,
                _ => {}
            }
        }
    })
    .await
    .expect("channel closes in time");
    (seen, status)
}

/// Whether `hay` contains `needle`.
pub fn contains(hay: &[u8], needle: &[u8]) -> bool {
    hay.windows(needle.len()).any(|w| w == needle)
}
