//! Encode once per group: screens alike in size, colours and link share one encoded frame.
//!
//! A shared scene (`tidepool serve`) shows the same picture to every player; players whose
//! terminals have the same size, colour mode and encoder settings, who draw in half-block cells
//! and whose links are of the same class ([`LinkClass`]) would each encode the same bytes. A
//! [`Group`] keeps its own screen model and encodes each frame once from it; a player's
//! [`Membership`] takes the group's bytes while its terminal shows the group's model ("in
//! step"), and encodes for itself only while it differs:
//!
//! - **In step**: the member holds the last [`GroupFrame`] its terminal got. The next frames of
//!   the group's [`GroupFeed`] (one, or a few it skipped while its writer was busy) go out as
//!   they are, if they fit its own link budget. Its screen keeps no model of its own meanwhile
//!   (its buffers are freed: memory per player stays small).
//! - **Out of step**: an overlay of its own (help, the aim marker, a message, another stone
//!   size on the status line), a group frame that did not fit its link, frames it missed that
//!   the feed no longer holds, a new size or link class. Its screen gets the model of the last
//!   group frame it showed and encodes for itself: its own frame while it has an overlay (with
//!   the group's status-line figures), otherwise towards the group's model, exactly. Only then
//!   is its model compared with the group's (equal cells: in step again).
//!
//! Every group frame starts from an unknown cursor and pen (an absolute move, explicit
//! colours), so a member whose cells equal the group's takes its bytes wherever its own cursor
//! was. The status line of a group frame carries the group's figures (frames and bytes a second
//! of the group's stream, its class's rate), not one player's. Real-pixel screens (kitty,
//! sixel, iTerm2) keep their own picture streams: they draw alone.

use std::collections::{HashMap, VecDeque};
use std::hash::Hash;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use rayon::prelude::*;
use tiny_skia::Pixmap;

use super::host::SceneStatus;
use super::player::Player;
use super::screen::compose::{Figures, half_block_picture};
use super::screen::probe::GraphicsRequest;
use super::screen::{Bandwidth, CellSource, LinkPath, Screen, ScreenConfig};
use super::seat::{DEFAULT_STONE_RADIUS, SeatView};
use crate::output::color::ColorMode;
use crate::output::diff::{EncodeOptions, Shown};
use crate::output::graphics::GraphicsMode;

/// Group frames a feed holds: a member that missed fewer than this many takes them all.
pub const FEED_FRAMES: usize = 8;
/// The slowest link class, bytes a second; classes double from here.
const SLOWEST_CLASS: f64 = 1_000.0;
/// The fastest link class, bytes a second (about half a megabyte a frame at 15 fps: a whole
/// frame of the largest common terminals); a faster link, or none, is in it too.
const FASTEST_CLASS: f64 = 8_192_000.0;
/// A member's rate may stray this far beyond its class's bounds before it changes class (so a
/// rate near a bound does not flap between groups).
const CLASS_HYSTERESIS: f64 = 0.1;
/// The share of its class's lower bound a group encodes at. Below the hysteresis's 0.9, so the
/// group's frames fit every member's link; and below it by enough that a member out of step
/// catches up with the group's model: at the bound, encoding towards a model that moves as
/// fast as its own link carries, a member on busy water never caught up (issue 31: 40 OpenSSH
/// clients took 43 % of their frames from the group, each joining once, late).
const GROUP_SHARE: f64 = 0.8;

/// A range of link rates that share frames: a group encodes below its lower bound
/// (`GROUP_SHARE`), so every member's link carries it with room to catch up.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct LinkClass {
    /// The lower bound, bytes a second (a power of two times [`SLOWEST_CLASS`]).
    floor: u64,
}

impl LinkClass {
    /// The class of a link of `rate` bytes a second (`None`: unlimited).
    pub fn of(rate: Option<f64>) -> LinkClass {
        let rate = rate.unwrap_or(f64::INFINITY).clamp(SLOWEST_CLASS, FASTEST_CLASS);
        let steps = (rate / SLOWEST_CLASS).log2().floor();
        LinkClass { floor: (SLOWEST_CLASS * steps.exp2()).round() as u64 }
    }

    /// The class for `rate` given the one a member is in: kept while the rate is within it
    /// (with [`CLASS_HYSTERESIS`]).
    fn next(self, rate: Option<f64>) -> LinkClass {
        let r = rate.unwrap_or(f64::INFINITY).min(FASTEST_CLASS);
        let (low, high) = (self.floor as f64, 2.0 * self.floor as f64);
        let fastest = self.floor as f64 >= FASTEST_CLASS;
        if r >= low * (1.0 - CLASS_HYSTERESIS) && (fastest || r < high * (1.0 + CLASS_HYSTERESIS)) {
            self
        } else {
            LinkClass::of(rate)
        }
    }

