//! Groups without a terminal or a socket: three players of one size on one host, their bytes
//! fed to terminal models.

use std::time::{Duration, Instant};

use tiny_skia::Pixmap;

use super::*;
use crate::PoolSettings;
use crate::output::vt::TerminalModel as Vt;
use crate::play::{Host, HostConfig, Request};
use crate::scene::SceneSpec;

const FRAME: Duration = Duration::from_nanos(1_000_000_000 / 30);
const TERM: (u16, u16) = (60, 16);

fn player(t0: Instant) -> Player {
    greeted(t0, None)
}

/// A player greeted with `greeting` (shown for its first seconds).
fn greeted(t0: Instant, greeting: Option<&str>) -> Player {
    let config = ScreenConfig {
        fps: 30,
        bandwidth: Bandwidth::Unlimited,
        color: ColorMode::TrueColor,
        color_auto: false,
        colour_hint: false,
        encode: EncodeOptions::default(),
        graphics: GraphicsRequest::Force(GraphicsMode::Cells),
        probe: None,
        link_path: LinkPath::Direct,
    };
    let screen = Screen::new(config, TERM, t0);
    let picture = screen.picture_size();
    Player::new(screen, picture, greeting.map(String::from))
}

/// One member: its player, its place in the group, its terminal, and what each frame was.
struct Member {
    player: Player,
    membership: Membership,
    vt: Vt,
    frames: Vec<(Vec<u8>, Source)>,
}

/// Three players of one size on one host for `frames` frames; `keys` are bytes the third
/// player's terminal sends at given frames. Returns the members, and the group's frames
/// encoded at each frame.
fn play(frames: u32, keys: &[(u32, &[u8])]) -> (Vec<Member>, Vec<u64>) {
    play_with(frames, keys, true)
}

/// [`play`], with stones or on still water (where only the status line's figures change).
fn play_with(frames: u32, keys: &[(u32, &[u8])], stones: bool) -> (Vec<Member>, Vec<u64>) {
    let t0 = Instant::now();
    let mut members: Vec<Member> = (0..3)
        .map(|_| Member {
            player: player(t0),
            membership: Membership::new(),
            vt: Vt::new(TERM.0 as usize, TERM.1 as usize),
            frames: Vec::new(),
        })
        .collect();
    let pool = PoolSettings { rain_rate: 0.0, breeze: 0.0, seed: 5, ..PoolSettings::default() };
    let config = HostConfig { scenes: vec![SceneSpec::Pool(pool)], seed: 5, record: None, screenshots: false };
    let size = members[0].player.screen.picture_size();
    let mut host = Host::new(config, size, t0).unwrap();
    let mut picture = Pixmap::new(size.0, size.1).unwrap();
    let first = &mut members[0];
    let key = first.membership.key(&first.player.screen).expect("a cell screen has a group");
    let mut group = Group::new(key, t0);
    let mut encoded = Vec::new();
    let mut requests = Vec::new();
    for k in 0..frames {
        let now = t0 + FRAME * k;
        if stones && k % 10 == 0 {
            // A stone every third of a second keeps the water moving.
            host.apply(Request::RandomStone { radius: 3 }, now);
        }
        host.advance(now);
        host.render(&mut picture);
        let status = host.status().clone();
        group.frame(now, &picture, &status);
        encoded.push(group.number);
        let feed = group.feed();
        for (i, m) in members.iter_mut().enumerate() {
            if i == 2 {
                for (_, bytes) in keys.iter().filter(|(at, _)| *at == k) {
                    m.player.feed(bytes, now);
                }
            }
            m.player.turn(now, &status, &mut requests);
            assert_eq!(m.membership.key(&m.player.screen), Some(key));
            let mut out = Vec::new();
            let (len, source) = m.membership.frame(&mut m.player, now, &picture, &status, Some(&feed), &mut out);
            assert_eq!(len, out.len());
            m.vt.feed(&out);
            m.frames.push((out, source));
        }
    }
    (members, encoded)
}

/// Whether two terminals look the same: each cell the same, or drawn another way that shows
/// the same (`▀` and `▄` with their colours swapped, a space whatever its foreground).
fn same(a: &Vt, b: &Vt) -> bool {
    let looks = |x: usize, y: usize| {
        let (p, q) = (a.cell(x, y), b.cell(x, y));
        let pixels = |vt: &Vt| [vt.pixel(x, 2 * y), vt.pixel(x, 2 * y + 1)];
        p == q
            || (pixels(a) == pixels(b) && pixels(a).iter().all(Option::is_some))
            || (p.ch == ' ' && q.ch == ' ' && p.bg == q.bg)
    };
    (0..a.rows()).all(|y| (0..a.cols()).all(|x| looks(x, y)))
}

