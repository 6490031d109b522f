//! Fake graphics terminals: each answers the player's questions and takes its pictures as one
//! real terminal does, from that terminal's documented behaviour (and its source where the
//! documentation is silent), so that a test can drive the real binary through a pseudo-terminal
//! or an SSH channel and see what a user of that terminal would see.
//!
//! A [`FakeTerminal`] is fed everything the program writes ([`FakeTerminal::feed`]) and
//! returns the bytes the terminal would answer, in order. It keeps:
//! - the text screen (a [`TerminalModel`]: half-block cells and the status line);
//! - the kitty graphics commands it accepted, rewritten as direct transmissions (a temporary
//!   file is read, and deleted, as the terminal reads it), for the independent decoder
//!   (`scripts/kitty_decode.py`); and whether the image is placed where it shows;
//! - the sixel images and iTerm2 files it was sent;
//! - the SGR colour in effect, for DECRQSS.
//!
//! The profiles ([`Profile`]) say which parts of each protocol a terminal speaks: kitty 0.26
//! (Debian 12's: frame edits, no Unicode placeholders: an unknown key rejects the whole
//! command without a word), a current kitty, Ghostty (kitty graphics without the animation
//! part: `a=f` is answered with nothing, its response carries no id), WezTerm (frame edits, no
//! Unicode placeholders: a `U=1` placement is made as a normal one), Konsole (direct
//! transmission only: `t=t` is answered `ENOTSUPPORTED`, `a=f` ignored, `U=1` placed as a
//! normal placement and answered `OK`; DA1 says sixel; iTerm2's cell size report), xterm
//! `-ti vt340` (sixel) and plain text terminals; and how each answers the colour questions
//! (XTGETTCAP `RGB`/`Tc`, DECRQSS of a 24-bit SGR colour).

use std::collections::BTreeMap;

use base64::Engine;
use base64::engine::general_purpose::STANDARD as BASE64;
use tidepool::testing::TerminalModel;

mod canvas;
mod profiles;
mod shown;

pub use canvas::Canvas;
pub use profiles::{Edits, Placeholders, Profile, Sgr, Tcap, kitty_026_answer_time, status_rate};
pub use shown::{Shown, Watch};

/// kitty's chunked transmission in progress: the first chunk's keys, the payload so far.
type Loading = (BTreeMap<char, String>, Vec<u8>);

/// A fake terminal (see the module docs).
pub struct FakeTerminal {
    pub profile: Profile,
    /// The text screen.
    pub screen: TerminalModel,
    /// The kitty commands accepted, as direct transmissions.
    pub kitty_stream: Vec<u8>,
    /// Each kitty image placed where it shows (id -> true), or placed virtually.
    pub placed: BTreeMap<u32, bool>,
    /// The sixel images received (each from `ESC P` to `ESC \`).
    pub sixels: Vec<Vec<u8>>,
    /// The pixels the sixel images painted.
    pub canvas: Canvas,
    /// Sixel images icy_sixel could not decode.
    pub broken_sixels: usize,
    /// The iTerm2 files received (their base64 payloads decoded).
    pub iterm2_files: Vec<Vec<u8>>,
    /// Everything received.
    pub raw: Vec<u8>,
    /// Device-attributes questions seen (the probe's and the link's).
    pub da1_questions: usize,
    /// kitty error replies sent.
    pub kitty_errors: usize,
    pending: Vec<u8>,
    loading: Option<Loading>,
    /// The SGR foreground in effect, as its parameters.
    sgr_fg: Option<String>,
    /// Stop answering DA1 after this many (a terminal that falls silent), if set.
    pub answer_da1: bool,
}

