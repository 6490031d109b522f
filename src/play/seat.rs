//! A seat: what one player holds between frames, apart from any terminal (the [`super::screen::Screen`] is
//! the terminal; a [`super::player::Player`] is the two together). Their aim, stone size, drag,
//! help and messages, and the [`Fit`] between their terminal and the scene. [`Seat::handle`] turns what they did into
//! [`Request`]s for the host: the one place a key or a click gets its meaning, for the local
//! player and every player of a shared pool alike.

use std::time::{Duration, Instant};

use super::fit::Fit;
use super::host::SceneStatus;
use super::input::Input;
use super::request::Request;
use crate::scene::Action;

/// Stone radii `+` and `-` step through, in pixels.
pub const STONE_RADII: [u32; 10] = [1, 2, 3, 4, 6, 8, 12, 16, 24, 32];
/// The stone radius a seat starts with, in pixels (a terminal pool is ~100 pixels tall).
pub const DEFAULT_STONE_RADIUS: u32 = 3;
/// How long the aim marker stays after the last aim key.
const AIM_VISIBLE: Duration = Duration::from_secs(4);
/// How long a message (a screenshot saved) stays.
const MESSAGE_VISIBLE: Duration = Duration::from_secs(4);
/// How long a greeting stays.
const GREETING_VISIBLE: Duration = Duration::from_secs(10);

/// Whether the person stays.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Flow {
    /// Keep playing.
    Continue,
    /// They quit (`q`, `Esc`, `Ctrl-C`).
    Quit,
}

/// What a seat shows over the picture this frame.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct SeatView<'a> {
    /// The aim marker's cell (column, row), while it is visible.
    pub aim: Option<(u16, u16)>,
    /// The help overlay's lines, while it is open.
    pub help: Option<&'a [(&'static str, &'static str)]>,
    /// A passing message for the status line.
    pub message: Option<&'a str>,
    /// The stone radius in pixels.
    pub stone: u32,
}

/// What one player holds: their aim, stone size, drag, help and messages, and their fit.
#[derive(Clone, Debug)]
pub struct Seat {
    fit: Fit,
    aim: (i32, i32),
    aim_until: Option<Instant>,
    radius: u32,
    drag: Option<(i32, i32)>,
    /// The help overlay's lines while it is open, and the scene they were made for.
    help: Option<(&'static str, Vec<(&'static str, &'static str)>)>,
    message: Option<(String, Instant)>,
    /// Whether `s` may save screenshots (never for a player of a shared pool).
    screenshots: bool,
}

impl Seat {
    /// A seat whose terminal shows the scene as `fit` says; the aim starts in the middle.
    pub fn new(fit: Fit) -> Seat {
        let (w, h) = fit.scene();
        Seat {
            fit,
            aim: ((w / 2) as i32, ((h / 2) & !1) as i32),
            aim_until: None,
            radius: DEFAULT_STONE_RADIUS,
            drag: None,
            help: None,
            message: None,
            screenshots: true,
        }
    }

    #[cfg(any(feature = "serve", feature = "testing", test))]
    /// A seat whose `s` key says screenshots are off instead of asking the host for one.
    pub fn without_screenshots(mut self) -> Seat {
        self.screenshots = false;
        self
    }

    /// Shows `text` on the status line for the first seconds.
    pub fn greet(&mut self, text: impl Into<String>, now: Instant) {
        self.message = Some((text.into(), now + GREETING_VISIBLE));
    }

    /// Shows `text` on the status line for a few seconds.
    pub fn say(&mut self, text: impl Into<String>, now: Instant) {
        self.message = Some((text.into(), now + MESSAGE_VISIBLE));
    }

    /// The terminal or the scene changed size: a new fit, the aim kept inside the scene.
    pub fn set_fit(&mut self, fit: Fit) {
        self.fit = fit;
        self.aim = self.clamped(self.aim);
    }

    #[cfg(any(feature = "serve", feature = "testing", test))]
    /// The fit in effect.
    pub fn fit(&self) -> &Fit {
        &self.fit
    }