    /// The class's lower bound, bytes a second (a group of it encodes at `GROUP_SHARE` of
    /// it).
    pub fn rate(self) -> u64 {
        self.floor
    }

    /// The rate a group of this class encodes at, bytes a second.
    fn group_rate(self) -> u64 {
        (self.floor as f64 * GROUP_SHARE) as u64
    }
}

/// A passing message on a status line (a hash of its text): players who show the same one
/// share a group too. A crowd that joins together is greeted alike for its first seconds; with
/// the message outside the key, each of them encoded its own frames all that time (issue 31:
/// 29 % of the frames of 40 OpenSSH clients' 40 s sessions).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Note(u64);

impl Note {
    /// The note of `text` (FNV-1a: stable from run to run).
    fn of(text: &str) -> Note {
        Note(text.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3)))
    }
}

/// What screens must share to share frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct GroupKey {
    /// Terminal size in cells.
    pub term: (u16, u16),
    /// Terminal colours.
    pub color: ColorMode,
    /// Encoder options.
    pub encode: EncodeOptions,
    /// Frames a second at most.
    pub fps: u32,
    /// The link's class.
    pub(crate) class: LinkClass,
    /// The passing message its status line shows, if any.
    pub(crate) note: Option<Note>,
}

impl GroupKey {
    /// The key of a member whose status line shows `message` (a passing message, or none).
    pub fn with_note(self, message: Option<&str>) -> GroupKey {
        GroupKey { note: message.map(Note::of), ..self }
    }

    /// The picture a group of this key draws, in pixels (as its members' screens take it).
    pub fn picture_size(&self) -> (u32, u32) {
        half_block_picture(self.term)
    }
}

/// Groups kept and group frames alive in this process (the feeds' and those members still
/// hold), for the bus's trace: what an edge's memory in use follows (bus.md round 9).
static GROUPS_KEPT: AtomicUsize = AtomicUsize::new(0);
static FRAMES_ALIVE: AtomicUsize = AtomicUsize::new(0);

/// The groups kept and the group frames alive in this process (the bus's trace reads it).
#[cfg(feature = "bus")]
pub fn alive() -> (usize, usize) {
    (GROUPS_KEPT.load(Ordering::Relaxed), FRAMES_ALIVE.load(Ordering::Relaxed))
}

/// Counts a group frame while it lives.
#[derive(Debug)]
struct Alive;

impl Alive {
    fn new() -> Alive {
        FRAMES_ALIVE.fetch_add(1, Ordering::Relaxed);
        Alive
    }
}

impl Drop for Alive {
    fn drop(&mut self) {
        FRAMES_ALIVE.fetch_sub(1, Ordering::Relaxed);
    }
}

/// One frame a group encoded.
#[derive(Debug)]
pub struct GroupFrame {
    /// The group's frames so far, this one included.
    pub number: u64,
    /// The bytes, from the model after the frame before (with its cursor and pen unknown).
    pub bytes: Vec<u8>,
    /// What a terminal that took the group's frames up to this one shows.
    after: Shown,
    /// The figures its status line carries.
    figures: Figures,
    _alive: Alive,
}

/// The group's last frames, oldest first, as published to its members.
#[derive(Clone, Debug)]
pub struct GroupFeed {
    key: GroupKey,
    frames: Arc<[Arc<GroupFrame>]>,
}

impl GroupFeed {
    /// The frames after frame `number`, if the feed still holds all of them.
    fn after(&self, number: u64) -> Option<&[Arc<GroupFrame>]> {
        let first = self.frames.first()?.number;
        if number + 1 < first {
            return None;
        }
        let from = (number + 1 - first) as usize;
        Some(self.frames.get(from..).unwrap_or(&[]))
    }
}

/// Screens alike enough to share frames, encoded once.
#[derive(Debug)]
pub struct Group {
    key: GroupKey,
    /// The group's own screen: its model, encoder, byte bucket at the class's rate, meter.
    screen: Screen,
    frames: VecDeque<Arc<GroupFrame>>,
    number: u64,
    /// The text of its key's note, shown on its status line.
    note: Option<Arc<str>>,
}