impl FakeTerminal {
    /// A terminal of `cols x rows` cells behaving as `profile`.
    pub fn new(profile: Profile, cols: usize, rows: usize) -> FakeTerminal {
        let (w, h) = profile.cell_px.unwrap_or((8, 16));
        let cell = (usize::from(w), usize::from(h));
        let mut screen = TerminalModel::new(cols, rows);
        // Raw mode: a line feed moves down only.
        screen.lf_returns = false;
        FakeTerminal {
            profile,
            screen,
            kitty_stream: Vec::new(),
            placed: BTreeMap::new(),
            sixels: Vec::new(),
            canvas: Canvas::new(cols, rows, cell),
            broken_sixels: 0,
            iterm2_files: Vec::new(),
            raw: Vec::new(),
            da1_questions: 0,
            kitty_errors: 0,
            pending: Vec::new(),
            loading: None,
            sgr_fg: None,
            answer_da1: true,
        }
    }

    /// Takes what the program wrote; returns the terminal's answers, in order.
    pub fn feed(&mut self, bytes: &[u8]) -> Vec<u8> {
        self.raw.extend_from_slice(bytes);
        self.pending.extend_from_slice(bytes);
        let mut answers = Vec::new();
        let mut at = 0;
        let buf = std::mem::take(&mut self.pending);
        // The screen sees each sequence as it is taken, so the cursor is where a picture that
        // follows is drawn.
        while let Some(rel) = buf[at..].iter().position(|&b| b == 0x1b) {
            let start = at + rel;
            match sequence_len(&buf[start..]) {
                Some(len) => {
                    self.screen.feed(&buf[at..start + len]);
                    self.sequence(&buf[start..start + len], &mut answers);
                    at = start + len;
                }
                None => {
                    self.screen.feed(&buf[at..start]);
                    self.pending = buf[start..].to_vec();
                    return answers;
                }
            }
        }
        self.screen.feed(&buf[at..]);
        answers
    }

    fn sequence(&mut self, seq: &[u8], answers: &mut Vec<u8>) {
        match seq.get(1) {
            Some(b'_') if seq.get(2) == Some(&b'G') => self.kitty(&seq[3..seq.len() - 2], answers),
            Some(b'P') => self.dcs(&seq[2..seq.len() - 2], seq, answers),
            Some(b']') => {
                let body = seq[2..].strip_suffix(b"\x1b\\").or_else(|| seq[2..].strip_suffix(b"\x07")).unwrap_or(&[]);
                self.osc(body, answers);
            }
            Some(b'[') => self.csi(&seq[2..], answers),
            _ => {}
        }
    }

    fn csi(&mut self, body: &[u8], answers: &mut Vec<u8>) {
        let p = &self.profile;
        match body {
            b"c" => {
                self.da1_questions += 1;
                if self.answer_da1 {
                    answers.extend_from_slice(p.da1);
                }
            }
            b"?1;1;0S" => {
                if let Some(n) = p.sixel_registers {
                    answers.extend_from_slice(format!("\x1b[?1;0;{n}S").as_bytes());
                }
            }
            b"?2;1;0S" if p.sixel_registers.is_some() => answers.extend_from_slice(b"\x1b[?2;0;4096;4096S"),
            b"16t" => {
                if let Some((w, h)) = p.cell_px {
                    answers.extend_from_slice(format!("\x1b[6;{h};{w}t").as_bytes());
                }
            }
            b"?2026$p" if p.modes => answers.extend_from_slice(b"\x1b[?2026;2$y"),
            b"?1016$p" if p.modes => answers.extend_from_slice(b"\x1b[?1016;2$y"),
            b"6n" => {
                let (x, y) = self.screen.cursor();
                answers.extend_from_slice(format!("\x1b[{};{}R", y + 1, x + 1).as_bytes());
            }
            _ if body.ends_with(b"m") => self.sgr(&body[..body.len() - 1]),
            _ => {}
        }
    }

    /// Keeps the foreground colour set by SGR, for DECRQSS.
    fn sgr(&mut self, params: &[u8]) {
        let text = String::from_utf8_lossy(params).into_owned();
        let parts: Vec<&str> = text.split(';').collect();
        let mut i = 0;
        while i < parts.len() {
            match parts[i] {
                "" | "0" => self.sgr_fg = None,
                "38" if parts.get(i + 1) == Some(&"2") && i + 4 < parts.len() => {
                    self.sgr_fg = Some(format!("38:2::{}:{}:{}", parts[i + 2], parts[i + 3], parts[i + 4]));
                    i += 4;
                }
                "38" if parts.get(i + 1) == Some(&"5") && i + 2 < parts.len() => {
                    self.sgr_fg = Some(format!("38:5:{}", parts[i + 2]));
                    i += 2;
                }
                "39" => self.sgr_fg = None,
                _ => {}
            }
            i += 1;
        }
    }