#[test]
fn two_players_of_one_size_get_byte_identical_frames_from_one_encode() {
    let (members, encoded) = play(30, &[]);
    // At most one group frame is encoded per frame, however many members take it.
    assert!(encoded.windows(2).all(|w| w[1] - w[0] <= 1), "{encoded:?}");
    let (a, b) = (&members[0], &members[1]);
    // Their first frame is their own (the terminal's set-up and a whole paint); from then on
    // every frame is the group's, byte for byte the same for both.
    let shared: Vec<usize> = (0..30).filter(|&k| a.frames[k].1 == Source::Group).collect();
    assert!(shared.len() >= 25, "frames from the group: {shared:?}");
    for &k in &shared {
        assert_eq!(b.frames[k].1, Source::Group, "frame {k}");
        assert_eq!(a.frames[k].0, b.frames[k].0, "frame {k}: the same bytes");
        assert!(!a.frames[k].0.is_empty());
    }
    assert!(same(&a.vt, &b.vt), "both terminals show the same");
    assert!(a.membership.in_step() && b.membership.in_step());
    // Every group frame starts with an absolute move: right wherever a member's cursor was.
    for &k in &shared {
        let body = a.frames[k].0.strip_prefix(crate::output::diff::SYNC_BEGIN).unwrap_or(&a.frames[k].0);
        let end = body.iter().position(|b| b.is_ascii_alphabetic()).unwrap();
        assert!(
            body.starts_with(b"\x1b[") && body[end] == b'H',
            "frame {k}: {:?}",
            String::from_utf8_lossy(&body[..12])
        );
    }
}

#[test]
fn a_third_who_opens_help_diverges_and_converges_back() {
    let (members, _) = play(60, &[(20, b"?"), (35, b"?")]);
    let (a, c) = (&members[0], &members[2]);
    let source = |k: usize| c.frames[k].1;
    assert_eq!(source(19), Source::Group, "in step before the help");
    assert_eq!(source(20), Source::Own, "the help is its own");
    let help = String::from_utf8_lossy(&c.frames[20].0).into_owned();
    assert!(help.contains("tidepool keys"), "the help is drawn");
    assert!((21..35).all(|k| source(k) != Source::Group), "out of step while the help is open");
    // Closed at frame 35: its own frames catch up with the group's model, then it takes the
    // group's frames again, the same bytes as the others.
    let back = (36..60).find(|&k| source(k) == Source::Group).expect("back in step");
    assert!(back <= 40, "back in step within a few frames: frame {back}");
    for k in back..60 {
        assert_eq!(c.frames[k].0, a.frames[k].0, "frame {k}: the group's bytes again");
    }
    assert!(same(&a.vt, &c.vt), "its terminal shows what the others' show");
    assert!(c.membership.in_step());
}

#[test]
fn link_classes_double_and_keep_a_member_near_a_bound() {
    assert_eq!(LinkClass::of(Some(1_500.0)).rate(), 1_000);
    assert_eq!(LinkClass::of(Some(100_000.0)).rate(), 64_000);
    assert_eq!(LinkClass::of(None).rate(), 8_192_000);
    assert_eq!(LinkClass::of(Some(1e9)), LinkClass::of(None));
    let class = LinkClass::of(Some(130_000.0));
    assert_eq!(class.rate(), 128_000);
    assert_eq!(class.next(Some(125_000.0)), class, "a little below the bound: kept");
    assert_eq!(class.next(Some(100_000.0)).rate(), 64_000, "well below: the next class down");
    assert_eq!(class.next(Some(270_000.0)), class, "a little above the next bound: kept");
    assert_eq!(class.next(Some(300_000.0)).rate(), 256_000);
}

#[test]
fn on_still_water_a_member_back_in_step_draws_the_status_line_in_the_groups_colours() {
    // Its own frames leave its pen on the water; the group's next frames change only the
    // figures of the status line, and must not count on the group's pen.
    let (members, _) = play_with(100, &[(10, b"?"), (20, b"?")], false);
    let (a, c) = (&members[0], &members[2]);
    assert!(c.membership.in_step());
    assert!((30..100).filter(|&k| c.frames[k].1 == Source::Group && !c.frames[k].0.is_empty()).count() >= 2);
    assert!(same(&a.vt, &c.vt), "its terminal shows what the others' show");
}

