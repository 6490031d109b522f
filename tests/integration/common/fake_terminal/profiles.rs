//! The terminals the fakes stand for: which parts of the kitty protocol, sixel and iTerm2 each
//! speaks, and how each answers the colour questions.

/// How a terminal treats kitty's root-frame edits (`a=f`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Edits {
    /// Applied; answered `OK` unless responses are suppressed.
    Apply,
    /// Refused with an error (`ENOENT`) unless `q=2`.
    Refuse,
    /// Not answered and not applied (no animation part at all).
    Ignore,
}

/// How a terminal treats a virtual placement (`U=1`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Placeholders {
    /// Virtual: nothing shown until placeholder cells are printed; answered `OK`.
    Honour,
    /// The unknown key rejects the whole command, silently (kitty 0.26).
    RejectSilently,
    /// The key is not known and the placement is made as a normal one (moving the cursor);
    /// answered `OK` when not quiet (Konsole; WezTerm before placeholders).
    PlaceNormally,
}

/// The kitty graphics protocol as one terminal speaks it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Kitty {
    /// Temporary files (`t=t`) are read.
    pub temp_files: bool,
    /// `ENOTSUPPORTED` for any medium but `t=d` (Konsole) instead of reading it.
    pub direct_only: bool,
    /// Root-frame edits.
    pub edits: Edits,
    /// Virtual placements.
    pub placeholders: Placeholders,
}

/// How a terminal answers the colour questions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tcap {
    /// XTGETTCAP `RGB` (and `Tc`) found.
    Rgb,
    /// Answered "not found".
    Missing,
    /// Not answered.
    Silent,
}

/// What DECRQSS of the SGR in effect reports.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sgr {
    /// The 24-bit colour as set (colon form, as xterm and kitty report it).
    TrueColor,
    /// The nearest 256-colour index (a terminal that keeps no 24-bit colours).
    Palette,
    /// Not answered.
    Silent,
}

/// One terminal's behaviour.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Profile {
    /// A name for messages.
    pub name: &'static str,
    /// `TERM` as the terminal sets it.
    pub term: &'static str,
    /// The DA1 answer.
    pub da1: &'static [u8],
    /// kitty graphics, if spoken.
    pub kitty: Option<Kitty>,
    /// Sixel colour registers answered by XTSMGRAPHICS (`None`: not answered).
    pub sixel_registers: Option<u16>,
    /// Answers iTerm2's `ReportCellSize`.
    pub iterm2_cell_size: bool,
    /// Cell size answered to `CSI 16 t` (width, height).
    pub cell_px: Option<(u16, u16)>,
    /// Answers DECRQM for 2026 and 1016 as set/reset.
    pub modes: bool,
    /// XTGETTCAP.
    pub tcap: Tcap,
    /// DECRQSS for SGR.
    pub sgr: Sgr,
}

const DA1_TEXT: &[u8] = b"\x1b[?62;22c";

impl Profile {
    /// Debian 12's kitty 0.26: kitty graphics with frame edits and temporary files, no Unicode
    /// placeholders (added in 0.28; 0.26 rejects `U=1` without a word), true colour (its
    /// terminfo has `RGB`... answered by XTGETTCAP, and DECRQSS keeps 24-bit colours).
    pub fn kitty_026() -> Profile {
        Profile {
            name: "kitty 0.26",
            term: "xterm-kitty",
            da1: b"\x1b[?62;c",
            kitty: Some(Kitty {
                temp_files: true,
                direct_only: false,
                edits: Edits::Apply,
                placeholders: Placeholders::RejectSilently,
            }),
            sixel_registers: None,
            iterm2_cell_size: false,
            cell_px: Some((8, 16)),
            modes: true,
            tcap: Tcap::Rgb,
            sgr: Sgr::TrueColor,
        }
    }

    /// A current kitty: everything, Unicode placeholders too.
    pub fn kitty_current() -> Profile {
        let mut p = Profile::kitty_026();
        p.name = "kitty (current)";
        p.kitty = Some(Kitty { placeholders: Placeholders::Honour, ..p.kitty.unwrap() });
        p
    }

    /// Ghostty: kitty graphics and Unicode placeholders, no animation frames (`a=f` gets a
    /// response without an id, which is never sent).
    pub fn ghostty() -> Profile {
        Profile {
            name: "Ghostty",
            term: "xterm-ghostty",
            da1: b"\x1b[?62;22;52c",
            kitty: Some(Kitty {
                temp_files: true,
                direct_only: false,
                edits: Edits::Ignore,
                placeholders: Placeholders::Honour,
            }),
            sixel_registers: None,
            iterm2_cell_size: false,
            cell_px: Some((8, 16)),
            modes: true,
            tcap: Tcap::Rgb,
            sgr: Sgr::TrueColor,
        }
    }

