//! The screen's side of the terminal's answers: what was read goes where it belongs (inputs to
//! the door, replies to the probe or the link), the probe ends at its deadline or its last
//! answer, the graphics mode is chosen (and changed by late answers or, under `auto`, by the
//! link's measured rate), and the link control follows the round trips.

use std::time::Instant;

use super::*;

impl Screen {
    pub(super) fn auto(&self) -> bool {
        self.config.bandwidth == Bandwidth::Auto
    }

    /// Sends what was read where it belongs.
    pub(super) fn route(&mut self, now: Instant, inputs: &mut Vec<Input>) {
        let (auto, probing) = (self.auto(), self.probing());
        let mut received = std::mem::take(&mut self.received);
        for r in received.drain(..) {
            let probe = match &mut self.asking {
                Asking::First { probe, .. } | Asking::Late { probe, .. } => Some(probe),
                Asking::No => None,
            };
            match (r, probe) {
                (Received::Reply(reply @ Reply::PrimaryAttributes(_)), probe) => {
                    // In order: the probe's answers come before any to the link's questions. An
                    // extra one (the outer terminal's, inside tmux) goes to the probe while the
                    // link has asked nothing.
                    let probes = self.probe_answers > 0 || (probe.is_some() && !self.link.asking());
                    if probes && self.link.foreign_due() {
                        // The link's queue drops the place it kept for the probe's answer.
                        self.link.answered(now);
                    }
                    match probe {
                        Some(probe) if probes => {
                            self.probe_answers = self.probe_answers.saturating_sub(1);
                            probe.receive(Received::Reply(reply));
                        }
                        _ if self.probe_answers > 0 => self.probe_answers -= 1,
                        // Inside tmux or screen the link's answers are device status reports:
                        // a device attributes answer there is the multiplexer's to the probe.
                        _ if self.link.asks_status() => {
                            if self.link.foreign_due() {
                                self.link.answered(now);
                            }
                        }
                        _ => {
                            if auto && self.link.answered(now) == Change::Down {
                                self.bucket.drain();
                            }
                        }
                    }
                }
                // The terminal's answer to the link's question wrapped for the multiplexer.
                (Received::Reply(Reply::DeviceStatus(_)), _) if self.link.asks_status() => {
                    if auto && self.link.status_answered(now) == Change::Down {
                        self.bucket.drain();
                    }
                }
                (r @ Received::Input(_), Some(probe)) if probing => {
                    probe.receive(r);
                }
                (Received::Input(input), _) => inputs.push(input),
                (r, Some(probe)) => {
                    probe.receive(r);
                }
                (_, None) => {}
            }
        }
        self.received = received;
        crate::play::input::coalesce(inputs);
        let done = match &self.asking {
            Asking::First { probe, .. } | Asking::Late { probe, .. } => probe.done(),
            Asking::No => false,
        };
        if done {
            self.end_probe(now, inputs);
        }
    }

    /// The probe's answers are in, or its deadline passed: choose how to draw. Before its
    /// answers are complete the terminal gets cells, and late answers may still upgrade it.
    pub(super) fn end_probe(&mut self, now: Instant, inputs: &mut Vec<Input>) {
        let asking = std::mem::replace(&mut self.asking, Asking::No);
        let (mut probe, first) = match asking {
            Asking::First { probe, .. } => (probe, true),
            Asking::Late { probe, .. } => (probe, false),
            Asking::No => return,
        };
        inputs.extend(probe.take_leftover());
        let support = probe.support();
        if first || support.true_color {
            self.settle_colours(support.true_color);
        }
        if !probe.done() {
            self.asking = Asking::Late { probe, until: now + LATE_ANSWERS };
            if first {
                // Draw cells now (or the forced mode), with what is known.
                self.choose(&support, true);
            }
            return;
        }
        // Late answers may upgrade `auto`'s cells, or show that a forced protocol's pictures
        // never appear (then cells, and why).
        let forced = self.config.graphics != GraphicsRequest::Auto;
        if first || forced || self.choice.mode == GraphicsMode::Cells {
            self.choose(&support, first);
        }
    }

