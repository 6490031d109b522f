use super::*;
use crate::sim::noise::NoiseKind;
use crate::sim::ripple::Stone;

fn header() -> Header {
    let options = PoolOptions::of(&PoolSettings::default(), None);
    Header { format: FORMAT, version: "0.1.0".into(), scene: SceneKind::Pool, seed: 7, size: [20, 10], options }
}

fn text(entries: &[Entry]) -> String {
    let mut t = header_line(&header()) + "\n";
    for e in entries {
        t += &(event_line(e) + "\n");
    }
    t
}

fn err(text: &str) -> String {
    parse(Path::new("r.jsonl"), text).unwrap_err().to_string()
}

#[test]
fn round_trip() {
    let entries = vec![
        Entry { step: 0, event: Event::Stone(Stone::new(-3, 4, 5, 160).unwrap()) },
        Entry { step: 3, event: Event::Rain(0.25) },
        Entry { step: 3, event: Event::Damping(Damping::OFF) },
        Entry { step: 4, event: Event::Clear },
        Entry { step: 9, event: Event::Resize([30, 12]) },
        Entry { step: 9, event: Event::Screenshot("a b.png".into()) },
        Entry { step: 10, event: Event::Wind([4.5, 0.0]) },
        Entry { step: 11, event: Event::Noise { octaves: 6, persistence: 0.55, kind: NoiseKind::Gradient } },
        Entry { step: 12, event: Event::End },
    ];
    let replay = parse(Path::new("r"), &text(&entries)).unwrap();
    assert_eq!(replay, Replay { header: header(), entries });
    assert_eq!(replay.end_step(), 12);
}

#[test]
fn a_file_written_by_0_1_0_reads_back() {
    // The first two lines of a replay recorded by tidepool 0.1.0 (keys in alphabetical order).
    let old = r#"{"options":{"background":null,"caustics":true,"damping":"4","depth":24.0,"rain":0.05,"refraction":"auto","shading":true,"sun":"315,60"},"scene":"pool","seed":7,"size":[100,58],"tidepool_replay":1,"version":"0.1.0"}
{"step":88,"stone":[8,18,3,48]}
{"rain":0.0,"step":209}
{"damping":"5","step":233}
{"clear":true,"step":519}
{"end":true,"step":598}
"#;
    let replay = parse(Path::new("old"), old).unwrap();
    assert_eq!(replay.header.options.damping, "4".parse().unwrap());
    assert_eq!(replay.header.options.sun, Sun::default());
    assert_eq!(replay.entries[0].event, Event::Stone(Stone::new(8, 18, 3, 48).unwrap()));
    assert_eq!(replay.entries.len(), 5);
    // Without the fields of the coherent pool, the pool of then: one cell a pixel, 60 steps a
    // second, the first breeze's wavelets.
    let options = &replay.header.options;
    assert_eq!((options.grid, options.steps_per_second, options.breeze_style), (1, 60, BreezeStyle::Wavelets));
    let settings = options.settings(7, Pixmap::new(1, 1).unwrap());
    assert_eq!((settings.grid, settings.steps_per_second, settings.breeze_style), (1, 60, BreezeStyle::Wavelets));
}

