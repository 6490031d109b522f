//! Fuzzes the replay parser (`render pool --replay FILE`): any text must give a replay or an
//! error naming a line, never a panic; a parsed replay must re-simulate without panicking.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let path = std::path::Path::new("fuzz.jsonl");
    if let Ok(replay) = tidepool::replay::parse(path, text) {
        // Keep the simulation small: huge sizes and step counts are legal but slow.
        let [w, h] = replay.header.size;
        if u64::from(w) * u64::from(h) <= 4096 && replay.end_step() <= 2000 {
            let _ = tidepool::commands::replay::simulate(path, &replay, None);
        }
    }
});