    fn dcs(&mut self, body: &[u8], whole: &[u8], answers: &mut Vec<u8>) {
        if let Some(names) = body.strip_prefix(b"+q") {
            match self.profile.tcap {
                Tcap::Silent => {}
                tcap => {
                    for name in names.split(|&b| b == b';') {
                        let known = tcap == Tcap::Rgb && (name == b"524742" || name == b"5463");
                        let reply = if known {
                            format!("\x1bP1+r{}\x1b\\", String::from_utf8_lossy(name))
                        } else {
                            format!("\x1bP0+r{}\x1b\\", String::from_utf8_lossy(name))
                        };
                        answers.extend_from_slice(reply.as_bytes());
                    }
                }
            }
        } else if body == b"$qm" {
            let fg = match (self.profile.sgr, &self.sgr_fg) {
                (Sgr::Silent, _) => return,
                (Sgr::TrueColor, Some(fg)) => format!("0;{fg}"),
                (Sgr::Palette, Some(fg)) if fg.starts_with("38:2::") => {
                    let v: Vec<u32> = fg[6..].split(':').map(|x| x.parse().unwrap_or(0)).collect();
                    let level = |c: u32| (c * 5 + 127) / 255;
                    format!("0;38:5:{}", 16 + 36 * level(v[0]) + 6 * level(v[1]) + level(v[2]))
                }
                (_, Some(fg)) => format!("0;{fg}"),
                (_, None) => "0".to_string(),
            };
            answers.extend_from_slice(format!("\x1bP1$r{fg}m\x1b\\").as_bytes());
        } else if body.iter().take(16).any(|&b| b == b'q') && self.profile.da1.windows(2).any(|w| w == b";4") {
            self.sixels.push(whole.to_vec());
            self.draw_sixel(whole);
        }
    }

    fn osc(&mut self, body: &[u8], answers: &mut Vec<u8>) {
        if body == b"1337;ReportCellSize" && self.profile.iterm2_cell_size {
            let (w, h) = self.profile.cell_px.unwrap_or((8, 16));
            answers.extend_from_slice(format!("\x1b]1337;ReportCellSize={h}.0;{w}.0;1.0\x1b\\").as_bytes());
        } else if let Some(rest) = body.strip_prefix(b"1337;File=")
            && self.profile.iterm2_cell_size
            && let Some(colon) = rest.iter().position(|&b| b == b':')
            && let Ok(file) = BASE64.decode(&rest[colon + 1..])
        {
            self.iterm2_files.push(file);
        }
    }

    /// A kitty graphics command (`keys;payload`).
    fn kitty(&mut self, body: &[u8], answers: &mut Vec<u8>) {
        let Some(k) = self.profile.kitty else { return };
        let text = String::from_utf8_lossy(body).into_owned();
        let (control, payload) = text.split_once(';').unwrap_or((&text, ""));
        let mut keys: BTreeMap<char, String> = BTreeMap::new();
        for kv in control.split(',').filter(|s| !s.is_empty()) {
            if let Some((key, value)) = kv.split_once('=')
                && let Some(c) = key.chars().next()
            {
                keys.insert(c, value.to_string());
            }
        }
        // A chunk continuing a transmission: the first chunk's keys count.
        if let Some((first, mut data)) = self.loading.take() {
            data.extend_from_slice(payload.as_bytes());
            if keys.get(&'m').map(String::as_str) == Some("1") {
                self.loading = Some((first, data));
                return;
            }
            let data = String::from_utf8(data).unwrap_or_default();
            self.complete(first, &data, answers);
            return;
        }
        if keys.contains_key(&'U') && k.placeholders == Placeholders::RejectSilently {
            return;
        }
        if keys.get(&'m').map(String::as_str) == Some("1") {
            self.loading = Some((keys, payload.as_bytes().to_vec()));
            return;
        }
        self.complete(keys, payload, answers);
    }