    /// Sets the protocol from what the terminal said (`first`: the first decision, before any
    /// frame; later only a change of protocol: `auto`'s cells upgraded to pixels, a forced
    /// protocol's pixels that would never show replaced by cells). With `auto`, pixels are drawn
    /// only where they show the truer moving picture at the link's rate (a fixed rate is known
    /// now; a measured one starts with pixels and [`Screen::follow_link`] switches).
    pub(super) fn choose(&mut self, support: &GraphicsSupport, first: bool) {
        let choice = probe::choose(self.config.graphics, Some(support));
        if !first && choice.mode == self.choice.mode {
            return;
        }
        self.support = support.clone();
        if choice.mode == GraphicsMode::Sixel && self.auto() && self.local_terminal() {
            // A sixel terminal on this machine: its pty's blocking writes pace the pictures
            // (the door drops frames while one is written). Measured in bytes, a sixel
            // picture's cost is its pixels, not its bytes (xterm draws 2-5 MB/s of them); the
            // link control settled at a few hundred kB/s and the stream drew its lowest rung,
            // a coarse mosaic. Unlimited: whole pictures at full resolution, as fast as the
            // terminal takes them.
            self.config.bandwidth = Bandwidth::Unlimited;
            self.bucket = ByteBucket::unlimited();
        }
        let mut notice: Vec<String> = choice.hint.map(str::to_owned).into_iter().collect();
        self.auto_pixels = None;
        let mut drawn = choice.clone();
        if self.config.graphics == GraphicsRequest::Auto && choice.mode != GraphicsMode::Cells {
            let known = match self.config.bandwidth {
                Bandwidth::Fixed(rate) => Some(rate as f64),
                Bandwidth::Auto | Bandwidth::Unlimited => None,
            };
            let switch = picture::auto_switch(&choice, support, known, self.auto());
            if switch.mode() == GraphicsMode::Cells {
                notice.push(picture::switch_notice(choice.mode, GraphicsMode::Cells, known));
                drawn = probe::choose(GraphicsRequest::Force(GraphicsMode::Cells), None);
            }
            self.auto_pixels = Some((switch, choice));
        }
        let late = if first { "" } else { " (the terminal answered late)" };
        self.draw_with(drawn, notice, late);
        // A new protocol from the probe's answers: the screen is repainted whole.
        self.shown = Shown::UNKNOWN;
        self.switch = None;
    }

    /// Whether the terminal is on this machine: not over SSH (the probe's environment), and
    /// nothing between (a multiplexer over SSH, mosh).
    fn local_terminal(&self) -> bool {
        self.config.probe.as_ref().is_some_and(|p| !p.env.ssh) && self.config.link_path == LinkPath::Direct
    }

    /// The colours from what the terminal said (`true_color`), when `--color` is `auto`: true
    /// colour when it said so (a repaint, if frames went out before a late answer); otherwise
    /// the environment's guess stays and, below true colour, the status line says how to get
    /// it.
    pub(super) fn settle_colours(&mut self, true_color: bool) {
        if !self.config.color_auto || self.config.color == ColorMode::TrueColor {
            return;
        }
        if true_color {
            self.config.color = ColorMode::TrueColor;
            self.shown = Shown::UNKNOWN;
            self.colour_hint = false;
        } else {
            self.colour_hint = self.config.colour_hint;
        }
    }

    /// `auto` between pixels and cells as the link's rate crosses the protocol's crossover
    /// (with the switch's hysteresis); a switch is said on the status line. The old picture
    /// stays until the new one covers it (see `switch`); pixel mouse reports end in `out`.
    pub(super) fn follow_link(&mut self, now: Instant, out: &mut Vec<u8>) {
        let rate = self.bucket.rate();
        let Some((switch, pixels)) = &mut self.auto_pixels else { return };
        let (mode, changed) = switch.update(rate, now);
        if !changed {
            return;
        }
        let choice = if mode == GraphicsMode::Cells {
            probe::choose(GraphicsRequest::Force(GraphicsMode::Cells), None)
        } else {
            pixels.clone()
        };
        let notice = picture::switch_notice(pixels.mode, mode, rate);
        // The old picture stays until the new one covers it (`switch`): only the pixel mouse
        // reports go now.
        if self.mouse_pixels {
            out.extend_from_slice(picture::PIXEL_MOUSE_OFF);
        }
        self.switch = Some(if mode == GraphicsMode::Cells {
            switch::Switch::ToCells { delete: picture::restore_bytes(&self.choice, false) }
        } else {
            switch::Switch::ToPixels
        });
        self.mouse_pixels = false;
        self.draw_with(choice, vec![notice], "");
    }

    /// Draws with `choice` from the next frame on, telling `notice` and which protocol draws.
    /// The terminal's cells stay known (a switch paints over them; see `switch`).
    pub(super) fn draw_with(&mut self, choice: GraphicsChoice, mut notice: Vec<String>, late: &str) {
        self.picture = Picture::new(&choice, &self.support, self.term, super::files_dir(&self.config));
        let mouse_pixels = picture::pixel_mouse(&choice, &self.support);
        self.mouse_pixels_pending = mouse_pixels && !self.mouse_pixels;
        self.mouse_pixels = mouse_pixels;
        if let Some(p) = &self.picture {
            let (w, h) = p.scene_size();
            notice.push(format!("{} graphics, {w}x{h} pixels{late}", choice.mode.name()));
        }
        if !notice.is_empty() {
            self.notice = Some(notice.join("; "));
        }
        self.choice = choice;
        self.layout_changed = true;
    }
}