/// Members whose links are at their class's lower bound (16 kB/s: what a terminal that answers
/// nothing gets) on busy water: one that left the group's step for a message of its own
/// catches up with the group's model and takes its frames again within a few seconds. With the
/// group encoding at the bound itself, its model moved as fast as the member's link carried and
/// the member never caught up (issue 31).
#[test]
fn a_member_at_its_class_bound_catches_up_on_busy_water() {
    let t0 = Instant::now();
    let term = (80, 24);
    let config = ScreenConfig {
        fps: 30,
        bandwidth: Bandwidth::Fixed(16_000),
        color: ColorMode::Palette256,
        color_auto: false,
        colour_hint: false,
        encode: EncodeOptions::default(),
        graphics: GraphicsRequest::Force(GraphicsMode::Cells),
        probe: None,
        link_path: LinkPath::Direct,
    };
    let mut members: Vec<(Player, Membership)> = (0..2)
        .map(|_| {
            let screen = Screen::new(config.clone(), term, t0);
            let picture = screen.picture_size();
            (Player::new(screen, picture, None), Membership::new())
        })
        .collect();
    let pool = PoolSettings { rain_rate: 1.0, breeze: 0.3, seed: 11, ..PoolSettings::default() };
    let host_config = HostConfig { scenes: vec![SceneSpec::Pool(pool)], seed: 11, record: None, screenshots: false };
    let size = members[0].0.screen.picture_size();
    let mut host = Host::new(host_config, size, t0).unwrap();
    let mut picture = Pixmap::new(size.0, size.1).unwrap();
    let (player, membership) = &mut members[0];
    let key = membership.key(&player.screen).unwrap();
    let mut group = Group::new(key, t0);
    // 20 s at 30 fps: the second member's message (4 s) from 8 s on; then busy water to 20 s.
    let mut second = Vec::new();
    for k in 0..600u32 {
        let now = t0 + FRAME * k;
        if k % 6 == 0 {
            host.apply(Request::RandomStone { radius: 4 }, now);
        }
        if k == 240 {
            members[1].0.seat.say("a message of its own", now);
        }
        host.advance(now);
        host.render(&mut picture);
        let status = host.status().clone();
        group.frame(now, &picture, &status);
        let feed = group.feed();
        for (i, (player, membership)) in members.iter_mut().enumerate() {
            let mut out = Vec::new();
            let (_, source) = membership.frame(player, now, &picture, &status, Some(&feed), &mut out);
            if i == 1 {
                second.push(source);
            }
        }
    }
    let joined = |from: usize| (from..second.len()).find(|&k| second[k] == Source::Group);
    let first = joined(0).expect("in step at the start");
    assert!(first <= 240, "in step within its first 8 s (frame {first})");
    assert!((250..360).all(|k| second[k] != Source::Group), "out of step while its message shows");
    let back = joined(360).expect("back in step after its message, on busy water");
    assert!(back <= 360 + 150, "back in step within 5 s of its message's end: frame {back}");
}

#[test]
fn players_greeted_alike_share_a_group_that_shows_the_greeting_then_the_plain_one() {
    const GREETING: &str = "a shared greeting";
    let t0 = Instant::now();
    // Three players greeted alike (as a crowd that joins together is); the greeting shows for
    // their first 10 s (300 frames at 30 fps).
    let mut members: Vec<(Player, Membership, Vt, Vec<Source>)> = (0..3)
        .map(|_| {
            (greeted(t0, Some(GREETING)), Membership::new(), Vt::new(TERM.0 as usize, TERM.1 as usize), Vec::new())
        })
        .collect();
    let pool = PoolSettings { rain_rate: 0.5, seed: 7, ..PoolSettings::default() };
    let config = HostConfig { scenes: vec![SceneSpec::Pool(pool)], seed: 7, record: None, screenshots: false };
    let size = members[0].0.screen.picture_size();
    let mut host = Host::new(config, size, t0).unwrap();
    let mut picture = Pixmap::new(size.0, size.1).unwrap();
    let mut groups = Groups::default();
    let mut requests = Vec::new();
    let status_row = |vt: &Vt| (0..vt.cols()).map(|x| vt.cell(x, vt.rows() - 1).ch).collect::<String>();
    let mut shown_at_150 = String::new();
    for k in 0..360u32 {
        let now = t0 + FRAME * k;
        if k % 10 == 0 {
            host.apply(Request::RandomStone { radius: 3 }, now);
        }
        host.advance(now);
        host.render(&mut picture);
        let status = host.status().clone();
        // The keys as the server takes them: each with its note's text.
        let keys: Vec<(GroupKey, Option<Arc<str>>)> = members
            .iter_mut()
            .map(|(p, m, _, _)| {
                p.turn(now, &status, &mut requests);
                let message = p.message(now);
                (m.key(&p.screen).expect("a group").with_note(message), message.map(Arc::from))
            })
            .collect();
        groups.keep(keys.clone(), now);
        let pictures = HashMap::from([(size, Arc::new(picture.clone()))]);
        groups.encode(&pictures, &status, now);
        let feeds = groups.feeds();
        for ((p, m, vt, sources), (key, _)) in members.iter_mut().zip(&keys) {
            let mut out = Vec::new();
            let (_, source) = m.frame(p, now, &picture, &status, feeds.get(key), &mut out);
            vt.feed(&out);
            sources.push(source);
        }
        if k == 150 {
            shown_at_150 = status_row(&members[0].2);
        }
    }
    // While greeted, they take the greeted group's frames, and their terminals show the
    // greeting (drawn by the group).
    for (_, m, vt, sources) in &members {
        let shared = (30..290).filter(|&k| sources[k] == Source::Group).count();
        assert!(shared >= 230, "frames from the greeted group while greeted: {shared} of 260");
        // After it, the plain group's (a status row apart: in step again within a second).
        let back = (300..360).find(|&k| sources[k] == Source::Group).expect("in the plain group's step after");
        assert!(back <= 330, "back in step at frame {back}");
        assert!(m.in_step());
        assert!(!status_row(vt).contains(GREETING), "the greeting is gone: {:?}", status_row(vt));
    }
    assert!(shown_at_150.contains(GREETING), "the greeting shows while greeted: {shown_at_150:?}");
}