    /// What the person did, as requests for the host (appended to `out`). `status` says what
    /// the scene is (its keys for the help).
    pub fn handle(&mut self, input: Input, now: Instant, status: &SceneStatus, out: &mut Vec<Request>) -> Flow {
        let radius = self.radius;
        match input {
            Input::Quit => return Flow::Quit,
            Input::Escape if self.help.is_some() => self.help = None,
            Input::Escape => return Flow::Quit,
            Input::Help => {
                self.help = match self.help {
                    Some(_) => None,
                    None => Some((status.name, help_lines(&status.keys, status.takes_stones))),
                }
            }
            Input::RandomStone => out.push(Request::RandomStone { radius }),
            Input::Aim(dx, dy) => {
                let (sx, sy) = self.fit.aim_step();
                self.aim = self.clamped((self.aim.0 + sx * dx, self.aim.1 + sy * dy));
                self.aim_until = Some(now + AIM_VISIBLE);
            }
            Input::DropAtAim => {
                let (x, y) = self.aim;
                self.aim_until = Some(now + AIM_VISIBLE);
                out.push(Request::Act(Action::Stone { x, y, radius, big: false }));
            }
            Input::ToggleRain => out.push(Request::Act(Action::ToggleRain)),
            Input::Clear => out.push(Request::Act(Action::Clear)),
            Input::Damping(stronger) => out.push(Request::Act(Action::Damping(stronger))),
            Input::StoneSize(bigger) => self.radius = next_radius(self.radius, bigger),
            Input::Pause => out.push(Request::TogglePause),
            Input::Screenshot if self.screenshots => out.push(Request::Screenshot),
            Input::Screenshot => self.say("screenshots are off here", now),
            Input::NextScene => out.push(Request::NextScene),
            Input::Other(c) => out.push(Request::Act(Action::Key(c))),
            Input::Press { col, row, big } => {
                if let Some((x, y)) = self.fit.scene_at(col, row) {
                    out.push(Request::Act(Action::Stone { x, y, radius, big }));
                    self.drag = (!big).then_some((x, y));
                }
            }
            Input::Drag { col, row } => {
                if let (Some(from), Some(to)) = (self.drag, self.fit.scene_at(col, row))
                    && from != to
                {
                    out.push(Request::Act(Action::Stir { from, to }));
                    self.drag = Some(to);
                }
            }
            Input::Release => self.drag = None,
        }
        Flow::Continue
    }

    /// What goes over the picture now. An open help follows the scene (`tab` changes its keys).
    pub(crate) fn view(&mut self, now: Instant, status: &SceneStatus) -> SeatView<'_> {
        if let Some((scene, _)) = &self.help
            && *scene != status.name
        {
            self.help = Some((status.name, help_lines(&status.keys, status.takes_stones)));
        }
        SeatView {
            aim: self.aim_until.is_some_and(|t| now < t).then(|| self.fit.cell_of(self.aim.0, self.aim.1)),
            help: self.help.as_ref().map(|(_, lines)| lines.as_slice()),
            message: self.message(now),
            stone: self.radius,
        }
    }

    /// The passing message on the status line at `now`, if any.
    pub(crate) fn message(&self, now: Instant) -> Option<&str> {
        self.message.as_ref().filter(|(_, until)| now < *until).map(|(m, _)| m.as_str())
    }

    /// Whether the help overlay is open.
    #[cfg(test)]
    pub fn help_open(&self) -> bool {
        self.help.is_some()
    }

    /// The aim kept on the scene, on an even row (the upper pixel of a half-block cell).
    fn clamped(&self, (x, y): (i32, i32)) -> (i32, i32) {
        let (w, h) = self.fit.scene();
        (x.clamp(0, w as i32 - 1), y.clamp(0, (h as i32 - 1) & !1))
    }
}

/// The radius after `radius` in [`STONE_RADII`], up (`bigger`) or down.
fn next_radius(radius: u32, bigger: bool) -> u32 {
    let i = STONE_RADII.iter().position(|&r| r >= radius).unwrap_or(0);
    let i = if bigger { (i + 1).min(STONE_RADII.len() - 1) } else { i.saturating_sub(1) };
    STONE_RADII[i]
}