impl Group {
    /// A group of screens of `key`, its clock starting at `now`.
    pub fn new(key: GroupKey, now: Instant) -> Group {
        let fastest = key.class.rate() as f64 >= FASTEST_CLASS;
        let bandwidth = if fastest { Bandwidth::Unlimited } else { Bandwidth::Fixed(key.class.group_rate()) };
        let config = ScreenConfig {
            fps: key.fps,
            bandwidth,
            color: key.color,
            color_auto: false,
            colour_hint: false,
            encode: key.encode,
            graphics: GraphicsRequest::Force(GraphicsMode::Cells),
            probe: None,
            link_path: LinkPath::Direct,
        };
        let screen = Screen::new(config, key.term, now).without_enter();
        Group { key, screen, frames: VecDeque::with_capacity(FEED_FRAMES), number: 0, note: None }
    }

    /// The group whose status line shows `text` (its key's note: ignored when it is not).
    pub fn noted(mut self, text: Option<Arc<str>>) -> Group {
        self.note = text.filter(|t| self.key.note == Some(Note::of(t)));
        self
    }

    /// What its members share.
    pub fn key(&self) -> GroupKey {
        self.key
    }

    /// Encodes the frame for now: `picture` (of [`GroupKey::picture_size`]) under the status
    /// line of `status`, with no one's overlay but the group's note. Returns whether the frame changed anything (a
    /// frame that sends nothing is no new group frame).
    pub fn frame(&mut self, now: Instant, picture: &Pixmap, status: &SceneStatus) -> bool {
        self.screen.forget_pen();
        let (fps, bytes_per_second) = self.screen.figures();
        let bandwidth = (self.screen.config().bandwidth != Bandwidth::Unlimited).then(|| self.key.class.group_rate());
        let figures = Figures { fps, bytes_per_second, bandwidth, pixels_elsewhere: false, note: None };
        let seat = SeatView { stone: DEFAULT_STONE_RADIUS, message: self.note.as_deref(), ..SeatView::default() };
        // The oldest frame's buffers are reused once no member holds it.
        let recycled = if self.frames.len() >= FEED_FRAMES { self.frames.pop_front() } else { None };
        let (mut bytes, mut after) = match recycled.map(Arc::try_unwrap) {
            Some(Ok(old)) => (old.bytes, old.after),
            _ => (Vec::new(), Shown::UNKNOWN),
        };
        bytes.clear();
        let len =
            self.screen.frame_from(now, picture, status, &seat, CellSource::Own { figures: Some(figures) }, &mut bytes);
        if len == 0 {
            return false;
        }
        after.clone_from(self.screen.shown());
        self.number += 1;
        self.frames.push_back(Arc::new(GroupFrame {
            number: self.number,
            bytes,
            after,
            figures,
            _alive: Alive::new(),
        }));
        true
    }

    /// The last frames, for the members.
    pub fn feed(&self) -> GroupFeed {
        GroupFeed { key: self.key, frames: self.frames.iter().cloned().collect() }
    }
}

/// The groups of one shared scene: one for every key that at least [`Groups::MIN_MEMBERS`]
/// players have, the [`Groups::MAX`] largest. The game keeps them from frame to frame.
#[derive(Debug, Default)]
pub struct Groups {
    groups: HashMap<GroupKey, Group>,
}

impl Groups {
    /// Most groups encoded per frame (the largest first); players of the others encode alone,
    /// on their own tasks. Bounds the game's work whatever sizes the players choose.
    pub const MAX: usize = 64;
    /// Players a key needs for a group: one player alone encodes for itself.
    pub const MIN_MEMBERS: usize = 2;

    /// Keeps a group for every key of `keys` (one a player, with the text of its note) that
    /// enough players have, new ones starting at `now`; drops the rest.
    pub fn keep(&mut self, keys: impl IntoIterator<Item = (GroupKey, Option<Arc<str>>)>, now: Instant) {
        let mut members: HashMap<GroupKey, (usize, Option<Arc<str>>)> = HashMap::new();
        for (key, note) in keys {
            let entry = members.entry(key).or_insert((0, note));
            entry.0 += 1;
        }
        let mut notes: HashMap<GroupKey, Option<Arc<str>>> = HashMap::new();
        let members: HashMap<GroupKey, usize> = members
            .into_iter()
            .map(|(key, (n, note))| {
                notes.insert(key, note);
                (key, n)
            })
            .collect();
        let mut keys: Vec<(usize, GroupKey)> =
            members.into_iter().filter(|&(_, n)| n >= Self::MIN_MEMBERS).map(|(k, n)| (n, k)).collect();
        if keys.len() > Self::MAX {
            // The largest groups save the most; ties by size so the choice is stable.
            keys.sort_unstable_by_key(|&(n, k)| (std::cmp::Reverse(n), k.term));
            keys.truncate(Self::MAX);
        }
        self.groups.retain(|key, _| keys.iter().any(|(_, k)| k == key));
        for (_, key) in keys {
            let note = notes.remove(&key).flatten();
            self.groups.entry(key).or_insert_with(|| Group::new(key, now).noted(note));
        }
        GROUPS_KEPT.store(self.groups.len(), Ordering::Relaxed);
    }

