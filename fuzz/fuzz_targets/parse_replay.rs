//! Fuzzes the replay reader (`render pool --replay FILE`): any text must give a replay or an
//! error naming a line, never a panic; a parsed replay must re-simulate without panicking.
//! The limits are injected small (a 64x64 picture, 2,000 steps, 200 events), so every input
//! is answered in milliseconds, and the invariant is that the parser enforces them: nothing it
//! accepts is bigger.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tidepool::replay::Limits;

const LIMITS: Limits = Limits { max_steps: 2_000, max_events: 200, max_pixels: 64 * 64, max_bytes: 1 << 20 };

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let path = std::path::Path::new("fuzz.jsonl");
    if let Ok(replay) = tidepool::replay::Replay::parse_with(path, text, &LIMITS) {
        let [w, h] = replay.size();
        assert!(u64::from(w) * u64::from(h) <= LIMITS.max_pixels, "the size limit holds");
        assert!(replay.end_step() <= LIMITS.max_steps, "the step limit holds");
        assert!(replay.script().len() <= LIMITS.max_events, "the event limit holds");
        let spec = replay.spec(tidepool::PoolSettings::default_floor());
        let _ = replay.simulate(&spec, None, &mut |_| {});
    }
});
