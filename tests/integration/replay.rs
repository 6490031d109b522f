//! Replays recorded by earlier versions stay readable and render bit-identically: the fixture
//! in `tests/fixtures/` was recorded in tmux by tidepool 0.1.0 (stones, rain, damping changes,
//! a resize, a screenshot, a clear) and rendered by that version.

use std::path::{Path, PathBuf};

use crate::common::{read_png, run_in, scratch, stderr};
use crate::goldens::rgba;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(name)
}

#[test]
fn a_replay_recorded_by_0_1_0_renders_bit_identically() {
    let path = fixture("replay-v0.1.0.jsonl");
    let replay = tidepool::replay::Replay::read(&path).unwrap();
    let spec = replay.spec(tidepool::PoolSettings::default_floor());
    for (steps, png) in [(None, "replay-v0.1.0-final.png"), (Some(489), "replay-v0.1.0-step489.png")] {
        let mut scene = replay.simulate(&spec, steps, &mut |_| {}).unwrap();
        let picture = rgba(&scene.snapshot().unwrap());
        assert!(picture == read_png(&fixture(png)), "{png}: the pixels of 0.1.0's render");
    }
    // Through the command line, the files themselves are the same bytes.
    let dir = scratch("replay_fixture");
    let out = run_in(&dir, &["render", "pool", "--replay", path.to_str().unwrap(), "--out", "final.png"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(
        std::fs::read(dir.join("final.png")).unwrap(),
        std::fs::read(fixture("replay-v0.1.0-final.png")).unwrap()
    );
    let args =
        ["render", "pool", "--replay", path.to_str().unwrap(), "--steps", "180", "--frames", "12", "--fps", "10"];
    let out = run_in(&dir, &[&args[..], &["--out", "anim.png"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(std::fs::read(dir.join("anim.png")).unwrap(), std::fs::read(fixture("replay-v0.1.0-anim.png")).unwrap());
}

#[test]
fn the_new_writer_reads_back_what_the_old_one_wrote() {
    let replay = tidepool::replay::Replay::read(&fixture("replay-v0.1.0.jsonl")).unwrap();
    let text = replay.to_text();
    assert_eq!(tidepool::replay::Replay::parse(Path::new("rewritten"), &text).unwrap(), replay);
}

/// Hostile replays are refused at once, in one line naming the file, the line and the limit:
/// no 1.7 GB allocation for a header of 60000x60000, no endless simulation for an end step of
/// 2^64 - 1, no million-line flood.
#[test]
fn replays_past_the_limits_are_refused_naming_line_and_limit() {
    let dir = scratch("replay_limits");
    let header = |size: &str| {
        format!(
            r#"{{"tidepool_replay":1,"scene":"pool","seed":1,"size":{size},"options":{{"background":null,"caustics":true,"damping":"5","depth":24.0,"rain":0.0,"refraction":"auto","shading":true,"sun":"315,60"}}}}"#
        )
    };
    let mut crowded = header("[64,48]") + "\n";
    for step in 0..=1_000_000 {
        crowded += &format!("{{\"step\":{step},\"clear\":true}}\n");
    }
    let cases = [
        (
            "huge.jsonl",
            header("[60000,60000]") + "\n{\"step\":9,\"end\":true}\n",
            "line 1: \"size\" is 60000x60000, over the picture limits",
        ),
        (
            "forever.jsonl",
            header("[64,48]") + "\n{\"step\":18446744073709551615,\"end\":true}\n",
            "line 2: step 18446744073709551615 is past the limit of 10000000 steps",
        ),
        ("crowded.jsonl", crowded, "line 1000002: more than 1000000 events, the limit"),
    ];
    for (name, text, needle) in cases {
        std::fs::write(dir.join(name), text).unwrap();
        let out = run_in(&dir, &["render", "pool", "--replay", name, "--out", "o.png"]);
        assert_eq!(out.status.code(), Some(2), "{name}");
        let err = stderr(&out);
        assert_eq!(err.lines().count(), 1, "{name}: {err}");
        assert!(err.contains(&format!("{name}, {needle}")), "{name}: {err}");
    }
    assert!(!dir.join("o.png").exists());
}