    /// Encodes every group's frame from the picture of its size in `pictures`, in parallel;
    /// returns how many changed something.
    pub fn encode(&mut self, pictures: &HashMap<(u32, u32), Arc<Pixmap>>, status: &SceneStatus, now: Instant) -> u64 {
        let mut work: Vec<&mut Group> = self.groups.values_mut().collect();
        work.par_iter_mut()
            .map(|group| match pictures.get(&group.key().picture_size()) {
                Some(picture) => u64::from(group.frame(now, picture, status)),
                None => 0,
            })
            .sum()
    }

    /// Every group's last frames, to publish.
    pub fn feeds(&self) -> HashMap<GroupKey, GroupFeed> {
        self.groups.iter().map(|(key, group)| (*key, group.feed())).collect()
    }
}

/// How the last frame of a member was made.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// Nothing was sent.
    Nothing,
    /// The group's bytes.
    Group,
    /// Its own encoding.
    Own,
}

/// Why a member left its group's step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Left {
    /// An overlay of its own, or another stone size.
    Overlay,
    /// The frames that follow its last are no longer in the feed (it waited too long).
    Missed,
    /// Another group (a new link class), or none.
    Key,
}

/// What a member did, for the log.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MembershipStats {
    /// Frames sent that were the group's bytes.
    pub taken: u64,
    /// Times it joined its group's step.
    pub joined: u64,
    /// Times it left it for an overlay of its own.
    pub left_for_overlay: u64,
    /// Times it left it because the feed no longer held the frames it needed.
    pub left_behind: u64,
    /// Times it left it for another group (link class) or none.
    pub left_for_key: u64,
}

/// A player's place in its group (see the module's documentation).
#[derive(Debug, Default)]
pub struct Membership {
    stats: MembershipStats,
    class: Option<LinkClass>,
    /// The group frame the terminal shows last, while in step.
    pinned: Option<Arc<GroupFrame>>,
    pinned_key: Option<GroupKey>,
}

impl Membership {
    /// A player who draws alone until it finds its group.
    pub fn new() -> Membership {
        Membership::default()
    }

    /// The group `screen` belongs in now; `None` while it draws alone (it is asking the
    /// terminal what it draws, draws real pixels, or is too small).
    pub fn key(&mut self, screen: &Screen) -> Option<GroupKey> {
        if screen.probing() || screen.mode() != GraphicsMode::Cells || !screen.drawable() {
            return None;
        }
        let class = match self.class {
            Some(class) => class.next(screen.rate()),
            None => LinkClass::of(screen.rate()),
        };
        self.class = Some(class);
        let config = screen.config();
        Some(GroupKey {
            term: screen.term(),
            color: config.color,
            encode: config.encode,
            fps: config.fps,
            class,
            note: None,
        })
    }

    #[cfg(any(feature = "testing", test))]
    /// Whether the player's terminal shows its group's frames now.
    pub fn in_step(&self) -> bool {
        self.pinned.is_some()
    }

    /// What it did so far.
    pub fn stats(&self) -> MembershipStats {
        self.stats
    }

    fn count(&mut self, why: Left) {
        match why {
            Left::Overlay => self.stats.left_for_overlay += 1,
            Left::Missed => self.stats.left_behind += 1,
            Left::Key => self.stats.left_for_key += 1,
        }
    }

