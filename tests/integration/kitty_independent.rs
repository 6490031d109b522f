//! The kitty graphics stream decoded by a decoder that shares no code with the encoder:
//! `scripts/kitty_decode.py`, written from the protocol's documentation (Python's own zlib and
//! base64, its own PNG reader). The project's Rust decoder (`kitty_decode`) is not used here, so
//! a misreading of the protocol shared by the encoder and that decoder cannot pass. Needs
//! `python3` (CI has it): without it the test fails, it does not skip.

use std::time::{Duration, Instant};

use tidepool::play::GraphicsMode;
use tidepool::testing::push_rgb;
use tidepool::testing::{Budget, ByteBucket, Part, PictureStream, Protocol, resample};
use tidepool::testing::{KittyEncoder, KittyOptions};
use tidepool::testing::{Layout, layout};
use tiny_skia::Pixmap;

use crate::common::fake_terminal::FakeTerminal;

/// Decodes `stream` with the Python decoder (`scripts/kitty_decode.py`, run as the fake
/// terminals run it): image id -> (width, height, RGB).
fn decode(name: &str, stream: &[u8]) -> Vec<(u32, u32, u32, Vec<u8>)> {
    let name = format!("kitty-independent-{name}");
    FakeTerminal::decode_kitty(&name, stream).into_iter().map(|i| (i.id, i.width, i.height, i.rgb)).collect()
}

fn pool(w: u32, h: u32, steps: u64) -> Pixmap {
    let settings = tidepool::PoolSettings { rain_rate: 0.05, seed: 3, ..Default::default() };
    let mut scene = tidepool::PoolScene::new(w, h, settings).unwrap();
    tidepool::Scene::apply(&mut scene, &tidepool::Event::Stone(tidepool::Stone::new(30, 20, 4, 128).unwrap()));
    tidepool::Scene::advance(&mut scene, steps);
    tidepool::Scene::snapshot(&mut scene).unwrap()
}

fn rgb(p: &Pixmap) -> Vec<u8> {
    let mut v = Vec::new();
    push_rgb(p, &mut v);
    v
}

#[test]
fn kitty_encoder_frames_and_edits_decode_pixel_for_pixel_through_tmux() {
    let (w, h) = (97, 61);
    for tmux in [false, true] {
        let mut enc = KittyEncoder::new(KittyOptions { frame_edits: true, tmux, ..KittyOptions::new((20, 8)) });
        let mut stream = Vec::new();
        let first = rgb(&pool(w, h, 10));
        enc.encode(&first, w, h, &mut stream).unwrap();
        // A small change: a frame edit of its rectangle.
        let mut second = first.clone();
        second[(30 * w as usize + 40) * 3..(30 * w as usize + 52) * 3].fill(250);
        enc.encode(&second, w, h, &mut stream).unwrap();
        let images = decode(if tmux { "encoder-tmux" } else { "encoder" }, &stream);
        assert_eq!(images.len(), 1);
        let (id, iw, ih, pixels) = &images[0];
        assert_eq!((*id, *iw, *ih), (KittyOptions::IMAGE_ID, w, h));
        assert!(*pixels == second, "tmux {tmux}: the decoded picture differs from the encoder's input");
    }
}

#[test]
fn picture_stream_offers_decode_to_the_picture_at_its_rung() {
    let l = layout(GraphicsMode::Kitty, (40, 13), Some((8, 16)), None, Layout::SCALED_CAP);
    let frame = Duration::from_nanos(1_000_000_000 / 30);
    let t0 = Instant::now();
    let (sw, sh) = (120, 72);
    // The four pictures the frames show (10 to 13 steps), each made once: a scene is the same
    // for the same steps, and making one per frame (its floor decoded each time) was 26 s of
    // this test's 27 s of CPU.
    let pictures: Vec<Pixmap> = (10..=13).map(|steps| pool(sw, sh, steps)).collect();
    // Zlib wholes without a limit; under a rate lossy PNG wholes and edits while the water
    // moves, then (the picture held still) exact edits of the worst blocks until the terminal
    // shows the exact picture at the top rung; at 5 kB/s (at most 500 bytes in the bucket)
    // the blocks are halved until they fit. The bucket refills as a link does.
    for (name, rate) in [("unlimited", None), ("2MBps", Some(2e6)), ("slow", Some(5e3))] {
        let mut stream =
            PictureStream::new(Protocol::Kitty(KittyOptions { frame_edits: true, ..KittyOptions::new(l.cells) }), l);
        let mut bucket = rate.map_or_else(ByteBucket::unlimited, ByteBucket::new);
        bucket.refill(t0);
        let (mut wire, mut parts, mut last, mut quiet) = (Vec::new(), Vec::new(), None, 0);
        // 24 frames of water that moves every 8 frames, then still until 60 frames in a row
        // send nothing (at most 100 s).
        for n in 1..3000u32 {
            let picture = &pictures[(n.min(24) / 8) as usize];
            let now = t0 + frame * n;
            bucket.refill(now);
            let budget = Budget::new(bucket.budget(), rate, frame);
            if let Some(offer) = stream.prepare(picture, budget, now) {
                assert!(offer.bytes.len() <= budget.available, "{name}: frame {n} over the bucket");
                bucket.spend(offer.bytes.len());
                wire.extend_from_slice(offer.bytes);
                parts.push(offer.state.part);
                stream.commit();
                (last, quiet) = (Some((picture, stream.state().size)), 0);
            } else if n > 24 {
                quiet += 1;
                if quiet == 60 {
                    break;
                }
            }
        }
        assert_eq!(quiet, 60, "{name}: the still picture never stopped being sent ({} offers)", parts.len());
        let (picture, size) = last.expect("offers");
        // The top rung: the source's own size within the layout's picture.
        assert_eq!(size, (sw, sh), "{name}: {parts:?}");
        if rate.is_some() {
            assert!(parts.iter().any(|p| matches!(p, Part::Changed(..))), "{name}: edits: {parts:?}");
        }
        let images = decode(name, &wire);
        let (_, iw, ih, pixels) = &images[0];
        assert_eq!((*iw, *ih), size, "{name}");
        let mut want = Vec::new();
        resample(picture.data(), 4, (sw, sh), size, &mut want);
        assert!(*pixels == want, "{name}: decoded pixels differ from the picture at {size:?} ({} offers)", parts.len());
    }
}