    /// A whole kitty command.
    fn complete(&mut self, mut keys: BTreeMap<char, String>, payload: &str, answers: &mut Vec<u8>) {
        let k = self.profile.kitty.expect("kitty commands reach a kitty terminal only");
        let id: u32 = keys.get(&'i').and_then(|v| v.parse().ok()).unwrap_or(0);
        let quiet: u8 = keys.get(&'q').and_then(|v| v.parse().ok()).unwrap_or(0);
        let action = keys.get(&'a').cloned().unwrap_or_else(|| "t".into());
        let reply = |message: &str, answers: &mut Vec<u8>, errors: &mut usize| {
            let ok = message == "OK";
            if id > 0 && (quiet == 0 || (quiet == 1 && !ok)) {
                answers.extend_from_slice(format!("\x1b_Gi={id};{message}\x1b\\").as_bytes());
            }
            *errors += usize::from(!ok);
        };
        let medium = keys.get(&'t').cloned().unwrap_or_else(|| "d".into());
        let mut payload = payload.to_string();
        if matches!(action.as_str(), "t" | "T" | "q" | "f") && medium != "d" {
            if k.direct_only {
                if quiet < 2 {
                    answers.extend_from_slice(format!("\x1b_Gi={id};ENOTSUPPORTED:\x1b\\").as_bytes());
                }
                self.kitty_errors += 1;
                return;
            }
            // The terminal reads the file (and deletes a temporary one) as it takes the command.
            let path = BASE64.decode(payload.as_bytes()).ok().and_then(|p| String::from_utf8(p).ok());
            let data = match path {
                Some(path) if k.temp_files && path.contains("tty-graphics-protocol") => {
                    let data = std::fs::read(&path).ok();
                    let _ = std::fs::remove_file(&path);
                    data
                }
                _ => None,
            };
            let Some(data) = data else {
                reply("EBADF:cannot read the file", answers, &mut self.kitty_errors);
                return;
            };
            keys.insert('t', "d".into());
            keys.remove(&'o');
            payload = BASE64.encode(data);
        }
        match action.as_str() {
            "q" => reply("OK", answers, &mut self.kitty_errors),
            "f" => match k.edits {
                Edits::Ignore => {}
                Edits::Refuse => reply("ENOENT:no such frame", answers, &mut self.kitty_errors),
                Edits::Apply => {
                    self.record(&keys, &payload);
                    reply("OK", answers, &mut self.kitty_errors);
                }
            },
            "t" | "T" => {
                self.record(&keys, &payload);
                if action == "T" {
                    let virtual_placement = keys.contains_key(&'U') && k.placeholders == Placeholders::Honour;
                    self.placed.insert(id, !virtual_placement);
                }
                reply("OK", answers, &mut self.kitty_errors);
            }
            "p" => {
                let virtual_placement = keys.contains_key(&'U') && k.placeholders == Placeholders::Honour;
                self.placed.insert(id, !virtual_placement);
                reply("OK", answers, &mut self.kitty_errors);
            }
            "d" => {
                self.record(&keys, "");
                self.placed.remove(&id);
            }
            _ => {}
        }
    }

    /// Appends a command to the stream kept for the decoder.
    fn record(&mut self, keys: &BTreeMap<char, String>, payload: &str) {
        let control: Vec<String> = keys.iter().filter(|(k, _)| **k != 'm').map(|(k, v)| format!("{k}={v}")).collect();
        self.kitty_stream.extend_from_slice(b"\x1b_G");
        self.kitty_stream.extend_from_slice(control.join(",").as_bytes());
        self.kitty_stream.push(b';');
        self.kitty_stream.extend_from_slice(payload.as_bytes());
        self.kitty_stream.extend_from_slice(b"\x1b\\");
    }

