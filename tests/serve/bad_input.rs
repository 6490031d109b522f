//! Bad input: one line naming the flag and the fix, exit 2, nothing started.

use std::os::unix::fs::PermissionsExt;
use std::process::Command;

/// Runs `tidepool serve ARGS`; a server that starts instead of refusing is killed after a
/// bound (for a hang, not a timing assertion) and reported as such, so a regression fails the
/// test instead of hanging it.
fn serve(args: &[&str]) -> (Option<i32>, String) {
    use std::io::Read;
    let mut child = Command::new(env!("CARGO_BIN_EXE_tidepool"))
        .arg("serve")
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(20);
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break Some(status);
        }
        if std::time::Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    let mut err = String::new();
    let _ = child.stderr.take().unwrap().read_to_string(&mut err);
    match status {
        Some(status) => (status.code(), err),
        None => (None, format!("the server started and ran for 20 s instead of refusing: {err}")),
    }
}

#[test]
fn each_bad_input_is_one_line_naming_the_flag_and_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let key = path("host_key");
    std::fs::write(path("bad_keys"), "ssh-ed25519 AAAAC3NzaC1lZDI1NTE5AAAAI-not-base64 x\n").unwrap();
    let player = russh::keys::PrivateKey::random(&mut rand_keys::rng(), russh::keys::Algorithm::Ed25519).unwrap();
    let line = player.public_key().to_openssh().unwrap();
    std::fs::write(path("forced_command"), format!("{line}\ncommand=\"/usr/bin/backup\" {line} backups\n")).unwrap();
    std::fs::write(path("host_name"), format!("from=\"*.example.com\" {line}\n")).unwrap();
    std::fs::write(path("loose_key"), "whatever").unwrap();
    std::fs::set_permissions(path("loose_key"), std::fs::Permissions::from_mode(0o644)).unwrap();
    std::fs::write(path("garbage_key"), "this is not a key\n").unwrap();
    std::fs::set_permissions(path("garbage_key"), std::fs::Permissions::from_mode(0o600)).unwrap();
    let (bad_keys, nope, loose, garbage) = (path("bad_keys"), path("nope"), path("loose_key"), path("garbage_key"));
    let (forced, host_name) = (path("forced_command"), path("host_name"));
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let taken_addr = taken.local_addr().unwrap().to_string();
    let cases: Vec<(&str, Vec<&str>, &str)> = vec![
        ("malformed authorized_keys", vec!["--authorized-keys", &bad_keys, "--host-key", &key], "line 1"),
        ("forced command", vec!["--authorized-keys", &forced, "--host-key", &key], "line 2: option 'command'"),
        (
            "host name in from=",
            vec!["--authorized-keys", &host_name, "--host-key", &key],
            "line 1: from=: '*.example.com'",
        ),
        ("missing authorized_keys", vec!["--authorized-keys", &nope, "--host-key", &key], "fix the path"),
        ("loose host key", vec!["--host-key", &loose], "chmod 600"),
        ("garbage host key", vec!["--host-key", &garbage], "not an OpenSSH private key"),
        ("port in use", vec!["--listen", &taken_addr, "--host-key", &key], "pick a free port"),
        ("no players", vec!["--max-clients", "0", "--host-key", &key], "give 1 to"),
        ("bad address", vec!["--listen", "localhost", "--host-key", &key], "127.0.0.1:2222"),
        ("bad port", vec!["--listen", "127.0.0.1:99999", "--host-key", &key], "127.0.0.1:2222"),
        ("no per-address room", vec!["--max-per-address", "0", "--host-key", &key], "give 1 to"),
        ("zero timeout", vec!["--idle-timeout-ms", "0", "--host-key", &key], "milliseconds"),
        ("huge scene", vec!["--size", "2000x2000", "--host-key", &key], "160x90"),
    ];
    for (name, args, fix) in cases {
        let flag = args.iter().find(|a| a.starts_with("--") && **a != "--host-key").unwrap_or(&"--host-key");
        let (code, err) = serve(&args);
        assert_eq!(code, Some(2), "{name}: exit 2: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{name}: one line: {err}");
        assert!(err.contains(flag), "{name}: names {flag}: {err}");
        assert!(err.contains(fix), "{name}: says {fix:?}: {err}");
    }
    drop(taken);
}
