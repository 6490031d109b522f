//! Helpers shared by the integration tests: running the binary and the golden-image harness.

pub mod fake_terminal;
pub mod golden;
pub mod pty;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The `tidepool` binary under test.
pub fn tidepool() -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_tidepool"));
    // Tests must not depend on the developer's terminal or SSH session.
    command.env_remove("SSH_CONNECTION").env_remove("COLORTERM").env("TERM", "xterm-256color");
    command
}

/// Runs `tidepool` with `args` and returns its output.
pub fn run(args: &[&str]) -> Output {
    tidepool().args(args).output().expect("the tidepool binary runs")
}

/// Runs `tidepool` with `args` in `dir`.
pub fn run_in(dir: &Path, args: &[&str]) -> Output {
    tidepool().current_dir(dir).args(args).output().expect("the tidepool binary runs")
}

/// Standard error as text.
pub fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// A fresh, empty scratch folder under `target/` for one test.
pub fn scratch(name: &str) -> PathBuf {
    let dir = target_dir().join("test-scratch").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Cargo's target folder (where failure strips and scratch files go).
pub fn target_dir() -> PathBuf {
    match std::env::var_os("CARGO_TARGET_DIR") {
        Some(dir) => PathBuf::from(dir),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).join("target"),
    }
}

/// Decodes a PNG file into straight RGBA.
pub fn read_png(path: &Path) -> image::RgbaImage {
    image::open(path).unwrap_or_else(|e| panic!("{} is not a readable image: {e}", path.display())).to_rgba8()
}

/// Reads a float32 NPY written by tidepool: (rows, columns, values).
pub fn read_npy(bytes: &[u8]) -> (usize, usize, Vec<f32>) {
    assert_eq!(&bytes[..8], b"\x93NUMPY\x01\x00");
    let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = std::str::from_utf8(&bytes[10..10 + header_len]).unwrap();
    let shape = header.split("'shape': (").nth(1).unwrap().split(')').next().unwrap();
    let dims: Vec<usize> = shape.split(',').filter_map(|d| d.trim().parse().ok()).collect();
    let values = bytes[10 + header_len..].chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect();
    (dims[0], dims[1], values)
}

/// Waits until process `pid` catches `signal` (its bit in the `SigCgt` mask of
/// `/proc/PID/status`): the readiness signal that its handler is installed.
pub fn wait_until_catches(pid: u32, signal: u32) {
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(20);
    loop {
        let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap_or_default();
        let caught = status
            .lines()
            .find_map(|l| l.strip_prefix("SigCgt:"))
            .and_then(|mask| u64::from_str_radix(mask.trim(), 16).ok())
            .is_some_and(|mask| mask & (1 << (signal - 1)) != 0);
        if caught {
            return;
        }
        assert!(std::time::Instant::now() < deadline, "process {pid} never caught signal {signal}");
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
}
