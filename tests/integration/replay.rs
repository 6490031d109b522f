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
    let replay = tidepool::replay::read(&path).unwrap();
    let spec = replay.spec(tidepool::pool_floor());
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
    let replay = tidepool::replay::read(&fixture("replay-v0.1.0.jsonl")).unwrap();
    let mut text = tidepool::replay::header_line(&replay.header) + "\n";
    for entry in &replay.entries {
        text += &(tidepool::replay::event_line(entry) + "\n");
    }
    assert_eq!(tidepool::replay::parse(Path::new("rewritten"), &text).unwrap(), replay);
}
