//! The limits a stranger meets before playing: the handshake deadline, garbage, connections
//! per address, the idle timeout; and the host key that outlives a restart.

use std::time::{Duration, Instant};

use tokio::io::{AsyncReadExt, AsyncWriteExt};

use crate::common::*;

#[tokio::test]
async fn garbage_before_the_banner_is_dropped_at_once() {
    // A long handshake deadline: a drop within HANG_GUARD is the parser's, not the timer's.
    let s = Server::start(&["--handshake-timeout-ms", "600000"]);
    let mut tcp = tokio::net::TcpStream::connect(("127.0.0.1", s.port)).await.unwrap();
    tcp.write_all(b"GET / HTTP/1.1\r\nHost: pool\r\n\r\n").await.unwrap();
    let mut got = Vec::new();
    let read = tokio::time::timeout(HANG_GUARD, tcp.read_to_end(&mut got)).await.expect("closed");
    assert!(read.is_ok() || read.unwrap_err().kind() == std::io::ErrorKind::ConnectionReset);
    assert!(String::from_utf8_lossy(&got).starts_with("SSH-2.0-tidepool\r\n"), "{got:?}");
}

#[tokio::test]
async fn a_silent_connection_is_cut_at_the_handshake_deadline() {
    let s = Server::start(&["--handshake-timeout-ms", "300"]);
    let mut tcp = tokio::net::TcpStream::connect(("127.0.0.1", s.port)).await.unwrap();
    let started = Instant::now();
    let mut got = Vec::new();
    let _ = tokio::time::timeout(HANG_GUARD, tcp.read_to_end(&mut got)).await.expect("cut");
    assert!(started.elapsed() >= Duration::from_millis(300), "not before the deadline");
    // An authenticated client that never asks for a shell is cut the same way.
    let h = connect_none(s.port).await;
    let _ch = h.channel_open_session().await.unwrap();
    tokio::time::timeout(HANG_GUARD, async {
        while !h.is_closed() {
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
    })
    .await
    .expect("an authenticated idler is cut");
}

#[tokio::test]
async fn connections_beyond_the_per_address_limit_are_closed_at_accept() {
    let s = Server::start(&["--max-per-address", "2"]);
    let _a = connect_none(s.port).await;
    let _b = connect_none(s.port).await;
    let mut tcp = tokio::net::TcpStream::connect(("127.0.0.1", s.port)).await.unwrap();
    let mut got = Vec::new();
    let _ = tokio::time::timeout(HANG_GUARD, tcp.read_to_end(&mut got)).await.expect("closed");
    assert!(got.is_empty(), "no SSH banner for a refused connection: {got:?}");
    s.wait_for_log("refused at accept: TooManyFromAddress").await;
}

#[tokio::test]
async fn an_idle_player_is_sent_home() {
    let s = Server::start(&["--idle-timeout-ms", "500"]);
    let h = connect_none(s.port).await;
    let mut ch = open_shell(&h, "xterm", 80, 24).await;
    let (text, status) = read_to_close(&mut ch).await;
    assert!(contains(&text, b"idle too long") && contains(&text, b"\x1b[?1049l"));
    assert_eq!(status, Some(0));
}

#[tokio::test]
async fn the_host_key_survives_a_restart() {
    let dir = tempfile::tempdir().unwrap();
    let first = Server::start_in(dir.path(), &[]);
    assert!(first.first_line.starts_with("host key created"), "{}", first.first_line);
    let (_h, client) = connect(first.port).await;
    let fp1 = client.server_fingerprint.lock().unwrap().clone().unwrap();
    first.stop(15);
    let second = Server::start_in(dir.path(), &[]);
    assert!(second.first_line.starts_with("host key loaded"), "{}", second.first_line);
    let (_h, client) = connect(second.port).await;
    let fp2 = client.server_fingerprint.lock().unwrap().clone().unwrap();
    assert_eq!(fp1, fp2);
    assert!(second.first_line.contains(&fp1), "the fingerprint is printed: {}", second.first_line);
    use std::os::unix::fs::PermissionsExt;
    let mode = std::fs::metadata(dir.path().join("host_key")).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode, 0o600);
    // OpenSSH reads the key file and prints the same fingerprint line; a key it rejects fails
    // here, and so does a missing ssh-keygen (the test needs it: it never passes without).
    let out = std::process::Command::new("ssh-keygen")
        .arg("-lf")
        .arg(dir.path().join("host_key"))
        .output()
        .expect("this test compares with `ssh-keygen -lf`: install OpenSSH's client (Debian: openssh-client)");
    assert!(out.status.success(), "ssh-keygen -lf rejected the host key: {}", String::from_utf8_lossy(&out.stderr));
    let line = String::from_utf8_lossy(&out.stdout);
    assert!(second.first_line.contains(line.trim_end()), "{line} in {}", second.first_line);
}