#[test]
fn the_coherent_pools_fields_round_trip_and_are_checked() {
    let settings = PoolSettings {
        grid: 2,
        steps_per_second: 30,
        breeze_style: BreezeStyle::Gusts,
        breeze: 1.0,
        ..PoolSettings::default()
    };
    let header = Header { options: PoolOptions::of(&settings, None), ..header() };
    let line = header_line(&header);
    assert!(line.contains(r#""breeze_style":"gusts","grid":2,"steps_per_second":30"#), "{line}");
    let text = format!("{line}\n{}\n", event_line(&Entry { step: 3, event: Event::End }));
    let replay = parse(Path::new("r"), &text).unwrap();
    assert_eq!(replay.header, header);
    for (bad, needle) in [
        (r#""grid":2"#, r#""grid":9"#),
        (r#""steps_per_second":30"#, r#""steps_per_second":0"#),
        (r#""breeze_style":"gusts""#, r#""breeze_style":"storm""#),
    ] {
        let broken = text.replacen(bad, needle, 1);
        let message = err(&broken);
        assert!(message.starts_with("r.jsonl, line 1: the header: "), "{message}");
        let name = needle.split('"').nth(1).unwrap();
        let expected = match name {
            "grid" => "outside 1..=4",
            "steps_per_second" => "outside 1..=240",
            _ => "is not a breeze style",
        };
        assert!(message.contains(expected), "{needle}: {message}");
    }
}

#[test]
fn errors_name_the_line() {
    let end = Entry { step: 5, event: Event::End };
    let good = text(&[Entry { step: 1, event: Event::Clear }, end.clone()]);
    let truncated = &good[..good.len() - 10];
    assert!(err(truncated).starts_with("r.jsonl, line 3: the line is cut short"), "{}", err(truncated));
    let lines: Vec<&str> = good.lines().collect();
    let missing_end = format!("{}\n{}\n", lines[0], lines[1]);
    assert!(err(&missing_end).contains("line 3: the replay stops without"), "{}", err(&missing_end));
    assert!(err("").contains("line 1: the file is empty"));
    assert!(err("{\"a\":1}").contains("line 1: not a tidepool replay"));
    let newer = good.replacen("\"tidepool_replay\":1", "\"tidepool_replay\":2", 1);
    assert!(err(&newer).contains("line 1: replay format 2 (recorded by 0.1.0) is newer"), "{}", err(&newer));
    let bad_event = good.replacen("\"clear\":true", "\"splash\":true", 1);
    assert!(err(&bad_event).contains("line 2: unknown event \"splash\""));
    let bad_stone = good.replacen("\"clear\":true", "\"stone\":[1,2,0,3]", 1);
    assert!(err(&bad_stone).contains("line 2: bad stone: the radius 0"), "{}", err(&bad_stone));
    let bad_noise =
        good.replacen("\"clear\":true", "\"noise\":{\"octaves\":0,\"persistence\":0.5,\"kind\":\"value\"}", 1);
    assert!(err(&bad_noise).contains("line 2: bad noise: the octave count 0"), "{}", err(&bad_noise));
    let backwards = good.replacen("\"step\":5", "\"step\":0", 1);
    assert!(err(&backwards).contains("line 3: step 0 comes after step 1"));
    let after_end = good.clone() + &event_line(&end) + "\n";
    assert!(err(&after_end).contains("line 4: text after the end line"));
    let no_size = good.replacen("\"size\":[20,10]", "\"size\":[0,10]", 1);
    assert!(err(&no_size).contains("line 1: \"size\""), "{}", err(&no_size));
    let wrong_type = good.replacen("\"clear\":true", "\"stone\":\"here\"", 1);
    assert!(err(&wrong_type).contains("line 2: \"stone\": invalid type"), "{}", err(&wrong_type));
}

#[test]
#[cfg(feature = "player")]
fn recorder_hands_out_its_file_once_when_finished() {
    let mut rec = Recorder::new(Path::new("s.jsonl"), &header());
    rec.record(2, Event::Clear);
    let (path, text) = rec.finish(7).expect("the file, at the end");
    assert!(rec.finish(9).is_none(), "handed out once");
    let replay = parse(&path, &text).unwrap();
    assert_eq!(replay.entries, vec![Entry { step: 2, event: Event::Clear }, Entry { step: 7, event: Event::End }]);
}

#[test]
#[cfg(feature = "player")]
fn a_recorder_finished_early_ends_at_the_last_step_reached() {
    // What the door's guard does when the session ends by a panic.
    let mut rec = Recorder::new(Path::new("s.jsonl"), &header());
    rec.advance(40);
    let (path, text) = rec.finish(0).unwrap();
    let replay = parse(&path, &text).unwrap();
    assert_eq!(replay.end_step(), 40);
}