/// Every key and mouse action there is, with the `scene`'s own keys added; the stone keys and
/// mouse actions only when the scene `takes_stones`.
pub fn help_lines(scene: &[(&'static str, &'static str)], takes_stones: bool) -> Vec<(&'static str, &'static str)> {
    let mut lines = Vec::new();
    if takes_stones {
        lines.extend_from_slice(&[
            ("space", "a stone at a random spot"),
            ("arrows hjkl", "move the aim"),
            ("enter", "a stone at the aim"),
            ("left click", "a stone where you click"),
            ("drag", "stir the water"),
            ("right click", "a big stone"),
            ("+ -", "bigger / smaller stones"),
        ]);
    }
    lines.extend_from_slice(scene);
    lines.extend_from_slice(&[
        ("p", "pause / resume"),
        ("s", "save a PNG screenshot"),
        ("tab", "next scene"),
        ("?", "this help"),
        ("q esc ctrl-c", "quit"),
    ]);
    lines
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::play::fit::CellGrid;

    fn seat(scene: (u32, u32), target: (u32, u32), rows: u16) -> Seat {
        Seat::new(Fit::new(scene, target, CellGrid::HalfBlocks { cols: target.0 as u16, rows }))
    }

    fn pool() -> SceneStatus {
        SceneStatus { name: "pool", takes_stones: true, keys: vec![("r", "rain on / off")], ..SceneStatus::default() }
    }

    fn requests(seat: &mut Seat, inputs: &[Input]) -> (Vec<Request>, Flow) {
        let mut out = Vec::new();
        let mut flow = Flow::Continue;
        for &i in inputs {
            flow = seat.handle(i, Instant::now(), &pool(), &mut out);
        }
        (out, flow)
    }

    #[test]
    fn keys_become_requests() {
        let mut s = seat((40, 22), (40, 22), 11);
        let (out, flow) = requests(&mut s, &[Input::RandomStone, Input::ToggleRain, Input::Pause, Input::Other('x')]);
        assert_eq!(flow, Flow::Continue);
        assert_eq!(
            out,
            vec![
                Request::RandomStone { radius: DEFAULT_STONE_RADIUS },
                Request::Act(Action::ToggleRain),
                Request::TogglePause,
                Request::Act(Action::Key('x')),
            ]
        );
        assert_eq!(requests(&mut s, &[Input::Quit]).1, Flow::Quit);
    }

    #[test]
    fn the_aim_moves_in_square_steps_and_stays_on_an_even_row_inside_the_scene() {
        let mut s = seat((40, 22), (40, 22), 11);
        let (out, _) = requests(&mut s, &[Input::Aim(1, 0), Input::Aim(0, 1), Input::DropAtAim]);
        assert_eq!(out, vec![Request::Act(Action::Stone { x: 22, y: 12, radius: 3, big: false })]);
        let far: Vec<Input> = std::iter::repeat_n(Input::Aim(1, 1), 50).chain([Input::DropAtAim]).collect();
        let (out, _) = requests(&mut s, &far);
        assert_eq!(out, vec![Request::Act(Action::Stone { x: 39, y: 20, radius: 3, big: false })]);
    }

    #[test]
    fn stone_sizes_step_through_the_radii_and_stop_at_the_ends() {
        let mut s = seat((40, 22), (40, 22), 11);
        requests(&mut s, &[Input::StoneSize(true), Input::StoneSize(true)]);
        assert_eq!(s.radius, 6);
        requests(&mut s, &vec![Input::StoneSize(false); 20]);
        assert_eq!(s.radius, 1);
        requests(&mut s, &vec![Input::StoneSize(true); 20]);
        assert_eq!(s.radius, 32);
    }

    #[test]
    fn clicks_and_drags_land_on_scene_pixels_through_the_fit() {
        // A 160x90 shared scene in a 200-column terminal: bars of 20 columns each side.
        let mut s = seat((160, 90), (200, 90), 45);
        let (out, _) = requests(
            &mut s,
            &[
                Input::Press { col: 30, row: 5, big: false },
                Input::Drag { col: 40, row: 5 },
                Input::Release,
                Input::Drag { col: 50, row: 5 },
                Input::Press { col: 5, row: 5, big: false },
                Input::Press { col: 30, row: 44, big: true },
            ],
        );
        assert_eq!(
            out,
            vec![
                Request::Act(Action::Stone { x: 10, y: 10, radius: 3, big: false }),
                Request::Act(Action::Stir { from: (10, 10), to: (20, 10) }),
                Request::Act(Action::Stone { x: 10, y: 88, radius: 3, big: true }),
            ]
        );
    }

    #[test]
    fn help_opens_with_the_scenes_keys_and_escape_closes_it_before_quitting() {
        let mut s = seat((40, 22), (40, 22), 11);
        requests(&mut s, &[Input::Help]);
        let now = Instant::now();
        let view = s.view(now, &pool());
        let lines = view.help.expect("open");
        assert!(lines.contains(&("r", "rain on / off")) && lines.contains(&("space", "a stone at a random spot")));
        assert_eq!(requests(&mut s, &[Input::Escape]).1, Flow::Continue);
        assert!(!s.help_open());
        assert_eq!(requests(&mut s, &[Input::Escape]).1, Flow::Quit);
        assert!(!help_lines(&[], false).iter().any(|(k, _)| *k == "space"), "no stones, no stone keys");
    }

    #[test]
    fn a_seat_without_screenshots_says_so_and_asks_nothing() {
        let mut s = seat((40, 22), (40, 22), 11).without_screenshots();
        let (out, _) = requests(&mut s, &[Input::Screenshot]);
        assert!(out.is_empty());
        assert_eq!(s.view(Instant::now(), &pool()).message, Some("screenshots are off here"));
    }
}