    /// WezTerm (a release before Unicode placeholders): kitty graphics with frames, a `U=1`
    /// placement made as a normal one, sixel, iTerm2's cell size report; `TERM` is
    /// xterm-256color unless its terminfo is installed.
    pub fn wezterm() -> Profile {
        Profile {
            name: "WezTerm",
            term: "xterm-256color",
            da1: b"\x1b[?65;4;6;18;22c",
            kitty: Some(Kitty {
                temp_files: true,
                direct_only: false,
                edits: Edits::Apply,
                placeholders: Placeholders::PlaceNormally,
            }),
            sixel_registers: Some(256),
            iterm2_cell_size: true,
            cell_px: Some((8, 16)),
            modes: true,
            tcap: Tcap::Silent,
            sgr: Sgr::TrueColor,
        }
    }

    /// Konsole: kitty graphics by direct transmission only, no frames, `U=1` placed normally
    /// and answered `OK`; DA1 with sixel (no XTSMGRAPHICS answer); iTerm2's cell size report.
    pub fn konsole() -> Profile {
        Profile {
            name: "Konsole",
            term: "xterm-256color",
            da1: b"\x1b[?62;1;4c",
            kitty: Some(Kitty {
                temp_files: false,
                direct_only: true,
                edits: Edits::Ignore,
                placeholders: Placeholders::PlaceNormally,
            }),
            sixel_registers: None,
            iterm2_cell_size: true,
            cell_px: Some((8, 16)),
            modes: false,
            tcap: Tcap::Silent,
            sgr: Sgr::Silent,
        }
    }

    /// A kitty-protocol terminal as the issue measured it: DA1 and the graphics query
    /// answered, frame edits as `edits` says, nothing else.
    pub fn kitty_minimal(edits: Edits) -> Profile {
        Profile {
            name: "kitty query only",
            term: "xterm-256color",
            da1: DA1_TEXT,
            kitty: Some(Kitty {
                temp_files: false,
                direct_only: false,
                edits,
                placeholders: Placeholders::RejectSilently,
            }),
            sixel_registers: None,
            iterm2_cell_size: false,
            cell_px: None,
            modes: false,
            tcap: Tcap::Silent,
            sgr: Sgr::Silent,
        }
    }

    /// xterm `-ti vt340` with 256 colour registers.
    pub fn xterm_vt340() -> Profile {
        Profile {
            name: "xterm -ti vt340",
            term: "xterm-256color",
            da1: b"\x1b[?63;1;2;4;6;9;15;16;22;28c",
            kitty: None,
            sixel_registers: Some(256),
            iterm2_cell_size: false,
            cell_px: Some((8, 16)),
            modes: true,
            tcap: Tcap::Missing,
            sgr: Sgr::TrueColor,
        }
    }

    /// A text terminal answering the colour questions as `tcap` and `sgr` say.
    pub fn text(tcap: Tcap, sgr: Sgr) -> Profile {
        Profile {
            name: "text",
            term: "xterm-256color",
            da1: DA1_TEXT,
            kitty: None,
            sixel_registers: None,
            iterm2_cell_size: false,
            cell_px: None,
            modes: false,
            tcap,
            sgr,
        }
    }
}

/// Debian 12's kitty 0.26 drawing with llvmpipe on a loaded machine: its own time to answer
/// the `n`th device-attributes question, as recorded both ways between kitty and ssh (4970
/// answers: median 18 ms, 90th percentile 98 ms, now and then most of a second). A fixed
/// sequence with those quantiles; the fake is busy (reads nothing) meanwhile, as kitty is
/// while it draws.
pub fn kitty_026_answer_time(n: u32) -> std::time::Duration {
    let u = u64::from((n.wrapping_mul(2_654_435_761) >> 8) % 1000);
    std::time::Duration::from_millis(match u {
        0..=499 => 2 + u * 16 / 500,
        500..=899 => 18 + (u - 500) * 80 / 400,
        900..=989 => 98 + (u - 900) * 300 / 90,
        _ => 400 + (u - 990) * 68,
    })
}

/// The link's rate the status line shows ("... of 286.3 kB/s"), bytes a second; `None` where it
/// shows none (no limit, or no status line yet).
pub fn status_rate(status: &str) -> Option<f64> {
    let after = &status[status.find(" of ")? + 4..];
    let mut words = after.split_whitespace();
    let number: f64 = words.next()?.parse().ok()?;
    let unit = match words.next()? {
        "B/s" => 1.0,
        "kB/s" => 1e3,
        "MB/s" => 1e6,
        _ => return None,
    };
    Some(number * unit)
}