    /// Appends the player's frame for now to `out`: its group's bytes while in step, else its
    /// own encoding of `picture` (of its screen's picture size); `feed` is the group's of its
    /// key ([`Membership::key`]), if there is one. Returns the bytes appended and how they
    /// were made.
    pub fn frame(
        &mut self,
        player: &mut Player,
        now: Instant,
        picture: &Pixmap,
        status: &SceneStatus,
        feed: Option<&GroupFeed>,
        out: &mut Vec<u8>,
    ) -> (usize, Source) {
        let Player { seat, screen, .. } = player;
        let view = seat.view(now, status);
        let key = self.key(screen).map(|k| k.with_note(view.message));
        let feed = feed.filter(|f| Some(f.key) == key && !f.frames.is_empty());
        let plain = plain(&view, status);
        if let Some(pinned) = self.pinned.clone() {
            let why = match feed {
                _ if !plain => Left::Overlay,
                Some(feed) if self.pinned_key == key => match feed.after(pinned.number) {
                    // As many of the frames that follow as the link takes now; none: wait
                    // (still in step) until it takes one, or the feed no longer holds it.
                    Some(frames) => return self.take(screen, now, picture, status, frames, out),
                    None => Left::Missed,
                },
                _ => Left::Key,
            };
            self.count(why);
            self.leave(screen);
        }
        let Some(feed) = feed else {
            return (screen.frame(now, picture, status, &view, out), Source::Own);
        };
        let latest = feed.frames.last().expect("a feed with frames");
        if !plain {
            let own = CellSource::Own { figures: Some(latest.figures) };
            return (screen.frame_from(now, picture, status, &view, own, out), Source::Own);
        }
        // Plain again: the cells of one of the group's frames? Then its later frames follow.
        if let Some(at) = feed.frames.iter().rposition(|f| looks_alike(&f.after, screen.shown())) {
            self.join(screen, feed.frames[at].clone(), key);
            return self.take(screen, now, picture, status, &feed.frames[at + 1..], out);
        }
        let Some(model) = &latest.after.frame else {
            return (screen.frame(now, picture, status, &view, out), Source::Own);
        };
        let len = screen.frame_from(now, picture, status, &view, CellSource::Toward(model), out);

        if looks_alike(&latest.after, screen.shown()) {
            self.join(screen, latest.clone(), key);
        }
        (len, Source::Own)
    }

    /// Sends as many of the group's `frames` (those following the one pinned) as the link takes
    /// now, and pins the last sent.
    fn take(
        &mut self,
        screen: &mut Screen,
        now: Instant,
        picture: &Pixmap,
        status: &SceneStatus,
        frames: &[Arc<GroupFrame>],
        out: &mut Vec<u8>,
    ) -> (usize, Source) {
        let budget = screen.budget(now);
        let mut sum = 0;
        let fit = frames.iter().take_while(|f| {
            sum += f.bytes.len();
            sum <= budget
        });
        let frames = &frames[..fit.count()];
        if frames.is_empty() {
            return (0, Source::Nothing);
        }
        self.stats.taken += 1;
        let joined: Vec<u8>;
        let bytes = match frames {
            [one] => one.bytes.as_slice(),
            many => {
                joined = many.iter().flat_map(|f| f.bytes.iter().copied()).collect();
                joined.as_slice()
            }
        };
        let len = screen.frame_from(now, picture, status, &SeatView::default(), CellSource::Taken(bytes), out);
        self.pinned = frames.last().cloned();
        (len, Source::Group)
    }

    /// In step from `frame` on: the screen's own model and buffers go.
    fn join(&mut self, screen: &mut Screen, frame: Arc<GroupFrame>, key: Option<GroupKey>) {
        self.stats.joined += 1;
        screen.release();
        self.pinned = Some(frame);
        self.pinned_key = key;
    }

    /// Out of step: the screen's model is what the terminal shows, the pinned frame's model,
    /// with the cursor and pen unknown (a member that joined on equal cells kept its own).
    fn leave(&mut self, screen: &mut Screen) {
        if let Some(pinned) = self.pinned.take() {
            screen.set_shown(&pinned.after);
            screen.forget_pen();
        }
        self.pinned_key = None;
    }

    /// The terminal's layout changed (a new size, real pixels): its screen repaints it whole,
    /// so what it showed of the group no longer counts.
    pub fn reset(&mut self) {
        if self.pinned.is_some() {
            self.count(Left::Key);
        }
        self.pinned = None;
        self.pinned_key = None;
    }
}

/// Whether two models show the same cells (a space's foreground does not show: the encoder
/// leaves it as it is, so it may differ).
fn looks_alike(a: &Shown, b: &Shown) -> bool {
    match (&a.frame, &b.frame) {
        (Some(a), Some(b)) => {
            (a.cols(), a.rows()) == (b.cols(), b.rows())
                && a.cells().iter().zip(b.cells()).all(|(p, q)| p.close_to(q, 0))
        }
        _ => false,
    }
}

/// Whether a seat shows nothing of its own over the group's frame (no aim or help, and the
/// stone size every seat starts with, where the status line shows it; its passing message is
/// its key's note, which the group shows).
fn plain(view: &SeatView<'_>, status: &SceneStatus) -> bool {
    view.aim.is_none() && view.help.is_none() && (view.stone == DEFAULT_STONE_RADIUS || !status.takes_stones)
}

#[cfg(test)]
mod tests;