    /// The last row's text.
    pub fn status(&self) -> String {
        self.screen.row_text(self.screen.rows() - 1)
    }

    /// Whether every half-block pixel of the picture rows shows a colour (the picture drawn in
    /// cells).
    pub fn cells_drawn(&self) -> bool {
        let (cols, rows) = (self.screen.cols(), self.screen.rows());
        (0..2 * (rows - 1)).all(|y| (0..cols).all(|x| self.screen.pixel(x, y).is_some()))
    }

    /// The text cells that show placeholder characters (U+10EEEE).
    pub fn placeholder_cells(&self) -> usize {
        let (cols, rows) = (self.screen.cols(), self.screen.rows());
        (0..rows).map(|y| (0..cols).filter(|&x| self.screen.cell(x, y).ch == '\u{10EEEE}').count()).sum()
    }
}

/// The length of the escape sequence at the start of `bytes`, or `None` when it is not
/// complete yet.
fn sequence_len(bytes: &[u8]) -> Option<usize> {
    match bytes.get(1)? {
        b'_' | b'P' | b']' | b'^' | b'X' => {
            let osc = bytes[1] == b']';
            let mut i = 2;
            while i < bytes.len() {
                match bytes[i] {
                    0x1b if bytes.get(i + 1) == Some(&b'\\') => return Some(i + 2),
                    0x1b if i + 1 == bytes.len() => return None,
                    0x07 if osc => return Some(i + 1),
                    _ => {}
                }
                i += 1;
            }
            None
        }
        b'[' => {
            let i = bytes[2..].iter().position(|&b| (0x40..=0x7e).contains(&b))?;
            Some(2 + i + 1)
        }
        _ => Some(2),
    }
}

/// The independent kitty decoder (`scripts/kitty_decode.py`).
const KITTY_DECODER: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/scripts/kitty_decode.py");

/// A kitty image as the independent decoder read it.
pub struct DecodedImage {
    pub id: u32,
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<u8>,
}

impl DecodedImage {
    /// How many distinct colours it has (a picture of water has hundreds; a flat image one).
    pub fn colours(&self) -> usize {
        shown::distinct(&self.rgb)
    }
}

impl FakeTerminal {
    /// Decodes a kitty command stream (as [`FakeTerminal::kitty_stream`] keeps it) with the
    /// independent decoder; `name` keeps parallel tests' files apart.
    pub fn decode_kitty(name: &str, stream: &[u8]) -> Vec<DecodedImage> {
        let dir = std::env::temp_dir().join(format!(
            "tidepool-fake-{}-{}-{:?}",
            name.replace(' ', "_"),
            std::process::id(),
            std::thread::current().id()
        ));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let input = dir.join("stream.bin");
        std::fs::write(&input, stream).unwrap();
        let out = std::process::Command::new("python3")
            .arg(KITTY_DECODER)
            .arg(&input)
            .arg(&dir)
            .output()
            .unwrap_or_else(|e| panic!("the kitty checks need python3 to run {KITTY_DECODER}: {e}"));
        assert!(
            out.status.success(),
            "the independent decoder refused the stream: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let images = String::from_utf8(out.stdout)
            .unwrap()
            .lines()
            .map(|line| {
                let v: Vec<u32> = line.split(' ').map(|x| x.parse().unwrap()).collect();
                let ppm = std::fs::read(dir.join(format!("image-{}.ppm", v[0]))).unwrap();
                let header = format!("P6\n{} {}\n255\n", v[1], v[2]);
                assert!(ppm.starts_with(header.as_bytes()));
                DecodedImage { id: v[0], width: v[1], height: v[2], rgb: ppm[header.len()..].to_vec() }
            })
            .collect();
        let _ = std::fs::remove_dir_all(&dir);
        images
    }

    /// Whether a kitty image is placed where it shows (a normal placement, or a virtual one
    /// with placeholder cells on the screen).
    pub fn kitty_shown(&self, id: u32) -> bool {
        match self.placed.get(&id) {
            Some(true) => true,
            Some(false) => self.placeholder_cells() > 0,
            None => false,
        }
    }
}
